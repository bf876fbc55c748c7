// Force elements and mass on a bar in spatial scenes (issue 13; numeric/src/spatial_forces.cc,
// spatial.h): each scene of tests/data/scenes/spatial_*.yaml run through every dynamics formulation
// against a motion known without numeric — a zero-length spring's linear oscillator in closed
// form, a point mass under forces given as laws (two axes in closed form, the third integrated
// here), a uniform bar as a conical pendulum (closed form) and as a physical pendulum (integrated
// here), a rotor on a tilted hinge under body torques (J θ̈ = a·T, integrated here) — and the
// elements' generalized forces against their potential and their derivatives (ALI3-P's tangent)
// against finite differences.
#include "dynamics_method_named.h"
#include "mechbench/loader.h"
#include "mechbench/numeric/dynamics.h"
#include "mechbench/numeric/forward_dynamics.h"
#include "mechbench/numeric/natural_data.h"
#include "mechbench/numeric/numeric_method.h"
#include "mechbench/numeric/spatial.h"

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <numbers>
#include <string>
#include <vector>

namespace mechbench::numeric {
namespace numeric_spatial_forces_test {  // this file's own names (the tests build in unity batches)
namespace {

using V3 = Eigen::Vector3d;
constexpr double kPi = std::numbers::pi;

Model Scene(const std::string& name) { return LoadScenario(std::string(MECHBENCH_TEST_DATA) + "/scenes/" + name + ".yaml"); }

bool Verbose() { return std::getenv("MECHBENCH_VERBOSE") != nullptr; }

// x'' = f(t, x, x') integrated with classical RK4 at step h from (t0, x0, v0) up to each requested t.
class Reference1D {
 public:
  Reference1D(std::function<double(double, double, double)> f, double t0, double x0, double v0)
      : f_(std::move(f)), t_(t0), x_(x0), v_(v0) {}
  double At(double t) {
    const double h = 1e-5;
    while (t_ < t - 0.5 * h) {
      const double k1x = v_, k1v = f_(t_, x_, v_);
      const double k2x = v_ + 0.5 * h * k1v, k2v = f_(t_ + 0.5 * h, x_ + 0.5 * h * k1x, k2x);
      const double k3x = v_ + 0.5 * h * k2v, k3v = f_(t_ + 0.5 * h, x_ + 0.5 * h * k2x, k3x);
      const double k4x = v_ + h * k3v, k4v = f_(t_ + h, x_ + h * k3x, k4x);
      x_ += h / 6 * (k1x + 2 * k2x + 2 * k3x + k4x);
      v_ += h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
      t_ += h;
    }
    return x_;
  }

