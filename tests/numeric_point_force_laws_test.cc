// Point forces given as expressions of t and of the state, and in a body's frame (a follower
// force), in the natural-coordinate dynamics (tests/data/scenes/block_force_*.yaml,
// bar_follower_*.yaml): every formulation against the closed forms, the energy balance with the
// forces' work, Q against the vector method's virtual power, and ∂Q/∂q, ∂Q/∂q̇ (ALI3-P's tangent)
// against finite differences.
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
namespace numeric_point_force_laws_test {  // this file's own names (the tests build in unity batches)
namespace {

using test::Formulation;
using test::Formulations;
using test::OffState;
using test::Scene;

struct ClosedForm {
  const char* file;
  const char* slot;                   // the coordinate the closed form gives
  std::function<double(double)> exact;  // [m or rad]
  double bound, ali3p_bound;          // max |q − q_exact|
};

// Bounds: about 3× the largest error measured over the formulations (printed by the test), dense
// and sparse alike. Measured (RelWithDebInfo), RK4 / DOPRI5 / ALI3-P / partitioning: sine push
// 3.8e-14, 6.7e-14, 1.2e-6, 6.7e-14 m; force law of the state 3.8e-14, 2.9e-13, 9.7e-8, 2.9e-13 m;
// follower force 4.7e-12, 5.0e-10, 7.3e-7, 1.1e-15 rad; follower motor curve 5.8e-12, 4.7e-10,
// 8.8e-7, 7.2e-11 rad (bar_motor_curve.yaml's figures: the same torque). Energy drift at most
// 7.0e-9 J (the Hermite rule on F·v over 0.01 s samples of the sine push), 1.6e-7 J (the motor
// curve's 0.1 s samples); ALI3-P 1.3e-6 J.
std::vector<ClosedForm> Cases() {
  const double sigma = 0.2, wd = std::sqrt(3.96), k = 0.5, w0 = 3;
  return {
      {"block_force_sine.yaml", "xB", [](double t) { return 2.0 / 3 * t - 2.0 / 9 * std::sin(3 * t); }, 2e-13, 3.5e-6},
      {"block_force_spring_law.yaml", "xB",
       [=](double t) { return 0.1 * std::exp(-sigma * t) * (std::cos(wd * t) + sigma / wd * std::sin(wd * t)); }, 1e-12,
       3e-7},
      {"bar_follower_force.yaml", "theta", [](double t) { return 0.45 * t * t; }, 1.5e-9, 2.2e-6},
      {"bar_follower_motor_curve.yaml", "theta", [=](double t) { return w0 * (t - (1 - std::exp(-k * t)) / k); }, 1.5e-9,
       3e-6},
  };
}

TEST(NumericPointForceLaws, EveryFormulationFollowsTheClosedForm) {
  for (const ClosedForm& c : Cases()) {
    const Model model = Scene(c.file);
    const int s = model.SlotIndex(c.slot);
    ASSERT_GE(s, 0);
    for (const Formulation& f : Formulations()) {
      SCOPED_TRACE(std::string(c.file) + " " + f.name);
      const Result r = f.make()->Run(model);
      ASSERT_EQ(r.status, Status::kOk) << r.reason;
      ASSERT_EQ(static_cast<int>(r.trajectory.size()), model.analysis.samples);
      double worst = 0;
      for (const Sample& x : r.trajectory) worst = std::max(worst, std::fabs(x.q[s] - c.exact(x.t)));
      const double drift = Get(r, "energy_drift");
      std::printf("  %-30s %-24s max |q − q_exact| = %.2e, energy drift %.2e J\n", c.file, f.name.c_str(), worst, drift);
      const bool ali3p = f.name.rfind("ali3p", 0) == 0;
      EXPECT_LT(worst, ali3p ? c.ali3p_bound : c.bound);
      // The balance E − W (∫ f_W·v dt of the varying forces) + D: constant along the exact motion.
      EXPECT_LT(drift, ali3p ? 2e-5 : 5e-7);
    }
  }
}

// Q of the forces at a state off the file's: numeric's against the vector method's virtual power
// (analytic/energy.h, the body's angle by atan2); ∂Q/∂q and ∂Q/∂q̇ against central differences.
TEST(NumericPointForceLaws, QAndItsDerivativesAgree) {
  for (const ClosedForm& c : Cases()) {
    SCOPED_TRACE(c.file);
    const Model model = Scene(c.file);
    const NaturalModel nm = Compile(model);
    Eigen::VectorXd q, qd;
    OffState(model, q, qd);
    const double t = 0.9;
    test::ExpectElementForcesAndTangents(model, nm, q, qd, t);
  }
}

// The power the energy balance integrates: f_W·v u, and its rate against a central difference
// along the state's motion (q̈ of a constant-acceleration path).
TEST(NumericPointForceLaws, PowerRateAgreesWithADifference) {
  for (const ClosedForm& c : Cases()) {
    SCOPED_TRACE(c.file);
    const Model model = Scene(c.file);
    const NaturalModel nm = Compile(model);
    Eigen::VectorXd q, qd;
    OffState(model, q, qd);
    const Eigen::VectorXd qdd = Eigen::VectorXd::Constant(q.size(), 0.4);
    const double t = 0.9, h = 1e-5;
    double rate = 0;
    const double P = VaryingPointForcePower(nm, q, qd, t, &qdd, &rate);
    EXPECT_GT(std::fabs(P), 1e-3);
    const auto at = [&](double dt) {
      return VaryingPointForcePower(nm, q + dt * qd + 0.5 * dt * dt * qdd, qd + dt * qdd, t + dt);
    };
    EXPECT_NEAR(rate, (at(h) - at(-h)) / (2 * h), 1e-6 * std::max(1.0, std::fabs(rate)));
  }
}

}  // namespace
}  // namespace numeric_point_force_laws_test
}  // namespace mechbench::numeric
