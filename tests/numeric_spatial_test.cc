// Spatial natural coordinates (issue 13; numeric/include/mechbench/numeric/spatial.h): the 3-D rows'
// Φ, Φ_q (dense and sparse), Φ̇_q, Φ̇_q q̇ and Hessians against finite differences row by row; the
// 3-D mass matrix against a rigid body's kinetic energy ½ m v_G² + ½ ωᵀ I ω; and the kinematic,
// rank and index-1 (Baumgarte, RK4) solvers on hand-built spatial models (the file format for 3-D
// comes later) against closed forms: a spherical pendulum (energy and angular momentum about the
// vertical conserved, the conical pendulum's steady rate) and an RSSR four-bar (output angle, its
// rate and acceleration from the input), and a planar four-bar built of 3-D revolute joints, whose
// loop is redundant in space (mobility formula −2, one degree of freedom).
#include "mechbench/analytic/analytic_method.h"
#include "mechbench/numeric/ali3p.h"
#include "mechbench/numeric/constraints.h"
#include "mechbench/numeric/dynamics.h"
#include "mechbench/loader.h"
#include "mechbench/motion_error.h"
#include "mechbench/numeric/dynamics_methods.h"
#include "dynamics_method_named.h"
#include "mechbench/numeric/forward_dynamics.h"
#include "mechbench/numeric/natural_data.h"
#include "mechbench/numeric/numeric_method.h"
#include "mechbench/numeric/solver.h"
#include "mechbench/numeric/spatial.h"

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <set>
#include <string>
#include <vector>

