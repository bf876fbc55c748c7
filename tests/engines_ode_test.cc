// ODE adapter: driven scenarios against the numeric method at a stated step, loop residuals, first
// order when the step halves, and the free four-bar against Simbody. Findings stay visible.
#ifdef MECHBENCH_WITH_ODE
#include "engines_support.h"
#include "mechbench/analytic/analytic_method.h"
#include "mechbench/engines/ode.h"
#include "mechbench/numeric/numeric_method.h"

#include <iostream>
#include <set>
#include <tuple>

namespace mechbench::engines {
namespace engines_ode_test {  // this file's own names (the tests build in unity batches)
namespace {

using namespace mechbench::engines::testing;

Result RunOde(const Model& m, const OdeOptions& o) { return RunIfApplicable(*MakeOdeMethod(o), m); }

OdeOptions WorldStep(double h) {
  OdeOptions o;
  o.name = "ode-worldstep";
  o.step = h;
  return o;
}

// Gear trains whose planet orbits a turning carrier: a finding at 1 ms (OdeGear.Finding…), not a
// first-order Euler error; the gear suite below states their tolerances and order.
const std::set<std::string> kOrbitFindings{"s6_2_epicyclic_train"};

class OdeDriven : public ::testing::TestWithParam<std::string> {};

// Each ODE variant at its own settings on every scene is held to its tolerances.yaml entry, and
// each known failure asserted to still fail, by the scenario × method suite
// (harness_scenarios_test): the one place the bounds are stated. Here: what only ODE shows.

// Halving the step: q̇ error halves (first order, ratio 1.6…2.6; measured 1.91–2.11). The
// position error and ‖Φ‖ fall by about 4 (measured 3.6–4.05, 2.7 on the 0.12 s §3.4 run): with
// the driver tracking its law's position every step, q is off only by the velocity-level joints'
// drift that ERP corrects, O(h²). The free four-bar below is first order in q.
TEST_P(OdeDriven, WorldStepErrorIsFirstOrder) {
  if (kOrbitFindings.count(GetParam())) GTEST_SKIP() << "second order: OdeGear.FindingOrbitingPlanetDrifts";
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
  if (e1 < 1e-9) return;  // exact already (every body driven; gear trains on fixed axes)
  EXPECT_GE(a.qd / b.qd, 1.6);
  EXPECT_LE(a.qd / b.qd, 2.6);
  EXPECT_GE(e1 / e2, 2.5);
  EXPECT_LE(e1 / e2, 4.5);
}

INSTANTIATE_TEST_SUITE_P(Builtin, OdeDriven, ::testing::ValuesIn(DrivenScenarios()),
                         [](const auto& param_info) { return param_info.param; });

// dWorldQuickStep's default variant is ODE's own 20 iterations (its agreement on every scene is the
// scenario × method suite's).
TEST(OdeQuickStep, DefaultVariantKeepsOdesTwentyIterations) {
  const auto all = MakeOdeMethods();
  const Result r = Variant(all, "ode-quickstep-default").Run(Load("fourbar_crank_rocker"), {.motion = false});
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_EQ(r.settings.at("quickstep_iterations").substr(0, 2), "20");
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
  EXPECT_LE(Compare(m, r1, r1).residual, FreeResidualOf("fourbar_free", "ode-worldstep-default"));
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
// against the reference trajectory (CompareMotion): semi-implicit Euler, first order. Measured
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
  // Gear trains: transmission joints on a stated layout, finite rotation; a planet on a turning
  // carrier with an internal mesh is left out with the reason.
  const Result g = all[0]->Run(Load("s6_1_planetary_case1"), {.motion = false});
  ASSERT_TRUE(g.ok()) << g.reason;
  for (const char* k : {"gears", "gear_layout", "planets", "rotation_update"}) EXPECT_TRUE(g.settings.count(k)) << k;
  EXPECT_NE(g.settings.at("gears").find("1 parallel-axes for external meshes, 1 chain-drive"), std::string::npos)
      << g.settings.at("gears");
  EXPECT_NE(g.settings.at("gears").find("ERP 0.2"), std::string::npos) << g.settings.at("gears");
  EXPECT_NE(g.settings.at("gear_layout").find("module 2 mm"), std::string::npos);
  EXPECT_NE(g.settings.at("gear_layout").find("sun-planet external: pitch radii 30 / 24 mm"), std::string::npos)
      << g.settings.at("gear_layout");
  EXPECT_NE(g.settings.at("gear_layout").find("planet-ring internal: pitch radii 24 / 78 mm (module 2 mm), centre distance 54 mm"),
            std::string::npos)
      << g.settings.at("gear_layout");
  EXPECT_NE(g.settings.at("rotation_update").find("finite"), std::string::npos);
  EXPECT_FALSE(all[0]->Applicability(Load("s6_3_compound_train")).has_value());
  const auto why = all[0]->Applicability(Load("s6_1_planetary_case2"));
  ASSERT_TRUE(why.has_value());
  EXPECT_NE(why->find("dJointCreateTransmission"), std::string::npos);
  EXPECT_NE(why->find("turning carrier"), std::string::npos);
}

// ---- gear trains (dJointCreateTransmission) -----------------------------------------------------

// Every built-in driven gear train.

// The planetary sets with a turning carrier: their ring–planet internal mesh has no transmission mode.
const std::set<std::string> kOdeGearNotApplicable{"s6_1_planetary_case2", "s6_1_planetary_case3"};

class OdeGear : public ::testing::TestWithParam<std::tuple<std::string, std::string>> {};

// Every (gear train, ODE variant) at the variant's own step (default 1 ms, tuned 0.1 ms; QuickStep
// 20 or 200 iterations) against the analytic method over the whole motion: angles (q), speeds (q̇)
// and the output/input speed ratio at the end, and ‖Φ‖ (Willis' relation). Trains on fixed axes,
// and §6.1 case 1 whose carrier is held, are exact to rounding: with the finite rotation update a
// body turns by exactly ω·h, and the transmission row holds the contact's speeds (measured worst
// q 4.1e-15, q̇ 1.1e-12 (QuickStep, 200 iterations, §6.1 case 1), ratio 9.6e-15, ‖Φ‖ 1.3e-15).
// The arm-driven epicyclic train, whose planet orbits: see FindingOrbitingPlanetDrifts; its tuned
// variants (0.1 ms) measure q 2.3e-6, q̇ 1.9e-5, ‖Φ‖ 1.4e-5, speed ratios at the end 1.6e-8. Every
// bound is the variant's tolerances.yaml entry for the scene.
TEST_P(OdeGear, FollowsTheAnalyticTrain) {
  const auto& [scenario, variant] = GetParam();
  const Model m = Load(scenario);
  const auto all = MakeOdeMethods();
  const Method& meth = Variant(all, variant);
  const Result r = RunIfApplicable(meth, m);
  if (kOdeGearNotApplicable.count(scenario)) {
    ASSERT_EQ(r.status, Status::kNotApplicable) << "ODE now runs " << scenario << ": give it a tolerance";
    EXPECT_NE(r.reason.find("an internal mesh whose planet orbits"), std::string::npos) << r.reason;
    return;
  }
  ASSERT_TRUE(r.ok()) << r.reason;
  const auto [e, ratio] = AgainstAnalyticTrain(m, r, scenario + " " + variant);
  if (KnownFailure(scenario, variant)) return;  // FindingOrbitingPlanetDrifts; the scenario suite asserts it
  const harness::Agreement at = ToleranceOf(scenario, variant);
  EXPECT_LE(e.q, at.q);
  EXPECT_LE(e.qd, at.qd);
  EXPECT_LE(ratio, at.qd);  // the speed ratios at the end, as relative as q̇
  EXPECT_LE(e.residual, at.residual);
}

INSTANTIATE_TEST_SUITE_P(Builtin, OdeGear,
                         ::testing::Combine(::testing::ValuesIn(GearScenarios()), ::testing::ValuesIn(Names(MakeOdeMethods()))),
                         ScenarioVariantName);

// FINDING (kept visible, in tolerances.yaml's known_failures): on the arm-driven epicyclic train
// (arm at 1000 rpm) the planet is a body hinged to the arm. Its centre moves along straight steps
// (a chord falls (ω h)³/3 rad short of the arc) and the hinge's ERP 0.2 pulls it back each step,
// so it settles a steady ~2e-3 rad behind the arm; the transmission's contact point follows the
// planet's actual centre, so the wheels settle at an angle offset (φ_out 2.6e-3 rad, φ_planet
// 2.0e-2 rad behind) after a ~25 ms transient in which the speeds are off. dWorldStep at 1 ms:
// q off by 1.9e-3, q̇ by 1.1e-2, ‖Φ‖ 1.2e-2 (over the variant's 1e-3 and 3e-3); at 0.5 ms 2.7e-4
// and 2.6e-3: q̇ falls by 4.0 when h halves (second order), q by 6.9 (about third, as the chord's
// shortfall). The transmission's own phase feedback is not the cause: ERP 0 on its rows leaves the
// error (3.2e-3 at 1 ms). The speed ratios at the end are right to 1.4e-8.
TEST(OdeGearFindings, FindingOrbitingPlanetDrifts) {
  const Model m = Load("s6_2_epicyclic_train");
  const Result ref = analytic::MakeAnalyticMethod()->Run(m);
  const Result r1 = RunOde(m, WorldStep(1e-3)), r2 = RunOde(m, WorldStep(5e-4));
  ASSERT_TRUE(r1.ok() && r2.ok());
  const Errors a = Compare(m, ref, r1), b = Compare(m, ref, r2);
  if (Verbose())
    std::printf("epicyclic worldstep: h 1e-3 q %.4g qd %.4g res %.4g; h 5e-4 q %.4g qd %.4g; ratios q %.3g qd %.3g\n", a.q,
                a.qd, a.residual, b.q, b.qd, a.q / b.q, a.qd / b.qd);
  EXPECT_GT(a.q, 1e-3) << "ODE now holds the orbiting planet at 1 ms: turn this finding into a tolerance";
  EXPECT_NEAR(a.q, 1.9e-3, 0.2e-3);
  EXPECT_NEAR(a.qd, 1.1e-2, 0.1e-2);
  EXPECT_NEAR(a.qd / b.qd, 4.0, 0.3);  // second order in q̇
  EXPECT_GT(a.q / b.q, 6.0);
}

// FINDING (why gear scenes use the finite rotation update): ODE's default infinitesimal quaternion
// update turns a body by 2·atan(ω·h/2) per step instead of ω·h. At 2000 rpm (§6.3's input) and
// 1 ms that is 7.6e-4 rad short every step: the driver's motor corrects its own member each step,
// but the train behind it (velocity-level transmission rows, ERP 0.2) ends off by q 4.9e-4 and
// q̇ 3.7e-3 (second order: q̇ 9.1e-4 at 0.5 ms). With the finite update it is exact to 1e-15.
TEST(OdeGearFindings, FindingInfinitesimalRotationUpdateLosesTheRatio) {
  const Model m = Load("s6_3_compound_train");
  const Result ref = analytic::MakeAnalyticMethod()->Run(m);
  OdeOptions o = WorldStep(1e-3);
  o.gear_finite_rotation = false;
  const Result inf = RunOde(m, o);
  const Result fin = RunOde(m, WorldStep(1e-3));
  ASSERT_TRUE(inf.ok() && fin.ok());
  EXPECT_NE(inf.settings.at("rotation_update").find("infinitesimal"), std::string::npos);
  const Errors a = Compare(m, ref, inf), b = Compare(m, ref, fin);
  if (Verbose()) std::printf("compound train, infinitesimal update: q %.4g qd %.4g; finite: q %.3g qd %.3g\n", a.q, a.qd, b.q, b.qd);
  EXPECT_GT(a.q, 1e-4) << "the infinitesimal update now keeps the ratio";
  EXPECT_NEAR(a.qd, 3.7e-3, 0.3e-3);
  EXPECT_LE(b.q, 1e-14);
}

}  // namespace
}  // namespace engines_ode_test
}  // namespace mechbench::engines
#endif
