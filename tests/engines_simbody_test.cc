// Simbody adapter: every driven scenario against the numeric method, loop residuals, the free
// four-bar's reference point θ(1 s) ≈ −0.0154 rad, and the variants' settings.
#ifdef MECHBENCH_WITH_SIMBODY
#include "engines_support.h"
#include "mechbench/engines/simbody.h"
#include "mechbench/numeric/dynamics_methods.h"
#include "mechbench/numeric/numeric_method.h"

#include <cmath>
#include <iostream>

namespace mechbench::engines {
namespace engines_simbody_test {  // this file's own names (the tests build in unity batches)
namespace {

using namespace mechbench::engines::testing;

class SimbodyDriven : public ::testing::TestWithParam<std::string> {};

// Simbody runs every driven scene, each variant within its tolerances.yaml entry (measured worst,
// CompareMotion: tuned q 3.1e-10, q̈ 1.8e-9 on §4.4; default q 3.8e-6 on §4.4, q̇ 8.2e-6 on §3.1,
// ‖Φ‖ 4.5e-6).
TEST_P(SimbodyDriven, RunsEverySceneWithinItsTolerance) {
  const Model m = Load(GetParam());
  const Result ref = numeric::MakeNumericMethod()->Run(m);
  ASSERT_TRUE(ref.ok()) << ref.reason;
  const auto all = MakeSimbodyMethods();
  for (const char* name : {"simbody-rkmerson-tuned", "simbody-rkmerson-default"}) {
    const Method& meth = Variant(all, name);
    if (auto why = meth.Applicability(m)) {
      ADD_FAILURE() << name << " left out: " << *why;
      continue;
    }
    const Result r = meth.Run(m);
    ASSERT_TRUE(r.ok()) << name << ": " << r.reason;
    const Errors e = Compare(m, ref, r);
    const harness::Agreement at = ToleranceOf(GetParam(), name);
    EXPECT_LE(e.q, at.q) << name;
    EXPECT_LE(e.qd, at.qd) << name;
    EXPECT_LE(e.qdd, at.qdd) << name;
    EXPECT_LE(e.residual, at.residual) << name;
    EXPECT_EQ(r.settings.count("accuracy"), 1u);
    if (Verbose())
      std::cout << GetParam() << " " << name << " q " << e.q << " qd " << e.qd << " qdd " << e.qdd << " res "
                << e.residual << " cpu " << r.cpu_seconds << "\n";
  }
}

INSTANTIATE_TEST_SUITE_P(Builtin, SimbodyDriven, ::testing::ValuesIn(DrivenScenarios()),
                         [](const auto& param_info) { return param_info.param; });

TEST(SimbodyFree, FourBarReferencePoint) {
  const Model m = Load("fourbar_free");
  const auto all = MakeSimbodyMethods();
  const Result tuned = Variant(all, "simbody-rkmerson-tuned").Run(m);
  const Result def = Variant(all, "simbody-rkmerson-default").Run(m);
  ASSERT_TRUE(tuned.ok()) << tuned.reason;
  ASSERT_TRUE(def.ok()) << def.reason;
  ASSERT_EQ(tuned.trajectory.size(), 101u);
  // The reference point, θ(1 s) ≈ −0.0154 rad; tuned measured −0.01542441185.
  EXPECT_NEAR(Final(m, tuned, "theta"), -0.0154244118, 1e-9);
  // Default accuracy agrees to 1e-8 (measured 1.5e-9).
  EXPECT_NEAR(Final(m, def, "theta"), Final(m, tuned, "theta"), 1e-8);
  const Errors e = Compare(m, tuned, def);
  EXPECT_LE(e.q, 1e-7);
  EXPECT_LE(Compare(m, tuned, tuned).residual, FreeResidualOf("fourbar_free", "simbody-rkmerson-tuned"));
  // Released from rest: the crank starts to fall (θ̈ < 0) and q̈ at t0 comes from the dynamics.
  EXPECT_LT(tuned.quantities.at("qdd.theta"), 0);
}

// §5.1 released from rest: Simbody's bushing needs a mass (1 % of the lightest link), so its
// initial accelerations differ a little from the massless book model's (index-1 method).
TEST(SimbodyFree, DiscBarBushingStartsLikeTheMasslessModel) {
  const Model m = Load("s5_1_disc_bar_bushing");
  const auto all = MakeSimbodyMethods();
  const Result r = Variant(all, "simbody-rkmerson-tuned").Run(m);
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_EQ(static_cast<int>(r.trajectory.size()), m.analysis.samples);
  const Result exact = numeric::MakeBaumgarteDopri5Method()->Run(m, {.motion = false});
  ASSERT_TRUE(exact.ok()) << exact.reason;
  for (const char* q : {"qdd.x1", "qdd.y1", "qdd.x2"}) {
    ASSERT_TRUE(r.quantities.count(q)) << q;
    const double a = r.quantities.at(q), b = exact.quantities.at(q);
    EXPECT_NEAR(a, b, 0.05 * std::fabs(b)) << q << ": Simbody " << a << ", massless model " << b;
  }
}

// Control::kTolerance at the variant's own accuracy (Simbody's default 1e-3, tuned 1e-10),
// honoured per run: accuracy and constraint tolerance set to the override.
TEST(SimbodyControl, HonoursTheAccuracyOverride) {
  const auto all = MakeSimbodyMethods();
  // Looser than 1e-7 the 10 ms samples, not the accuracy, set the steps (interpolation is off:
  // one step per sample, the same run for any accuracy 1e-2 … 1e-6 on the free four-bar), so
  // each variant is overridden towards the other's accuracy.
  ExpectHonoursOverride(Variant(all, "simbody-rkmerson-default"), Control::kTolerance, 1e-3, 1e-10, "accuracy");
  ExpectHonoursOverride(Variant(all, "simbody-rkmerson-tuned"), Control::kTolerance, 1e-10, 1e-6, "accuracy");
  const Result r = Variant(all, "simbody-rkmerson-default").Run(ShortFreeFourBar(), {.tolerance = 1e-6});
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_EQ(r.settings.at("constraint_tolerance"), "1e-06");
}

TEST(SimbodyMethods, NamesAndSettings) {
  const auto all = MakeSimbodyMethods();
  ASSERT_EQ(all.size(), 2u);
  EXPECT_EQ(all[0]->name(), "simbody-rkmerson-default");
  EXPECT_EQ(all[1]->name(), "simbody-rkmerson-tuned");
  const Result r = all[0]->Run(Load("fourbar_crank_rocker"), {.motion = false});
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_NE(r.settings.at("accuracy").find("Simbody default"), std::string::npos);
  EXPECT_NE(r.settings.at("loop_closures").find("PointOnLine"), std::string::npos);
  EXPECT_TRUE(r.settings.count("graph.link_default_mass"));
}

}  // namespace
}  // namespace engines_simbody_test
}  // namespace mechbench::engines
#endif
