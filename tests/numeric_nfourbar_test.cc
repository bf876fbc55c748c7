// The IFToMM N-four-bar (A02): its exact motion (every crank alike), the singular horizontal
// positions each formulation must get through or report, the reference that is confirmed between
// and across them, and the benchmark scene file.
#include "mechbench/errors.h"
#include "mechbench/format.h"
#include "mechbench/loader.h"
#include "mechbench/motion_error.h"
#include "mechbench/numeric/dynamics_methods.h"
#include "mechbench/references/cranks.h"
#include "mechbench/references/nfourbar.h"
#include "mechbench/references/registry.h"
#include "mechbench/numeric/reference.h"
#include "quantity.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

namespace mechbench::numeric {
namespace numeric_nfourbar_test {  // this file's own names (the tests build in unity batches)
namespace {

using namespace ::mechbench::references;  // the N-four-bar's generator and exact motion

// The largest spread of the crank angles atan2(yPi, xPi − i) over a trajectory [rad].
double CrankSpread(const Model& model, int n, const std::vector<Sample>& traj) {
  double worst = 0;
  for (const Sample& s : traj) {
    const double th0 = std::atan2(s.q[model.SlotIndex("yP0")], s.q[model.SlotIndex("xP0")]);
    for (int i = 1; i <= n; ++i) {
      const double th = std::atan2(s.q[model.SlotIndex("yP" + std::to_string(i))], s.q[model.SlotIndex("xP" + std::to_string(i))] - i);
      worst = std::max(worst, std::fabs(std::remainder(th - th0, 2 * std::numbers::pi)));
    }
  }
  return worst;
}

// The reduced equation: energy kept, every crank alike by construction, the singular positions
// where sin θ = 0 (N = 1: first at 0.708 s, the time the full model's methods meet it too), and
// the full natural-coordinate model agreeing with it before the first one (RK4 at 0.5 ms, fourth
// order: 1.7e-12 measured over 0.6 s).
TEST(NumericNFourBar, ExactMotionIsThePendulumOfTheFullModel) {
  const Model model = NFourBar({.n = 3, .t1 = 0.6, .samples = 61});
  ASSERT_NO_THROW(Validate(model));
  const NFourBarSolution exact = NFourBarExact(model);
  EXPECT_LT(exact.energy_drift, 1e-11 * exact.energy);
  EXPECT_TRUE(exact.crossings.empty());
  EXPECT_LT(CrankSpread(model, 3, exact.trajectory), 1e-15);
  const Result rk4 = MakeBaumgarteRk4Method()->Run(model, {.step = 5e-4});
  ASSERT_TRUE(rk4.ok()) << rk4.reason;
  EXPECT_LT(CompareMotion(model, exact.trajectory, rk4.trajectory).q.max, 1e-10);
  // q̇ and q̈ of the reduced solution are those of the full model's start.
  EXPECT_LT((exact.trajectory[0].qd - rk4.trajectory[0].qd).cwiseAbs().maxCoeff(), 1e-14);
  EXPECT_LT((exact.trajectory[0].qdd - rk4.trajectory[0].qdd).cwiseAbs().maxCoeff(), 1e-12);

  const NFourBarSolution one = NFourBarExact(NFourBar({.n = 1, .t1 = 2, .samples = 21}));
  ASSERT_EQ(one.crossings.size(), 2u);
  EXPECT_NEAR(one.crossings[0], 0.70845, 1e-4);
}

// The registry checks the structure, not the names: another mass, another initial velocity or
// renamed bodies are still a row of parallelograms (their exact motion differs, and is computed
// from their own J and K); a crank out of parallel, a torque or the free four-bar are not, and
// the scene that names `nfourbar` is rejected with the reason.
TEST(NumericNFourBar, RegistryChecksTheStructureNotTheNames) {
  const Model m = NFourBar({.n = 4, .t1 = 3, .samples = 31});
  ASSERT_TRUE(m.exact_reference.has_value());
  EXPECT_EQ(m.exact_reference->name, "nfourbar");
  ParallelCranks pc;
  std::string why;
  ASSERT_TRUE(AnalyzeParallelCranks(m, pc, why)) << why;
  EXPECT_EQ(pc.couplers, 4);
  Model heavier = m;
  heavier.bodies[2].mass = 2;
  for (Body& b : heavier.bodies) b.name = "bar_" + b.name;
  EXPECT_NO_THROW(Validate(heavier));
  ParallelCranks ph;
  ASSERT_TRUE(AnalyzeParallelCranks(heavier, ph, why));
  EXPECT_GT(ph.J, pc.J);
  Model pushed = m;
  pushed.initial[0].velocity = 2;
  EXPECT_NO_THROW(Validate(pushed));
  Model tilted = m;
  tilted.points[tilted.PointIndex("P2")].p_W.x() += 0.1;
  EXPECT_THROW(Validate(tilted), ScenarioError);
  Model driven = m;
  driven.torques.push_back({.body = 0, .torque = 1.0, .law = nullptr, .src = {}});
  EXPECT_THROW(Validate(driven), ScenarioError);
  Model other = LoadScenario(ResolveScenario("fourbar_free"));
  other.exact_reference = ExactReferenceName{"nfourbar", {}};
  EXPECT_THROW(Validate(other), ScenarioError);
  other.exact_reference = ExactReferenceName{"no_such_motion", {}};
  try {
    Validate(other);
    ADD_FAILURE() << "an unknown name passed";
  } catch (const ScenarioError& e) {
    EXPECT_NE(std::string(e.what()).find("nfourbar, pendulum"), std::string::npos) << e.what();
  }
}

// A heavier coupler changes J and K, and the registry's exact motion follows the full model
// (RK4 at 0.5 ms over 0.6 s, before the first singular position).
TEST(NumericNFourBar, ExactMotionOfAnotherMassIsItsOwn) {
  Model model = NFourBar({.n = 2, .t1 = 0.6, .samples = 61});
  model.bodies[4].mass = 3;  // a coupler
  const NFourBarSolution exact = NFourBarExact(model);
  const Result rk4 = MakeBaumgarteRk4Method()->Run(model, {.step = 5e-4});
  ASSERT_TRUE(rk4.ok()) << rk4.reason;
  EXPECT_LT(CompareMotion(model, exact.trajectory, rk4.trajectory).q.max, 1e-10);
}

// The brief's exact check, N = 1 through three singular positions with ALI3-P: the coupler
// translates (both cranks at the same angle all along), the energy is kept, and the motion is the
// reduced equation's to ALI3-P's second-order error (1.2e-5 measured at h = 1 ms).
TEST(NumericNFourBar, Ali3pKeepsEveryCrankAlikeThroughSingularPositions) {
  const Model model = NFourBar({.n = 1, .t1 = 2.8, .samples = 281});
  const NFourBarSolution exact = NFourBarExact(model);
  ASSERT_EQ(exact.crossings.size(), 3u);  // 0.708, 1.215, 2.632 s
  const Result r = MakeAli3pMethod()->Run(model);
  ASSERT_EQ(r.status, Status::kOk) << r.reason;
  EXPECT_LT(CrankSpread(model, 1, r.trajectory), 1e-10);
  EXPECT_LT(Get(r, "energy_drift"), 1e-4 * exact.energy);
  EXPECT_LT(CompareMotion(model, exact.trajectory, r.trajectory).q.max, 5e-5);
  double lowest = 1;
  for (const Sample& s : r.trajectory) lowest = std::min(lowest, s.q[model.SlotIndex("yP0")]);
  EXPECT_LT(lowest, -0.99);  // through the horizontal to below the pivots and back
  // And at N = 40 over the first two singular positions (sparse, the benchmark's size).
  const Model n40 = NFourBar({.n = 40, .t1 = 1.5, .samples = 16});
  const Result r40 = MakeAli3pMethod()->Run(n40);
  ASSERT_EQ(r40.status, Status::kOk) << r40.reason;
  EXPECT_LT(CrankSpread(n40, 40, r40.trajectory), 1e-9);
  EXPECT_LT(CompareMotion(n40, NFourBarExact(n40).trajectory, r40.trajectory).q.max, 1e-4);
}

// A long chain keeps ALI3-P's accuracy: its Newton steps are measured against the links (1 m), not
// against the chain's extent (1000 m here), whose scale let each step keep an error of 1e-10 × N m
// and (4/h²) times that in q̈ (1.2e-6 of the range over 0.1 s at N = 1000, 1.6e-5 at N = 3000, and
// the run stopped on the singular-position guard at N = 10,000). With the links' scale: 8.6e-8,
// 2.9e-8 and 8.8e-9 (RelWithDebInfo, 2026-11-26), the N = 40 run's size of error.
TEST(NumericNFourBar, Ali3pStaysAccurateOnAThousandLoops) {
  const Model model = NFourBar({.n = 1000, .t1 = 0.1, .samples = 11});
  const Result r = MakeAli3pMethod()->Run(model);
  ASSERT_EQ(r.status, Status::kOk) << r.reason;
  EXPECT_LT(CompareMotion(model, NFourBarExact(model).trajectory, r.trajectory).q.max, 3e-7);
}

// A formulation that cannot pass a singular position says so, with the time, and keeps the
// samples before it, which are still on the branch: index-1 DOPRI5 at a tight tolerance resolves
// the crossing finely and meets the unbounded constraint forces of a branch switch (stopped by the
// singular-position guard at t = 1.215 s, the second crossing); coordinate partitioning stops at
// the first (0.708 s).
TEST(NumericNFourBar, FormulationsThatCannotPassReportWhereAndWhy) {
  const Model model = NFourBar({.n = 1, .t1 = 2, .samples = 201});
  const NFourBarSolution exact = NFourBarExact(model);
  const Result dopri = MakeBaumgarteDopri5Method()->Run(model, {.tolerance = 1e-10});
  ASSERT_EQ(dopri.status, Status::kDiverged);
  EXPECT_NE(dopri.reason.find("at t = 1.21"), std::string::npos) << dopri.reason;
  EXPECT_NE(dopri.reason.find("singular position"), std::string::npos) << dopri.reason;
  EXPECT_NE(dopri.settings.at("singular_guard").find("the run stops above 100"), std::string::npos);
  ASSERT_EQ(dopri.trajectory.size(), 122u);  // 0 … 1.21 s
  std::vector<Sample> before(exact.trajectory.begin(), exact.trajectory.begin() + 122);
  EXPECT_LT(CompareMotion(model, before, dopri.trajectory).q.max, 1e-8);

  const Result cp = MakeCoordinatePartitioningMethod()->Run(model);
  ASSERT_EQ(cp.status, Status::kDiverged);
  EXPECT_NE(cp.reason.find("at t = 0.708"), std::string::npos) << cp.reason;
  EXPECT_NE(cp.reason.find("loses rank"), std::string::npos) << cp.reason;
}

// RK4 at fixed steps jumps over the singular positions and stays on the branch; its accelerations
// stay within a few times their scale there (the guard's margin).
TEST(NumericNFourBar, Rk4PassesWithBoundedAccelerations) {
  const Model model = NFourBar({.n = 2, .t1 = 2, .samples = 21});
  const Result r = MakeBaumgarteRk4Method()->Run(model);
  ASSERT_EQ(r.status, Status::kOk) << r.reason;
  EXPECT_LT(CrankSpread(model, 2, r.trajectory), 1e-8);
  EXPECT_LT(CompareMotion(model, NFourBarExact(model).trajectory, r.trajectory).q.max, 1e-6);
  const std::string guard = r.settings.at("singular_guard");
  const double peak = std::stod(guard.substr(guard.find("‖q̈‖ ") + std::string("‖q̈‖ ").size()));
  EXPECT_LT(peak, 10.0) << guard;
}

// The reference of an N-four-bar: the reduced equation, confirmed on the full model by index-1
// DOPRI5 between the singular positions (restarted after each) to the stated 1e-8 (1.8e-12
// measured at N = 1 over 20 s, 1.3e-12 at N = 40), and across them by the whole run in complex time.
TEST(NumericNFourBar, ReferenceIsTheReducedEquationConfirmedBetweenSingularPositions) {
  const Model model = NFourBar({.n = 2, .t1 = 3.3, .samples = 34});
  const Reference ref = ReferenceFor(model);
  EXPECT_TRUE(ref.confirmed) << ref.description;
  EXPECT_LE(ref.agreement, 1e-10) << ref.description;
  EXPECT_LE(ref.segment_agreement, 1e-10) << ref.description;
  EXPECT_EQ(ref.singular_positions, 4);
  EXPECT_GE(ref.compared_samples, 30);
  EXPECT_LT(ref.compared_samples, 34);  // the samples within 0.02 s of a crossing are not compared
  EXPECT_LT(ref.whole_run_spread, 1e-9);
  EXPECT_LE(ref.whole_run_agreement, ref.whole_run_tolerance) << ref.description;
  EXPECT_NE(ref.description.find("reduced equation"), std::string::npos) << ref.description;
  EXPECT_NE(ref.description.find("confirmed by index-1 DOPRI5"), std::string::npos) << ref.description;
  ASSERT_EQ(ref.trajectory().size(), 34u);
  EXPECT_LT(CompareMotion(model, NFourBarExact(model).trajectory, ref.trajectory()).q.max, 1e-12);
}

// Across the singular positions: one run of the full model's index-1 equations from its own
// initial state along t + 0.02i s in complex time, down to the real axis at every sample, agrees
// with the reduced equation over all samples, the ones beside each crossing included, to the
// stated 1e-8 (N = 1 through 21 singular positions in 20 s: 1.9e-9 measured, 0.4 s), without
// extrapolation. It is the analytic continuation: another detour gives the same motion, and the
// imaginary parts back on the real axis vanish.
TEST(NumericNFourBar, ReferenceIsConfirmedAcrossSingularPositionsInComplexTime) {
  const Model model = NFourBar({.n = 1, .t1 = 20, .samples = 201});
  const Reference ref = ReferenceFor(model);
  EXPECT_TRUE(ref.confirmed) << ref.description;
  EXPECT_EQ(ref.singular_positions, 21);
  EXPECT_LT(ref.compared_samples, 201);  // the segments leave out the samples beside the crossings
  ASSERT_TRUE(ref.whole_run.ok()) << ref.whole_run.reason;
  ASSERT_EQ(ref.whole_run.trajectory.size(), 201u);
  EXPECT_EQ(ref.whole_run_tolerance, 1e-8);
  EXPECT_LE(ref.whole_run_agreement, ref.whole_run_tolerance) << ref.description;
  EXPECT_GT(ref.whole_run_agreement, 0.0);
  EXPECT_EQ(ref.agreement, std::max(ref.segment_agreement, ref.whole_run_agreement));
  EXPECT_LT(ref.whole_run_spread, 1e-12);  // every crank alike: the parallelogram branch all along
  EXPECT_LT(ref.whole_run.quantities.at("imaginary"), 1e-8);
  EXPECT_NE(ref.description.find("in complex time"), std::string::npos) << ref.description;
  EXPECT_NE(ref.description.find("over all 201 samples (stated 1e-08)"), std::string::npos) << ref.description;
  // The samples within 0.02 s of a singular position, which only the whole run compares.
  const NFourBarSolution exact = NFourBarExact(model);
  std::vector<Sample> beside_ref, beside_run;
  for (size_t k = 0; k < exact.trajectory.size(); ++k)
    for (double c : exact.crossings)
      if (std::fabs(exact.trajectory[k].t - c) < 0.02) {
        beside_ref.push_back(exact.trajectory[k]);
        beside_run.push_back(ref.whole_run.trajectory[k]);
      }
  ASSERT_GE(beside_ref.size(), 5u);
  EXPECT_LE(CompareMotion(model, ScaleOfMotion(model, exact.trajectory), beside_ref, beside_run).q.max, 1e-8);

  ReferenceOptions wider;
  wider.detour = 0.05;
  const Reference other = ReferenceFor(model, wider);
  ASSERT_TRUE(other.whole_run.ok()) << other.whole_run.reason;
  EXPECT_LE(CompareMotion(model, ref.whole_run.trajectory, other.whole_run.trajectory).q.max, 1e-8);
}

// The reference is confirmed only when both confirmations are within their statements: a
// statement tighter than the whole run's DOPRI5 error leaves it unconfirmed, and says so.
TEST(NumericNFourBar, ReferenceNeedsBothConfirmations) {
  const Model model = NFourBar({.n = 1, .t1 = 3, .samples = 31});
  ReferenceOptions tight;
  tight.whole_run_agreement = 1e-14;
  const Reference ref = ReferenceFor(model, tight);
  EXPECT_LE(ref.segment_agreement, tight.agreement);
  EXPECT_FALSE(ref.confirmed) << ref.description;
  EXPECT_NE(ref.description.find("UNCONFIRMED"), std::string::npos) << ref.description;
  EXPECT_NE(ref.description.find("differs by"), std::string::npos) << ref.description;
}

// The reduced equation stops every 1 ms of the motion to find the singular positions: t1 = 1e9 s
// is 1e12 stops. They used to be listed first (their count overflowed an int; t1 = 1e5 s took
// gigabytes); now they are visited one at a time within the reference's budget, which says so.
TEST(NumericNFourBar, AReferenceFarLongerThanItsBudgetStopsAndSaysWhy) {
  const Model model = NFourBar({.n = 1, .t1 = 1e9, .samples = 201});
  ReferenceOptions o;
  o.cpu_budget = 0.2;
  const Reference ref = ReferenceFor(model, o);
  EXPECT_EQ(ref.primary.status, Status::kOverBudget);
  EXPECT_FALSE(ref.confirmed);
  EXPECT_NE(ref.description.find("no reference: stopped at t = 0 s of 1e+09 s: its CPU budget of 0.2 s ran out"),
            std::string::npos)
      << ref.description;
  EXPECT_LT(ref.primary.cpu_seconds, 2.0);
}

// Its exact motion is cheap at any N (one degree of freedom), its confirmations on the full model
// are not: they stop on the same budget, each with its reason, and the reference is unconfirmed.
TEST(NumericNFourBar, ConfirmationsStopOnTheirBudgetToo) {
  const Model model = NFourBar({.n = 200, .t1 = 20, .samples = 201});
  // The smallest budget (doubling from 0.3 s) in which the primary run finishes on this machine
  // and build (a sanitizer build is several times slower): the confirmations, which cost more, do not.
  ReferenceOptions o;
  Reference ref;
  for (o.cpu_budget = 0.3; o.cpu_budget < 40; o.cpu_budget *= 2) {
    ref = ReferenceFor(model, o);
    if (ref.primary.ok()) break;
  }
  ASSERT_TRUE(ref.primary.ok()) << ref.primary.reason;
  EXPECT_FALSE(ref.confirmed);
  EXPECT_EQ(ref.confirmation.status, Status::kOverBudget) << ref.confirmation.reason;
  EXPECT_EQ(ref.whole_run.status, Status::kOverBudget) << ref.whole_run.reason;
  EXPECT_NE(ref.description.find("its CPU budget of " + Fmt(o.cpu_budget, 3) + " s ran out"), std::string::npos)
      << ref.description;
}

// A02 itself (N = 40, 20 s, 20 singular positions; about 8 s): both confirmations within 1e-8,
// 1.3e-12 between the singular positions and 2.8e-9 over the whole run across them.
TEST(NumericNFourBar, ReferenceOfA02IsConfirmedAcrossSingularPositionsSlow) {
  const Model model = NFourBar({.n = 40});
  const Reference ref = ReferenceFor(model);
  EXPECT_TRUE(ref.confirmed) << ref.description;
  EXPECT_EQ(ref.singular_positions, 20);
  EXPECT_LE(ref.segment_agreement, 1e-10) << ref.description;
  ASSERT_EQ(ref.whole_run.trajectory.size(), 201u) << ref.whole_run.reason;
  EXPECT_LE(ref.whole_run_agreement, ref.whole_run_tolerance) << ref.description;
  EXPECT_LT(ref.whole_run_spread, 1e-9);
}

// scenarios/benchmarks/a02_nfourbar_40.yaml is what `mechbench generate nfourbar 40 --samples 401
// --criteria` writes (the benchmark's 400 output steps and its precision levels), and
// loads as the recognised N-four-bar (so `mechbench run` on it gets the confirmed reference).
TEST(NumericNFourBar, BenchmarkSceneFileIsTheGeneratorsOutput) {
  const std::string path = std::string(MECHBENCH_TEST_DATA) + "/../../scenarios/benchmarks/a02_nfourbar_40.yaml";
  std::ifstream in(path);
  ASSERT_TRUE(in) << path;
  std::ostringstream text;
  text << in.rdbuf();
  EXPECT_EQ(text.str(), NFourBarYaml({.n = 40, .samples = 401, .criteria = true}))
      << "regenerate it: mechbench generate nfourbar 40 --samples 401 --criteria -o " << path;
  const Model file = LoadScenario(path);
  ASSERT_TRUE(file.exact_reference.has_value());
  EXPECT_EQ(file.exact_reference->name, "nfourbar");
  ParallelCranks pc;
  std::string why;
  ASSERT_TRUE(AnalyzeParallelCranks(file, pc, why)) << why;
  EXPECT_EQ(pc.couplers, 40);
  EXPECT_EQ(file.analysis.t1, 20.0);
  ASSERT_TRUE(file.criteria.has_value());
  EXPECT_EQ(file.criteria->output_steps, 400);
  EXPECT_EQ(file.points[file.criteria->point].name, "P0");
}

}  // namespace
}  // namespace numeric_nfourbar_test
}  // namespace mechbench::numeric
