// Force elements (spring–dampers and torques, Model::springs and Model::torques) in the natural-
// coordinate dynamics: their Q against a hand computation and the potential's derivative, their
// tangents against finite differences, a torque's exact motion through every formulation, the
// energy balance with and without damping, and ALI3-P's order on a stiff spring.
#include "mechbench/analytic/energy.h"
#include "mechbench/errors.h"
#include "mechbench/loader.h"
#include "mechbench/motion_error.h"
#include "mechbench/numeric/dynamics.h"
#include "mechbench/numeric/dynamics_methods.h"
#include "mechbench/numeric/forward_dynamics.h"
#include "mechbench/numeric/natural_model.h"
#include "mechbench/references/nfourbar.h"
#include "mechbench/references/registry.h"
#include "formulations.h"
#include "quantity.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace mechbench::numeric {
namespace numeric_force_elements_test {  // this file's own names (the tests build in unity batches)
namespace {

using namespace ::mechbench::references;  // the N-four-bar's generator and exact motion

using test::Formulation;
using test::Formulations;
using test::Scene;

// At the file's state (A at (1, 0), S at (1, 1), θ̇ = 1 so ṙ_A = (0, 1)): d = A − S = (0, −1),
// L = 1, L̇ = −1; F = 50 (1 − 0.5) + 0.8 (−1) + 2 = 26.2 N, pulling A up: Q_yA = +26.2, Q_xA = 0.
TEST(NumericForceElements, SpringDamperQByHand) {
  const Model model = Scene("pendulum_spring_damper.yaml");
  const NaturalModel nm = Compile(model);
  const Eigen::VectorXd q = model.GuessQ();
  Eigen::VectorXd qd = Eigen::VectorXd::Zero(nm.n);
  qd[model.SlotIndex("yA")] = 1;
  qd[model.SlotIndex("theta")] = 1;
  Eigen::VectorXd Q = Eigen::VectorXd::Zero(nm.n);
  AddElementForces(nm, q, qd, model.analysis.t0, Q);
  EXPECT_NEAR(Q[model.SlotIndex("xA")], 0.0, 1e-14);
  EXPECT_NEAR(Q[model.SlotIndex("yA")], 26.2, 1e-13);
  EXPECT_EQ(Q[model.SlotIndex("theta")], 0.0);
  // The vector method's virtual power gives the same (analytic/energy.h).
  const Eigen::VectorXd Qa = analytic::ElementForcesByPower(model, q, qd, model.analysis.t0);
  EXPECT_LT((Qa - Q).cwiseAbs().maxCoeff(), 1e-13) << Qa.transpose() << " / " << Q.transpose();
  // In mm (lengths × 1000, Q in N and stiffness in N/m unchanged): the same newtons.
  const Model mm = Scene("pendulum_spring_damper_mm.yaml");
  const NaturalModel nmm = Compile(mm);
  Eigen::VectorXd Qmm = Eigen::VectorXd::Zero(nmm.n);
  AddElementForces(nmm, mm.GuessQ(), qd * 1000, mm.analysis.t0, Qmm);
  EXPECT_NEAR(Qmm[mm.SlotIndex("yA")], 26.2, 1e-12);
}

// The whole Q at a state — gravity and the elements — is the same in newtons from the vector
// method's virtual power and from numeric, in metres and in millimetres (gravity in m/s² either way).
TEST(NumericForceElements, GravityAndElementsGiveOneQInEveryLengthUnit) {
  for (const auto& [file, scale] : {std::pair{"pendulum_spring_damper.yaml", 1.0}, {"pendulum_spring_damper_mm.yaml", 1000.0}}) {
    SCOPED_TRACE(file);
    const Model model = Scene(file);
    const NaturalModel nm = Compile(model);
    NaturalData data(nm);
    GeneralizedForces(nm, data);
    const Eigen::VectorXd q = model.GuessQ();
    Eigen::VectorXd qd = Eigen::VectorXd::Zero(nm.n);
    qd[model.SlotIndex("yA")] = scale;
    Eigen::VectorXd Q = data.Q;
    AddElementForces(nm, q, qd, model.analysis.t0, Q);
    const Eigen::VectorXd Qa = analytic::MassAndForcesByEnergy(model).Q + analytic::ElementForcesByPower(model, q, qd, model.analysis.t0);
    EXPECT_LT((Qa - Q).cwiseAbs().maxCoeff(), 1e-12) << Qa.transpose() << " / " << Q.transpose();
    // Half the bar's weight on A, and the spring's 25 N + the preload's 2 N − the damper's 0.8 N at L̇ = −1 m/s.
    EXPECT_NEAR(Q[model.SlotIndex("yA")], 26.2 - 0.5 * 9.81, 1e-12);
  }
}

// Without velocity Q_e = −∂V/∂q (V = ½ k ((L − L0) u)² + F0 (L − L0) u), central differences at
// a state off the file's; ∂Q/∂q and ∂Q/∂q̇ (ElementDerivatives, ALI3-P's tangent) likewise, for
// springs, dampers and the torque together.
TEST(NumericForceElements, DerivativesMatchFiniteDifferences) {
  for (const char* file : {"pendulum_spring_damper.yaml", "pendulum_spring_damper_mm.yaml", "pendulum_spring_torque.yaml"}) {
    SCOPED_TRACE(file);
    const Model model = Scene(file);
    const NaturalModel nm = Compile(model);
    Eigen::VectorXd q = model.GuessQ();
    q[model.SlotIndex("xA")] = 0.8 * nm.length_scale, q[model.SlotIndex("yA")] = -0.55 * nm.length_scale;
    Eigen::VectorXd qd = Eigen::VectorXd::Zero(nm.n);
    const auto Qat = [&](const Eigen::VectorXd& x, const Eigen::VectorXd& xd) {
      Eigen::VectorXd Q = Eigen::VectorXd::Zero(nm.n);
      AddElementForces(nm, x, xd, model.analysis.t0, Q);
      return Q;
    };
    const double u = nm.meters_per_unit;
    if (model.torques.empty()) {
      const Eigen::VectorXd Q = Qat(q, qd);
      for (int s = 0; s < nm.n; ++s) {
        const double dx = 1e-6 * nm.q_scale[s];
        Eigen::VectorXd a = q, b = q;
        a[s] += dx, b[s] -= dx;
        // Q [N] · δq [length] · u = −δV [J].
        const double dV = (SpringPotential(nm, a) - SpringPotential(nm, b)) / (2 * dx);
        EXPECT_NEAR(Q[s] * u, -dV, 1e-7 * std::max(1.0, std::fabs(dV))) << model.q_layout[s].name;
      }
    }
    qd[model.SlotIndex("xA")] = 0.3 * nm.length_scale, qd[model.SlotIndex("yA")] = 0.7 * nm.length_scale;
    std::vector<ElementDerivative> D;
    ElementDerivatives(nm, q, qd, model.analysis.t0, D);
    Eigen::MatrixXd K = Eigen::MatrixXd::Zero(nm.n, nm.n), C = K;
    for (const ElementDerivative& d : D)
      for (size_t i = 0; i < d.slot.size(); ++i)
        for (size_t j = 0; j < d.slot.size(); ++j)
          if (d.slot[i] >= 0 && d.slot[j] >= 0) K(d.slot[i], d.slot[j]) += d.K(i, j), C(d.slot[i], d.slot[j]) += d.C(i, j);
    for (int s = 0; s < nm.n; ++s) {
      const double dx = 1e-6 * nm.q_scale[s];
      Eigen::VectorXd a = q, b = q, ad = qd, bd = qd;
      a[s] += dx, b[s] -= dx, ad[s] += dx, bd[s] -= dx;
      const Eigen::VectorXd Kfd = (Qat(a, qd) - Qat(b, qd)) / (2 * dx), Cfd = (Qat(q, ad) - Qat(q, bd)) / (2 * dx);
      EXPECT_LT((K.col(s) - Kfd).cwiseAbs().maxCoeff(), 1e-6 * std::max(1.0, Kfd.cwiseAbs().maxCoeff())) << s;
      EXPECT_LT((C.col(s) - Cfd).cwiseAbs().maxCoeff(), 1e-6 * std::max(1.0, Cfd.cwiseAbs().maxCoeff())) << s;
    }
  }
}

// (a) θ(t) = T t² / (2 I_O) = 0.75 t² exactly, 3 rad at 2 s. Measured, largest |θ − 0.75 t²| over
// the 21 samples (printed): RK4 2.4e-11, DOPRI5 1.7e-9, ALI3-P 3.4e-6, coordinate partitioning
// 1.3e-15 rad, dense and sparse alike; energy drift 2.1e-12, 1.7e-9, 2.8e-6, 1.3e-14 J.
TEST(NumericForceElements, TorqueOnAPinnedBarFollowsTheClosedForm) {
  const Model model = Scene("bar_torque.yaml");
  const int th = model.SlotIndex("theta");
  for (const Formulation& f : Formulations()) {
    const Result r = f.make()->Run(model);
    ASSERT_EQ(r.status, Status::kOk) << f.name << ": " << r.reason;
    ASSERT_EQ(r.trajectory.size(), 21u) << f.name;
    double worst = 0;
    for (const Sample& s : r.trajectory) worst = std::max(worst, std::fabs(s.q[th] - 0.75 * s.t * s.t));
    std::printf("  torque closed form, %-24s max |θ − T t²/(2 I_O)| = %.2e rad, energy drift %.2e J\n", f.name.c_str(),
                worst, Get(r, "energy_drift"));
    EXPECT_LT(worst, f.name.rfind("ali3p", 0) == 0 ? 1e-5 : 1e-7) << f.name;
    EXPECT_LT(Get(r, "energy_drift"), f.name.rfind("ali3p", 0) == 0 ? 1e-4 : 1e-6) << f.name;
    // θ̈ = T / I_O = 1.5 rad/s² at t0 (the index-1 solution every formulation starts from).
    EXPECT_NEAR(Get(r, "qdd.theta"), 1.5, 1e-12) << f.name;
  }
}

// (c) The energy balance E − W_torque + D (EnergyBalance) is the run's energy_drift. Undamped
// with a torque and a preloaded spring: E − W_torque constant (E gains 0.856 J from the torque;
// drift RK4 4.1e-9, DOPRI5 3.5e-7, partitioning 1.6e-7, ALI3-P 1.5e-4 J). Damped: E falls by
// 4.460 J, the dampers' dissipation, to 4.5e-6 J (the Hermite quadrature over 10 ms samples;
// ALI3-P 1.6e-4 J).
TEST(NumericForceElements, EnergyBalanceHoldsWithSpringsDampersAndTorques) {
  for (const char* file : {"pendulum_spring_torque.yaml", "pendulum_spring_damper.yaml"}) {
    const Model model = Scene(file);
    const NaturalModel nm = Compile(model);
    for (const Formulation& f : Formulations()) {
      const Result r = f.make()->Run(model);
      ASSERT_EQ(r.status, Status::kOk) << file << " " << f.name << ": " << r.reason;
      const DynamicsSystem sys(nm);
      const double loss = sys.Energy(r.trajectory.front().q, r.trajectory.front().qd) -
                          sys.Energy(r.trajectory.back().q, r.trajectory.back().qd);
      const double drift = Get(r, "energy_drift");
      std::printf("  %-28s %-24s E(t0) − E(t1) = %+.4f J, balance drift %.2e J\n", file, f.name.c_str(), loss, drift);
      const bool ali3p = f.name.rfind("ali3p", 0) == 0;
      EXPECT_LT(drift, ali3p ? 2e-3 : 1e-5) << file << " " << f.name;
      if (!model.springs[0].damping) continue;
      EXPECT_GT(loss, 1.0) << "the damper dissipates: " << file << " " << f.name;
    }
  }
}

// (d) ALI3-P's order on the stiff spring (ω ≈ 245 rad/s) against DOPRI5 at rtol 1e-12, dense and
// sparse: the error falls by 4 per halving of h. Measured 1.15e-1, 2.96e-2, 7.46e-3 at h = 1, 0.5,
// 0.25 ms (ratios 3.88, 3.98), both branches, about 5 Newton iterations a step.
TEST(NumericForceElements, Ali3pStaysSecondOrderOnAStiffSpring) {
  const Model model = Scene("pendulum_stiff_spring.yaml");
  BaumgarteOptions ref_o;
  ref_o.rtol = 1e-12;
  const Result ref = MakeBaumgarteDopri5Method(ref_o)->Run(model);
  ASSERT_EQ(ref.status, Status::kOk) << ref.reason;
  for (LinearAlgebra la : {LinearAlgebra::kDense, LinearAlgebra::kSparse}) {
    std::vector<double> e;
    for (double h : {1e-3, 5e-4, 2.5e-4}) {
      Ali3pOptions o;
      o.h = h;
      o.linear_algebra = la;
      const Result r = MakeAli3pMethod(o)->Run(model);
      ASSERT_EQ(r.status, Status::kOk) << r.reason;
      e.push_back(CompareMotion(model, ref.trajectory, r.trajectory).q.max);
      std::printf("  ALI3-P %s, stiff spring, h = %.3g ms: error %.3e, Newton iterations %g\n", ToString(la), h * 1e3,
                  e.back(), Get(r, "iterations"));
    }
    for (int k = 0; k < 2; ++k) {
      std::printf("  ALI3-P %s, ratio %d: %.3f\n", ToString(la), k, e[k] / e[k + 1]);
      EXPECT_GT(e[k] / e[k + 1], 3.6) << ToString(la) << " halving " << k;
      EXPECT_LT(e[k] / e[k + 1], 4.4) << ToString(la) << " halving " << k;
    }
  }
}

// The same scene in mm and in m moves alike: stiffness and damping are per metre.
TEST(NumericForceElements, LengthUnitDoesNotChangeTheMotion) {
  const Result m = MakeBaumgarteRk4Method()->Run(Scene("pendulum_spring_damper.yaml"));
  const Result mm = MakeBaumgarteRk4Method()->Run(Scene("pendulum_spring_damper_mm.yaml"));
  ASSERT_EQ(m.status, Status::kOk) << m.reason;
  ASSERT_EQ(mm.status, Status::kOk) << mm.reason;
  const Model model = Scene("pendulum_spring_damper.yaml");
  const int th = model.SlotIndex("theta");
  double worst = 0;
  for (size_t k = 0; k < m.trajectory.size(); ++k) worst = std::max(worst, std::fabs(m.trajectory[k].q[th] - mm.trajectory[k].q[th]));
  EXPECT_LT(worst, 1e-9);
  EXPECT_NEAR(Get(m, "energy_drift"), Get(mm, "energy_drift"), 1e-6);
}

// The N-four-bar's exact motion assumes constant loads: a torque makes it an ordinary scene.
TEST(NumericForceElements, NFourBarWithATorqueIsNotRecognised) {
  Model model = NFourBar({.n = 2, .t1 = 0.1, .samples = 3});
  ASSERT_NO_THROW(Validate(model));
  model.torques.push_back({.body = 0, .torque = 1.0, .law = nullptr, .src = {}});
  EXPECT_THROW(Validate(model), ScenarioError);
}

}  // namespace
}  // namespace numeric_force_elements_test
}  // namespace mechbench::numeric
