#include "mechbench/analytic/energy.h"

#include "mechbench/errors.h"

namespace mechbench::analytic {
namespace {

// Velocity of a basic point for a given q̇ (fixed and eliminated coordinates do not move).
Eigen::Vector2d PointVelocity(const Model& m, int point, const Eigen::VectorXd& qd) {
  Eigen::Vector2d v = Eigen::Vector2d::Zero();
  for (int axis = 0; axis < 2; ++axis)
    if (const int s = m.SlotOf(point, axis); s >= 0) v[axis] = qd[s];
  return v;
}

// Body-frame coordinates (X, Y)/L of a material point as the map C.
Eigen::Matrix2d Interpolation(const Body& b, const Eigen::Vector2d& p_B) {
  const double L = b.Length();
  Eigen::Matrix2d C;
  C << p_B.x() / L, -p_B.y() / L, p_B.y() / L, p_B.x() / L;
  return C;
}

double KineticEnergy(const Model& m, const Eigen::VectorXd& qd) {
  double T = 0;
  for (const Body& b : m.bodies) {
    if (!b.HasMass() || b.points.size() < 2) continue;
    const Eigen::Vector2d v0 = PointVelocity(m, b.points[0], qd);
    const Eigen::Vector2d u = PointVelocity(m, b.points[1], qd) - v0;  // ṙ_01
    const Eigen::Vector2d vG = v0 + Interpolation(b, b.com_B) * u;   // v_G = v0 + ω × r_0G
    const double L = b.Length();
    T += 0.5 * b.mass * vG.squaredNorm() + 0.5 * b.inertia_com * u.squaredNorm() / (L * L);
  }
  return T;
}

// Power of gravity and of the point forces for a given q̇: Q·q̇.
double LoadPower(const Model& m, const Eigen::VectorXd& qd) {
  double P = 0;
  for (const Body& b : m.bodies) {
    if (!b.HasMass() || b.points.size() < 2) continue;
    const Eigen::Vector2d v0 = PointVelocity(m, b.points[0], qd);
    const Eigen::Vector2d u = PointVelocity(m, b.points[1], qd) - v0;
    P += b.mass * m.gravity.dot(v0 + Interpolation(b, b.com_B) * u);
  }
  for (const PointForce& f : m.forces) P += f.f_W.dot(PointVelocity(m, f.point, qd));
  return P;
}

}  // namespace

MassAndForces MassAndForcesByEnergy(const Model& m) {
  for (const Body& b : m.bodies)
    MB_ASSERT(!b.HasMass() || b.points.size() >= 2, "a massive linkage body has two points");
  const int n = static_cast<int>(m.q_layout.size());
  MassAndForces out{Eigen::MatrixXd::Zero(n, n), Eigen::VectorXd::Zero(n)};
  // T is a quadratic form ½ q̇ᵀ M q̇: read M off it by polarisation, Q off the power.
  auto e = [n](int i) { Eigen::VectorXd v = Eigen::VectorXd::Zero(n); v[i] = 1; return v; };
  for (int i = 0; i < n; ++i) {
    out.M(i, i) = 2 * KineticEnergy(m, e(i));
    out.Q[i] = LoadPower(m, e(i));
  }
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j)
      out.M(i, j) = out.M(j, i) = KineticEnergy(m, e(i) + e(j)) - 0.5 * (out.M(i, i) + out.M(j, j));
  return out;
}

}  // namespace mechbench::analytic
