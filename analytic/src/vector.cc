#include "mechbench/analytic/vector.h"

#include <cmath>

namespace mechbench::analytic {

Vec3 Unit(const Vec3& r) { return r / r.norm(); }
Vec2 Unit(const Vec2& r) { return r / r.norm(); }

double AngleBetween(const Vec3& a, const Vec3& b) { return std::atan2(Cross(a, b).norm(), a.dot(b)); }

Vec3 Cross(const Vec3& a, const Vec3& b) {
  // Expansion of the determinant |i j k; a; b| along its first row (eq. 1.11).
  return Vec3(a.y() * b.z() - a.z() * b.y(), -(a.x() * b.z() - a.z() * b.x()), a.x() * b.y() - a.y() * b.x());
}

Mat3 Skew(const Vec3& r) {
  Mat3 m;
  m << 0, -r.z(), r.y(),  //
      r.z(), 0, -r.x(),   //
      -r.y(), r.x(), 0;
  return m;
}

Vec3 TripleCross(const Vec3& a, const Vec3& b, const Vec3& c) { return Cross(a, Cross(b, c)); }

double TripleScalar(const Vec3& a, const Vec3& b, const Vec3& c) { return a.dot(Cross(b, c)); }

Vec2 Direction(double phi) { return Vec2(std::cos(phi), std::sin(phi)); }

bool SolveCramer2(const Vec2& c1, const Vec2& c2, const Vec2& rhs, double& x1, double& x2, double tol) {
  const double det = Cross2(c1, c2);
  const double scale = c1.norm() * c2.norm();
  if (!(std::fabs(det) > tol * scale)) return false;
  x1 = Cross2(rhs, c2) / det;
  x2 = Cross2(c1, rhs) / det;
  return true;
}

}  // namespace mechbench::analytic