 private:
  std::function<double(double, double, double)> f_;
  double t_, x_, v_;
};

Result RunWith(const std::string& method, const Model& m) {
  const std::unique_ptr<Method> run = test::DynamicsMethodNamed(method);
  EXPECT_FALSE(run->Applicability(m).has_value());
  return run->Run(m, RunOptions{});
}

// ---- loading ----------------------------------------------------------------------------------------

TEST(SpatialForces, FilesLoadTheElements) {
  const Model chain = Scene("spatial_spring_chain");
  ASSERT_EQ(chain.spatial.springs.size(), 2u);
  EXPECT_EQ(chain.spatial.springs[0].stiffness, 40);
  EXPECT_EQ(chain.spatial.springs[0].preload, 1);
  EXPECT_EQ(chain.spatial.entities[chain.spatial.springs[1].points[0]].name, "P");
  EXPECT_TRUE(chain.HasForceElements());
  const Model forces = Scene("spatial_point_forces");
  ASSERT_EQ(forces.spatial.forces.size(), 2u);
  EXPECT_TRUE(forces.spatial.forces[0].law[0] && !forces.spatial.forces[0].law[2]);
  EXPECT_EQ(forces.spatial.forces[0].value.z(), -2);
  EXPECT_TRUE(forces.HasVaryingPointForces());
  const Model rotor = Scene("spatial_rotor_torque");
  ASSERT_EQ(rotor.spatial.torques.size(), 3u);
  EXPECT_NEAR(rotor.spatial.torques[0].value.y(), 3, 0);
  const Model bar = Scene("spatial_bar_swing");
  EXPECT_EQ(bar.spatial.bodies[0].mass, 0.7);
}

// The bar's mass matrix: the rod's kinetic energy ∫ ½ |ṙ(s)|² m ds over s ∈ [0, 1] with
// ṙ(s) = (1 − s) ṙ_O + s ṙ_P, by Gauss–Legendre (exact for this quadratic), for a random q̇: here
// O is fixed, so ½ q̇ᵀ M q̇ over P's slots; and its weight m g / 2 on P.
TEST(SpatialForces, BarMassMatrixIsTheUniformRods) {
  const Model m = Scene("spatial_bar_swing");
  const NaturalModel nm = Compile(m);
  NaturalData data(nm);
  MassMatrix(nm, data);
  GeneralizedForces(nm, data);
  const double mass = 0.7;
  const Eigen::VectorXd qd = (Eigen::VectorXd(3) << 0.3, -1.1, 0.7).finished();
  const V3 vP = qd;
  double T = 0;
  for (double xi : {-1 / std::sqrt(3.0), 1 / std::sqrt(3.0)}) {
    const double s = 0.5 * (1 + xi);
    T += 0.5 * 0.5 * mass * (s * vP).squaredNorm();
  }
  EXPECT_NEAR(0.5 * qd.dot(data.M * qd), T, 1e-15);
  EXPECT_NEAR(data.Q[2], -0.5 * mass * 9.81, 1e-14);
  EXPECT_EQ(data.Q[0], 0.0);
}

// ---- derivatives against finite differences -----------------------------------------------------

// At a state off the file's (every slot moved, q̇ ≠ 0): ∂Q/∂q and ∂Q/∂q̇ of the elements
// (ElementDerivatives) against central differences of AddElementForces; without velocity, the
// springs' Q against −∂V/∂q (SpringPotential); the power Σ Q q̇ u against the code's powers.
TEST(SpatialForces, DerivativesMatchFiniteDifferences) {
  for (const char* file : {"spatial_spring_chain", "spatial_spring_oscillator", "spatial_point_forces", "spatial_rotor_torque",
                           "spatial_spring_law_pendulum", "spatial_spring_law_constant", "spatial_follower_force",
                           "spatial_follower_motor_curve"}) {
    SCOPED_TRACE(file);
    const Model m = Scene(file);
    const NaturalModel nm = Compile(m);
    const double t = 0.7, u = nm.meters_per_unit;
    Eigen::VectorXd q = m.GuessQ(), qd(nm.n);
    for (int s = 0; s < nm.n; ++s) q[s] += 0.05 * std::sin(3.0 * s + 1), qd[s] = 0.4 * std::cos(2.0 * s + 0.5);
    const auto Qat = [&](const Eigen::VectorXd& x, const Eigen::VectorXd& xd) {
      Eigen::VectorXd Q = Eigen::VectorXd::Zero(nm.n);
      AddElementForces(nm, x, xd, t, Q);
      return Q;
    };
    EXPECT_GT(Qat(q, qd).cwiseAbs().maxCoeff(), 0.1);  // a load is there
    std::vector<ElementDerivative> D;
    ElementDerivatives(nm, q, qd, t, D);
    ASSERT_EQ(D.size(), ElementSlots(nm).size());
    Eigen::MatrixXd K = Eigen::MatrixXd::Zero(nm.n, nm.n), C = K;
    for (const ElementDerivative& d : D)
      for (size_t i = 0; i < d.slot.size(); ++i)
        for (size_t j = 0; j < d.slot.size(); ++j)
          if (d.slot[i] >= 0 && d.slot[j] >= 0) K(d.slot[i], d.slot[j]) += d.K(i, j), C(d.slot[i], d.slot[j]) += d.C(i, j);
    double worst = 0;
    for (int s = 0; s < nm.n; ++s) {
      const double dx = 1e-6;
      Eigen::VectorXd a = q, b = q, ad = qd, bd = qd;
      a[s] += dx, b[s] -= dx, ad[s] += dx, bd[s] -= dx;
      const Eigen::VectorXd Kfd = (Qat(a, qd) - Qat(b, qd)) / (2 * dx), Cfd = (Qat(q, ad) - Qat(q, bd)) / (2 * dx);
      const double scale = std::max(1.0, std::max(Kfd.cwiseAbs().maxCoeff(), Cfd.cwiseAbs().maxCoeff()));
      worst = std::max(worst, std::max((K.col(s) - Kfd).cwiseAbs().maxCoeff(), (C.col(s) - Cfd).cwiseAbs().maxCoeff()) / scale);
    }
    if (Verbose()) std::printf("%s: ∂Q/∂q, ∂Q/∂q̇ against central differences: %.2g (relative)\n", file, worst);
    EXPECT_LT(worst, 1e-7);
    if (!m.spatial.springs.empty() && !m.HasSpringLaws()) {  // a spring with a law has no potential
      const Eigen::VectorXd zero = Eigen::VectorXd::Zero(nm.n), Q = Qat(q, zero);
      for (int s = 0; s < nm.n; ++s) {
        const double dx = 1e-6;
        Eigen::VectorXd a = q, b = q;
        a[s] += dx, b[s] -= dx;
        const double dV = (SpringPotential(nm, a) - SpringPotential(nm, b)) / (2 * dx);
        EXPECT_NEAR(Q[s] * u, -dV, 1e-7 * std::max(1.0, std::fabs(dV))) << m.q_layout[s].name;
      }
    }
    // Power: Q·q̇ u is the dampers' −c L̇² plus the springs' −V̇ plus the torques' and the laws' powers.
    const Eigen::VectorXd Q = Qat(q, qd);
    const double dx = 1e-6;
    const double Vdot = (SpringPotential(nm, q + dx * qd) - SpringPotential(nm, q - dx * qd)) / (2 * dx);
    const double P = -DamperPower(nm, q, qd) - Vdot + LawTorquePower(nm, q, qd, t) + VaryingPointForcePower(nm, q, qd, t) +
                     LawSpringPower(nm, q, qd, t);
    EXPECT_NEAR(Q.dot(qd) * u, P, 1e-7 * std::max(1.0, std::fabs(P)));
  }
}

// The power's rate given q̈ (the energy balance's Hermite rule uses it) against a central
// difference of the power along q(t) = q + q̇ τ + q̈ τ²/2.
TEST(SpatialForces, PowerRatesMatchFiniteDifferences) {
  for (const char* file : {"spatial_spring_chain", "spatial_point_forces", "spatial_rotor_torque", "spatial_spring_law_pendulum",
                           "spatial_follower_force", "spatial_follower_motor_curve"}) {
    SCOPED_TRACE(file);
    const Model m = Scene(file);
    const NaturalModel nm = Compile(m);
    const double t = 0.7;
    Eigen::VectorXd q = m.GuessQ(), qd(nm.n), qdd(nm.n);
    for (int s = 0; s < nm.n; ++s) qd[s] = 0.4 * std::cos(2.0 * s + 0.5), qdd[s] = 0.9 * std::sin(1.3 * s + 0.2);
    const auto power = [&](double tau, double* rate) {
      const Eigen::VectorXd x = q + qd * tau + 0.5 * qdd * tau * tau, xd = qd + qdd * tau;
      double r1 = 0, r2 = 0, r3 = 0, r4 = 0;
      const double p = DamperPower(nm, x, xd, &qdd, &r1) - LawTorquePower(nm, x, xd, t + tau, &qdd, &r2) -
                       VaryingPointForcePower(nm, x, xd, t + tau, &qdd, &r3) - LawSpringPower(nm, x, xd, t + tau, &qdd, &r4);
      if (rate) *rate = r1 - r2 - r3 - r4;
      return p;
    };
    double rate = 0;
    power(0, &rate);
    const double h = 1e-5, fd = (power(h, nullptr) - power(-h, nullptr)) / (2 * h);
    EXPECT_GT(std::fabs(fd), 1e-3);
    EXPECT_NEAR(rate, fd, 1e-7 * std::max(1.0, std::fabs(fd)));
  }
}

// ---- motions against references ----------------------------------------------------------------

struct Bound {
  const char* method;
  double error;   // the test's measure [m or rad]
  double energy;  // the energy balance's largest change [J] (EnergyBalance), where checked
};

// Sample by sample: the largest |EnergyBalance − its first value| over the run.
double EnergyDrift(const Model& m, const Result& r) {
  const NaturalModel nm = Compile(m);
  const DynamicsSystem sys(nm);
  EnergyBalance balance(sys);
  double e0 = NAN, drift = 0;
  for (const Sample& s : r.trajectory) {
    const double e = balance.Next(s.t, s.q, s.qd, s.qdd);
    if (std::isnan(e0)) e0 = e;
    drift = std::max(drift, std::fabs(e - e0));
  }
  return drift;
}

class SpatialSpringOscillator : public ::testing::TestWithParam<Bound> {};

// r(t) = c + (r0 − c) cos ωt + v0/ω sin ωt, c = r_A + m g/k, ω = √(k/m) (free length 0: linear).
TEST_P(SpatialSpringOscillator, FollowsTheClosedForm) {
  const Bound bound = GetParam();
  const Model m = Scene("spatial_spring_oscillator");
  const Result r = RunWith(bound.method, m);
  ASSERT_TRUE(r.ok()) << r.reason;
  ASSERT_EQ(static_cast<int>(r.trajectory.size()), m.analysis.samples);
  const double mass = m.constants.at("mb"), k = m.constants.at("k"), w = std::sqrt(k / mass);
  const V3 A = m.spatial.entities[m.spatial.EntityIndex("A")].r_W, g = m.spatial.gravity;
  const V3 c = A + mass * g / k, r0 = r.trajectory[0].q.head<3>(), v0 = r.trajectory[0].qd.head<3>();
  EXPECT_NEAR((v0 - V3(0.1, 0.6, -0.3)).norm(), 0, 1e-12);
  double worst = 0, reach = 0;
  for (const Sample& s : r.trajectory) {
    const double t = s.t - m.analysis.t0;
    const V3 ref = c + (r0 - c) * std::cos(w * t) + v0 / w * std::sin(w * t);
    worst = std::max(worst, (s.q.head<3>() - ref).norm());
    reach = std::max(reach, (s.q.head<3>() - r0).norm());
  }
  const double drift = EnergyDrift(m, r);
  if (Verbose()) std::printf("spring oscillator, %s: |r − r_ref| %.2g m (moved %.3g m), energy %.2g J\n", bound.method, worst, reach, drift);
  EXPECT_GT(reach, 0.3);
  EXPECT_LT(worst, bound.error);
  EXPECT_LT(drift, bound.energy);
}

INSTANTIATE_TEST_SUITE_P(Methods, SpatialSpringOscillator,
                         // Measured (RelWithDebInfo, 3 s, 3.3 periods, P moved 1.16 m; MECHBENCH_VERBOSE prints
                         // them): |r − r_ref| RK4 (1 ms) 4.3e-11 m, DOPRI5 5.6e-9, ALI3-P 1.7e-5 (second order),
                         // partitioning 5.6e-9; energy 2.3e-12, 7.9e-8, 3.5e-13, 7.9e-8 J.
                         ::testing::Values(Bound{"rk4", 3e-10, 2e-11}, Bound{"dopri5", 5e-8, 5e-7},
                                           Bound{"ali3p", 1e-4, 1e-11}, Bound{"partitioning", 5e-8, 5e-7}),
                         [](const auto& param_info) { return std::string(param_info.param.method); });

class SpatialSpringChain : public ::testing::TestWithParam<Bound> {};

// Two bobs on spring–dampers: the energy balance (kinetic + weight + springs + dissipated) is
// constant along an exact motion; against DOPRI5 at rtol 1e-12 as a reference for the motion.
TEST_P(SpatialSpringChain, KeepsItsEnergyBalance) {
  const Bound bound = GetParam();
  const Model m = Scene("spatial_spring_chain");
  const Result r = RunWith(bound.method, m);
  ASSERT_TRUE(r.ok()) << r.reason;
  ASSERT_EQ(static_cast<int>(r.trajectory.size()), m.analysis.samples);
  RunOptions tight;
  tight.tolerance = 1e-12;
  const Result ref = test::DynamicsMethodNamed("dopri5")->Run(m, tight);
  ASSERT_TRUE(ref.ok()) << ref.reason;
  double worst = 0;
  for (size_t k = 0; k < r.trajectory.size(); ++k) worst = std::max(worst, (r.trajectory[k].q - ref.trajectory[k].q).cwiseAbs().maxCoeff());
  const double drift = EnergyDrift(m, r);
  if (Verbose()) std::printf("spring chain, %s: |q − q_ref| %.2g m, energy balance %.2g J\n", bound.method, worst, drift);
  EXPECT_LT(worst, bound.error);
  EXPECT_LT(drift, bound.energy);
}

INSTANTIATE_TEST_SUITE_P(Methods, SpatialSpringChain,
                         // Measured (2 s): against DOPRI5 at 1e-12, RK4 3.3e-11 m, DOPRI5 (default) 8.3e-10,
                         // ALI3-P 7.2e-6, partitioning 8.3e-10; the balance 1.1e-8, 1.3e-8, 3.7e-6, 1.3e-8 J (for
                         // RK4, DOPRI5, partitioning mostly the Hermite rule on the dampers' c L̇² 10 ms apart).
                         ::testing::Values(Bound{"rk4", 1e-9, 5e-8}, Bound{"dopri5", 1e-8, 5e-8},
                                           Bound{"ali3p", 5e-5, 2e-5}, Bound{"partitioning", 1e-8, 5e-8}),
                         [](const auto& param_info) { return std::string(param_info.param.method); });

class SpatialPointForces : public ::testing::TestWithParam<Bound> {};

// x = x0 + vx0 t + F1 t³/(6m), z = z0 + vz0 t + (−2/m + g_z) t²/2, m ÿ = 1.5 − kk y − cc ẏ.
TEST_P(SpatialPointForces, FollowTheirLaws) {
  const Bound bound = GetParam();
  const Model m = Scene("spatial_point_forces");
  const Result r = RunWith(bound.method, m);
  ASSERT_TRUE(r.ok()) << r.reason;
  ASSERT_EQ(static_cast<int>(r.trajectory.size()), m.analysis.samples);
  const double mass = 2, F1 = m.constants.at("F1"), kk = m.constants.at("kk"), cc = m.constants.at("cc"), gz = -9.81;
  Reference1D y([&](double, double x, double v) { return (1.5 - kk * x - cc * v) / mass; }, m.analysis.t0, 0.2, -0.5);
  double worst = 0;
  for (const Sample& s : r.trajectory) {
    const double t = s.t - m.analysis.t0;
    const V3 ref(0.1 + 0.2 * t + F1 * t * t * t / (6 * mass), y.At(s.t), 0.3 + 1.0 * t + 0.5 * (-2 / mass + gz) * t * t);
    worst = std::max(worst, (s.q.head<3>() - ref).norm());
  }
  const double drift = EnergyDrift(m, r);
  if (Verbose()) std::printf("point forces, %s: |r − r_ref| %.2g m, energy balance %.2g J\n", bound.method, worst, drift);
  EXPECT_LT(worst, bound.error);
  EXPECT_LT(drift, bound.energy);
}

INSTANTIATE_TEST_SUITE_P(Methods, SpatialPointForces,
                         // Measured (2 s): RK4 3.1e-13 m, DOPRI5 1.5e-9, ALI3-P 3.3e-7, partitioning 1.5e-9; the
                         // balance 1.2e-6 J for all four: the Hermite rule on the laws' power F·v 50 ms apart.
                         ::testing::Values(Bound{"rk4", 1e-11, 3e-6}, Bound{"dopri5", 1e-8, 3e-6},
                                           Bound{"ali3p", 2e-6, 3e-6}, Bound{"partitioning", 1e-8, 3e-6}),
                         [](const auto& param_info) { return std::string(param_info.param.method); });

class SpatialBar : public ::testing::TestWithParam<Bound> {};

// A uniform bar as a conical pendulum: P keeps its height and turns at Ω² = 3 g / (2 L cos α).
TEST_P(SpatialBar, ConicalPendulumAtTheRodsRate) {
  const Bound bound = GetParam();
  const Model m = Scene("spatial_bar_conical");
  const Result r = RunWith(bound.method, m);
  ASSERT_TRUE(r.ok()) << r.reason;
  const double Omega = m.constants.at("Omega"), L = m.constants.at("L");
  const double z0 = r.trajectory[0].q[2];
  double dz = 0, dturn = 0, turned = 0, last = 0;
  for (const Sample& s : r.trajectory) {
    dz = std::max(dz, std::fabs(s.q[2] - z0));
    const double az = std::atan2(s.q[1], s.q[0]);
    turned += std::remainder(az - last, 2 * kPi);
    last = az;
    dturn = std::max(dturn, std::fabs(turned - Omega * (s.t - m.analysis.t0)));
  }
  const double drift = EnergyDrift(m, r);
  if (Verbose()) std::printf("bar conical, %s: height %.2g m, azimuth %.2g rad, energy %.2g J\n", bound.method, dz, dturn, drift);
  EXPECT_GT(turned, 2 * kPi - 0.1);
  EXPECT_LT(dz, bound.error * L);
  EXPECT_LT(dturn, bound.error);
  EXPECT_LT(drift, bound.energy);
}

// The same bar swinging in a plane: θ̈ = −(3 g / (2 L)) sin θ, θ the angle of O→P from −z.
TEST_P(SpatialBar, PhysicalPendulumSwing) {
  const Bound bound = GetParam();
  const Model m = Scene("spatial_bar_swing");
  const Result r = RunWith(bound.method, m);
  ASSERT_TRUE(r.ok()) << r.reason;
  const double L = m.constants.at("L");
  Reference1D th([&](double, double x, double) { return -1.5 * 9.81 / L * std::sin(x); }, m.analysis.t0, m.constants.at("th0"), 0);
  double worst = 0, out = 0, low = 10;
  for (const Sample& s : r.trajectory) {
    const double ref = th.At(s.t);
    worst = std::max(worst, std::fabs(std::atan2(s.q[0], -s.q[2]) - ref));
    out = std::max(out, std::fabs(s.q[1]));
    low = std::min(low, ref);
  }
  if (Verbose()) std::printf("bar swing, %s: |θ − θ_ref| %.2g rad (θ down to %.3g), out of plane %.2g m\n", bound.method, worst, low, out);
  EXPECT_LT(low, -1.0);  // it swung across
  EXPECT_LT(worst, bound.error);
  EXPECT_LT(out, 1e-12);
}

INSTANTIATE_TEST_SUITE_P(Methods, SpatialBar,
                         // Measured: conical (one turn) height / azimuth / energy RK4 6.2e-12 m, 2.2e-11 rad,
                         // 3.2e-11 J; DOPRI5 9.0e-12, 2.2e-11, 7.8e-11; ALI3-P 9.5e-15, 9.2e-6, 1.1e-13;
                         // partitioning 1.1e-10, 2.4e-10, 1.4e-9. Swing (2 s, θ from 1.2 to −1.2 rad): RK4
                         // 5.2e-10 rad, DOPRI5 1.8e-8, ALI3-P 4.4e-5, partitioning 7.0e-8; out of plane 0.
                         ::testing::Values(Bound{"rk4", 3e-9, 2e-10}, Bound{"dopri5", 1e-7, 5e-10},
                                           Bound{"ali3p", 2e-4, 1e-11}, Bound{"partitioning", 3e-7, 1e-8}),
                         [](const auto& param_info) { return std::string(param_info.param.method); });

class SpatialRotor : public ::testing::TestWithParam<Bound> {};

// J θ̈ = T0 + T1 t − cz sin β θ̇, J = m |r_G ⊥ a|² + aᵀ I_G a: the torque across the axis does nothing.
TEST_P(SpatialRotor, TorqueAboutTheHingeAxisAlone) {
  const Bound bound = GetParam();
  const Model m = Scene("spatial_rotor_torque");
  const Result r = RunWith(bound.method, m);
  ASSERT_TRUE(r.ok()) << r.reason;
  const SpatialModel& s = m.spatial;
  const SpatialBody& body = s.bodies.at(0);
  const V3 a = s.entities[s.EntityIndex("a")].r_W, rG0 = body.com_W - s.entities[s.EntityIndex("O")].r_W;
  const double J = body.mass * (rG0 - rG0.dot(a) * a).squaredNorm() + a.dot(body.inertia_W * a);
  const double T0 = m.constants.at("T0"), T1 = m.constants.at("T1"), cz = m.constants.at("cz"), beta = m.constants.at("beta");
  Reference1D th([&](double t, double, double v) { return (T0 + T1 * t - cz * std::sin(beta) * v) / J; }, m.analysis.t0, 0, 0.5);
  const int slot = m.SlotIndex("theta");
  double worst = 0, reached = 0;
  for (const Sample& smp : r.trajectory) {
    const double ref = th.At(smp.t);
    worst = std::max(worst, std::fabs(smp.q[slot] - ref));
    reached = ref;
  }
  const double drift = EnergyDrift(m, r);
  if (Verbose()) std::printf("rotor torque, %s: |θ − θ_ref| %.2g rad (θ to %.3g rad), energy balance %.2g J\n", bound.method, worst, reached, drift);
  EXPECT_GT(reached, 3.0);
  EXPECT_LT(worst, bound.error);
  EXPECT_LT(drift, bound.energy);
}

INSTANTIATE_TEST_SUITE_P(Methods, SpatialRotor,
                         // Measured (2 s, θ to 5.77 rad): RK4 1.6e-10 rad, DOPRI5 6.7e-9, ALI3-P 1.5e-5,
                         // partitioning 5.6e-12; the balance (∫ T·ω dt) 1.3e-9, 2.1e-8, 1.2e-5, 1.6e-9 J.
                         ::testing::Values(Bound{"rk4", 1e-9, 1e-8}, Bound{"dopri5", 5e-8, 1e-7},
                                           Bound{"ali3p", 1e-4, 1e-4}, Bound{"partitioning", 1e-10, 1e-8}),
                         [](const auto& param_info) { return std::string(param_info.param.method); });

// ---- spring laws and follower forces (the planar elements' features in 3-D) ------------------------

Model PlanarScene(const std::string& name) {
  return LoadScenario(std::string(MECHBENCH_TEST_DATA) + "/scenes/" + name + ".yaml");
}

// Each law's value never changes (max(k, k − t) = k for t ≥ 0): the forces are the constant
// spring's, so is the motion, to the last bits (the energy balance integrates their work instead).
TEST(SpatialSpringLaws, LawsEqualToConstantsGiveTheConstantSpring) {
  const Model constant = Scene("spatial_spring_chain"), law = Scene("spatial_spring_law_constant");
  ASSERT_TRUE(law.HasSpringLaws() && !constant.HasSpringLaws());
  for (const char* method : {"rk4", "dopri5", "ali3p", "partitioning"}) {
    SCOPED_TRACE(method);
    const Result a = RunWith(method, constant), b = RunWith(method, law);
    ASSERT_TRUE(a.ok()) << a.reason;
    ASSERT_TRUE(b.ok()) << b.reason;
    ASSERT_EQ(a.trajectory.size(), b.trajectory.size());
    double worst = 0;
    for (size_t k = 0; k < a.trajectory.size(); ++k)
      worst = std::max(worst, (a.trajectory[k].q - b.trajectory[k].q).cwiseAbs().maxCoeff());
    const double drift = EnergyDrift(law, b), drift_constant = EnergyDrift(constant, a);
    if (Verbose())
      std::printf("spring laws equal to constants, %s: max |q_law − q_const| %.2g m, energy balance %.2g J (constant %.2g J)\n",
                  method, worst, drift, drift_constant);
    EXPECT_LE(worst, 1e-15);
    // The same motion; the balance differs by the Hermite rule on the springs' work (10 ms samples):
    // measured 1.8e-7, 1.7e-7, 1.1e-5, 1.7e-7 J (constant 1.1e-8, 1.3e-8, 3.7e-6, 1.3e-8 J).
    EXPECT_LT(drift, std::string(method) == "ali3p" ? 3e-5 : 6e-7);
  }
}

// The two features against the planar solver: a spatial scene and its planar original have one
// motion (θ and the tip A), each run at DOPRI5's tight tolerance; and each formulation's energy
// balance within its bound.
struct CopyCase {
  const char* spatial;
  const char* planar;
  double agreement;  // max |θ − θ_planar| and |r_A − r_A,planar| [rad, m], DOPRI5 at rtol 1e-12
};
class SpatialPlanarCopy : public ::testing::TestWithParam<CopyCase> {};

TEST_P(SpatialPlanarCopy, SameMotionAsThePlanarScene) {
  const CopyCase c = GetParam();
  const Model m3 = Scene(c.spatial), m2 = PlanarScene(c.planar);
  RunOptions tight;
  tight.tolerance = 1e-12;
  const Result r3 = test::DynamicsMethodNamed("dopri5")->Run(m3, tight), r2 = test::DynamicsMethodNamed("dopri5")->Run(m2, tight);
  ASSERT_TRUE(r3.ok()) << r3.reason;
  ASSERT_TRUE(r2.ok()) << r2.reason;
  ASSERT_EQ(r3.trajectory.size(), r2.trajectory.size());
  const int th3 = m3.SlotIndex("theta"), th2 = m2.SlotIndex("theta");
  const int x3 = m3.SlotIndex("xA"), y3 = m3.SlotIndex("yA"), x2 = m2.SlotIndex("xA"), y2 = m2.SlotIndex("yA");
  ASSERT_TRUE(th3 >= 0 && th2 >= 0 && x3 >= 0 && y3 >= 0 && x2 >= 0 && y2 >= 0);
  double worst = 0, reach = 0;
  for (size_t k = 0; k < r3.trajectory.size(); ++k) {
    const Sample &a = r3.trajectory[k], &b = r2.trajectory[k];
    worst = std::max({worst, std::fabs(a.q[th3] - b.q[th2]), std::fabs(a.q[x3] - b.q[x2]), std::fabs(a.q[y3] - b.q[y2]),
                      std::fabs(a.qd[th3] - b.qd[th2])});
    reach = std::max(reach, std::fabs(b.q[th2] - r2.trajectory[0].q[th2]));
  }
  if (Verbose()) std::printf("%s against %s: max difference %.2g (θ moved %.3g rad)\n", c.spatial, c.planar, worst, reach);
  EXPECT_GT(reach, 0.5);
  EXPECT_LT(worst, c.agreement);
}

INSTANTIATE_TEST_SUITE_P(Scenes, SpatialPlanarCopy,
                         // Measured (DOPRI5 at 1e-12 both, 2 s): 2.7e-12, 2.8e-14, 5.0e-14; bounds about 10× above.
                         ::testing::Values(CopyCase{"spatial_spring_law_pendulum", "pendulum_spring_law", 3e-11},
                                           CopyCase{"spatial_follower_force", "bar_follower_force", 1e-12},
                                           CopyCase{"spatial_follower_motor_curve", "bar_follower_motor_curve", 1e-12}),
                         [](const auto& param_info) { return std::string(param_info.param.spatial).substr(8); });

struct LawBound {
  const char* method;
  double error;   // against the reference [rad]
  double energy;  // the energy balance's largest change [J]
};
class SpatialSpringLawPendulum : public ::testing::TestWithParam<LawBound> {};

// No closed form: each formulation against DOPRI5 at rtol 1e-12, and its energy balance.
TEST_P(SpatialSpringLawPendulum, FormulationsAgreeAndKeepTheBalance) {
  const LawBound bound = GetParam();
  const Model m = Scene("spatial_spring_law_pendulum");
  RunOptions tight;
  tight.tolerance = 1e-12;
  const Result ref = test::DynamicsMethodNamed("dopri5")->Run(m, tight);
  const Result r = RunWith(bound.method, m);
  ASSERT_TRUE(ref.ok()) << ref.reason;
  ASSERT_TRUE(r.ok()) << r.reason;
  const int th = m.SlotIndex("theta");
  double worst = 0;
  for (size_t k = 0; k < r.trajectory.size(); ++k) worst = std::max(worst, std::fabs(r.trajectory[k].q[th] - ref.trajectory[k].q[th]));
  const double drift = EnergyDrift(m, r);
  if (Verbose()) std::printf("spatial spring law pendulum, %s: |θ − θ_ref| %.2g rad, energy balance %.2g J\n", bound.method, worst, drift);
  EXPECT_LT(worst, bound.error);
  EXPECT_LT(drift, bound.energy);
}

INSTANTIATE_TEST_SUITE_P(Methods, SpatialSpringLawPendulum,
                         // Measured: see the verbose line (MECHBENCH_VERBOSE); the planar scene's bounds
                         // (2 s): RK4 (1 ms) 1.0e-9 rad, DOPRI5 1.9e-8, ALI3-P 4.1e-5, partitioning 2.0e-8; the
                         // balance 2.2e-5, 2.2e-5, 5.0e-5, 2.2e-5 J, mostly the Hermite rule on the stiff spring's
                         // work 10 ms apart: the planar scene's figures (numeric_spring_laws_test.cc) and bounds.
                         ::testing::Values(LawBound{"rk4", 5e-9, 6e-5}, LawBound{"dopri5", 6e-8, 6e-5},
                                           LawBound{"ali3p", 1.2e-4, 1.5e-4}, LawBound{"partitioning", 6e-8, 6e-5}),
                         [](const auto& param_info) { return std::string(param_info.param.method); });

class SpatialFollower : public ::testing::TestWithParam<LawBound> {};

// A follower force across the bar, F = 0.3 N at L = 1 m: a constant torque about the hinge,
// θ = F L t²/(2 I_O); with F = F0 (1 − ω/ω0): θ = ω0 (t − (1 − e^(−k t))/k), k = F0 L/(ω0 I_O).
TEST_P(SpatialFollower, ClosedFormsAboutTheHinge) {
  const LawBound bound = GetParam();
  const double I_O = 1.0 / 3;
  for (const char* file : {"spatial_follower_force", "spatial_follower_motor_curve"}) {
    SCOPED_TRACE(file);
    const Model m = Scene(file);
    ASSERT_EQ(m.spatial.forces.size(), 1u);
    ASSERT_GE(m.spatial.forces[0].frame, 0);
    const bool curve = m.spatial.forces[0].HasLaw();
    const Result r = RunWith(bound.method, m);
    ASSERT_TRUE(r.ok()) << r.reason;
    const int th = m.SlotIndex("theta");
    double worst = 0, reached = 0;
    for (const Sample& s : r.trajectory) {
      const double t = s.t - m.analysis.t0;
      double ref = 0.3 * t * t / (2 * I_O);
      if (curve) {
        const double F0 = m.constants.at("F0"), w0 = m.constants.at("omega0"), k = F0 / (w0 * I_O);
        ref = w0 * (t - (1 - std::exp(-k * t)) / k);
      }
      worst = std::max(worst, std::fabs(s.q[th] - ref));
      reached = ref;
    }
    const double drift = EnergyDrift(m, r);
    if (Verbose()) std::printf("%s, %s: |θ − θ_ref| %.2g rad (θ to %.3g rad), energy balance %.2g J\n", file, bound.method, worst, reached, drift);
    EXPECT_GT(reached, 1.0);
    EXPECT_LT(worst, bound.error);
    EXPECT_LT(drift, bound.energy);
  }
}

INSTANTIATE_TEST_SUITE_P(Methods, SpatialFollower,
                         // Measured (2 s, 21 samples): the force θ RK4 (1 ms) 4.7e-12 rad, DOPRI5 5.5e-10, ALI3-P
                         // 7.3e-7, partitioning 2.2e-16 (the planar bar's figures, README); the motor curve 5.8e-12,
                         // 5.1e-10, 8.8e-7, 7.9e-11. The balance: the force 2.8e-11, 2.2e-9, 4.4e-7, 9.1e-15 J; the
                         // curve 1.6e-7 J each (the Hermite rule on its work 0.1 s apart), ALI3-P 4.9e-7.
                         ::testing::Values(LawBound{"rk4", 2e-11, 5e-7}, LawBound{"dopri5", 2e-9, 5e-7},
                                           LawBound{"ali3p", 3e-6, 1.5e-6}, LawBound{"partitioning", 3e-10, 5e-7}),
                         [](const auto& param_info) { return std::string(param_info.param.method); });

}  // namespace
}  // namespace numeric_spatial_forces_test
}  // namespace mechbench::numeric
