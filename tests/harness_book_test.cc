// The book checks: every printed value's verdict must match the list kept in
// tests/data/expected_verdicts.tsv, so a new disagreement (or a fixed one) fails CI and is looked at.
#include "mechbench/harness/compare.h"
#include "mechbench/harness/registry.h"
#include "mechbench/harness/tolerances.h"
#include "mechbench/format.h"
#include "mechbench/loader.h"
#include "mechbench/motion_error.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <numbers>
#include <map>
#include <sstream>

namespace mechbench::harness {
namespace harness_book_test {  // this file's own names (the tests build in unity batches)
namespace {

TEST(Verdict, HalfAndOneUnitOfTheLastDigit) {
  BookValue b;
  b.value = -0.8138;
  b.last_digit = 1e-4;
  EXPECT_EQ(Judge(b, -0.81379), Verdict::kAgrees);
  EXPECT_EQ(Judge(b, -0.81385), Verdict::kAgrees);   // exactly half a unit
  EXPECT_EQ(Judge(b, -0.81388), Verdict::kLastDigit);
  EXPECT_EQ(Judge(b, -0.81392), Verdict::kDiffers);
  b.last_digit = 0;  // an exact claim
  EXPECT_EQ(Judge(b, -0.8138), Verdict::kAgrees);
  EXPECT_EQ(Judge(b, -0.81380001), Verdict::kDiffers);
}

using Key = std::tuple<std::string, std::string, std::string>;  // scenario, quantity, where

std::map<Key, std::string> ExpectedVerdicts() {
  std::map<Key, std::string> m;
  std::ifstream in(MECHBENCH_TEST_DATA "/expected_verdicts.tsv");
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::stringstream ss(line);
    std::string scenario, quantity, where, verdict;
    std::getline(ss, scenario, '\t');
    std::getline(ss, quantity, '\t');
    std::getline(ss, where, '\t');
    std::getline(ss, verdict, '\t');
    m[{scenario, quantity, where}] = verdict;
  }
  return m;
}

TEST(BookChecks, EveryVerdictIsTheExpectedOne) {
  const auto expected = ExpectedVerdicts();
  ASSERT_FALSE(expected.empty());
  // The exact methods, as `mechbench check` uses them by default.
  std::vector<MethodPtr> methods;
  for (auto& m : AllMethods())
    if (m->name() == "analytic" || m->name() == "numeric") methods.push_back(std::move(m));
  size_t seen = 0;
  for (const std::string& f : BuiltinScenarioFiles()) {
    const Model m = LoadScenario(f);
    std::vector<Result> results;
    for (const auto& meth : methods) results.push_back(meth->Run(m, {.motion = false}));
    for (const BookCheck& row : CheckBook(m, results)) {
      ++seen;
      const Key key{m.name, row.book.quantity, row.book.where};
      std::ostringstream values;
      for (const auto& [meth, v] : row.computed) values << " " << meth << "=" << (v ? std::to_string(*v) : "n/a");
      EXPECT_TRUE(row.methods_agree) << m.name << " " << row.book.quantity << values.str();
      const auto it = expected.find(key);
      if (it == expected.end()) {
        ADD_FAILURE() << "no expected verdict for " << m.name << "\t" << row.book.quantity << "\t" << row.book.where
                      << "\t" << ToString(row.verdict) << "\t(add it to tests/data/expected_verdicts.tsv)" << values.str();
        continue;
      }
      EXPECT_EQ(ToString(row.verdict), it->second)
          << m.name << " " << row.book.quantity << " (" << row.book.where << ") book " << row.book.printed << values.str();
    }
  }
  EXPECT_EQ(seen, expected.size()) << "expected_verdicts.tsv lists values that no scenario prints any more";
}

// Claims at a time of a driven scene's motion (crank_rocker_claims_at.yaml): the drivers' law gives
// the exact kinematics at t, so analytic's and numeric's trajectories decide the verdict as for a
// claim about the instant (no reference trajectory is needed). The crank's value and rate are the
// law's, the coupler's angle and pin the four-bar's closed form, which the fixture prints and which
// the sample also satisfies here (the bars' lengths, the angle of 1→2). A quantity a sample does
// not hold is not-computed with the reason.
TEST(BookChecks, ClaimsAtATimeOfADrivenMotionAreJudgedOnItsKinematics) {
  const Model m = LoadScenario(MECHBENCH_TEST_DATA "/scenes/crank_rocker_claims_at.yaml");
  ASSERT_FALSE(m.IsFree());
  std::vector<Result> results;
  for (auto& meth : AllMethods())
    if (meth->name() == "analytic" || meth->name() == "numeric") results.push_back(meth->Run(m, {.motion = true}));
  ASSERT_EQ(results.size(), 2u);
  const std::vector<BookCheck> rows = CheckBook(m, results);
  ASSERT_EQ(rows.size(), 5u);
  int judged = 0;
  for (const BookCheck& row : rows) {
    SCOPED_TRACE(row.book.quantity);
    if (row.book.quantity == "omega.coupler") {
      EXPECT_EQ(row.verdict, Verdict::kNotComputed);
      EXPECT_NE(row.reason.find("at t0 only"), std::string::npos) << row.reason;
      continue;
    }
    EXPECT_EQ(row.verdict, Verdict::kAgrees) << row.reason;
    EXPECT_TRUE(row.reason.empty()) << row.reason;
    EXPECT_TRUE(row.methods_agree);
    for (const auto& [meth, v] : row.computed) {
      if (!v) continue;
      ++judged;
      EXPECT_LE(std::fabs(*v - row.book.value), row.allowed) << meth;
    }
  }
  EXPECT_GE(judged, 4);  // numeric at least, on every claim
  // The numeric sample at 0.25 s is the closed form's four-bar: bars 2, 8, 5 long, phi_c along 1→2.
  const Result& num = results[1].method == "numeric" ? results[1] : results[0];
  ASSERT_TRUE(num.ok()) << num.reason;
  const Quantities q = SampleQuantities(m, num.trajectory.at(10));  // t = 0.25 s: 10 of 40 intervals
  const double x1 = q.at("p.1.x"), y1 = q.at("p.1.y"), x2 = q.at("p.2.x"), y2 = q.at("p.2.y");
  EXPECT_NEAR(std::hypot(x1, y1), 2, 1e-9);
  EXPECT_NEAR(std::hypot(x2 - x1, y2 - y1), 8, 1e-9);
  EXPECT_NEAR(std::hypot(x2 - 10, y2), 5, 1e-9);
  EXPECT_NEAR(q.at("q.phi_c"), std::atan2(y2 - y1, x2 - x1), 1e-9);
  EXPECT_NEAR(q.at("q.theta"), 100 * std::numbers::pi / 180, 1e-12);
}

// A stated precision replaces the printed digits' band (crank_rocker_precision.yaml): a printed "0"
// with precision 1e-9 claims zero to 1e-9, so 1.97 m differs (it was ±0.5 and agreed).
TEST(BookChecks, AStatedPrecisionReplacesTheDigitsBand) {
  const Model m = LoadScenario(MECHBENCH_TEST_DATA "/scenes/crank_rocker_precision.yaml");
  std::vector<Result> results;
  for (auto& meth : AllMethods())
    if (meth->name() == "analytic" || meth->name() == "numeric") results.push_back(meth->Run(m, {.motion = true}));
  const std::vector<BookCheck> rows = CheckBook(m, results);
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[0].verdict, Verdict::kDiffers) << rows[0].reason;
  EXPECT_NEAR(rows[0].allowed, 1e-9, 1e-20);
  EXPECT_EQ(rows[1].verdict, Verdict::kAgrees) << rows[1].reason;
  EXPECT_NEAR(rows[1].allowed, 1e-12 * 100, 1e-20);
  EXPECT_EQ(rows[2].verdict, Verdict::kAgrees) << rows[2].reason;
  EXPECT_NEAR(rows[2].allowed, 1e-9 * 1.969615506, 1e-20);
}

// Claims at a time on a spatial scene's 3-D components (rssr_fourbar_angles.yaml: its input crank's
// end and the output crank's end at t = 0.5 s from the RSSR closed form, printed to 10 digits):
// numeric's sample decides them, as for a linkage's points.
TEST(BookChecks, ClaimsAtATimeOnASpatialScenesPoints) {
  const Model m = LoadScenario(MECHBENCH_TEST_DATA "/scenes/rssr_fourbar_angles.yaml");
  ASSERT_EQ(m.kind, ScenarioKind::kSpatial);
  std::vector<Result> results;
  for (auto& meth : AllMethods())
    if (meth->name() == "numeric") results.push_back(meth->Run(m, {.motion = true}));
  ASSERT_EQ(results.size(), 1u);
  const std::vector<BookCheck> rows = CheckBook(m, results);
  ASSERT_EQ(rows.size(), 3u);
  for (const BookCheck& row : rows) {
    SCOPED_TRACE(row.book.quantity);
    EXPECT_EQ(row.verdict, Verdict::kAgrees) << row.reason;
    ASSERT_EQ(row.computed.size(), 1u);
    ASSERT_TRUE(row.computed[0].second.has_value());
    EXPECT_NEAR(*row.computed[0].second, row.book.value, 1e-10);  // the claim's last digit
  }
}

// The spatial RSSR benchmark (scenarios/benchmarks/rssr_crank_rocker.yaml) carries six claims
// computed apart in Python (the output angle, C's y and z, the output rate): analytic's closed form
// and numeric both agree with each, at the claims' printed digits.
TEST(BookChecks, SpatialRssrBenchmarkClaimsAgreeInAnalyticAndNumeric) {
  const Model m = LoadScenario(MECHBENCH_TEST_DATA "/../../scenarios/benchmarks/rssr_crank_rocker.yaml");
  std::vector<Result> results;
  for (auto& meth : AllMethods())
    if (meth->name() == "numeric" || meth->name() == "analytic") results.push_back(meth->Run(m, {.motion = true}));
  ASSERT_EQ(results.size(), 2u);
  for (const Result& r : results) ASSERT_TRUE(r.ok()) << r.method << ": " << r.reason;
  const std::vector<BookCheck> rows = CheckBook(m, results);
  ASSERT_EQ(rows.size(), 6u);
  for (const BookCheck& row : rows) {
    SCOPED_TRACE(row.book.quantity);
    EXPECT_EQ(row.verdict, Verdict::kAgrees) << row.reason;
    ASSERT_EQ(row.computed.size(), 2u);
    for (const auto& c : row.computed) {
      ASSERT_TRUE(c.second.has_value()) << c.first;
      EXPECT_NEAR(*c.second, row.book.value, 1e-8) << c.first;  // the claims' last printed digit
    }
  }
}

// §3.1 on its turning platform: an engine's absolute accelerations come from finite differences of
// its velocities (3.5021 against analytic's 3.5). `check` holds each method to its own tolerance
// for the quantity (tolerances.yaml, as `run` judges it at t0), not to the exact methods' 1e-9;
// without the tolerances the same values disagree.
TEST(BookChecks, EachMethodIsHeldToItsOwnToleranceForTheQuantity) {
  const Model m = LoadScenario(ResolveScenario("s3_1_carousel"));
  std::vector<Result> results;
  for (const MethodPtr& meth : AllMethods())
    if (meth->name() == "analytic" || meth->name() == "ode-worldstep-tuned")
      results.push_back(meth->Run(m, {.motion = false}));  // as `check` runs them: the instant
  if (results.size() < 2) GTEST_SKIP() << "ODE is not built";
  for (const Result& r : results) ASSERT_TRUE(r.ok()) << r.method << ": " << r.reason;
  const Tolerances tol = LoadTolerances(m.name);
  int finite_differences = 0;
  for (const BookCheck& row : CheckBook(m, results, nullptr, &tol)) {
    EXPECT_TRUE(row.methods_agree) << row.book.quantity << ": " << (row.outside.empty() ? "" : row.outside[0]);
    EXPECT_TRUE(row.not_judged.empty()) << row.book.quantity << ": ODE's q̈ has a bound";
    if (row.book.quantity.rfind("aabs.", 0) == 0) ++finite_differences;
  }
  EXPECT_EQ(finite_differences, 3);
  const std::vector<BookCheck> exact = CheckBook(m, results);
  EXPECT_TRUE(std::any_of(exact.begin(), exact.end(), [](const BookCheck& row) { return !row.methods_agree; }))
      << "held to 1e-9, ODE's aabs from finite differences would disagree";
}


// §3.1 again, MuJoCo Euler: its q̈ has no bound (∞ in tolerances.yaml, "shown, not judged" by
// `run`), and its absolute accelerations at t0, differenced from its world velocities, have the
// wrong sign on D (aabs.D.y 0.92 against −0.47). `check` shows the number and labels it: the cell
// keeps the value, the method is named as not judged, and it gives no verdict.
TEST(BookChecks, AValueWithoutABoundIsShownAsNotJudged) {
  const Model m = LoadScenario(ResolveScenario("s3_1_carousel"));
  std::vector<Result> results;
  for (const MethodPtr& meth : AllMethods())
    if (meth->name() == "analytic" || meth->name() == "mujoco-euler-default")
      results.push_back(meth->Run(m, {.motion = false}));
  if (results.size() < 2) GTEST_SKIP() << "MuJoCo is not built";
  for (const Result& r : results) ASSERT_TRUE(r.ok()) << r.method << ": " << r.reason;
  const Tolerances tol = LoadTolerances(m.name);
  ASSERT_TRUE(std::isinf(tol.For("mujoco-euler-default").AccelerationAtT0()));
  int shown = 0;
  for (const BookCheck& row : CheckBook(m, results, nullptr, &tol)) {
    if (row.book.quantity.rfind("aabs.", 0) != 0) continue;
    SCOPED_TRACE(row.book.quantity);
    ASSERT_EQ(row.computed.size(), 2u);
    ASSERT_TRUE(row.computed[1].second) << "an unjudged value is hidden";
    ASSERT_EQ(row.not_judged, std::vector<std::string>{"mujoco-euler-default"});
    ASSERT_EQ(row.not_judged_values.size(), 1u);
    EXPECT_EQ(*row.computed[1].second, row.not_judged_values[0]);
    EXPECT_TRUE(std::none_of(row.verdicts.begin(), row.verdicts.end(),
                             [](const auto& v) { return v.first == "mujoco-euler-default"; }))
        << "a value without a bound gives no verdict";
    EXPECT_TRUE(row.methods_agree);
    ++shown;
  }
  EXPECT_EQ(shown, 3);
}

// §3.2, the thumb on its turning frame: `check` judged ODE dWorldStep's differenced aabs
// component by component (aabs.B.y off by 1.3 against an allowed 1, exit 1) while `run` never saw
// it (a motion run has no aabs at t0 for an engine without accelerations there, exit 0). Both now
// judge the one quantity — the instant run's differenced aabs, relative to the largest of its
// family, against the method's bound for accelerations at t0 — and reach one verdict.
TEST(BookChecks, RunAndCheckJudgeTheTurningFramesAabsAlike) {
  const Model m = LoadScenario(ResolveScenario("s3_2_thumb"));
  std::vector<MethodPtr> methods;
  for (MethodPtr& meth : AllMethods())
    if (meth->name() == "numeric" || meth->name() == "ode-worldstep-tuned" || meth->name() == "ode-worldstep-default")
      methods.push_back(std::move(meth));
  if (methods.size() < 3) GTEST_SKIP() << "ODE is not built";
  const Tolerances tol = LoadTolerances(m);
  const RunReport rep = RunScenario(m, methods, {}, tol);
  std::vector<Result> instant;
  for (const MethodPtr& meth : methods) instant.push_back(meth->Run(m, {.motion = false}));  // as `check`
  const std::vector<BookCheck> rows = CheckBook(m, instant, nullptr, &tol);
  for (const std::string engine : {"ode-worldstep-tuned", "ode-worldstep-default"}) {
    SCOPED_TRACE(engine);
    const auto p = std::find_if(rep.pairs.begin(), rep.pairs.end(), [&](const PairComparison& c) { return c.method == engine; });
    ASSERT_NE(p, rep.pairs.end());
    ASSERT_EQ(p->worst_acceleration_quantity.rfind("aabs.", 0), 0u)
        << "run judges no aabs: " << p->worst_acceleration_quantity;
    const double bound = InstantBound(tol.For(engine), "aabs.B.x");
    const bool run_within = p->acceleration_quantity <= bound;
    // check's rows on aabs: outside exactly when run's is.
    bool check_within = true;
    for (const BookCheck& row : rows) {
      if (row.book.quantity.rfind("aabs.", 0) != 0) continue;
      for (const std::string& o : row.outside) check_within = check_within && o.rfind(engine + " ", 0) != 0;
      for (const std::string& o : row.known_outside) check_within = check_within && o.rfind(engine + " ", 0) != 0;
    }
    EXPECT_EQ(run_within, check_within) << "run: " << p->worst_acceleration_quantity << " " << p->acceleration_quantity
                                        << " against " << bound;
    if (std::getenv("MECHBENCH_VERBOSE"))
      std::printf("%s: aabs at t0 %s %.3g of its family (bound %.3g)\n", engine.c_str(),
                  p->worst_acceleration_quantity.c_str(), p->acceleration_quantity, bound);
  }
}

// A user's two-stage train driving a rack (tests/data/scenes/gear_train_rack_book.yaml), with
// claims at t = 2 s: btMultiBody's rack is 1e-6 mm off analytic's 144 mm (q error 7e-9 of its
// range), its speed 0.009 mm/s off 90 (1e-4 of the largest): inside the bounds `run` holds its
// motion to. `check` judges each method at a claim's time with those same bounds (its q, q̇ or q̈
// agreement times that order's scale of the motion), so the two commands agree on the scene.
TEST(BookChecks, ClaimsAtATimeHoldEachMethodToItsRunTolerance) {
  const Model m = LoadScenario(MECHBENCH_TEST_DATA "/scenes/gear_train_rack_book.yaml");
  ASSERT_FALSE(m.IsFree());
  std::vector<Result> results;
  for (const MethodPtr& meth : AllMethods())
    if (meth->name() == "analytic" || meth->name() == "bullet-multibody-default")
      results.push_back(meth->Run(m, {.motion = true}));
  if (results.size() < 2) GTEST_SKIP() << "Bullet is not built";
  for (const Result& r : results) ASSERT_TRUE(r.ok()) << r.method << ": " << r.reason;
  ASSERT_EQ(results[0].method, "analytic");
  const Tolerances tol = LoadTolerances(m.name);
  // `run`'s judgement of the engine's motion: inside its bounds.
  const MotionError e = CompareMotion(m, results[0].trajectory, results[1].trajectory);
  const Agreement a = tol.For(results[1].method);
  ASSERT_LE(e.q.max, a.q);
  ASSERT_LE(e.qd.max, a.qd);
  int timed = 0;
  for (const BookCheck& row : CheckBook(m, results, nullptr, &tol)) {
    SCOPED_TRACE(row.book.quantity);
    EXPECT_TRUE(row.methods_agree) << (row.outside.empty() ? "" : row.outside[0]);
    if (!row.book.AtTime()) continue;
    ++timed;
    EXPECT_EQ(row.verdict, Verdict::kAgrees);
    // The engine's value differs from the closed form by more than the exact methods' 1e-9.
    ASSERT_TRUE(row.computed[0].second && row.computed[1].second);
    EXPECT_GT(std::fabs(*row.computed[1].second - *row.computed[0].second), 1e-9 * std::fabs(row.book.value));
  }
  EXPECT_EQ(timed, 2);
  // Held to 1e-9 (no tolerances), the same values disagree: the bound above is what decides.
  const std::vector<BookCheck> exact = CheckBook(m, results);
  EXPECT_TRUE(std::any_of(exact.begin(), exact.end(), [](const BookCheck& row) { return !row.methods_agree; }));
  // A method outside its bound is still flagged: the same claim held to a tenth of the engine's
  // own q error.
  Tolerances tight = tol;
  Agreement t = a;
  t.q = e.q.max / 10;
  t.qd = e.qd.max / 10;
  tight.methods[results[1].method] = t;
  const std::vector<BookCheck> strict = CheckBook(m, results, nullptr, &tight);
  int flagged = 0;
  for (const BookCheck& row : strict)
    if (row.book.AtTime()) {
      flagged += !row.methods_agree;
      for (const std::string& o : row.outside) {
        // The value as the column prints it (10 significant digits), not rounded to 6.
        EXPECT_EQ(o.find(results[1].method + " " + Fmt(*row.computed[1].second, 10) + " "), 0u) << o;
      }
    }
  EXPECT_EQ(flagged, 2);
}

}  // namespace
}  // namespace harness_book_test
}  // namespace mechbench::harness
