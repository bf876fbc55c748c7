#include "mechbench/analytic/energy.h"

#include "mechbench/errors.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

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

// The points whose velocities carry a body: its first two; a point body's point and, on a guide
// along a moving body (model.h), the guide's first two, which turn the block.
std::vector<int> CarryingPoints(const Model& m, const Body& b) {
  if (!b.IsPointBody()) return {b.points[0], b.points[1]};
  if (b.guide >= 0 && m.joints[b.guide].type == JointType::kPointOnBody) {
    const Body& g = m.bodies[m.joints[b.guide].body];
    return {b.points[0], g.points[0], g.points[1]};
  }
  return {b.points[0]};
}

// A body's centre-of-mass velocity v_G and ω² (as |ṙ_01|²/L²) from its carrying points'
// velocities: v_G = v0 + C(com) ṙ_01 for a body on its first two points, and for a point body
// v_G = v_P + C(com) ṙ_12 with the block's x axis along its moving guide 1→2 (ω² from the
// guide), or v_G = v_P without one (a fixed guide or none: the block does not turn).
struct BodyMotion {
  Eigen::Vector2d vG;
  double omega2 = 0;
};
template <class Velocity>
BodyMotion Motion(const Model& m, const Body& b, const Velocity& velocity) {
  const std::vector<int> P = CarryingPoints(m, b);
  if (P.size() == 1) return {velocity(P[0]), 0.0};
  const bool point_body = P.size() == 3;
  const Body& frame = point_body ? m.bodies[m.joints[b.guide].body] : b;
  const Eigen::Vector2d v0 = velocity(P[0]);
  const Eigen::Vector2d u = velocity(P[point_body ? 2 : 1]) - velocity(P[point_body ? 1 : 0]);  // ṙ_01 or ṙ_12
  const double L = frame.Length();
  return {v0 + Interpolation(frame, b.com_B) * u, u.squaredNorm() / (L * L)};
}

double KineticEnergy(const Model& m, const Eigen::VectorXd& qd) {
  double T = 0;
  for (const Body& b : m.bodies) {
    if (!b.HasMass() || b.points.empty()) continue;
    const BodyMotion mo = Motion(m, b, [&](int p) { return PointVelocity(m, p, qd); });
    T += 0.5 * b.mass * mo.vG.squaredNorm() + 0.5 * b.inertia_com * mo.omega2;
  }
  return T;
}

double MetersPerUnit(const std::string& unit) { return unit == "mm" ? 1e-3 : unit == "cm" ? 1e-2 : 1.0; }

// Power of gravity and of the point forces for a given q̇: Q·q̇, in newtons per coordinate (as
// numeric's Q and the force elements': gravity in m/s², whatever the file's length unit).
double LoadPower(const Model& m, const Eigen::VectorXd& qd) {
  double P = 0;
  for (const Body& b : m.bodies) {
    if (!b.HasMass() || b.points.empty()) continue;
    const BodyMotion mo = Motion(m, b, [&](int p) { return PointVelocity(m, p, qd); });
    P += b.mass * (m.gravity * MetersPerUnit(m.length_unit)).dot(mo.vG);
  }
  for (const PointForce& f : m.forces)
    if (f.IsConstantWorld()) P += f.f_W.dot(PointVelocity(m, f.point, qd));  // the others: ElementForcesByPower
  return P;
}

Eigen::Vector2d PointPosition(const Model& m, int point, const Eigen::VectorXd& q) {
  Eigen::Vector2d r = m.points[point].p_W;  // fixed, or the constant of an eliminated coordinate
  for (int axis = 0; axis < 2; ++axis)
    if (const int s = m.SlotOf(point, axis); s >= 0) r[axis] = q[s];
  return r;
}