namespace mechbench::numeric {
namespace numeric_spatial_test {  // this file's own names (the tests build in unity batches)
namespace {

using V3 = Eigen::Vector3d;
using M3 = Eigen::Matrix3d;
constexpr double kPi = std::numbers::pi;

// ---- helpers ------------------------------------------------------------------------------------

M3 RandomRotation(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  return Eigen::Quaterniond(n(rng), n(rng), n(rng), n(rng)).normalized().toRotationMatrix();
}

V3 RandomVector(std::mt19937& rng, double size = 1.0) {
  std::uniform_real_distribution<double> u(-size, size);
  return {u(rng), u(rng), u(rng)};
}

// q̇ of a rigid motion of the whole model about the world origin: ṙ = v + ω × r for points,
// u̇ = ω × u for vectors (constant entities must be left at rest by it).
Eigen::VectorXd RigidVelocity(const NaturalModel& nm, const Eigen::VectorXd& q, const V3& omega, const V3& v = V3::Zero()) {
  Eigen::VectorXd qd = Eigen::VectorXd::Zero(nm.n);
  for (int e = 0; e < static_cast<int>(nm.entities.size()); ++e) {
    const V3 r = EntityValue(nm, q, e);
    const V3 rd = omega.cross(r) + (nm.entities[e].kind == EntityKind::kPoint ? v : V3::Zero());
    for (int c = 0; c < 3; ++c)
      if (const int s = nm.entities[e].slot[c]; s >= 0) qd[s] = rd[c];
  }
  return qd;
}

Eigen::MatrixXd DenseJacobian(const NaturalModel& nm, const Eigen::VectorXd& q) {
  NaturalData d(nm, LinearAlgebra::kDense);
  EvalJacobian(nm, d, q);
  return d.Phi_q;
}

Eigen::MatrixXd FiniteDifferenceJacobian(const NaturalModel& nm, const Eigen::VectorXd& q) {
  NaturalData d(nm, LinearAlgebra::kDense);
  Eigen::MatrixXd J(nm.m(), nm.n);
  for (int j = 0; j < nm.n; ++j) {
    const double h = 1e-6;
    Eigen::VectorXd qp = q, qm = q;
    qp[j] += h;
    qm[j] -= h;
    EvalPhi(nm, d, qp, 0.0);
    const Eigen::VectorXd fp = d.Phi;
    EvalPhi(nm, d, qm, 0.0);
    J.col(j) = (fp - d.Phi) / (2 * h);
  }
  return J;
}

// ---- every spatial row kind -----------------------------------------------------------------------

// Two bodies on a spherical joint (the shared point P1), one on two points and two vectors, one on
// a point and three vectors; a point and a vector attached to the first (linear rows); dot products
// of a segment with a vector and with a fixed vector; a distance to a fixed point; points on lines
// along a vector and along a segment, each with its distance coordinate.
NaturalModel EveryRowModel(Eigen::VectorXd* q0 = nullptr) {
  SpatialBuilder b;
  const int O = b.Point("O", V3(0, 0, 0), /*fixed=*/true);
  const int z = b.Vector("z", V3::UnitZ(), /*fixed=*/true);
  const int P0 = b.Point("P0", V3(0.1, 0.2, 0.3));
  const int P1 = b.Point("P1", V3(1.1, 0.2, 0.3));
  const int u = b.Vector("u", V3::UnitY());
  const int v = b.Vector("v", V3(1, 0, 1).normalized());
  const int body = b.Body("a", {P0, P1, u, v}, 2.0, V3(0.5, 0.2, 0.3), 0.1 * M3::Identity());
  const int P2 = b.Point("P2", V3(0.4, 0.9, -0.2));
  b.Attach(body, P2);
  const int w = b.Vector("w", V3(1, 1, 1).normalized());
  b.Attach(body, w);
  const int u2 = b.Vector("u2", V3::UnitX()), v2 = b.Vector("v2", V3::UnitY()), w2 = b.Vector("w2", V3::UnitZ());
  b.Body("b", {P1, u2, v2, w2}, 1.0, V3(1.3, 0.2, 0.3), 0.05 * M3::Identity());
  b.Dot(P2, P0, u2, -1);
  b.Distance(O, P2);
  b.Dot(P1, O, z, -1);
  const int P3 = b.Point("P3", V3(1.8, 0.2, 0.3));
  b.PointOnLine(P3, P1, u2, -1, b.Coordinate("s", 0.7, /*is_length=*/true));
  const int P4 = b.Point("P4", V3(0.6, 0.2, 0.3));
  b.PointOnLine(P4, P0, P1, P0, b.Coordinate("s2", 0.5, /*is_length=*/true));
  // The angle from body a's u to body b's v2 about b's u2 (0 at the build pose).
  b.Angle(u, v2, u2, b.Coordinate("th", 0.0, /*is_length=*/false));
  if (q0) *q0 = b.q0();
  return b.Build();
}

TEST(SpatialRows, EveryKindIsThere) {
  Eigen::VectorXd q0;
  const NaturalModel nm = EveryRowModel(&q0);
  EXPECT_EQ(nm.dim, 3);
  std::set<RowKind> kinds;
  for (const ConstraintRow& row : nm.rows) kinds.insert(row.kind);
  for (RowKind k : {RowKind::kUnit3, RowKind::kDistance3, RowKind::kDot3, RowKind::kLinear3, RowKind::kPointOnLine3,
                    RowKind::kAngle3})
    EXPECT_TRUE(kinds.count(k)) << ToString(k);
  // Body a: 6 rows; P2 and w: 3 each; body b: 6; three more dot/distance rows; two lines: 3 each;
  // one angle.
  EXPECT_EQ(nm.m(), 6 + 3 + 3 + 6 + 3 + 3 + 3 + 1);
  // The build pose is assembled: Φ = 0 there.
  NaturalData d(nm);
  EvalPhi(nm, d, q0, 0.0);
  EXPECT_LT(d.Phi.cwiseAbs().maxCoeff(), 1e-15);
}

// Φ_q, Φ̇_q, Φ̇_q q̇ and the Hessians at random states off the constraint manifold (the identities
// hold everywhere): dense against central differences, sparse against dense.
TEST(SpatialRows, DerivativesAgainstFiniteDifferences) {
  const NaturalModel nm = EveryRowModel();
  std::mt19937 rng(13);
  std::normal_distribution<double> noise(0.0, 0.3);
  for (int trial = 0; trial < 5; ++trial) {
    Eigen::VectorXd q(nm.n), qd(nm.n);
    for (int j = 0; j < nm.n; ++j) q[j] = noise(rng) + 0.5, qd[j] = noise(rng) * 3;
    const Eigen::MatrixXd J = DenseJacobian(nm, q);
    const Eigen::MatrixXd Jfd = FiniteDifferenceJacobian(nm, q);
    for (int i = 0; i < nm.m(); ++i)
      EXPECT_LT((J.row(i) - Jfd.row(i)).cwiseAbs().maxCoeff(), 1e-8) << "row " << i << " " << nm.rows[i].element;

    // Φ̇_q = d/dt Φ_q along q̇.
    NaturalData d(nm, LinearAlgebra::kDense);
    EvalPhidotQdot(nm, d, q, qd);
    const double h = 1e-6;
    const Eigen::MatrixXd Jdot_fd = (DenseJacobian(nm, q + h * qd) - DenseJacobian(nm, q - h * qd)) / (2 * h);
    for (int i = 0; i < nm.m(); ++i)
      EXPECT_LT((d.Phidot_q.row(i) - Jdot_fd.row(i)).cwiseAbs().maxCoeff(), 1e-7) << "row " << i << " " << nm.rows[i].element;
    const Eigen::VectorXd jdot_qd = d.Phidot_q_qd;

    // The sparse path: the same Φ, Φ_q, Φ̇_q q̇.
    NaturalData s(nm, LinearAlgebra::kSparse);
    ASSERT_TRUE(s.sparse);
    EvalPhiJacobian(nm, s, q, 0.0);
    EvalPhi(nm, d, q, 0.0);
    EXPECT_LT((s.Phi - d.Phi).cwiseAbs().maxCoeff(), 1e-15);
    EXPECT_LT((Eigen::MatrixXd(s.jac.J()) - J).cwiseAbs().maxCoeff(), 1e-15);
    EvalPhidotQdot(nm, s, q, qd);
    EXPECT_LT((s.Phidot_q_qd - jdot_qd).cwiseAbs().maxCoeff(), 1e-12 * (1 + jdot_qd.cwiseAbs().maxCoeff()));
    EXPECT_LT((Eigen::MatrixXd(s.jac.Jdot()) - d.Phidot_q).cwiseAbs().maxCoeff(), 1e-13);

    // Hessian of each row: column j is ∂(row i of Φ_q)/∂q_j.
    for (int i = 0; i < nm.m(); ++i) {
      std::vector<Eigen::Triplet<double>> t;
      SpatialRowHessian(nm, nm.rows[i], q, t);
      Eigen::SparseMatrix<double> H(nm.n, nm.n);
      H.setFromTriplets(t.begin(), t.end());
      Eigen::MatrixXd Hfd(nm.n, nm.n);
      for (int j = 0; j < nm.n; ++j) {
        Eigen::VectorXd qp = q, qm = q;
        qp[j] += h;
        qm[j] -= h;
        Hfd.col(j) = ((DenseJacobian(nm, qp).row(i) - DenseJacobian(nm, qm).row(i)) / (2 * h)).transpose();
      }
      EXPECT_LT((Eigen::MatrixXd(H) - Hfd).cwiseAbs().maxCoeff(), 1e-7) << "row " << i << " " << nm.rows[i].element;
    }
  }
}

// ---- the 3-D mass matrix ----------------------------------------------------------------------------

// One body on each kind of basis, its mass properties random, at a random pose (the build pose
// turned by R and moved by t, so the state is consistent) with a random rigid velocity: ½ q̇ᵀ M q̇
// must be the rigid body's ½ m v_G² + ½ ωᵀ (R I Rᵀ) ω, and Qᵀ q̇ the weight's power m g·v_G.
TEST(SpatialMass, KineticEnergyOfEveryBasis) {
  std::mt19937 rng(7);
  const V3 g(0.3, -1.0, -9.81);
  for (int basis_kind = 0; basis_kind < 4; ++basis_kind) {
    SCOPED_TRACE("basis kind " + std::to_string(basis_kind));
    const M3 F = RandomRotation(rng);  // the basis' directions at the build pose (not orthogonal below)
    const V3 p0 = RandomVector(rng);
    SpatialBuilder b;
    std::array<int, 4> basis{};
    basis[0] = b.Point("e0", p0);
    const V3 d1 = 0.9 * F.col(0), d2 = (F.col(1) + 0.3 * F.col(0)).normalized(), d3 = (F.col(2) - 0.2 * F.col(1)).normalized();
    // 0: two points and two vectors; 1: a point and three vectors; 2: three points and a vector;
    // 3: four points.
    basis[1] = basis_kind == 1 ? b.Vector("e1", d1.normalized()) : b.Point("e1", p0 + d1);
    basis[2] = basis_kind >= 2 ? b.Point("e2", p0 + 1.3 * d2) : b.Vector("e2", d2);
    basis[3] = basis_kind == 3 ? b.Point("e3", p0 + 0.7 * d3) : b.Vector("e3", d3);
    const double m = 2.5;
    const V3 com = p0 + RandomVector(rng, 0.5);
    const M3 Rr = RandomRotation(rng);
    const M3 I = Rr * V3(0.3, 0.4, 0.5).asDiagonal() * Rr.transpose();  // principal moments obey the triangle inequality
    b.Body("body", basis, m, com, I);
    b.Gravity(g);
    const NaturalModel nm = b.Build();
    NaturalData data(nm, LinearAlgebra::kDense);
    MassMatrix(nm, data);
    GeneralizedForces(nm, data);
    NaturalData sdata(nm, LinearAlgebra::kSparse);
    MassMatrix(nm, sdata);
    EXPECT_LT((Eigen::MatrixXd(sdata.M_sparse) - data.M).cwiseAbs().maxCoeff(), 1e-15);

    for (int trial = 0; trial < 5; ++trial) {
      const M3 R = RandomRotation(rng);
      const V3 t = RandomVector(rng), omega = RandomVector(rng, 3.0), v = RandomVector(rng, 2.0);
      Eigen::VectorXd q = b.q0();
      for (int e = 0; e < 4; ++e) {
        const Entity3& E = nm.entities[basis[e]];
        const V3 x = R * E.value + (E.kind == EntityKind::kPoint ? t : V3::Zero());
        for (int c = 0; c < 3; ++c) q[E.slot[c]] = x[c];
      }
      const Eigen::VectorXd qd = RigidVelocity(nm, q, omega, v);
      const V3 rG = R * com + t;
      const V3 vG = v + omega.cross(rG);
      const double T_rigid = 0.5 * m * vG.squaredNorm() + 0.5 * omega.dot(R * I * R.transpose() * omega);
      const double T_natural = 0.5 * qd.dot(data.M * qd);
      EXPECT_NEAR(T_natural, T_rigid, 1e-12 * T_rigid);
      EXPECT_NEAR(data.Q.dot(qd), m * g.dot(vG), 1e-12 * m * g.norm() * vG.norm());
    }
  }
}

// ---- dynamics: the spherical pendulum -------------------------------------------------------------

// A rigid pendulum on a spherical joint at the fixed origin O: basis {O, P, u, v} with P at the
// rod's end, the rod at `alpha` from the downward vertical; mass m with its centre on the rod at
// l_G, axially symmetric inertia (A_G about the rod, B_G across it).
struct Pendulum {
  NaturalModel nm;
  Eigen::VectorXd q0;
  int O = -1, P = -1, u = -1, v = -1;
  double m = 2.0, L = 1.0, l_G = 0.6, A_G = 0.02, B_G = 0.1, g = 9.81;
  M3 X_B;   // the basis columns [P − O, u, v] at the build pose
  M3 I_B;   // inertia about the centre of mass at the build pose
  V3 com_B; // centre of mass at the build pose
};

Pendulum MakePendulum(double alpha) {
  Pendulum p;
  SpatialBuilder b;
  const V3 e(std::sin(alpha), 0, -std::cos(alpha));
  p.O = b.Point("O", V3::Zero(), /*fixed=*/true);
  p.P = b.Point("P", p.L * e);
  p.u = b.Vector("u", V3(std::cos(alpha), 0, std::sin(alpha)));
  p.v = b.Vector("v", V3::UnitY());
  p.I_B = p.A_G * e * e.transpose() + p.B_G * (M3::Identity() - e * e.transpose());
  p.com_B = p.l_G * e;
  b.Body("pendulum", {p.O, p.P, p.u, p.v}, p.m, p.com_B, p.I_B);
  b.Gravity(V3(0, 0, -p.g));
  p.nm = b.Build();
  p.q0 = b.q0();
  p.X_B << p.L * e, EntityValue(p.nm, p.q0, p.u), EntityValue(p.nm, p.q0, p.v);
  return p;
}

// The body's rotation R = X X̄⁻¹ and angular velocity ([ω]× = Ẋ X⁻¹) from q, q̇.
void RigidState(const Pendulum& p, const Eigen::VectorXd& q, const Eigen::VectorXd& qd, M3& R, V3& omega) {
  M3 X, Xd;
  X << EntityValue(p.nm, q, p.P), EntityValue(p.nm, q, p.u), EntityValue(p.nm, q, p.v);
  Xd << EntityRate(p.nm, qd, p.P), EntityRate(p.nm, qd, p.u), EntityRate(p.nm, qd, p.v);
  R = X * p.X_B.inverse();
  const M3 W = Xd * X.inverse();
  omega = 0.5 * V3(W(2, 1) - W(1, 2), W(0, 2) - W(2, 0), W(1, 0) - W(0, 1));
}

// Angular momentum about O, vertical component: [m r_G × v_G + R I Rᵀ ω]_z.
double VerticalMomentum(const Pendulum& p, const Eigen::VectorXd& q, const Eigen::VectorXd& qd) {
  M3 R;
  V3 omega;
  RigidState(p, q, qd, R, omega);
  const V3 rG = R * p.com_B, vG = omega.cross(rG);
  return (p.m * rG.cross(vG) + R * p.I_B * R.transpose() * omega).z();
}

// Integrates the index-1 equations with Baumgarte (α = β = 10 /s) by RK4 at step h for `steps`
// steps, calling `each(t, q, q̇)` after every step.
template <typename Each>
void Simulate(DynamicsSystem& sys, Eigen::VectorXd q, Eigen::VectorXd qd, double h, int steps, Each each) {
  const int n = sys.n();
  Eigen::VectorXd y(2 * n), qdd, lambda;
  y << q, qd;
  const OdeRhs f = [&](double t, const Eigen::VectorXd& yy, Eigen::VectorXd& dy, std::string& why) {
    sys.SetTime(t);
    if (!sys.Accelerations(yy.head(n), yy.tail(n), 10.0, 10.0, qdd, lambda, &why)) return false;
    dy.resize(2 * n);
    dy << yy.tail(n), qdd;
    return true;
  };
  OdeStats stats;
  Rk4Scratch scratch;
  std::string why;
  for (int k = 0; k < steps; ++k) {
    ASSERT_TRUE(Rk4Step(f, nullptr, k * h, h, y, why, stats, &scratch)) << why;
    each((k + 1) * h, y.head(n), y.tail(n));
  }
}

class SpatialPendulum : public ::testing::TestWithParam<LinearAlgebra> {};

// A general motion: energy and the angular momentum about the vertical through O are conserved.
TEST_P(SpatialPendulum, ConservesEnergyAndVerticalMomentum) {
  const Pendulum p = MakePendulum(0.5);
  DynamicsSystem sys(p.nm, GetParam());
  EXPECT_EQ(sys.sparse(), GetParam() == LinearAlgebra::kSparse);
  const Eigen::VectorXd qd0 = RigidVelocity(p.nm, p.q0, V3(0.3, -0.5, 2.0));
  const double E0 = sys.Energy(p.q0, qd0), H0 = VerticalMomentum(p, p.q0, qd0);
  double dE = 0, dH = 0, phi = 0, z_min = 0, z_max = -1;
  Simulate(sys, p.q0, qd0, 1e-3, 2000, [&](double, const Eigen::VectorXd& q, const Eigen::VectorXd& qd) {
    dE = std::max(dE, std::fabs(sys.Energy(q, qd) - E0));
    dH = std::max(dH, std::fabs(VerticalMomentum(p, q, qd) - H0));
    phi = std::max(phi, sys.ScaledPhi(q));
    const double z = EntityValue(p.nm, q, p.P).z();
    z_min = std::min(z_min, z), z_max = std::max(z_max, z);
  });
  if (std::getenv("MECHBENCH_VERBOSE"))
    std::printf("spherical pendulum 2 s, RK4 h = 1 ms: |ΔE| %.2g J of %.3g, |ΔH_z| %.2g of %.3g, ‖Φ‖ %.2g\n", dE, E0, dH, H0, phi);
  EXPECT_GT(z_max - z_min, 0.05);  // it does swing (not a trivial motion)
  EXPECT_LT(dE, 1e-9 * p.m * p.g * p.L);
  EXPECT_LT(dH, 1e-9 * std::fabs(H0));
  EXPECT_LT(phi, 1e-10);
}

// The conical pendulum: turning as a rigid body at Ω about the vertical with the rod at α, where
// gravity's moment m g l_G sin α equals the rate of change of the angular momentum,
// Ω² = m g l_G / ((B_O − A_G) cos α), B_O = B_G + m l_G². Over one revolution the rod's end keeps
// its height and turns at Ω; 5 % off Ω it does not (the check can fail).
TEST_P(SpatialPendulum, ConicalSteadyStateAtItsClosedFormRate) {
  const double alpha = 0.6;
  const Pendulum p = MakePendulum(alpha);
  const double B_O = p.B_G + p.m * p.l_G * p.l_G;
  const double Omega = std::sqrt(p.m * p.g * p.l_G / ((B_O - p.A_G) * std::cos(alpha)));
  const double period = 2 * kPi / Omega, h = period / 2000;
  DynamicsSystem sys(p.nm, GetParam());
  for (double factor : {1.0, 1.05}) {
    const Eigen::VectorXd qd0 = RigidVelocity(p.nm, p.q0, V3(0, 0, factor * Omega));
    const double z0 = EntityValue(p.nm, p.q0, p.P).z();
    double dz = 0, dturn = 0, turned = 0, last = 0;
    Simulate(sys, p.q0, qd0, h, 2000, [&](double t, const Eigen::VectorXd& q, const Eigen::VectorXd&) {
      const V3 r = EntityValue(p.nm, q, p.P);
      dz = std::max(dz, std::fabs(r.z() - z0));
      const double az = std::atan2(r.y(), r.x());
      turned += std::remainder(az - last, 2 * kPi);
      last = az;
      dturn = std::max(dturn, std::fabs(turned - Omega * t));
    });
    if (std::getenv("MECHBENCH_VERBOSE"))
      std::printf("conical pendulum at %.2f Ω (Ω = %.6f rad/s): height %.2g m, azimuth off Ω t by %.2g rad\n", factor,
                  Omega, dz, dturn);
    if (factor == 1.0) {
      EXPECT_LT(dz, 1e-9 * p.L);
      EXPECT_LT(dturn, 1e-8);
    } else {
      EXPECT_GT(dz, 1e-3 * p.L);
    }
  }
}

// ALI3-P (index-3 augmented Lagrangian, trapezoidal rule, with the spatial rows' Hessians in its
// tangent) on the same conical steady state: the trapezoidal rule's phase error is second order,
// so the bounds are its, not round-off's.
TEST_P(SpatialPendulum, Ali3pHoldsTheConicalSteadyState) {
  const double alpha = 0.6;
  const Pendulum p = MakePendulum(alpha);
  const double B_O = p.B_G + p.m * p.l_G * p.l_G;
  const double Omega = std::sqrt(p.m * p.g * p.l_G / ((B_O - p.A_G) * std::cos(alpha)));
  const double period = 2 * kPi / Omega, h = period / 2000;
  DynamicsSystem sys(p.nm, GetParam(), kSparseAli3pFromCoordinates);
  Eigen::VectorXd q = p.q0, qd = RigidVelocity(p.nm, p.q0, V3(0, 0, Omega)), qdd, lambda;
  ASSERT_TRUE(sys.Accelerations(q, qd, 0.0, 0.0, qdd, lambda));
  Ali3pOptions o;
  o.h = h;
  o.linear_algebra = GetParam();
  Ali3pStepper stepper(sys, o, h, lambda);
  const double z0 = EntityValue(p.nm, q, p.P).z(), E0 = sys.Energy(q, qd);
  double dz = 0, dturn = 0, dE = 0, turned = 0, last = 0;
  std::string why;
  for (int k = 1; k <= 2000; ++k) {
    ASSERT_TRUE(stepper.Step(h, q, qd, qdd, why)) << why;
    const V3 r = EntityValue(p.nm, q, p.P);
    dz = std::max(dz, std::fabs(r.z() - z0));
    const double az = std::atan2(r.y(), r.x());
    turned += std::remainder(az - last, 2 * kPi);
    last = az;
    dturn = std::max(dturn, std::fabs(turned - Omega * k * h));
    dE = std::max(dE, std::fabs(sys.Energy(q, qd) - E0));
  }
  if (std::getenv("MECHBENCH_VERBOSE"))
    std::printf("ALI3-P conical pendulum (%s), one revolution in 2000 steps: height %.2g m, azimuth %.2g rad, "
                "|ΔE| %.2g J, %.2f Newton iterations a step\n",
                ToString(GetParam()), dz, dturn, dE, static_cast<double>(stepper.iterations()) / 2000);
  EXPECT_LT(dz, 1e-6 * p.L);
  EXPECT_LT(dturn, 1e-4);
  EXPECT_LT(dE, 1e-6 * p.m * p.g * p.L);
}

INSTANTIATE_TEST_SUITE_P(LinearAlgebra, SpatialPendulum, ::testing::Values(LinearAlgebra::kDense, LinearAlgebra::kSparse),
                         [](const auto& param_info) { return std::string(ToString(param_info.param)); });

// ---- the spherical pendulum as a file -----------------------------------------------------------

// tests/data/scenes/spherical_pendulum.yaml, started as a conical pendulum, through each dynamics
// method that runs spatial scenes. The closed form comes from the file's mass properties alone
// (Ω² = m g l_G / ((B_O − A_G) cos α), B_O = B_G + m l_G²), the energy and angular momentum from
// the rigid body's own formulas (not the natural-coordinate mass matrix): over one revolution the
// rod's end keeps its height and turns at Ω, and both are conserved.
struct FilePendulum {
  Model m;
  NaturalModel nm;
  int O, P, u, v;
  double mass, g, l_G, A_G, B_G, alpha, Omega;
  V3 com_B;
  M3 I_B, X_B;
  explicit FilePendulum(const std::string& file) : m(LoadScenario(file)), nm(Compile(m)) {
    const SpatialModel& s = m.spatial;
    O = s.EntityIndex("O"), P = s.EntityIndex("P"), u = s.EntityIndex("u"), v = s.EntityIndex("v");
    const SpatialBody& b = s.bodies.at(0);
    mass = b.mass, com_B = b.com_W, I_B = b.inertia_W, g = -s.gravity.z();
    const V3 rP = s.entities[P].r_W - s.entities[O].r_W, e = rP.normalized();
    alpha = std::acos(-e.z());
    l_G = (com_B - s.entities[O].r_W).norm();
    A_G = e.dot(I_B * e);
    B_G = 0.5 * (I_B.trace() - A_G);
    Omega = std::sqrt(mass * g * l_G / ((B_G + mass * l_G * l_G - A_G) * std::cos(alpha)));
    X_B << rP, s.entities[u].r_W, s.entities[v].r_W;
  }
  // Rotation and angular velocity from the basis at q, q̇; then H_z about O and the energy [J].
  void Rigid(const Eigen::VectorXd& q, const Eigen::VectorXd& qd, M3& R, V3& omega) const {
    M3 X, Xd;
    X << EntityValue(nm, q, P) - EntityValue(nm, q, O), EntityValue(nm, q, u), EntityValue(nm, q, v);
    Xd << EntityRate(nm, qd, P), EntityRate(nm, qd, u), EntityRate(nm, qd, v);
    R = X * X_B.inverse();
    const M3 W = Xd * X.inverse();
    omega = 0.5 * V3(W(2, 1) - W(1, 2), W(0, 2) - W(2, 0), W(1, 0) - W(0, 1));
  }
  double Hz(const Eigen::VectorXd& q, const Eigen::VectorXd& qd) const {
    M3 R;
    V3 w;
    Rigid(q, qd, R, w);
    const V3 rG = R * com_B, vG = w.cross(rG);
    return (mass * rG.cross(vG) + R * I_B * R.transpose() * w).z();
  }
  double Energy(const Eigen::VectorXd& q, const Eigen::VectorXd& qd) const {
    M3 R;
    V3 w;
    Rigid(q, qd, R, w);
    const V3 rG = R * com_B, vG = w.cross(rG);
    return 0.5 * mass * vG.squaredNorm() + 0.5 * w.dot(R * I_B * R.transpose() * w) + mass * g * rG.z();
  }
};

struct PendulumBound {
  const char* method;
  double height, azimuth, energy, momentum;  // relative to L, rad, m g L, |H_z|
};

class SpatialPendulumFile : public ::testing::TestWithParam<PendulumBound> {};

TEST_P(SpatialPendulumFile, ConicalSteadyStateFromTheFile) {
  const PendulumBound bound = GetParam();
  const FilePendulum p(std::string(MECHBENCH_TEST_DATA) + "/scenes/spherical_pendulum.yaml");
  ASSERT_EQ(p.m.kind, ScenarioKind::kSpatial);
  ASSERT_EQ(p.m.q_layout.size(), 9u);
  EXPECT_EQ(p.m.q_layout[3].name, "xu");
  const std::unique_ptr<Method> method = test::DynamicsMethodNamed(bound.method);
  if (const auto why = method->Applicability(p.m)) GTEST_SKIP() << *why;
  const Result r = method->Run(p.m, RunOptions{});
  ASSERT_TRUE(r.ok()) << r.reason;
  ASSERT_EQ(static_cast<int>(r.trajectory.size()), p.m.analysis.samples);
  const double L = (p.m.spatial.entities[p.P].r_W - p.m.spatial.entities[p.O].r_W).norm();
  const Eigen::VectorXd& q0 = r.trajectory[0].q;
  const double z0 = EntityValue(p.nm, q0, p.P).z();
  const double E0 = p.Energy(q0, r.trajectory[0].qd), H0 = p.Hz(q0, r.trajectory[0].qd);
  double dz = 0, dturn = 0, dE = 0, dH = 0, turned = 0, last = 0;
  for (const Sample& s : r.trajectory) {
    const V3 rP = EntityValue(p.nm, s.q, p.P);
    dz = std::max(dz, std::fabs(rP.z() - z0));
    const double az = std::atan2(rP.y(), rP.x());
    turned += std::remainder(az - last, 2 * kPi);
    last = az;
    dturn = std::max(dturn, std::fabs(turned - p.Omega * (s.t - p.m.analysis.t0)));
    dE = std::max(dE, std::fabs(p.Energy(s.q, s.qd) - E0));
    dH = std::max(dH, std::fabs(p.Hz(s.q, s.qd) - H0));
  }
  if (std::getenv("MECHBENCH_VERBOSE"))
    std::printf("spherical pendulum file, %s, one revolution: height %.2g m, azimuth %.2g rad, |ΔE| %.2g J, |ΔH_z| %.2g, "
                "steps %ld\n", bound.method, dz, dturn, dE, dH, r.steps);
  EXPECT_GT(turned, 2 * kPi - 0.1);  // it did turn once
  EXPECT_LT(dz, bound.height * L);
  EXPECT_LT(dturn, bound.azimuth);
  EXPECT_LT(dE, bound.energy * p.mass * p.g * L);
  EXPECT_LT(dH, bound.momentum * std::fabs(H0));
}

INSTANTIATE_TEST_SUITE_P(Methods, SpatialPendulumFile,
                         // Measured (RelWithDebInfo): RK4 (h = 1 ms) height 1.1e-11, azimuth 3.4e-11 rad, ΔE 4e-12
                         // m g L, ΔH_z 5.5e-12; DOPRI5 (rtol 1e-8) 7e-12, 2e-11, 6e-12; ALI3-P 1.4e-14, 9.2e-6
                         // (the trapezoidal rule's second-order phase), 2e-14; partitioning 6.9e-10, 2.3e-9, 1.1e-9.
                         ::testing::Values(PendulumBound{"rk4", 1e-9, 1e-9, 1e-10, 1e-9},
                                           PendulumBound{"dopri5", 1e-9, 1e-9, 1e-10, 1e-9},
                                           PendulumBound{"ali3p", 1e-12, 1e-4, 1e-12, 1e-11},
                                           PendulumBound{"partitioning", 1e-8, 1e-7, 1e-8, 1e-7}),
                         [](const auto& param_info) { return std::string(param_info.param.method); });

// ---- a hinge about a tilted axis, its angle a coordinate ------------------------------------------

// tests/data/scenes/hinge_pendulum_tilted.yaml through each dynamics method: the hinge angle θ
// (an `angle` coordinate, kAngle3) against J θ̈ = a·(r_G(θ) × m g) integrated here on its own
// (RK4, 10 µs steps), r_G(θ) = R(a, θ) r_G0, J = m |r_G0 ⊥ a|² + aᵀ I_G a from the file; and θ
// against the angle its vectors f, u make (the row's own consistency).
struct HingeBound {
  const char* file;
  const char* method;
  double theta;       // |θ − θ_ref| [rad]
  double consistent;  // |θ − the angle of f, u| [rad]: the angle row's residual (drift for Baumgarte)
};

class SpatialHingeFile : public ::testing::TestWithParam<HingeBound> {};

TEST_P(SpatialHingeFile, AngleCoordinateFollowsTheHingeEquation) {
  const HingeBound bound = GetParam();
  const Model m = LoadScenario(std::string(MECHBENCH_TEST_DATA) + "/scenes/" + bound.file + ".yaml");
  const NaturalModel nm = Compile(m);
  const SpatialModel& s = m.spatial;
  const SpatialBody& body = s.bodies.at(0);
  const V3 a = s.entities[s.EntityIndex("a")].r_W, O = s.entities[s.EntityIndex("O")].r_W;
  const V3 rG0 = body.com_W - O, g = s.gravity;
  const double J = body.mass * (rG0 - rG0.dot(a) * a).squaredNorm() + a.dot(body.inertia_W * a);
  const auto accel = [&](double th, double thd) {
    const V3 rG = Eigen::AngleAxisd(th, a) * rG0;
    double torque = a.dot(rG.cross(body.mass * g));
    for (const TorsionSpring& ts : m.torsions)
      torque += -ts.stiffness * (th - ts.free_angle) - ts.damping * thd + ts.preload;
    return torque / J;
  };
  const std::unique_ptr<Method> method = test::DynamicsMethodNamed(bound.method);
  if (const auto why = method->Applicability(m)) GTEST_SKIP() << *why;
  const Result r = method->Run(m, RunOptions{});
  ASSERT_TRUE(r.ok()) << r.reason;
  ASSERT_EQ(static_cast<int>(r.trajectory.size()), m.analysis.samples);
  const int th = m.SlotIndex("theta"), f = s.EntityIndex("f"), u = s.EntityIndex("u");
  double x = 0, v = 0, t = m.analysis.t0, worst = 0, consistent = 0;
  const double h = 1e-5;
  for (const Sample& smp : r.trajectory) {
    while (t < smp.t - 0.5 * h) {
      const double k1x = v, k1v = accel(x, v);
      const double k2x = v + 0.5 * h * k1v, k2v = accel(x + 0.5 * h * k1x, k2x);
      const double k3x = v + 0.5 * h * k2v, k3v = accel(x + 0.5 * h * k2x, k3x);
      const double k4x = v + h * k3v, k4v = accel(x + h * k3x, k4x);
      x += h / 6 * (k1x + 2 * k2x + 2 * k3x + k4x);
      v += h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
      t += h;
    }
    worst = std::max(worst, std::fabs(smp.q[th] - x));
    const V3 fv = EntityValue(nm, smp.q, f), uv = EntityValue(nm, smp.q, u);
    consistent = std::max(consistent, std::fabs(std::remainder(smp.q[th] - std::atan2(fv.cross(uv).dot(a), fv.dot(uv)), 2 * kPi)));
  }
  if (std::getenv("MECHBENCH_VERBOSE"))
    std::printf("%s, %s: |θ − θ_ref| %.2g rad (θ reached %.3g rad), θ against its vectors %.2g rad\n", bound.file,
                bound.method, worst, x, consistent);
  EXPECT_GT(std::fabs(x), 0.2);  // it did swing
  EXPECT_LT(worst, bound.theta);
  EXPECT_LT(consistent, bound.consistent);
}

INSTANTIATE_TEST_SUITE_P(Methods, SpatialHingeFile,
                         // Measured (RelWithDebInfo, 1.5 s, θ swinging to −2.51 rad): RK4 (h = 1 ms) 1.4e-10 rad,
                         // its vectors 1.5e-11; DOPRI5 5.5e-9, 1.1e-9 (Baumgarte's drift); ALI3-P 1.1e-5 (the
                         // trapezoidal rule's second order), 4.4e-16; partitioning 3.5e-9, 4.4e-16.
                         // With the torsional spring–damper (hinge_pendulum_torsion, θ to −0.455 rad): RK4 1.9e-11, 2.4e-12;
                         // DOPRI5 1.7e-9, 3.7e-10; ALI3-P 4.4e-6, 2.2e-16; partitioning 4.4e-9, 4.6e-14.
                         ::testing::Values(HingeBound{"hinge_pendulum_tilted", "rk4", 1e-9, 1e-10},
                                           HingeBound{"hinge_pendulum_tilted", "dopri5", 5e-8, 1e-8},
                                           HingeBound{"hinge_pendulum_tilted", "ali3p", 1e-4, 1e-12},
                                           HingeBound{"hinge_pendulum_tilted", "partitioning", 3e-8, 1e-12},
                                           HingeBound{"hinge_pendulum_torsion", "rk4", 1e-9, 1e-10},
                                           HingeBound{"hinge_pendulum_torsion", "dopri5", 5e-8, 1e-8},
                                           HingeBound{"hinge_pendulum_torsion", "ali3p", 1e-4, 1e-12},
                                           HingeBound{"hinge_pendulum_torsion", "partitioning", 3e-8, 1e-12}),
                         [](const auto& param_info) {
                           return std::string(param_info.param.file).substr(15) + "_" + param_info.param.method;
                         });

// ---- kinematics: the RSSR four-bar ------------------------------------------------------------------

// Input crank A–B (length a) turning about the z axis through A = 0, coupler B–C (length b) with
// spherical joints at both ends, output crank D–C (length c) turning about the x axis through D:
//   B(θ) = a (cos θ, sin θ, 0),  C(φ) = D + c (0, cos φ, sin φ),  |C − B|² = b².
// Closed form: with d = D − B, d₂ cos φ + d₃ sin φ = K = (b² − c² − |d|²) / (2c), so
//   φ = atan2(d₃, d₂) + acos(K / √(d₂² + d₃²))   (one assembly branch),
// φ' = −F_θ / F_φ with F = |C − B|² − b²: F_θ = −2 (C − B)·B', F_φ = 2 (C − B)·C'.
struct Rssr {
  double a = 1.0, b = 3.0, c = 2.0;
  V3 D{2.0, 1.0, 1.5};
  Rssr() = default;
  // The same linkage as a file gives it: its constants a, b, c and its fixed point D.
  explicit Rssr(const Model& m)
      : a(m.constants.at("a")), b(m.constants.at("b")), c(m.constants.at("c")),
        D(m.spatial.entities[m.spatial.EntityIndex("D")].r_W) {}
  V3 B(double th) const { return a * V3(std::cos(th), std::sin(th), 0); }
  V3 C(double phi) const { return D + c * V3(0, std::cos(phi), std::sin(phi)); }
  double Phi(double th) const {
    const V3 d = D - B(th);
    const double K = (b * b - c * c - d.squaredNorm()) / (2 * c);
    return std::atan2(d.z(), d.y()) + std::acos(K / std::hypot(d.y(), d.z()));
  }
  double PhiPrime(double th) const {
    const double phi = Phi(th);
    const V3 r = C(phi) - B(th);
    const V3 Bp = a * V3(-std::sin(th), std::cos(th), 0), Cp = c * V3(0, -std::sin(phi), std::cos(phi));
    return r.dot(Bp) / r.dot(Cp);
  }
  double PhiSecond(double th) const {  // differentiated numerically: the closed form of φ' is the reference
    const double e = 1e-5;
    return (PhiPrime(th + e) - PhiPrime(th - e)) / (2 * e);
  }
};

TEST(SpatialKinematics, RssrOutputAngleRateAndAccelerationMatchTheClosedForm) {
  const Rssr k;
  const double th0 = kPi / 3;
  SpatialBuilder b;
  const int A = b.Point("A", V3::Zero(), true), D = b.Point("D", k.D, true);
  const int zhat = b.Vector("z", V3::UnitZ(), true), xhat = b.Vector("x", V3::UnitX(), true);
  const int B = b.Point("B", k.B(th0)), C = b.Point("C", k.C(k.Phi(th0)));
  b.Distance(A, B);
  b.Dot(B, A, zhat, -1);  // the input crank stays in the plane z = 0: a revolute about z
  b.Distance(B, C);       // the coupler, spherical at both ends
  b.Distance(D, C);
  b.Dot(C, D, xhat, -1);  // the output crank in the plane x = D_x: a revolute about x
  Driver drive;
  drive.coordinate = "Bx";
  b.Drive(b.Slot(B, 0), drive);
  NaturalModel nm = b.Build();
  ASSERT_EQ(nm.n, 6);
  ASSERT_EQ(nm.m(), 5);
  for (LinearAlgebra la : {LinearAlgebra::kDense, LinearAlgebra::kSparse}) {
    SCOPED_TRACE(ToString(la));
    NaturalData data(nm, la);
    Eigen::VectorXd q = b.q0();
    const double thd = 1.3;  // input rate [rad/s], constant
    double worst[3] = {0, 0, 0};
    for (double deg = 20; deg <= 140; deg += 5) {
      const double th = deg * kPi / 180;
      // x_B = a cos θ(t) at t = 0 with θ̇ = thd, θ̈ = 0.
      nm.drivers[0].law.value = k.a * std::cos(th);
      nm.drivers[0].law.velocity = -k.a * std::sin(th) * thd;
      nm.drivers[0].law.acceleration = -k.a * std::cos(th) * thd * thd;
      const NewtonReport r = SolvePosition(nm, data, q, 0.0);
      ASSERT_TRUE(r.converged) << deg;
      q = data.q;
      ASSERT_EQ(SolveVelocity(nm, data, 0.0), nm.n);
      ASSERT_EQ(SolveAcceleration(nm, data, 0.0), nm.n);
      const V3 rc = EntityValue(nm, data.q, C) - k.D, vc = EntityRate(nm, data.qd, C), ac = EntityRate(nm, data.qdd, C);
      const double phi = std::atan2(rc.z(), rc.y());
      const double phid = (rc.y() * vc.z() - rc.z() * vc.y()) / (k.c * k.c);
      const double phidd = (rc.y() * ac.z() - rc.z() * ac.y()) / (k.c * k.c);
      EXPECT_LT(std::fabs(EntityValue(nm, data.q, B).y() - k.B(th).y()), 1e-12) << deg;  // the branch sin θ > 0
      worst[0] = std::max(worst[0], std::fabs(std::remainder(phi - k.Phi(th), 2 * kPi)));
      worst[1] = std::max(worst[1], std::fabs(phid - k.PhiPrime(th) * thd));
      worst[2] = std::max(worst[2], std::fabs(phidd - k.PhiSecond(th) * thd * thd));
    }
    if (std::getenv("MECHBENCH_VERBOSE"))
      std::printf("RSSR against its closed form (%s): φ %.2g rad, φ̇ %.2g rad/s, φ̈ %.2g rad/s²\n", ToString(la), worst[0],
                  worst[1], worst[2]);
    EXPECT_LT(worst[0], 1e-12);
    EXPECT_LT(worst[1], 1e-12);
    EXPECT_LT(worst[2], 1e-8);  // the reference's own central difference
  }
}

// The same RSSR as a file (tests/data/scenes/rssr_fourbar.yaml: the cranks rigid bodies on their
// points, fixed axis and a vector across them; the coupler a bar), driven by x_B = a cos θ(t),
// θ = th0 + w t, through `mechbench run`'s numeric method: at every sample the output angle and
// its rate against the closed form above.
TEST(SpatialScenes, RssrFileMatchesTheClosedForm) {
  const Model m = LoadScenario(std::string(MECHBENCH_TEST_DATA) + "/scenes/rssr_fourbar.yaml");
  ASSERT_EQ(m.kind, ScenarioKind::kSpatial);
  const Rssr k(m);
  const double th0 = m.constants.at("th0"), w = m.constants.at("w");
  const auto method = MakeNumericMethod();
  ASSERT_FALSE(method->Applicability(m)) << *method->Applicability(m);
  const Result r = method->Run(m, RunOptions{});
  ASSERT_TRUE(r.ok()) << r.reason;
  ASSERT_EQ(static_cast<int>(r.trajectory.size()), m.analysis.samples);
  EXPECT_EQ(r.quantities.at("dof"), 1);
  const NaturalModel nm = Compile(m);
  EXPECT_EQ(nm.n, 12);   // B, C, w1, w3
  EXPECT_EQ(nm.m(), 11);  // 5 + 1 + 5
  const int C = m.spatial.EntityIndex("C");
  double worst[2] = {0, 0};
  for (const Sample& s : r.trajectory) {
    const double th = th0 + w * s.t;
    const V3 rc = EntityValue(nm, s.q, C) - k.D, vc = EntityRate(nm, s.qd, C);
    const double phi = std::atan2(rc.z(), rc.y());
    const double phid = (rc.y() * vc.z() - rc.z() * vc.y()) / (k.c * k.c);
    worst[0] = std::max(worst[0], std::fabs(std::remainder(phi - k.Phi(th), 2 * kPi)));
    worst[1] = std::max(worst[1], std::fabs(phid - k.PhiPrime(th) * w));
  }
  if (std::getenv("MECHBENCH_VERBOSE"))
    std::printf("RSSR file against its closed form over %zu samples: φ %.2g rad, φ̇ %.2g rad/s\n", r.trajectory.size(),
                worst[0], worst[1]);
  EXPECT_LT(worst[0], 1e-12);  // measured 8.9e-16
  EXPECT_LT(worst[1], 1e-12);  // measured 6.7e-16
}

// The same RSSR with angle coordinates (tests/data/scenes/rssr_fourbar_angles.yaml): the input
// crank's angle theta about z driven, th0 + w t, and the output crank's angle phi about x a
// coordinate of q, so the closed form is compared with q, q̇ and q̈ directly.
TEST(SpatialScenes, RssrAngleCoordinatesMatchTheClosedForm) {
  const Model m = LoadScenario(std::string(MECHBENCH_TEST_DATA) + "/scenes/rssr_fourbar_angles.yaml");
  const Rssr k(m);
  const double th0 = m.constants.at("th0"), w = m.constants.at("w");
  const int theta = m.SlotIndex("theta"), phi = m.SlotIndex("phi");
  ASSERT_GE(theta, 0);
  ASSERT_GE(phi, 0);
  EXPECT_EQ(SlotKind(m, phi), 1);  // an angle: compared with the angles, not the lengths
  const Result r = MakeNumericMethod()->Run(m, RunOptions{});
  ASSERT_TRUE(r.ok()) << r.reason;
  ASSERT_EQ(static_cast<int>(r.trajectory.size()), m.analysis.samples);
  EXPECT_EQ(r.quantities.at("dof"), 1);
  double worst[3] = {0, 0, 0};
  for (const Sample& s : r.trajectory) {
    const double th = th0 + w * s.t;
    EXPECT_NEAR(s.q[theta], th, 1e-14);
    worst[0] = std::max(worst[0], std::fabs(std::remainder(s.q[phi] - k.Phi(th), 2 * kPi)));
    worst[1] = std::max(worst[1], std::fabs(s.qd[phi] - k.PhiPrime(th) * w));
    worst[2] = std::max(worst[2], std::fabs(s.qdd[phi] - k.PhiSecond(th) * w * w));
  }
  if (std::getenv("MECHBENCH_VERBOSE"))
    std::printf("RSSR with angle coordinates over %zu samples: φ %.2g rad, φ̇ %.2g rad/s, φ̈ %.2g rad/s²\n",
                r.trajectory.size(), worst[0], worst[1], worst[2]);
  EXPECT_LT(worst[0], 1e-12);
  EXPECT_LT(worst[1], 1e-12);
  EXPECT_LT(worst[2], 1e-8);  // the reference's own central difference
}

// ---- the analytic method's spatial closed forms against numeric -----------------------------------

// analytic's closed forms (analytic/src/spatial.cc) and numeric's Newton / linear solves on the same
// file, every slot of q, q̇, q̈ at every sample: the largest difference over the motion, relative to
// the slot's own scale (1 + its largest magnitude over the motion) so that one bound serves a
// point's coordinates and an angle. Measured (RelWithDebInfo): q / q̇ / q̈ 5.1e-16 / 7.3e-16 /
// 1.6e-15 (rssr_fourbar), 4.3e-16 / 9.1e-16 / 1.3e-15 (rssr_fourbar_angles), 2.6e-16 / 6.8e-16 /
// 7.9e-16 (spatial_slider_crank), 8e-16 / 1.1e-15 / 3.6e-15 (the benchmark, 241 samples): both
// at round-off; the bound 1e-12 is numeric's own Newton tolerance (phi_ and step_tolerance).
struct ClosedFormCase {
  const char* name;
  const char* file;   // under tests/data
  double q, qd, qdd;  // bounds
};

class SpatialClosedForms : public ::testing::TestWithParam<ClosedFormCase> {};

TEST_P(SpatialClosedForms, AnalyticAgreesWithNumericOverTheMotion) {
  const Model m = LoadScenario(std::string(MECHBENCH_TEST_DATA) + "/" + GetParam().file);
  const Result a = analytic::MakeAnalyticMethod()->Run(m), n = MakeNumericMethod()->Run(m);
  ASSERT_TRUE(a.ok()) << a.reason;
  ASSERT_TRUE(n.ok()) << n.reason;
  ASSERT_EQ(a.trajectory.size(), n.trajectory.size());
  const int slots = static_cast<int>(m.q_layout.size());
  Eigen::VectorXd scale = Eigen::VectorXd::Ones(slots), scale_d = scale, scale_dd = scale;
  for (const Sample& s : n.trajectory) {
    scale = scale.cwiseMax(Eigen::VectorXd::Ones(slots) + s.q.cwiseAbs());
    scale_d = scale_d.cwiseMax(Eigen::VectorXd::Ones(slots) + s.qd.cwiseAbs());
    scale_dd = scale_dd.cwiseMax(Eigen::VectorXd::Ones(slots) + s.qdd.cwiseAbs());
  }
  double worst[3] = {0, 0, 0};
  for (size_t k = 0; k < n.trajectory.size(); ++k) {
    const Sample &sa = a.trajectory[k], &sn = n.trajectory[k];
    ASSERT_EQ(sa.q.size(), slots);
    EXPECT_EQ(sa.t, sn.t);
    worst[0] = std::max(worst[0], ((sa.q - sn.q).cwiseAbs().cwiseQuotient(scale)).maxCoeff());
    worst[1] = std::max(worst[1], ((sa.qd - sn.qd).cwiseAbs().cwiseQuotient(scale_d)).maxCoeff());
    worst[2] = std::max(worst[2], ((sa.qdd - sn.qdd).cwiseAbs().cwiseQuotient(scale_dd)).maxCoeff());
  }
  if (std::getenv("MECHBENCH_VERBOSE"))
    std::printf("%s: analytic vs numeric over %zu samples, relative: q %.2g, qd %.2g, qdd %.2g\n", GetParam().name,
                n.trajectory.size(), worst[0], worst[1], worst[2]);
  EXPECT_LT(worst[0], GetParam().q);
  EXPECT_LT(worst[1], GetParam().qd);
  EXPECT_LT(worst[2], GetParam().qdd);
}

INSTANTIATE_TEST_SUITE_P(Fixtures, SpatialClosedForms,
                         ::testing::Values(
                             ClosedFormCase{"rssr_fourbar", "scenes/rssr_fourbar.yaml", 1e-12, 1e-12, 1e-12},
                             ClosedFormCase{"rssr_fourbar_angles", "scenes/rssr_fourbar_angles.yaml", 1e-12, 1e-12, 1e-12},
                             ClosedFormCase{"spatial_slider_crank", "scenes/spatial_slider_crank.yaml", 1e-12, 1e-12, 1e-12},
                             ClosedFormCase{"rssr_crank_rocker", "../../scenarios/benchmarks/rssr_crank_rocker.yaml", 1e-12,
                                            1e-12, 1e-12}),
                         [](const auto& param_info) { return std::string(param_info.param.name); });

// The same slider-crank driven at its slider (an inverse slider-crank: the crank is the output,
// on the branch of the file's pose): spatial_slider_crank.yaml with its driver moved, in memory, to
// s = s0 + 0.2 t over 0.5 s (the crank turns −0.15 rad, far from its dead points). Measured: q 1e-15,
// q̇ 5e-16, q̈ 7.8e-16 (absolute).
TEST(SpatialClosedFormsInverse, AnalyticAgreesWithNumericWhenTheSliderDrives) {
  Model m = LoadScenario(std::string(MECHBENCH_TEST_DATA) + "/scenes/spatial_slider_crank.yaml");
  const int s = m.SlotIndex("s"), theta = m.SlotIndex("theta");
  ASSERT_GE(s, 0);
  Driver d;
  d.coordinate = "s";
  d.value = m.spatial.coordinates[m.q_layout[s].spatial_coordinate].value;
  d.velocity = 0.2;
  d.src = m.drivers[0].src;
  m.drivers = {d};
  m.analysis.t1 = 0.5;
  m.analysis.samples = 11;
  const auto analytic = analytic::MakeAnalyticMethod();
  ASSERT_FALSE(analytic->Applicability(m)) << *analytic->Applicability(m);
  const Result a = analytic->Run(m), n = MakeNumericMethod()->Run(m);
  ASSERT_TRUE(a.ok()) << a.reason;
  ASSERT_TRUE(n.ok()) << n.reason;
  ASSERT_EQ(a.trajectory.size(), n.trajectory.size());
  double worst[3] = {0, 0, 0};
  for (size_t k = 0; k < a.trajectory.size(); ++k) {
    worst[0] = std::max(worst[0], (a.trajectory[k].q - n.trajectory[k].q).cwiseAbs().maxCoeff());
    worst[1] = std::max(worst[1], (a.trajectory[k].qd - n.trajectory[k].qd).cwiseAbs().maxCoeff());
    worst[2] = std::max(worst[2], (a.trajectory[k].qdd - n.trajectory[k].qdd).cwiseAbs().maxCoeff());
  }
  const double turn = a.trajectory.back().q[theta] - a.trajectory.front().q[theta];
  if (std::getenv("MECHBENCH_VERBOSE"))
    std::printf("inverse slider-crank: the crank turns %.3g rad; analytic vs numeric q %.2g, qd %.2g, qdd %.2g\n", turn,
                worst[0], worst[1], worst[2]);
  EXPECT_GT(std::fabs(turn), 0.01);  // the crank does move
  EXPECT_LT(worst[0], 1e-12);        // numeric's Newton tolerance, as above
  EXPECT_LT(worst[1], 1e-12);
  EXPECT_LT(worst[2], 1e-12);
}

// ---- rank: a planar four-bar of 3-D revolute joints ------------------------------------------------

// Crank A0–B, coupler B–C, rocker D0–C, each a body on two points, the fixed z axis (the shared
// vector of every revolute joint) and a vector of its own across its bar in the plane. 15
// coordinates, 15 rows, one degree of freedom: in space the loop closes twice in z (the coupler's
// and the rocker's (C − ·)·z rows say the same), the redundancy the rank solver has to find, as in
// Bricard's linkage. Driven by x_B, the rocker's angle follows the planar four-bar's closed form.
TEST(SpatialRank, PlanarLoopOfRevolutesIsRedundantInSpace) {
  const double a = 1.0, l = 3.2, c = 2.5, d = 3.0;  // crank, coupler, rocker, frame
  const auto rocker = [&](double th) {              // C from the two circles (the branch above the frame)
    const Eigen::Vector2d Bp(a * std::cos(th), a * std::sin(th)), Dp(d, 0);
    const Eigen::Vector2d e = Dp - Bp;
    const double s = e.norm(), x = (l * l - c * c + s * s) / (2 * s), y = std::sqrt(l * l - x * x);
    const Eigen::Vector2d u = e / s, Cp = Bp + x * u + y * Eigen::Vector2d(-u.y(), u.x());
    return V3(Cp.x(), Cp.y(), 0);
  };
  const double th0 = 1.0;
  SpatialBuilder b;
  const int A0 = b.Point("A0", V3::Zero(), true), D0 = b.Point("D0", V3(d, 0, 0), true);
  const int z = b.Vector("z", V3::UnitZ(), true);
  const V3 Bv = a * V3(std::cos(th0), std::sin(th0), 0), Cv = rocker(th0);
  const int B = b.Point("B", Bv), C = b.Point("C", Cv);
  const auto across = [](const V3& from, const V3& to) { return V3::UnitZ().cross(to - from).normalized(); };
  b.Body("crank", {A0, B, z, b.Vector("w1", across(V3::Zero(), Bv))});
  b.Body("coupler", {B, C, z, b.Vector("w2", across(Bv, Cv))});
  b.Body("rocker", {D0, C, z, b.Vector("w3", across(V3(d, 0, 0), Cv))});
  Driver drive;
  drive.coordinate = "Bx";
  b.Drive(b.Slot(B, 0), drive);
  NaturalModel nm = b.Build();
  ASSERT_EQ(nm.n, 15);
  ASSERT_EQ(nm.m(), 15);
  NaturalData data(nm);
  Eigen::VectorXd q = b.q0();
  UpdatePoints(nm, data, q);
  const RankReport rk = AnalyzeRank(nm, data);
  EXPECT_EQ(rk.rank, 14);
  EXPECT_EQ(rk.dof, 1);
  EXPECT_EQ(rk.augmented_rank, 15);
  ASSERT_EQ(rk.redundant_rows.size(), 1u);
  EXPECT_EQ(nm.rows[rk.redundant_rows[0]].kind, RowKind::kDot3) << nm.rows[rk.redundant_rows[0]].element;
  double worst = 0;
  for (double th = 0.6; th <= 2.0; th += 0.1) {
    nm.drivers[0].law.value = a * std::cos(th);
    const NewtonReport r = SolvePosition(nm, data, q, 0.0);
    ASSERT_TRUE(r.converged) << th;
    q = data.q;
    worst = std::max(worst, (EntityValue(nm, q, C) - rocker(th)).norm());
  }
  EXPECT_LT(worst, 1e-12);
}

}  // namespace
}  // namespace numeric_spatial_test
}  // namespace mechbench::numeric
