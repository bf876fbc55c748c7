// Loads given as expressions (a torque law of t or of the state) and torsional spring–dampers in
// the natural-coordinate dynamics (tests/data/scenes/bar_*.yaml): every formulation against the
// closed forms, the energy balance with the laws' work, Q against the vector method's virtual power,
// and ∂Q/∂q, ∂Q/∂q̇ (automatic differentiation of the laws) against finite differences.
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

#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace mechbench::numeric {
namespace numeric_load_laws_test {  // this file's own names (the tests build in unity batches)
namespace {

using test::Formulation;
using test::Formulations;
using test::Scene;

struct ClosedForm {
  const char* file;
  std::function<double(double)> theta;  // [rad]
  double bound, ali3p_bound;            // max |θ − θ_exact| [rad]
};

// Bounds: about 3× the largest error measured over the formulations (printed by the test), dense
// and sparse alike. Measured (RelWithDebInfo): ramp RK4 2.2e-11, DOPRI5 6.3e-10, ALI3-P 3.0e-6,
// partitioning 1.3e-15 rad; torsion 1.5e-11, 7.9e-10, 5.3e-6, 9.4e-9; motor curve 5.8e-12,
// 4.7e-10, 8.8e-7, 7.2e-11. Energy drift: at most 2.7e-9 J (ramp), 1.4e-8 J (torsion), 1.65e-7 J
// (motor curve: the Hermite rule on T ω over 0.1 s samples, the same for every formulation);
// ALI3-P 7.0e-6, 1.8e-7, 4.9e-7 J.
std::vector<ClosedForm> Cases() {
  const double k = 0.5, w0 = 3;
  return {
      {"bar_torque_ramp.yaml", [](double t) { return 0.3 * t * t * t; }, 2e-9, 1e-5},
      {"bar_torsion_spring.yaml", [](double t) { return 0.5 * std::cos(3 * t); }, 3e-8, 1.6e-5},
      {"bar_motor_curve.yaml", [=](double t) { return w0 * (t - (1 - std::exp(-k * t)) / k); }, 1.5e-9, 3e-6},
  };
}

TEST(NumericLoadLaws, EveryFormulationFollowsTheClosedForm) {
  for (const ClosedForm& c : Cases()) {
    const Model model = Scene(c.file);
    const int th = model.SlotIndex("theta");
    for (const Formulation& f : Formulations()) {
      SCOPED_TRACE(std::string(c.file) + " " + f.name);
      const Result r = f.make()->Run(model);
      ASSERT_EQ(r.status, Status::kOk) << r.reason;
      ASSERT_EQ(static_cast<int>(r.trajectory.size()), model.analysis.samples);
      double worst = 0;
      for (const Sample& s : r.trajectory) worst = std::max(worst, std::fabs(s.q[th] - c.theta(s.t)));
      const double drift = Get(r, "energy_drift");
      std::printf("  %-24s %-24s max |θ − θ_exact| = %.2e rad, energy drift %.2e J\n", c.file, f.name.c_str(), worst, drift);
      const bool ali3p = f.name.rfind("ali3p", 0) == 0;
      EXPECT_LT(worst, ali3p ? c.ali3p_bound : c.bound);
      // The balance E − W_laws (∫ T ω dt) + D: constant along the exact motion.
      EXPECT_LT(drift, ali3p ? 2e-5 : 5e-7);
    }
  }
}

// The torsion's energy: E = ½ I θ̇² + ½ k θ² stays at ½ k θ0² = 0.375 J (no law, no damper).
TEST(NumericLoadLaws, TorsionPotentialIsInTheEnergy) {
  const Model model = Scene("bar_torsion_spring.yaml");
  const NaturalModel nm = Compile(model);
  const DynamicsSystem sys(nm);
  const Result r = MakeBaumgarteDopri5Method({})->Run(model);
  ASSERT_EQ(r.status, Status::kOk) << r.reason;
  for (const Sample& s : r.trajectory) EXPECT_NEAR(sys.Energy(s.q, s.qd), 0.375, 1e-6) << s.t;
}

// Q of the laws and the torsion at a state off the file's: numeric's against the vector method's
// virtual power (analytic/energy.h); ∂Q/∂q and ∂Q/∂q̇ (ALI3-P's tangent) against central differences.
TEST(NumericLoadLaws, QAndItsDerivativesAgree) {
  for (const char* file : {"bar_torque_ramp.yaml", "bar_torsion_spring.yaml", "bar_motor_curve.yaml"}) {
    SCOPED_TRACE(file);
    Model model = Scene(file);
    const NaturalModel nm = Compile(model);
    Eigen::VectorXd q = model.GuessQ(), qd = Eigen::VectorXd::Zero(nm.n);
    const double a = 0.7;  // a consistent state: A on its circle at θ = a, turning at 1.3 rad/s
    q[model.SlotIndex("xA")] = std::cos(a), q[model.SlotIndex("yA")] = std::sin(a), q[model.SlotIndex("theta")] = a;
    qd[model.SlotIndex("xA")] = -1.3 * std::sin(a), qd[model.SlotIndex("yA")] = 1.3 * std::cos(a);
    qd[model.SlotIndex("theta")] = 1.3;
    const double t = 0.9;
    test::ExpectElementForcesAndTangents(model, nm, q, qd, t);
  }
}

}  // namespace
}  // namespace numeric_load_laws_test
}  // namespace mechbench::numeric