// The varying point forces' Q (a law, or a body frame: PointForce) by virtual power f_W·v_P for
// each unit q̇, the body frame's direction (cos φ, sin φ) read as the angle of its first two points
// (atan2, not numeric's d/L), the laws at the load variables x.
void AddVaryingPointForces(const Model& m, const Eigen::VectorXd& q, const std::vector<double>& x, Eigen::VectorXd& Q) {
  const int n = static_cast<int>(Q.size());
  for (const PointForce& f : m.forces) {
    if (f.IsConstantWorld()) continue;
    Eigen::Vector2d F = f.components;
    for (int k = 0; k < 2; ++k)
      if (f.law[k]) F[k] = f.law[k]->Eval(x.data());
    Eigen::Vector2d f_W = F;
    if (f.frame >= 0) {
      const Body& b = m.bodies[f.frame];
      const Eigen::Vector2d r01 = PointPosition(m, b.points[1], q) - PointPosition(m, b.points[0], q);
      const double phi = std::atan2(r01.y(), r01.x());
      f_W = Eigen::Rotation2Dd(phi) * F;
    }
    for (int i = 0; i < n; ++i) {
      Eigen::VectorXd ei = Eigen::VectorXd::Zero(n);
      ei[i] = 1;
      Q[i] += f_W.dot(PointVelocity(m, f.point, ei));
    }
  }
}

}  // namespace

Eigen::VectorXd ElementForcesByPower(const Model& m, const Eigen::VectorXd& q, const Eigen::VectorXd& qd, double t) {
  const int n = static_cast<int>(m.q_layout.size());
  const double u = MetersPerUnit(m.length_unit);
  Eigen::VectorXd Q = Eigen::VectorXd::Zero(n);
  std::vector<double> x(static_cast<size_t>(1 + 2 * n), 0.0);  // the load variables [t, q, q̇] (model.h)
  x[kLoadVarTime] = t;
  for (int i = 0; i < n; ++i) x[LoadVarQ(i)] = q[i], x[LoadVarQd(i, n)] = qd[i];
  for (const SpringDamper& s : m.springs) {
    const Eigen::Vector2d d = PointPosition(m, s.points[1], q) - PointPosition(m, s.points[0], q);
    const double L = d.norm();
    if (!(L > 0)) continue;
    const Eigen::Vector2d e = d / L;
    const double Ldot = e.dot(PointVelocity(m, s.points[1], qd) - PointVelocity(m, s.points[0], qd));
    // Each parameter its constant or its law at (t, q, q̇).
    auto param = [&](SpringDamper::Param p) { return s.law[p] ? s.law[p]->Eval(x.data()) : s.Constant(p); };
    const double F = param(SpringDamper::kStiffness) * (L - param(SpringDamper::kFreeLength)) * u +
                     param(SpringDamper::kDamping) * Ldot * u + param(SpringDamper::kPreload);
    // Tension pulls b towards a: power −F e·v_b + F e·v_a = −F L̇ for the virtual velocity.
    for (int i = 0; i < n; ++i) {
      Eigen::VectorXd ei = Eigen::VectorXd::Zero(n);
      ei[i] = 1;
      Q[i] -= F * e.dot(PointVelocity(m, s.points[1], ei) - PointVelocity(m, s.points[0], ei));
    }
  }
  for (const BodyTorque& bt : m.torques) {
    const Body& b = m.bodies[bt.body];
    const double torque = bt.law ? bt.law->Eval(x.data()) : bt.torque;
    const Eigen::Vector2d r01 = PointPosition(m, b.points[1], q) - PointPosition(m, b.points[0], q);
    for (int i = 0; i < n; ++i) {
      Eigen::VectorXd ei = Eigen::VectorXd::Zero(n);
      ei[i] = 1;
      const Eigen::Vector2d v01 = PointVelocity(m, b.points[1], ei) - PointVelocity(m, b.points[0], ei);
      // ω per unit virtual velocity [rad/s per length/s]; T ω is in N·m/s, Q·q̇ in N·length/s.
      Q[i] += torque * (r01.x() * v01.y() - r01.y() * v01.x()) / r01.squaredNorm() / u;
    }
  }
  // A torsion's torque T on θ: power T θ̇, and θ is a coordinate of q.
  for (const TorsionSpring& ts : m.torsions)
    Q[ts.slot] += (-ts.stiffness * (q[ts.slot] - ts.free_angle) - ts.damping * qd[ts.slot] + ts.preload) / u;
  AddVaryingPointForces(m, q, x, Q);
  return Q;
}

