// MuJoCo adapter: every driven scenario against the numeric method for the tuned (RK4) and the
// default (Euler, MuJoCo's softness) variants, loop residuals, the free four-bar against Simbody,
// and the variants' settings. Findings stay visible.
#ifdef MECHBENCH_WITH_MUJOCO
#include "engines_support.h"
#include "mechbench/engines/mujoco.h"
#include "mechbench/numeric/numeric_method.h"

#include <iostream>
#include <set>

namespace mechbench::engines {
namespace {

using namespace mechbench::engines::testing;

Result RunMujoco(const Model& m, const MujocoOptions& o) { return RunIfApplicable(*MakeMujocoMethod(o), m); }

MujocoOptions Tuned() {
  MujocoOptions o;
  o.name = "mujoco-rk4-tuned";
  o.integrator = "RK4";
  o.step = 1e-4;
  o.solref = {2e-4, 1.0};
  o.solimp = {0.9999, 0.9999, 0.001, 0.5, 2.0};
  o.tolerance = 1e-12;
  return o;
}

// Scenes whose light slider block or actuator half (1e-2 of the lightest link) MuJoCo's default
// softness does not hold: see FindingDefaultSoftnessLosesLightBlocks.
const std::set<std::string> kDefaultFindings{"disc_slotted_bar_full_turn", "s3_4_disc_slotted_bar", "s4_4_quick_return",
                                             "s4_7_linear_actuator"};

class MujocoDriven : public ::testing::TestWithParam<std::string> {};

// Tuned (RK4, h = 1e-4 s, solref 2e-4 1, solimp 0.9999): q within 2e-5 and q̇ within 1e-4 of the
// numeric motion, scaled ‖Φ‖ below 5e-6. Measured worst: q 5.2e-6 (full-turn disc–slotted bar),
// q̇ 3.0e-5 (§4.2), ‖Φ‖ 1.8e-6 (crank-rocker). Gear trains without a carrier: exact to 1e-13.
TEST_P(MujocoDriven, TunedFollowsTheNumericMotion) {
  const Model m = Load(GetParam());
  const Result ref = numeric::MakeNumericMethod()->Run(m);
  ASSERT_TRUE(ref.ok()) << ref.reason;
  const Result r = RunMujoco(m, Tuned());
  if (r.status == Status::kNotApplicable) {
    EXPECT_NE(r.reason.find("carrier"), std::string::npos) << r.reason;
    return;
  }
  ASSERT_TRUE(r.ok()) << r.reason;
  const Errors e = Compare(m, ref, r);
  EXPECT_LE(e.q, 2e-5);
  EXPECT_LE(e.qd, 1e-4);
  EXPECT_LE(e.residual, 5e-6);
  EXPECT_EQ(r.trajectory[0].qdd.size(), static_cast<long>(m.q_layout.size())) << "MuJoCo has q̈ at every sample";
  if (Verbose())
    std::cout << GetParam() << " tuned q " << e.q << " qd " << e.qd << " qdd " << e.qdd << " res " << e.residual << " cpu "
              << r.cpu_seconds << "\n";
}

// MuJoCo's defaults (Euler, 2 ms, solref 0.02 1, solimp 0.9 0.95 0.001): q within 1e-2, ‖Φ‖ below
// 2e-2 outside the findings. Measured worst: q 5.7e-3 and ‖Φ‖ 1.5e-2 (crank-rocker).
TEST_P(MujocoDriven, DefaultsFollowTheNumericMotion) {
  if (kDefaultFindings.count(GetParam())) GTEST_SKIP() << "a documented finding (FindingDefaultSoftnessLosesLightBlocks)";
  const Model m = Load(GetParam());
  const Result r = RunMujoco(m, MujocoOptions{});
  if (r.status == Status::kNotApplicable) return;
  ASSERT_TRUE(r.ok()) << r.reason;
  const Errors e = Compare(m, numeric::MakeNumericMethod()->Run(m), r);
  EXPECT_LE(e.q, 1e-2);
  EXPECT_LE(e.residual, 2e-2);
  if (Verbose()) std::cout << GetParam() << " default q " << e.q << " qd " << e.qd << " res " << e.residual << "\n";
}

INSTANTIATE_TEST_SUITE_P(Builtin, MujocoDriven, ::testing::ValuesIn(DrivenScenarios()),
                         [](const auto& param_info) { return param_info.param; });

// FINDING (kept visible): with MuJoCo's default equality softness (solref 0.02 1, solimp 0.9 0.95)
// a light slider block or actuator half riding on a turning bar is not held at the default 2 ms
// Euler step: q off by 0.52 (full-turn disc–slotted bar, ‖Φ‖ 0.15), 0.086 (§3.4), 0.72 (§4.4
// quick-return) and 0.17 (§4.7). The same step with the stiffest softness it allows (solref 4e-3,
// = 2 h, solimp 0.9999) is within 1e-2: it is the softness, not the step. The test fails the day
// the defaults hold these scenes.
TEST(MujocoFindings, FindingDefaultSoftnessLosesLightBlocks) {
  for (const std::string& name : kDefaultFindings) {
    const Model m = Load(name);
    const Result ref = numeric::MakeNumericMethod()->Run(m);
    const Result def = RunMujoco(m, MujocoOptions{});
    MujocoOptions stiff;
    stiff.solref = {4e-3, 1.0};
    stiff.solimp = {0.9999, 0.9999, 0.001, 0.5, 2.0};
    const Result st = RunMujoco(m, stiff);
    ASSERT_TRUE(def.ok() && st.ok());
    const Errors e = Compare(m, ref, def), f = Compare(m, ref, st);
    if (Verbose()) std::cout << name << " default q " << e.q << " res " << e.residual << "; stiff q " << f.q << "\n";
    EXPECT_GT(e.q, 5e-2) << name << ": the defaults now hold it; turn this finding into a tolerance";
    EXPECT_LE(f.q, 1e-2) << name;
  }
}

// FINDING (kept visible): MuJoCo's q̈ at a sample is its solver's, and on a closed loop it carries
// the soft constraints' reference acceleration −b·v − k·r (tuned: k = 2.5e7 s⁻², b = 1e4 s⁻¹), so
// a residual of 1e-7 already moves it by O(1): on the crank-rocker the tuned q̈ is off by 0.5
// (relative), while on the open-chain thumb (no equality) it is within 1e-5 (measured 5.7e-6).
TEST(MujocoFindings, FindingLoopAccelerationsCarryTheConstraintStabilisation) {
  const Model loop = Load("fourbar_crank_rocker");
  const Errors e = Compare(loop, numeric::MakeNumericMethod()->Run(loop), RunMujoco(loop, Tuned()));
  EXPECT_GT(e.qdd, 0.1) << "loop q̈ now follows the motion; turn this finding into a tolerance";
  const Model tree = Load("s3_2_thumb");
  const Errors t = Compare(tree, numeric::MakeNumericMethod()->Run(tree), RunMujoco(tree, Tuned()));
  EXPECT_LE(t.qdd, 1e-5);
  if (Verbose()) std::cout << "qdd: crank-rocker " << e.qdd << ", thumb " << t.qdd << "\n";
}

// The free four-bar against Simbody's θ(1 s) = −0.0154244118 rad: tuned (RK4, 1e-4 s) within
// 2e-7 (measured +7.8e-8, θ = −0.0154243342); defaults (Euler, 2 ms) off by −1.63e-3
// (θ = −0.0170515). The loop stays closed to ‖Φ‖ 1.0e-7 (tuned) and 4.9e-4 (default).
TEST(MujocoFree, FourBarAgainstTheReference) {
  const Model m = Load("fourbar_free");
  const double ref = -0.0154244118;  // Simbody RK-Merson at accuracy 1e-10 (engines_simbody_test)
  const Result tuned = RunMujoco(m, Tuned());
  const Result def = RunMujoco(m, MujocoOptions{});
  ASSERT_TRUE(tuned.ok() && def.ok());
  const double et = Final(m, tuned, "theta") - ref, ed = Final(m, def, "theta") - ref;
  if (Verbose()) std::cout << "fourbar_free theta(1) error tuned " << et << " default " << ed << "\n";
  EXPECT_LE(std::fabs(et), 2e-7);
  EXPECT_NEAR(ed, -1.63e-3, 0.05e-3);
  EXPECT_LE(Compare(m, tuned, tuned).residual, 3e-7);
  EXPECT_LE(Compare(m, def, def).residual, 1e-3);
  // Released from rest: the crank starts to fall, and MuJoCo gives q̈ at t0.
  EXPECT_LT(tuned.quantities.at("qdd.theta"), 0);
}

TEST(MujocoFree, DiscBarBushingRuns) {
  const Model m = Load("s5_1_disc_bar_bushing");
  for (const auto& meth : MakeMujocoMethods()) {
    const Result r = meth->Run(m);
    ASSERT_TRUE(r.ok()) << meth->name() << ": " << r.reason;
    EXPECT_EQ(r.trajectory.size(), static_cast<size_t>(m.analysis.samples)) << meth->name();
  }
}

TEST(MujocoMethods, VariantsAndSettings) {
  const auto all = MakeMujocoMethods();
  ASSERT_EQ(all.size(), 2u);
  EXPECT_EQ(all[0]->name(), "mujoco-euler-default");
  EXPECT_EQ(all[1]->name(), "mujoco-rk4-tuned");
  const Result r = all[0]->Run(Load("fourbar_crank_rocker"), {.motion = false});
  ASSERT_TRUE(r.ok()) << r.reason;
  for (const char* k : {"integrator", "step", "solref", "solimp", "solver", "drivers", "loop_closures", "planarity"})
    EXPECT_TRUE(r.settings.count(k)) << k;
  EXPECT_EQ(r.settings.at("integrator"), "Euler");
  EXPECT_NE(r.settings.at("solref").find("0.02 1"), std::string::npos);
  const Result t = all[1]->Run(Load("s6_3_compound_train"), {.motion = false});
  ASSERT_TRUE(t.ok()) << t.reason;
  EXPECT_NE(t.settings.at("gears").find("polycoef"), std::string::npos);
  const auto why = all[1]->Applicability(Load("s6_1_planetary_case1"));
  ASSERT_TRUE(why.has_value());
  EXPECT_NE(why->find("Willis"), std::string::npos);
}

}  // namespace
}  // namespace mechbench::engines
#endif
