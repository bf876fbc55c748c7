// Spring–dampers whose parameters are laws of t and of the state (tests/data/scenes/block_spring_*.yaml,
// pendulum_spring_*law.yaml) in the natural-coordinate dynamics: every formulation against the
// closed forms, the energy balance with the springs' work (a spring with a law has no potential),
// Q against the vector method's virtual power, ∂Q/∂q and ∂Q/∂q̇ (ALI3-P's tangent) against finite
// differences, and a law equal to a constant against the constant spring.
#include "mechbench/analytic/energy.h"
#include "mechbench/loader.h"
#include "mechbench/numeric/dynamics.h"
#include "mechbench/numeric/dynamics_methods.h"
#include "mechbench/numeric/forward_dynamics.h"
#include "mechbench/numeric/natural_model.h"
#include "element_forces_check.h"
#include "formulations.h"
#include "quantity.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

namespace mechbench::numeric {
namespace numeric_spring_laws_test {  // this file's own names (the tests build in unity batches)
namespace {

using test::Formulation;
using test::Formulations;
using test::OffState;
using test::Scene;

struct ClosedForm {
  const char* file;
  std::function<double(const Model&, double)> xB;  // [m]
  double bound, ali3p_bound;                       // max |x − x_exact| [m]
};

// The preload ramp F0 = a t: m ẍ = −k x − a t, x = x0 cos ωt + a/(k ω) sin ωt − a t/k (ω = √(k/m)).
double RampMotion(const Model& m, double t) {
  const double k = m.springs[0].stiffness, a = m.constants.at("a"), w = std::sqrt(k / m.bodies[0].mass);
  return m.initial[0].value * std::cos(w * t) + a / (k * w) * std::sin(w * t) - a * t / k;
}
// L0 = 2 + a q.xB, F0 = c qd.xB: tension k (1 − a) x + c ẋ, a damped oscillator from rest at x0.
double StateLawMotion(const Model& m, double t) {
  const double k = m.constants.at("k") * (1 - m.constants.at("a")), c = m.constants.at("c"), mass = m.bodies[0].mass;
  const double s = c / (2 * mass), wd = std::sqrt(k / mass - s * s);
  return m.initial[0].value * std::exp(-s * t) * (std::cos(wd * t) + s / wd * std::sin(wd * t));
}

// Bounds: about 3× the largest error measured over the formulations (printed by the test), dense
// and sparse alike. Measured (RelWithDebInfo), RK4 / DOPRI5 / ALI3-P / partitioning: preload ramp
// 1.1e-13, 5.1e-13, 2.6e-7, 5.1e-13 m; laws of the state 7.8e-15, 2.9e-14, 3.8e-8, 2.9e-14 m.
// Energy drift at most 1.9e-10 J (ALI3-P 7.8e-8 J) on 0.01 s samples.
std::vector<ClosedForm> Cases() {
  return {{"block_spring_preload_ramp.yaml", RampMotion, 1.5e-12, 8e-7},
          {"block_spring_state_law.yaml", StateLawMotion, 1e-13, 1.2e-7}};
}

TEST(NumericSpringLaws, LoaderKeepsTheLaws) {
  const Model ramp = Scene("block_spring_preload_ramp.yaml");
  ASSERT_EQ(ramp.springs.size(), 1u);
  const SpringDamper& s = ramp.springs[0];
  EXPECT_TRUE(s.law[SpringDamper::kPreload] && !s.law[SpringDamper::kStiffness] && !s.law[SpringDamper::kFreeLength]);
  EXPECT_EQ(s.preload, 0.0);  // a t at t0 = 0
  EXPECT_TRUE(ramp.HasSpringLaws() && ramp.HasLoadLaws());
  // A constant (even one named from the file's constants) stays a constant: no law evaluated.
  const Model state = Scene("block_spring_state_law.yaml");
  EXPECT_FALSE(state.springs[0].law[SpringDamper::kStiffness]);
  EXPECT_EQ(state.springs[0].stiffness, 8.0);
  EXPECT_FALSE(Scene("pendulum_spring_damper.yaml").HasSpringLaws());
  const Model every = Scene("pendulum_spring_damper_law.yaml");  // kept alive: the loop reads its springs
  for (const auto& law : every.springs[0].law) EXPECT_TRUE(law);
}

TEST(NumericSpringLaws, EveryFormulationFollowsTheClosedForm) {
  for (const ClosedForm& c : Cases()) {
    const Model model = Scene(c.file);
    const int s = model.SlotIndex("xB");
    ASSERT_GE(s, 0);
    for (const Formulation& f : Formulations()) {
      SCOPED_TRACE(std::string(c.file) + " " + f.name);
      const Result r = f.make()->Run(model);
      ASSERT_EQ(r.status, Status::kOk) << r.reason;
      ASSERT_EQ(static_cast<int>(r.trajectory.size()), model.analysis.samples);
      double worst = 0;
      for (const Sample& x : r.trajectory) worst = std::max(worst, std::fabs(x.q[s] - c.xB(model, x.t)));
      const double drift = Get(r, "energy_drift");
      std::printf("  %-32s %-24s max |x − x_exact| = %.2e m, energy drift %.2e J\n", c.file, f.name.c_str(), worst,
                  drift);
      const bool ali3p = f.name.rfind("ali3p", 0) == 0;
      EXPECT_LT(worst, ali3p ? c.ali3p_bound : c.bound);
      // E − W (∫ −F L̇ dt of the spring with laws) + D: constant along the exact motion.
      EXPECT_LT(drift, ali3p ? 2e-5 : 5e-7);
    }
  }
}

const char* const kLawScenes[] = {"block_spring_preload_ramp.yaml", "block_spring_state_law.yaml",
                                  "pendulum_spring_law.yaml", "pendulum_spring_damper_law.yaml"};

// Q at a state off the file's: numeric's against the vector method's virtual power with the laws;
// ∂Q/∂q and ∂Q/∂q̇ (the laws' automatic derivatives) against central differences.
TEST(NumericSpringLaws, QAndItsDerivativesAgree) {
  for (const char* file : kLawScenes) {
    SCOPED_TRACE(file);
    const Model model = Scene(file);
    const NaturalModel nm = Compile(model);
    Eigen::VectorXd q, qd;
    OffState(model, q, qd);
    test::ExpectElementForcesAndTangents(model, nm, q, qd, 0.9);
  }
}

// The power the energy balance integrates, −F L̇ u, and its rate against a central difference
// along the state's motion (q̈ of a constant-acceleration path).
TEST(NumericSpringLaws, PowerRateAgreesWithADifference) {
  for (const char* file : kLawScenes) {
    SCOPED_TRACE(file);
    const Model model = Scene(file);
    const NaturalModel nm = Compile(model);
    Eigen::VectorXd q, qd;
    OffState(model, q, qd);
    const Eigen::VectorXd qdd = Eigen::VectorXd::Constant(q.size(), 0.4);
    const double t = 0.9, h = 1e-5;
    double rate = 0;
    const double P = LawSpringPower(nm, q, qd, t, &qdd, &rate);
    EXPECT_GT(std::fabs(P), 1e-3);
    const auto at = [&](double dt) { return LawSpringPower(nm, q + dt * qd + 0.5 * dt * dt * qdd, qd + dt * qdd, t + dt); };
    EXPECT_NEAR(rate, (at(h) - at(-h)) / (2 * h), 1e-6 * std::max(1.0, std::fabs(rate)));
    // Springs with laws are out of the potential and of the dampers' dissipation.
    EXPECT_EQ(SpringPotential(nm, q), 0.0);
    EXPECT_EQ(DamperPower(nm, q, qd), 0.0);
  }
}

// Laws equal to constants (50 + 0 t, …) give the constant spring's motion to round-off, in every
// formulation (measured: identical, 0). The energy balance differs (the spring's work integrated by
// the Hermite rule instead of its potential): FormulationsAgreeOnTheLawsOfTheState checks it.
TEST(NumericSpringLaws, LawsEqualToConstantsGiveTheConstantSpring) {
  const Model constant = Scene("pendulum_spring_damper.yaml"), law = Scene("pendulum_spring_damper_law.yaml");
  ASSERT_EQ(constant.q_layout.size(), law.q_layout.size());
  for (const Formulation& f : Formulations()) {
    SCOPED_TRACE(f.name);
    const Result a = f.make()->Run(constant), b = f.make()->Run(law);
    ASSERT_EQ(a.status, Status::kOk) << a.reason;
    ASSERT_EQ(b.status, Status::kOk) << b.reason;
    ASSERT_EQ(a.trajectory.size(), b.trajectory.size());
    double worst = 0, scale = 0;
    for (size_t k = 0; k < a.trajectory.size(); ++k) {
      worst = std::max(worst, (a.trajectory[k].q - b.trajectory[k].q).cwiseAbs().maxCoeff());
      scale = std::max(scale, a.trajectory[k].q.cwiseAbs().maxCoeff());
    }
    std::printf("  %-24s max |q_law − q_const| = %.2e, energy drift %.2e J (constant %.2e J)\n", f.name.c_str(), worst,
                Get(b, "energy_drift"), Get(a, "energy_drift"));
    EXPECT_LE(worst, 1e-13 * scale);
  }
}

// No closed form: every formulation against DOPRI5 (dense), and the energy balance. With a stiff
// spring's work integrated by the Hermite rule on 0.01 s samples the drift is mostly that rule's
// error (measured 2.2e-5 J, ALI3-P 5.0e-5 J): ten times more samples divide DOPRI5's by > 1000.
TEST(NumericSpringLaws, FormulationsAgreeOnTheLawsOfTheState) {
  const Model model = Scene("pendulum_spring_law.yaml");
  const Result ref = Formulations()[2].make()->Run(model);
  ASSERT_EQ(ref.status, Status::kOk) << ref.reason;
  for (const Formulation& f : Formulations()) {
    SCOPED_TRACE(f.name);
    const Result r = f.make()->Run(model);
    ASSERT_EQ(r.status, Status::kOk) << r.reason;
    ASSERT_EQ(r.trajectory.size(), ref.trajectory.size());
    double worst = 0;
    for (size_t k = 0; k < r.trajectory.size(); ++k)
      worst = std::max(worst, (r.trajectory[k].q - ref.trajectory[k].q).cwiseAbs().maxCoeff());
    const double drift = Get(r, "energy_drift");
    std::printf("  %-24s max |q − q_dopri5| = %.2e, energy drift %.2e J\n", f.name.c_str(), worst, drift);
    const bool ali3p = f.name.rfind("ali3p", 0) == 0;
    EXPECT_LT(worst, ali3p ? 1.2e-4 : 5e-8);
    EXPECT_LT(drift, ali3p ? 1.5e-4 : 6e-5);
  }
  Model fine = model;  // the same motion sampled every 1 ms
  fine.analysis.samples = 10 * (model.analysis.samples - 1) + 1;
  const Result r = Formulations()[2].make()->Run(fine);
  ASSERT_EQ(r.status, Status::kOk) << r.reason;
  const double coarse = Get(ref, "energy_drift"), drift = Get(r, "energy_drift");
  std::printf("  dopri5 dense, 1 ms samples: energy drift %.2e J (0.01 s: %.2e J)\n", drift, coarse);
  EXPECT_LT(drift, coarse / 1000);
}

}  // namespace
}  // namespace numeric_spring_laws_test
}  // namespace mechbench::numeric