MassAndForces MassAndForcesByEnergy(const Model& m, int sparse_from) {
  const int n = static_cast<int>(m.q_layout.size());
  if (n < sparse_from) {
    auto e = [n](int i) { Eigen::VectorXd v = Eigen::VectorXd::Zero(n); v[i] = 1; return v; };
    MassAndForces out{false, Eigen::MatrixXd::Zero(n, n), {}, Eigen::VectorXd::Zero(n)};
    // T is a quadratic form ½ q̇ᵀ M q̇: read M off it by polarisation, Q off the power.
    for (int i = 0; i < n; ++i) {
      out.M(i, i) = 2 * KineticEnergy(m, e(i));
      out.Q[i] = LoadPower(m, e(i));
    }
    for (int i = 0; i < n; ++i)
      for (int j = i + 1; j < n; ++j)
        out.M(i, j) = out.M(j, i) = KineticEnergy(m, e(i) + e(j)) - 0.5 * (out.M(i, i) + out.M(j, j));
    return out;
  }
  // The same polarisation, each energy summed over the bodies that move for that q̇ only (the
  // others add exactly 0), each point's slots from one table.
  std::vector<std::array<int, 2>> slot(m.points.size(), {-1, -1});
  for (int s = 0; s < n; ++s)
    if (m.q_layout[s].point >= 0 && (m.q_layout[s].axis == 0 || m.q_layout[s].axis == 1))
      slot[m.q_layout[s].point][m.q_layout[s].axis] = s;
  std::vector<std::vector<int>> bodies_at(n);  // massive bodies whose carrying points use slot s
  for (size_t b = 0; b < m.bodies.size(); ++b) {
    const Body& body = m.bodies[b];
    if (!body.HasMass() || body.points.empty()) continue;
    for (int p : CarryingPoints(m, body))
      for (int s : slot[p])
        if (s >= 0 && (bodies_at[s].empty() || bodies_at[s].back() != static_cast<int>(b)))
          bodies_at[s].push_back(static_cast<int>(b));
  }
  Eigen::VectorXd qd = Eigen::VectorXd::Zero(n);
  const auto velocity = [&](int p) {
    Eigen::Vector2d v = Eigen::Vector2d::Zero();
    for (int axis = 0; axis < 2; ++axis)
      if (slot[p][axis] >= 0) v[axis] = qd[slot[p][axis]];
    return v;
  };
  const auto energy = [&](const std::vector<int>& bodies) {
    double T = 0;
    for (int b : bodies) {
      const Body& body = m.bodies[b];
      const BodyMotion mo = Motion(m, body, velocity);
      T += 0.5 * body.mass * mo.vG.squaredNorm() + 0.5 * body.inertia_com * mo.omega2;
    }
    return T;
  };
  const Eigen::Vector2d g_SI = m.gravity * MetersPerUnit(m.length_unit);
  const auto power = [&](int i) {  // LoadPower for q̇ = e_i
    double P = 0;
    for (int b : bodies_at[i]) {
      P += m.bodies[b].mass * g_SI.dot(Motion(m, m.bodies[b], velocity).vG);
    }
    for (const PointForce& f : m.forces)
      if (f.IsConstantWorld() && (slot[f.point][0] == i || slot[f.point][1] == i)) P += f.f_W.dot(velocity(f.point));
    return P;
  };
  MassAndForces out{true, {}, {}, Eigen::VectorXd::Zero(n)};
  Eigen::VectorXd diag(n);
  for (int i = 0; i < n; ++i) {
    qd[i] = 1;
    diag[i] = 2 * energy(bodies_at[i]);
    out.Q[i] = power(i);
    qd[i] = 0;
  }
  std::vector<Eigen::Triplet<double>> t;
  std::vector<int> both;
  for (int i = 0; i < n; ++i) {
    if (diag[i] != 0) t.emplace_back(i, i, diag[i]);
    std::vector<int> partners;
    for (int b : bodies_at[i])
      for (int p : CarryingPoints(m, m.bodies[b]))
        for (int s : slot[p])
          if (s > i) partners.push_back(s);
    std::sort(partners.begin(), partners.end());
    partners.erase(std::unique(partners.begin(), partners.end()), partners.end());
    for (int j : partners) {
      both.clear();
      std::set_union(bodies_at[i].begin(), bodies_at[i].end(), bodies_at[j].begin(), bodies_at[j].end(),
                     std::back_inserter(both));
      qd[i] = qd[j] = 1;
      const double Mij = energy(both) - 0.5 * (diag[i] + diag[j]);
      qd[i] = qd[j] = 0;
      if (Mij != 0) t.emplace_back(i, j, Mij), t.emplace_back(j, i, Mij);
    }
  }
  out.M_sparse.resize(n, n);
  out.M_sparse.setFromTriplets(t.begin(), t.end());
  return out;
}

}  // namespace mechbench::analytic
