// ODE adapter: driven scenarios against the numeric method at a stated step, loop residuals, first
// order when the step halves, and the free four-bar against Simbody. Findings stay visible.
#ifdef MECHBENCH_WITH_ODE
#include "engines_support.h"
#include "mechbench/engines/ode.h"
#include "mechbench/numeric/numeric_method.h"

#include <iostream>

namespace mechbench::engines {
namespace {

using namespace mechbench::engines::testing;

Result RunOde(const Model& m, const OdeOptions& o) { return RunIfApplicable(*MakeOdeMethod(o), m); }

OdeOptions WorldStep(double h) {
  OdeOptions o;
  o.name = "ode-worldstep";
  o.step = h;
  return o;
}

class OdeDriven : public ::testing::TestWithParam<std::string> {};

// dWorldStep with ODE's defaults (ERP 0.2, CFM 1e-5) at h = 1e-3 s: q within 2e-3 and q̇ within
// 3e-2 of the numeric motion, scaled ‖Φ‖ below 1e-3. The q̈ of a first-order velocity-level
// stepper is only its (v_{n+1} − v_n)/h: checked loosely (0.5) once the start-up transient is past.
TEST_P(OdeDriven, WorldStepFollowsTheNumericMotion) {
  const Model m = Load(GetParam());
  const Result r = RunOde(m, WorldStep(1e-3));
  if (r.status == Status::kNotApplicable) GTEST_SKIP() << r.reason;
  ASSERT_TRUE(r.ok()) << r.reason;
  const Result ref = numeric::MakeNumericMethod()->Run(m);
  ASSERT_TRUE(ref.ok()) << ref.reason;
  const Errors e = Compare(m, ref, r);
  EXPECT_LE(e.q, 2e-3);
  EXPECT_LE(e.qd, 3e-2);
  EXPECT_LE(e.residual, 1e-3);
  EXPECT_TRUE(r.trajectory[0].qdd.size() == 0) << "ODE has no acceleration at t0";
  if (Verbose())
    std::cout << GetParam() << " worldstep h=1e-3 q " << e.q << " qd " << e.qd << " qdd " << e.qdd << " res "
              << e.residual << " cpu " << r.cpu_seconds << "\n";
}

// Halving the step: q̇ error halves (first order, ratio 1.6…2.6; measured 1.91–2.11). The
// position error and ‖Φ‖ fall by about 4 (measured 3.6–4.05, 2.7 on the 0.12 s §3.4 run): with
// the driver tracking its law's position every step, q is off only by the velocity-level joints'
// drift that ERP corrects, O(h²). The free four-bar below is first order in q.
TEST_P(OdeDriven, WorldStepErrorIsFirstOrder) {
  const Model m = Load(GetParam());
  if (!m.analysis.HasMotion()) GTEST_SKIP() << "an instant-only scene: no motion to step";
  const Result r1 = RunOde(m, WorldStep(1e-3));
  if (r1.status == Status::kNotApplicable) GTEST_SKIP() << r1.reason;
  const Result r2 = RunOde(m, WorldStep(5e-4));
  ASSERT_TRUE(r1.ok() && r2.ok());
  const Result ref = numeric::MakeNumericMethod()->Run(m);
  const Errors a = Compare(m, ref, r1), b = Compare(m, ref, r2);
  const double e1 = a.q, e2 = b.q;
  if (Verbose())
    std::cout << GetParam() << " worldstep q error h=1e-3 " << e1 << " h=5e-4 " << e2 << " ratio " << e1 / e2
              << "; qd " << a.qd << " " << b.qd << " ratio " << a.qd / b.qd << "; res ratio " << a.residual / b.residual << "\n";
  if (e1 < 1e-9) return;  // exact already (every body driven)
  EXPECT_GE(a.qd / b.qd, 1.6);
  EXPECT_LE(a.qd / b.qd, 2.6);
  EXPECT_GE(e1 / e2, 2.5);
  EXPECT_LE(e1 / e2, 4.5);
}

INSTANTIATE_TEST_SUITE_P(Builtin, OdeDriven, ::testing::ValuesIn(DrivenScenarios()),
                         [](const auto& param_info) { return param_info.param; });

// dWorldQuickStep with its defaults (20 iterations) at h = 1e-3 s on the crank-rocker: within
// 5e-4 in q (measured 1.2e-4).
TEST(OdeQuickStep, CrankRockerWithDefaults) {
  const Model m = Load("fourbar_crank_rocker");
  OdeOptions o = WorldStep(1e-3);
  o.quick = true;
  const Result r = RunOde(m, o);
  ASSERT_TRUE(r.ok()) << r.reason;
  const Errors e = Compare(m, numeric::MakeNumericMethod()->Run(m), r);
  EXPECT_LE(e.q, 5e-4);
  EXPECT_LE(e.residual, 1e-3);
  EXPECT_EQ(r.settings.at("quickstep_iterations").substr(0, 2), "20");
}

// FINDING (kept visible, not tolerated away): with a light slider block (1e-2 of the lightest
// link) riding along a turning bar, QuickStep's 20 SOR iterations do not keep the joints: the
// full-turn disc–slotted bar ends with q off by O(1) (measured 0.59 relative, ‖Φ‖ 0.27) and the
// quick-return by 1.2; dWorldStep on the same scenes stays within 3e-4. This test documents the
// measured failure; it fails (and should be revisited) the day QuickStep holds these joints.
TEST(OdeQuickStep, FindingLosesSliderBlocksOnTurningBars) {
  for (const char* name : {"disc_slotted_bar_full_turn", "s4_4_quick_return"}) {
    const Model m = Load(name);
    OdeOptions o = WorldStep(1e-3);
    o.quick = true;
    const Result r = RunOde(m, o);
    ASSERT_TRUE(r.ok()) << r.reason;
    const Errors e = Compare(m, numeric::MakeNumericMethod()->Run(m), r);
    if (Verbose()) std::cout << name << " quickstep q " << e.q << " res " << e.residual << "\n";
    EXPECT_GT(e.q, 0.1) << name << ": QuickStep now follows the motion; turn this finding into a tolerance test";
  }
}

// The free four-bar: ODE at h = 1e-3 s is first-order off Simbody's θ(1 s) = −0.0154244118 rad,
// by about 1.3e-3 rad (measured 1.342e-3); at 5e-4 s by half of that.
TEST(OdeFree, FourBarIsFirstOrderOffTheReference) {
  const Model m = Load("fourbar_free");
  const double ref = -0.0154244118;  // Simbody RK-Merson at accuracy 1e-10 (engines_simbody_test)
  const Result r1 = RunOde(m, WorldStep(1e-3));
  const Result r2 = RunOde(m, WorldStep(5e-4));
  ASSERT_TRUE(r1.ok() && r2.ok());
  const double e1 = Final(m, r1, "theta") - ref, e2 = Final(m, r2, "theta") - ref;
  if (Verbose()) std::cout << "fourbar_free theta(1) error h=1e-3 " << e1 << " h=5e-4 " << e2 << "\n";
  EXPECT_NEAR(std::fabs(e1), 1.34e-3, 0.1e-3);
  EXPECT_NEAR(e1 / e2, 2.0, 0.2);
  EXPECT_LE(Compare(m, r1, r1).residual, 1e-4);
}

// ---- work–precision control (RunOptions::step) and the order of every variant ------------------

class OdeVariant : public ::testing::TestWithParam<std::string> {};

double OwnStep(const std::string& name) { return name.find("tuned") != std::string::npos ? 1e-4 : 1e-3; }

// Control::kStep at the variant's own step (default 1 ms, tuned 0.1 ms), honoured per run.
TEST_P(OdeVariant, HonoursTheStepOverride) {
  const auto all = MakeOdeMethods();
  ExpectHonoursOverride(Variant(all, GetParam()), Control::kStep, OwnStep(GetParam()), 2 * OwnStep(GetParam()), "step");
}

// Step halving on the free four-bar (1 s, 10 ms samples) through RunOptions::step, position error
// against the reference trajectory (ComparePositions): semi-implicit Euler, first order. Measured
// e(2e-3 s), e(1e-3 s), ratio, order:
//   ode-worldstep-default  2.979e-3  1.527e-3  1.95  0.964
//   ode-worldstep-tuned    2.979e-3  1.527e-3  1.95  0.964
//   ode-quickstep-default  2.977e-3  1.526e-3  1.95  0.964
//   ode-quickstep-tuned    2.979e-3  1.527e-3  1.95  0.964
// (the order tends to 1 as h falls: 0.982, 0.991, 0.995 for the next three halvings).
TEST_P(OdeVariant, FreeFourBarStepHalvingIsFirstOrder) {
  const auto all = MakeOdeMethods();
  const StepHalving s = HalveStep(Variant(all, GetParam()), 2e-3);
  EXPECT_NEAR(s.order(), 1.0, 0.1) << "e(h) " << s.e_h << ", e(h/2) " << s.e_half;
}

INSTANTIATE_TEST_SUITE_P(Variants, OdeVariant, ::testing::ValuesIn(Names(MakeOdeMethods())), ParamName);

TEST(OdeMethods, VariantsAndSettings) {
  const auto all = MakeOdeMethods();
  std::vector<std::string> names;
  for (const auto& m : all) names.push_back(m->name());
  EXPECT_EQ(names, (std::vector<std::string>{"ode-worldstep-default", "ode-worldstep-tuned", "ode-quickstep-default",
                                             "ode-quickstep-tuned"}));
  const Result r = all[0]->Run(Load("s4_5_fourbar_position"));
  ASSERT_TRUE(r.ok()) << r.reason;
  for (const char* k : {"stepper", "erp", "cfm", "step", "precision", "drivers"}) EXPECT_TRUE(r.settings.count(k)) << k;
  EXPECT_NE(r.settings.at("cfm").find("ODE default"), std::string::npos);
  // Gear trains are left out with the reason.
  const auto why = all[0]->Applicability(Load("s6_3_compound_train"));
  ASSERT_TRUE(why.has_value());
  EXPECT_NE(why->find("dJointCreateTransmission"), std::string::npos);
}

}  // namespace
}  // namespace mechbench::engines
#endif
