// One way to time a method (harness/timing.h, Result::cpu): the phases of every method's run add
// up to its CPU time, integration holds the method's steps, and one-time costs are paid apart.
#include "mechbench/harness/timing.h"
#include "mechbench/harness/registry.h"
#include "mechbench/loader.h"
#include "mechbench/references/nfourbar.h"
#include "mechbench/run_control.h"

#include <gtest/gtest.h>

#include <cmath>

namespace mechbench::harness {
namespace harness_timing_test {  // this file's own names (the tests build in unity batches)
namespace {

// A free and a driven scene: between them every method applies to one.
const Model& Scene(const std::string& name) {
  static std::map<std::string, Model> cache;
  auto it = cache.find(name);
  if (it == cache.end()) it = cache.emplace(name, LoadScenario(ResolveScenario(name))).first;
  return it->second;
}

TEST(Timing, EveryMethodsPhasesAddUpToItsRun) {
  for (const char* scene : {"fourbar_free", "fourbar_crank_rocker"}) {
    const Model& m = Scene(scene);
    for (const MethodPtr& method : AllMethods()) {
      if (method->Applicability(m)) continue;
      const Result r = method->Run(m);
      SCOPED_TRACE(std::string(scene) + " " + method->name());
      ASSERT_TRUE(r.ok()) << r.reason;
      EXPECT_GE(r.cpu.setup, 0);
      EXPECT_GE(r.cpu.integration, 0);
      EXPECT_GE(r.cpu.observation, 0);
      EXPECT_NEAR(r.cpu.total(), r.cpu_seconds, 1e-12 + 1e-9 * r.cpu_seconds);
      // A method that integrated the motion (or solved its samples) says how many steps it took,
      // and their time is integration, not set-up.
      if (r.trajectory.size() > 1) {
        EXPECT_GT(r.steps, 0);
        EXPECT_GT(r.cpu.integration, 0);
      }
    }
  }
}

TEST(Timing, StepsFollowTheOneFixedStepSchedule) {
  // Every fixed-step method lands on each of the 100 sample intervals of 10 ms in ⌈10 ms / h⌉
  // equal steps (run_control.h, StepsTo): 100 × 4 at h = 2.5 ms, 100 × 3 at h = 4 ms (3.33 ms).
  const Model& m = Scene("fourbar_free");
  for (const MethodPtr& method : AllMethods()) {
    if (method->control() != Control::kStep || method->Applicability(m)) continue;
    SCOPED_TRACE(method->name());
    const Result a = method->Run(m, {.step = 2.5e-3});
    const Result b = method->Run(m, {.step = 4e-3});
    ASSERT_TRUE(a.ok() && b.ok()) << a.reason << b.reason;
    EXPECT_EQ(a.steps, 400);
    EXPECT_EQ(b.steps, 300);
  }
}

TEST(Timing, StepsToLandsOnTheSampleExactly) {
  const Substeps s = StepsTo(0.1, 0.2, 1e-3);
  EXPECT_EQ(s.n, 100);  // 0.1 / 1e-3 is 100.00000000000001 in floating point: not 101 steps
  EXPECT_DOUBLE_EQ(s.h * static_cast<double>(s.n), 0.1);
  EXPECT_EQ(StepsTo(0, 0.01, 0.003).n, 4);
  EXPECT_EQ(StepsTo(0, 0.01, 0.05).n, 1);  // a step longer than the interval is the interval
}

TEST(Timing, WarmUpPaysOncePerProcessAndMeasuresIt) {
  const Model& m = Scene("fourbar_free");
  for (const MethodPtr& method : AllMethods()) {
    if (method->Applicability(m) || method->name() == "analytic") continue;
    SCOPED_TRACE(method->name());
    // Other tests in this process may have warmed it already (the sanitizer build runs many tests
    // in one process): WarmUp measures only when it had not.
    const bool before = WarmedInThisProcess(*method);
    const StartupCost first = WarmUp(*method, m);
    EXPECT_EQ(first.done, !before);
    EXPECT_TRUE(WarmedInThisProcess(*method));
    EXPECT_FALSE(WarmUp(*method, m).done) << "warmed twice in one process";
    const StartupCost measured = MeasureStartup(*method, m);  // what WarmUp does the first time
    ASSERT_TRUE(measured.done);
    EXPECT_GT(measured.first, 0);
    EXPECT_GT(measured.again, 0);
    EXPECT_GE(measured.one_time(), 0);
    break;  // one method is enough: the rule is the same for all
  }
}

TEST(Timing, ScenesTooLargeAreNotWarmed) {
  // The warm-up runs the scene's set-up twice more; past kWarmUpMaxBodies that costs more than it saves.
  const Model big = references::NFourBar({.n = kWarmUpMaxBodies, .t1 = 0.01, .samples = 2});
  ASSERT_GT(static_cast<int>(big.bodies.size()), kWarmUpMaxBodies);
  for (const MethodPtr& method : AllMethods()) {
    if (method->name() != "dyn-ali3p") continue;
    EXPECT_FALSE(WarmUp(*method, big).done);
  }
}

// A first sample interval that takes long (100 s of motion here) does not hold the warm-up up:
// each of its short runs stops on kWarmUpRunBudget.
TEST(Timing, WarmUpOfALongFirstIntervalStopsOnItsBudget) {
  const Model m = LoadScenario(std::string(MECHBENCH_TEST_DATA) + "/scenes/fourbar_free_long.yaml");
  int checked = 0;
  for (const MethodPtr& method : AllMethods()) {
    if (method->Applicability(m) || method->control() != Control::kStep) continue;
    SCOPED_TRACE(method->name());
    const StartupCost c = MeasureStartup(*method, m);
    ASSERT_TRUE(c.done);
    EXPECT_LE(c.runs, kWarmUpRuns);
    // A budget is checked every 64 steps: a run ends a little past it, never at the interval's end.
    EXPECT_LT(c.first, 2 * kWarmUpRunBudget);
    EXPECT_LT(c.again, 2 * kWarmUpRunBudget);
    ++checked;
  }
  EXPECT_GE(checked, 2);
}

}  // namespace
}  // namespace harness_timing_test
}  // namespace mechbench::harness
