// Spatial scenes (kind: spatial) through every registered method: the numeric method and the
// dynamics formulations that run them agree with each other on the fixtures; MuJoCo runs them
// through the engines' spatial graph where it maps them; analytic runs the
// RSSR and the spatial slider-crank and gives its reason elsewhere ("no closed form for this
// spatial mechanism …"); every other method gives its reason ("spatial scenes: not yet in …") and
// Run reports it as not applicable, never a crash. The closed-form checks are in
// numeric_spatial_test.cc and analytic_spatial_test.cc.
#include "mechbench/harness/compare.h"
#include "mechbench/harness/registry.h"
#include "mechbench/harness/tolerances.h"
#include "mechbench/loader.h"

#include <gtest/gtest.h>

#include <algorithm>

#include <string>

namespace mechbench::harness {
namespace harness_spatial_test {  // this file's own names (the tests build in unity batches)
namespace {

std::string Scene(const std::string& name) { return std::string(MECHBENCH_TEST_DATA) + "/scenes/" + name + ".yaml"; }

class SpatialScene : public ::testing::TestWithParam<const char*> {};

TEST_P(SpatialScene, EveryMethodRunsOrSaysWhyNot) {
  Model m = LoadScenario(Scene(GetParam()));
  ASSERT_EQ(m.kind, ScenarioKind::kSpatial);
  // Whether each method runs, not how well (the engines' and formulations' own tests judge that):
  // the first quarter of each motion, so that every engine variant, tuned ones included, costs little.
  m.analysis.t1 = m.analysis.t0 + (m.analysis.t1 - m.analysis.t0) / 4;
  m.analysis.samples = std::max(3, (m.analysis.samples - 1) / 4 + 1);
  int ran = 0;
  for (const MethodPtr& meth : AllMethods()) {
    SCOPED_TRACE(meth->name());
    const std::optional<std::string> why = meth->Applicability(m);
    const Result r = meth->Run(m, RunOptions{});
    if (why) {
      EXPECT_EQ(r.status, Status::kNotApplicable) << r.reason;
      EXPECT_FALSE(why->empty());
      const bool numeric_family = meth->name() == "numeric" || meth->name().rfind("dyn-", 0) == 0;
      // The numeric family runs spatial scenes (a dynamics method refuses a driven one, saying so);
      // analytic names the kinds it has closed forms for; an engine names what the spatial graph does
      // not map, after the same words.
      if (meth->name() == "analytic") {
        EXPECT_EQ(why->rfind("no closed form for this spatial mechanism (RSSR and spatial slider-crank only): ", 0), 0u)
            << *why;
      } else if (!numeric_family) {
        EXPECT_EQ(why->rfind("spatial scenes: not yet in ", 0), 0u) << *why;
      }
      continue;
    }
    ++ran;
    // A run that goes wrong must be a known failure, with its numbers (harness/tolerances.yaml).
    if (!r.ok()) {
      EXPECT_NE(LoadTolerances(m.name).KnownFailure(meth->name()), nullptr) << r.reason;
      continue;
    }
    // The kinematic method reports a free scene's instant only (its motion is forward dynamics).
    const bool instant_only = m.IsFree() && meth->name() == "numeric";
    EXPECT_EQ(static_cast<int>(r.trajectory.size()), instant_only ? 1 : m.analysis.samples);
    for (const char* axis : {"x", "y", "z"}) {
      EXPECT_TRUE(r.quantities.count(std::string("q.") + axis + "B") || r.quantities.count(std::string("q.") + axis + "P"));
    }
  }
  EXPECT_GE(ran, 1);
}

INSTANTIATE_TEST_SUITE_P(Fixtures, SpatialScene, ::testing::Values("spherical_pendulum", "rssr_fourbar", "rssr_fourbar_angles",
                                                           "hinge_pendulum_tilted", "hinge_pendulum_torsion",
                                                           "spatial_slider_crank", "spatial_rotor_driven",
                                                           "spatial_collar_on_turning_rod"),
                         [](const auto& param_info) { return std::string(param_info.param); });

}  // namespace
}  // namespace harness_spatial_test
}  // namespace mechbench::harness
