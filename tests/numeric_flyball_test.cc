// IFToMM A05, the stiff flyball governor (scenarios/benchmarks/a05_flyball_governor.yaml), loaded
// as it is (its horizon shortened for the test's CPU): its redundant rows, the benchmark's
// published s(t) followed by ALI3-P over its first 0.3 s, and explicit RK4's stability limit on its
// stiff spring–dampers told apart from a singular position in the message.
#include "dynamics_method_named.h"
#include "mechbench/loader.h"
#include "mechbench/numeric/natural_data.h"
#include "mechbench/numeric/natural_model.h"
#include "mechbench/numeric/solver.h"
#include "mechbench/numeric/spatial.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace mechbench::numeric {
namespace numeric_flyball_test {  // this file's own names (the tests build in unity batches)
namespace {

std::string FlyballFile() { return std::string(MECHBENCH_TEST_DATA) + "/../../scenarios/benchmarks/a05_flyball_governor.yaml"; }

// 32 rows of rank 27 (the shared hinge axis v's unit row in the slider and both rods, the slider's
// z · v, z's attachment in the shaft): four degrees of freedom, the shaft's turn, the slider's
// height and the two rods' angles.
TEST(Flyball, FileHasFiveRedundantRowsAndFourDegreesOfFreedom) {
  const Model m = LoadScenario(FlyballFile());
  ASSERT_EQ(m.kind, ScenarioKind::kSpatial);
  const NaturalModel nm = Compile(m);
  NaturalData d(nm, LinearAlgebra::kDense);
  d.q = m.GuessQ();  // the file's pose, drawn assembled
  const RankReport rk = AnalyzeRank(nm, d);
  EXPECT_EQ(rk.m, 32);
  EXPECT_EQ(rk.rank, 27);
  EXPECT_EQ(rk.dof, 4);
  EXPECT_EQ(rk.redundant_rows.size(), 5u);
}

// The file's first three claims (the published reference's plot, to its 1e-3) at ALI3-P's default
// step, which the stiff springs do not trouble (implicit): s = p.E.z at 0.1, 0.2, 0.3 s
// (measured 2026-11-27 against the file's confirmed reference: within 1e-6 m).
TEST(Flyball, Ali3pFollowsThePublishedCurveAtTheStart) {
  Model m = LoadScenario(FlyballFile());
  m.analysis.t1 = 0.3;
  m.analysis.samples = 4;
  const Result r = MakeAli3pMethod()->Run(m, RunOptions{});
  ASSERT_TRUE(r.ok()) << r.reason;
  const NaturalModel nm = Compile(m);
  const int E = m.spatial.EntityIndex("E");
  const double published[] = {0.5238, 0.5852, 0.6588};  // read off the plot (the file's book claims)
  for (int k = 1; k <= 3; ++k)
    EXPECT_NEAR(EntityValue(nm, r.trajectory[k].q, E).z(), published[k - 1], 1e-3) << "t = " << r.trajectory[k].t;
}

// RK4 at its default 1 ms is past its stability limit on the dampers (C/m ~ 1e4 1/s): the guard
// stops it at the first step, and with Φ_q of full rank the message names both causes; at 0.1 ms
// it runs (0.05 s here).
TEST(Flyball, Rk4PastItsStabilityLimitIsNotCalledASingularPosition) {
  Model m = LoadScenario(FlyballFile());
  m.analysis.t1 = 0.05;
  m.analysis.samples = 6;
  const std::unique_ptr<Method> rk4 = test::DynamicsMethodNamed("rk4");
  const Result coarse = rk4->Run(m, RunOptions{});
  EXPECT_EQ(coarse.status, Status::kDiverged);
  EXPECT_NE(coarse.reason.find("with Φ_q of full rank here (27, as at t0)"), std::string::npos) << coarse.reason;
  EXPECT_NE(coarse.reason.find("past explicit RK4's stability limit"), std::string::npos) << coarse.reason;
  EXPECT_NE(coarse.reason.find("force elements may be stiff"), std::string::npos) << coarse.reason;
  const Result fine = rk4->Run(m, RunOptions{.step = 1e-4});
  EXPECT_TRUE(fine.ok()) << fine.reason;
}

}  // namespace
}  // namespace numeric_flyball_test
}  // namespace mechbench::numeric
