#include "mechbench/analytic/kinematics.h"

#include <cmath>
#include <limits>

namespace mechbench::analytic {

PointState3 RigidBodyPoint(const PointState3& A, const Vec3& omega, const Vec3& alpha, const Vec3& p_B) {
  const Vec3 r_AB = p_B - A.p;
  PointState3 B;
  B.p = p_B;
  B.v = A.v + Cross(omega, r_AB);
  B.a = A.a + Cross(alpha, r_AB) + TripleCross(omega, omega, r_AB);
  return B;
}

PointState3 MovingFramePoint(const PointState3& A, const Vec3& omega, const Vec3& alpha, const Vec3& p_B,
                             const Vec3& v_rel, const Vec3& a_rel) {
  PointState3 B = RigidBodyPoint(A, omega, alpha, p_B);  // the drag (arrastre) terms
  B.v += v_rel;
  B.a += a_rel + 2.0 * Cross(omega, v_rel);  // relative + Coriolis
  return B;
}

Intrinsic IntrinsicCoordinates(const Vec3& p, const Vec3& v, const Vec3& a) {
  Intrinsic r;
  r.speed = v.norm();
  r.e_t = v / r.speed;
  r.a_t = a.dot(r.e_t);
  const Vec3 a_n = a - r.a_t * r.e_t;  // the component of a normal to the path
  r.a_n = a_n.norm();
  // |v×a| = |v| a_n; comparing against the size of a keeps a straight path straight.
  const double vxa = Cross(v, a).norm();
  if (r.a_n > 1e-13 * (a.norm() + r.speed * r.speed) && vxa > 0) {
    r.radius = r.speed * r.speed * r.speed / vxa;
    r.e_n = a_n / r.a_n;
    r.centre = p + r.radius * r.e_n;
  } else {
    r.radius = std::numeric_limits<double>::infinity();
    r.centre = Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
  }
  return r;
}

}  // namespace mechbench::analytic
