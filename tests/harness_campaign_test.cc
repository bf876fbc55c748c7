// The campaign behind `mechbench sweep | stress | report`: cases, process isolation, outcomes.
#include "mechbench/harness/campaign.h"
#include "mechbench/harness/chains.h"
#include "mechbench/format.h"
#include "mechbench/harness/compare.h"
#include "mechbench/harness/registry.h"
#include "mechbench/harness/tolerances.h"
#include "mechbench/loader.h"
#include "mechbench/references/nfourbar.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <map>
#include <set>
#include <thread>

namespace mechbench::harness {
namespace harness_campaign_test {  // this file's own names (the tests build in unity batches)
namespace {

using nlohmann::json;

bool Has(const std::string& method) {
  for (const MethodPtr& m : AllMethods())
    if (m->name() == method) return true;
  return false;
}

// The records of the cases whose id starts with `prefix`, run in worker processes.
std::vector<json> RunOnly(CampaignOptions o, const std::string& prefix) {
  o.progress = false;
  std::vector<Case> mine;
  for (const Case& c : EnumerateCases(o))
    if (c.id.rfind(prefix, 0) == 0) mine.push_back(c);
  EXPECT_FALSE(mine.empty()) << "no case " << prefix;
  return ExecuteCases(mine, o);
}

TEST(RunIsolated, ReturnsTheChildsValue) {
  const json j = RunIsolated([] { return json{{"answer", 42}}; }, 10);
  EXPECT_EQ(j.value("answer", 0), 42);
}

TEST(RunIsolated, AnAbortIsACrashNotTheEndOfTheRun) {
  const json j = RunIsolated([]() -> json { std::abort(); }, 10);
  EXPECT_EQ(j.value("isolation", ""), "crashed");
  EXPECT_NE(j.value("detail", "").find("signal 6"), std::string::npos) << j.dump();
}

TEST(RunIsolated, AHangIsKilledAtTheTimeLimit) {
  const auto t0 = std::chrono::steady_clock::now();
  const json j = RunIsolated(
      []() -> json {
        for (;;) std::this_thread::sleep_for(std::chrono::milliseconds(10));
      },
      0.3);
  EXPECT_EQ(j.value("isolation", ""), "timed_out");
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 5.0);
}

TEST(Campaign, CasesAreDeterministicAndShardsPartitionThem) {
  CampaignOptions o;
  o.quick = true;
  const std::vector<Case> all = EnumerateCases(o), again = EnumerateCases(o);
  ASSERT_EQ(all.size(), again.size());
  std::set<std::string> ids;
  for (size_t i = 0; i < all.size(); ++i) {
    EXPECT_EQ(all[i].id, again[i].id);
    EXPECT_EQ(all[i].index, static_cast<int>(i));
    EXPECT_TRUE(ids.insert(all[i].id).second) << "duplicate case id " << all[i].id;
  }
  std::set<std::string> union_ids;
  size_t total = 0;
  for (int k = 1; k <= 3; ++k) {
    o.shard = k;
    o.shards = 3;
    for (const Case& c : EnumerateCases(o)) {
      EXPECT_EQ(c.index % 3, k - 1);
      union_ids.insert(c.id);
      ++total;
    }
  }
  EXPECT_EQ(total, all.size());
  EXPECT_EQ(union_ids, ids);
}

TEST(Campaign, IsolationDoesNotChangeResults) {
  if (!Has("ode-worldstep-default")) GTEST_SKIP() << "built without ODE";
  CampaignOptions o;
  o.scenarios = {"fourbar_free"};
  o.methods = {"dyn-baumgarte-rk4", "ode-worldstep-default"};
  o.quick = true;
  o.stress = false;
  o.progress = false;
  const std::vector<Case> cases = EnumerateCases(o);
  o.isolate = true;
  o.jobs = 2;
  const std::vector<json> forked = ExecuteCases(cases, o);
  o.isolate = false;
  const std::vector<json> inproc = ExecuteCases(cases, o);
  ASSERT_EQ(forked.size(), inproc.size());
  for (size_t i = 0; i < forked.size(); ++i) {
    EXPECT_EQ(forked[i]["id"], inproc[i]["id"]);
    EXPECT_EQ(forked[i].value("status", ""), inproc[i].value("status", ""));
    if (forked[i].contains("error")) {
      EXPECT_EQ(forked[i]["error"], inproc[i]["error"]) << forked[i]["id"];
    }
  }
}

// A sweep honours the rung: the value used is the rung, and a first-order engine's error halves
// with the step.
TEST(Campaign, SweepRungsFollowTheirStep) {
  if (!Has("ode-worldstep-default")) GTEST_SKIP() << "built without ODE";
  CampaignOptions o;
  o.scenarios = {"fourbar_free"};
  o.methods = {"ode-worldstep-default"};
  o.quick = true;
  o.check = o.run = o.stress = false;
  const std::vector<json> rungs = RunOnly(o, "sweep/");
  ASSERT_EQ(rungs.size(), 3u);  // quick ladder: 4, 2, 1 ms
  for (size_t i = 0; i < rungs.size(); ++i) {
    EXPECT_EQ(rungs[i]["status"], "ok");
    EXPECT_NEAR(rungs[i]["value"].get<double>(), 4e-3 / (1 << i), 1e-15);
  }
  // Measured: q_max 4.8e-3, 3.0e-3, 1.5e-3 (first order, not yet asymptotic at 4 ms).
  const double e2 = rungs[1]["error"]["q_max"], e1 = rungs[2]["error"]["q_max"];
  EXPECT_NEAR(std::log2(e2 / e1), 1.0, 0.2);
}

// An observed order only for a fixed-step method: an error-controlled one's rungs vary its
// tolerance, and `derived` gives its error's slope against that instead (no "order 0.00").
TEST(Campaign, OrderForFixedStepsSlopeAgainstTheToleranceOtherwise) {
  CampaignOptions o;
  o.scenarios = {"fourbar_free"};
  o.methods = {"dyn-baumgarte-rk4", "dyn-baumgarte-dopri5"};
  o.quick = true;
  o.check = o.run = o.stress = false;
  const std::vector<json> rungs = RunOnly(o, "sweep/");
  // The least-squares slope of log q_max against log control over a method's rungs.
  const auto slope = [&](const std::string& method, const std::string& control) {
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    int n = 0;
    for (const json& r : rungs) {
      if (r["method"] != method) continue;
      EXPECT_EQ(r["control"], control);
      EXPECT_EQ(r["status"], "ok");
      const double x = std::log(r["value"].get<double>()), y = std::log(r["error"]["q_max"].get<double>());
      sx += x, sy += y, sxx += x * x, sxy += x * y, ++n;
    }
    EXPECT_GE(n, 2) << method;
    return (n * sxy - sx * sy) / (n * sxx - sx * sx);
  };
  const double p_rk4 = slope("dyn-baumgarte-rk4", "step"), s_dopri = slope("dyn-baumgarte-dopri5", "tolerance");
  const json results = Assemble(rungs, o);
  int seen = 0;
  for (const json& d : results["derived"]) {
    SCOPED_TRACE(d.dump());
    if (d["method"] == "dyn-baumgarte-rk4") {
      ASSERT_TRUE(d["order"].is_number());
      EXPECT_NEAR(d["order"].get<double>(), p_rk4, 1e-9);
      EXPECT_TRUE(d["tolerance_slope"].is_null());
      ++seen;
    } else if (d["method"] == "dyn-baumgarte-dopri5") {
      EXPECT_TRUE(d["order"].is_null());
      ASSERT_TRUE(d["tolerance_slope"].is_number());
      EXPECT_NEAR(d["tolerance_slope"].get<double>(), s_dopri, 1e-9);
      ++seen;
    }
  }
  EXPECT_EQ(seen, 2);
  if (std::getenv("MECHBENCH_VERBOSE")) std::printf("rk4 order %.3f, dopri5 slope against the tolerance %.3f\n", p_rk4, s_dopri);
}

// A stress case whose engine fails yields its outcome and the rest of the run goes on.
TEST(Campaign, StressOutcomesAreRowsNotFailures) {
  if (!Has("ode-worldstep-default")) GTEST_SKIP() << "built without ODE";
  CampaignOptions o;
  o.scenarios = {"fourbar_crank_rocker"};
  o.methods = {"analytic", "ode-worldstep-default"};
  o.check = o.run = o.sweep = false;
  const std::vector<json> rows = RunOnly(o, "stress/fourbar_crank_rocker/");
  std::map<std::string, std::string> outcome;
  for (const json& r : rows) outcome[r["case"].get<std::string>() + "/" + r["method"].get<std::string>()] = r["outcome"];
  // At the change point the closed form has no continuation past θ = 180° (the loop's two paths
  // are tangent): locked up; ODE's momentum carries the rocker on, into the other assembly.
  EXPECT_EQ(outcome["change_point/analytic"], "locked_up");
  EXPECT_EQ(outcome["change_point/ode-worldstep-default"], "branch_switched");
  // At 10,000 rpm ODE's joints cannot hold the loop (scaled ‖Φ‖ 1.1e-2 within 0.3 ms).
  EXPECT_EQ(outcome["input_speed=10000rpm/ode-worldstep-default"], "loop_opened");
  EXPECT_EQ(outcome["input_speed=10000rpm/analytic"], "ok");
  for (const json& r : rows) {
    if (r["outcome"] == "loop_opened" || r["outcome"] == "locked_up") {
      EXPECT_TRUE(r["t_fail"].is_number()) << r.dump();
    }
  }
}

// A stand-in for an engine that blows up at t = 0.5 s: it follows the exact motion, then NaN.
class BlowsUp final : public Method {
 public:
  BlowsUp() : Method("blows-up", "follows the analytic motion, then NaN from t = 0.5 s") {}
  std::optional<std::string> Applicability(const Model&) const override { return std::nullopt; }
  Control control() const override { return Control::kStep; }

 protected:
  void DoRun(const Model& model, const RunOptions&, Result& result) const override {
    for (const MethodPtr& m : AllMethods())
      if (m->name() == "analytic") result.trajectory = m->Run(model).trajectory;
    for (Sample& s : result.trajectory)
      if (s.t >= 0.5) s.q.setConstant(std::numeric_limits<double>::quiet_NaN());
  }
};

TEST(Campaign, AnEngineThatBlowsUpIsDivergedWithTheTime) {
  const Model m = LoadScenario(ResolveScenario("fourbar_crank_rocker"));
  std::vector<Sample> exact;
  for (const MethodPtr& meth : AllMethods())
    if (meth->name() == "analytic") exact = meth->Run(m).trajectory;
  const Result r = BlowsUp().Run(m);
  ASSERT_EQ(r.status, Status::kDiverged);  // Method::Run turns non-finite values into a status
  const StressOutcome o = ClassifyRun(m, r, exact, 1e-2);
  EXPECT_EQ(o.outcome, "diverged") << o.detail;
  EXPECT_NEAR(o.t_fail, 0.5, 1.0 / 72) << o.detail;
  // The same motion without the blow-up is judged ok against the same reference.
  Result fine = r;
  fine.status = Status::kOk;
  fine.trajectory = exact;
  EXPECT_EQ(ClassifyRun(m, fine, exact, 1e-2).outcome, "ok");
}

// A CPU budget stops a slow run as a row: status over-budget with the time it reached, its samples
// kept and judged up to there, and the campaign's outcome timed_out. A step of 1 µs over the free
// four-bar's 1 s would take seconds; the budget is 50 ms.
TEST(Budget, ASlowRunStopsAsARowWithTheTimeItReached) {
  const Model m = LoadScenario(ResolveScenario("fourbar_free"));
  RunOptions o;
  o.step = 1e-6;
  o.cpu_budget = 0.05;
  int checked = 0;
  for (const MethodPtr& meth : AllMethods()) {
    if (meth->control() != Control::kStep || meth->Applicability(m)) continue;
    SCOPED_TRACE(meth->name());
    const Result r = meth->Run(m, o);
    ASSERT_EQ(r.status, Status::kOverBudget) << r.reason;
    ASSERT_FALSE(r.trajectory.empty());
    EXPECT_LT(r.trajectory.size(), static_cast<size_t>(m.analysis.samples));
    EXPECT_NE(r.reason.find("budget"), std::string::npos) << r.reason;
    EXPECT_NE(r.reason.find(Fmt(r.trajectory.back().t, 4) + " s of 1 s"), std::string::npos) << r.reason;
    const StressOutcome out = ClassifyRun(m, r, {}, 1e-3);
    EXPECT_EQ(out.outcome, "timed_out") << out.detail;
    EXPECT_DOUBLE_EQ(out.t_fail, std::stod(Fmt(r.trajectory.back().t, 4)));
    ++checked;
  }
  EXPECT_GE(checked, 2);  // RK4 and ALI3-P at least; each engine variant with a step when built
}

TEST(Budget, RunJudgesAnOverBudgetRunUpToWhereItGot) {
  const Model m = LoadScenario(ResolveScenario("fourbar_free"));
  std::vector<MethodPtr> methods;
  for (MethodPtr& meth : AllMethods())
    if (meth->name() == "dyn-ali3p") methods.push_back(std::move(meth));
  ASSERT_EQ(methods.size(), 1u);
  RunOptions o;
  o.step = 1e-6;  // ALI3-P at 1 µs: accurate, and far too slow for the budget
  // The smallest budget (doubling from 0.05 s) in which it gets past a few samples on this machine
  // and build (a sanitizer build is several times slower).
  RunReport rep;
  for (o.cpu_budget = 0.05; o.cpu_budget < 5; o.cpu_budget *= 2) {
    rep = RunScenario(m, methods, o, LoadTolerances(m.name));
    if (rep.results[0].trajectory.size() >= 3) break;
  }
  ASSERT_EQ(rep.results[0].status, Status::kOverBudget);
  ASSERT_GE(rep.results[0].trajectory.size(), 3u);
  ASSERT_EQ(rep.free.size(), 1u);
  const FreeComparison& c = rep.free[0];
  EXPECT_EQ(c.reached_t, rep.results[0].trajectory.back().t);
  EXPECT_TRUE(c.problem.empty()) << c.problem;
  EXPECT_LT(c.position, 1e-5);  // measured 2.9e-7 (ALI3-P's Newton tolerance, not its step, limits it)
  EXPECT_TRUE(c.within);
  EXPECT_TRUE(std::isnan(c.first_outside_t));
  EXPECT_LT(c.energy_drift, 1e-4);  // measured 4.9e-6 J
  EXPECT_TRUE(rep.ok) << (rep.problems.empty() ? "" : rep.problems[0]);  // stopping on a budget is no disagreement
}

// run compares each method's joint reactions at t0 with the first method that gives them: the
// formulations share one index-1 solution at t0, so theirs agree to the bit.
TEST(RunReactions, EachMethodAgainstTheFirstThatReportsThem) {
  const Model m = LoadScenario(ResolveScenario("fourbar_free"));
  std::vector<MethodPtr> methods;
  for (MethodPtr& meth : AllMethods())
    if (meth->name() == "analytic" || meth->name() == "dyn-baumgarte-rk4" || meth->name() == "dyn-ali3p")
      methods.push_back(std::move(meth));
  ASSERT_EQ(methods.size(), 3u);
  const RunReport rep = RunScenario(m, methods, {.motion = false}, LoadTolerances(m.name));
  ASSERT_EQ(rep.reactions.size(), 1u);  // analytic gives none
  EXPECT_EQ(rep.reactions[0].reference, "dyn-baumgarte-rk4");
  EXPECT_EQ(rep.reactions[0].method, "dyn-ali3p");
  EXPECT_EQ(rep.reactions[0].components, 12);  // pins A, 1, 2, B: two bodies each at 1 and 2
  EXPECT_EQ(rep.reactions[0].relative, 0.0);
}

// A point-mass pendulum released at the horizontal falls freely at t0: every reaction is zero, and
// methods that agree to round-off (1e-16 N) must not read as "1e+288 of the largest": reactions are
// judged against a thousandth of the scene's weight where they vanish.
TEST(RunReactions, VanishingReactionsAreJudgedAgainstTheScenesWeight) {
  const Model m = LoadScenario(std::string(MECHBENCH_TEST_DATA) + "/scenes/pendulum_horizontal.yaml");
  std::vector<MethodPtr> methods;
  for (MethodPtr& meth : AllMethods())
    if (meth->name() == "dyn-baumgarte-rk4" || meth->name() == "dyn-ali3p" || meth->name() == "simbody-rkmerson-default" ||
        meth->name() == "ode-worldstep-default")
      methods.push_back(std::move(meth));
  const RunReport rep = RunScenario(m, methods, {.motion = false}, LoadTolerances(m.name));
  ASSERT_FALSE(rep.reactions.empty());
  for (const ReactionComparison& c : rep.reactions) {
    SCOPED_TRACE(c.method);
    EXPECT_EQ(c.components, 2);
    EXPECT_LT(c.absolute, 1e-12);                // [N]: round-off
    EXPECT_LT(c.relative, 1e-12 / (1e-3 * 9.81));  // against 1e-3 × 1 kg × 9.81 m/s²
  }
}

// A case whose process aborts or hangs (an engine's assert, an endless solver loop) is a row
// with that outcome, and every other case still reports.
TEST(Campaign, AnAbortingOrHangingCaseIsARow) {
  CampaignOptions o;
  o.scenarios = {"fourbar_crank_rocker"};
  o.methods = {"analytic", "numeric"};
  o.check = o.run = o.sweep = false;
  o.timeout = 2;
  o.progress = false;
  o.jobs = 2;
  std::vector<Case> cases;
  for (const Case& c : EnumerateCases(o))
    if (c.variant == "change_point" || c.variant == "toggle=1e-3") cases.push_back(c);
  ASSERT_EQ(cases.size(), 4u);
  ::setenv("MECHBENCH_FAULT", ("abort:" + cases[0].id).c_str(), 1);
  std::vector<json> rows = ExecuteCases(cases, o);
  ::setenv("MECHBENCH_FAULT", ("hang:" + cases[1].id).c_str(), 1);
  const std::vector<json> hung = ExecuteCases(cases, o);
  ::unsetenv("MECHBENCH_FAULT");
  ASSERT_EQ(rows.size(), 4u);
  ASSERT_EQ(hung.size(), 4u);
  EXPECT_EQ(rows[0]["outcome"], "crashed") << rows[0].dump();
  EXPECT_NE(rows[0]["detail"].get<std::string>().find("signal 6"), std::string::npos);
  EXPECT_EQ(hung[1]["outcome"], "timed_out") << hung[1].dump();
  EXPECT_EQ(rows[1]["outcome"], hung[0]["outcome"]);  // the others as usual
  for (size_t i = 2; i < 4; ++i) EXPECT_EQ(rows[i]["outcome"], hung[i]["outcome"]);
  for (const json& r : rows) EXPECT_EQ(r["kind"], "stress");
}

// A method's sweep rungs share one process; a rung that aborts or hangs in the middle of that
// batch is its own row, and the rungs after it still run, in a new process, with the same results.
TEST(Campaign, ARungThatAbortsOrHangsInABatchIsARowAndTheRestRun) {
  CampaignOptions o;
  o.scenarios = {"fourbar_free"};
  o.methods = {"dyn-baumgarte-rk4"};
  o.quick = true;
  o.check = o.run = o.stress = o.precision = false;
  o.timeout = 5;
  o.progress = false;
  o.jobs = 1;
  std::vector<Case> cases;
  for (const Case& c : EnumerateCases(o))
    if (c.kind == "sweep") cases.push_back(c);
  ASSERT_EQ(cases.size(), 3u);  // the quick ladder: 4, 2, 1 ms
  const std::vector<json> clean = ExecuteCases(cases, o);
  ::setenv("MECHBENCH_FAULT", ("abort:" + cases[1].id).c_str(), 1);
  const std::vector<json> aborted = ExecuteCases(cases, o);
  ::setenv("MECHBENCH_FAULT", ("hang:" + cases[1].id).c_str(), 1);
  const std::vector<json> hung = ExecuteCases(cases, o);
  ::unsetenv("MECHBENCH_FAULT");
  ASSERT_EQ(clean.size(), 3u);
  ASSERT_EQ(aborted.size(), 3u);
  ASSERT_EQ(hung.size(), 3u);
  for (const json& r : clean) EXPECT_EQ(r["status"], "ok") << r.dump();
  EXPECT_EQ(aborted[1]["status"], "crashed") << aborted[1].dump();
  EXPECT_NE(aborted[1]["reason"].get<std::string>().find("signal 6"), std::string::npos) << aborted[1].dump();
  EXPECT_EQ(hung[1]["status"], "timed_out") << hung[1].dump();
  for (const std::vector<json>* rows : {&aborted, &hung}) {
    for (size_t i : {size_t{0}, size_t{2}}) {
      EXPECT_EQ((*rows)[i]["status"], "ok") << (*rows)[i].dump();
      EXPECT_EQ((*rows)[i]["error"]["q_max"], clean[i]["error"]["q_max"]);  // the same run, whichever process
    }
  }
}

// Simbody's default and tuned variants at one swept accuracy are one computation (Method::
// Computation): the campaign runs each rung once for both, and the second variant's record says
// so and holds what a run of its own gives.
TEST(Campaign, OneComputationOfTwoVariantsIsRunOnceForBoth) {
  if (!Has("simbody-rkmerson-default")) GTEST_SKIP() << "built without Simbody";
  CampaignOptions o;
  o.scenarios = {"fourbar_free"};
  o.methods = {"simbody-rkmerson-default", "simbody-rkmerson-tuned"};
  o.quick = true;
  o.check = o.run = o.stress = o.precision = false;
  o.progress = false;
  o.jobs = 1;
  std::vector<Case> both, tuned;
  for (const Case& c : EnumerateCases(o))
    if (c.kind == "sweep") {
      both.push_back(c);
      if (c.method == "simbody-rkmerson-tuned") tuned.push_back(c);
    }
  ASSERT_FALSE(tuned.empty());
  const std::vector<json> shared = ExecuteCases(both, o);
  const std::vector<json> alone = ExecuteCases(tuned, o);
  std::map<double, std::vector<json>> by_value;
  for (const json& r : shared) by_value[r["value"].get<double>()].push_back(r);
  ASSERT_EQ(by_value.size(), tuned.size());
  for (const auto& [value, rows] : by_value) {
    ASSERT_EQ(rows.size(), 2u) << value;
    const json& second = rows[0].contains("shared_with") ? rows[0] : rows[1];
    const json& first = rows[0].contains("shared_with") ? rows[1] : rows[0];
    ASSERT_TRUE(second.contains("shared_with")) << "accuracy " << value << ": neither record shared its run";
    EXPECT_FALSE(first.contains("shared_with"));
    EXPECT_EQ(second["shared_with"], first["method"]);
    EXPECT_EQ(second["error"]["q_max"], first["error"]["q_max"]);
    EXPECT_EQ(second["cpu_seconds"], first["cpu_seconds"]);  // the one run's time, not a second's
  }
  for (const json& r : alone) {
    EXPECT_FALSE(r.contains("shared_with")) << r.dump();
    const double v = r["value"].get<double>();
    EXPECT_EQ(r["error"]["q_max"], by_value[v][0]["error"]["q_max"]) << "accuracy " << v << ": a run of its own differs";
  }
  // In `derived`, a level reached by a shared rung names the method whose run it is (the report
  // marks that cell "(X's run)"), and only there: the run is measured once, shown twice.
  const json results = Assemble(shared, o);
  int marked = 0;
  for (const json& d : results["derived"])
    for (const char* level : {"1e-3", "1e-6"}) {
      const std::string key = std::string("shared_at_") + level;
      // The rung behind the level: the cheapest whose q error is within it (Assemble's rule).
      const json* rung = nullptr;
      for (const json& r : shared)
        if (r["method"] == d["method"] && r["status"] == "ok" && r["error"]["q_max"].get<double>() <= std::stod(level) &&
            (!rung || r["cpu"]["integration"].get<double>() < (*rung)["cpu"]["integration"].get<double>()))
          rung = &r;
      SCOPED_TRACE(d.dump());
      if (rung && rung->contains("shared_with")) {
        ASSERT_TRUE(d.contains(key));
        EXPECT_EQ(d[key], (*rung)["shared_with"]);
        ++marked;
      } else {
        EXPECT_FALSE(d.contains(key));
      }
    }
  EXPECT_GT(marked, 0);
}

// Every step method gets a largest stable step, and the search brackets it.
TEST(Campaign, StableStepIsBracketed) {
  if (!Has("ode-worldstep-default")) GTEST_SKIP() << "built without ODE";
  CampaignOptions o;
  o.scenarios = {"fourbar_free"};
  o.methods = {"ode-worldstep-default"};
  o.check = o.run = o.sweep = false;
  const std::vector<json> rows = RunOnly(o, "stable_step/");
  ASSERT_EQ(rows.size(), 1u);
  const json& r = rows[0];
  ASSERT_TRUE(r["largest_stable"].is_number()) << r.dump();
  ASSERT_TRUE(r["first_unstable"].is_number()) << r.dump();
  EXPECT_LT(r["largest_stable"].get<double>(), r["first_unstable"].get<double>());
  bool saw_stable = false, saw_unstable = false;
  for (const json& t : r["tried"]) (t["stable"].get<bool>() ? saw_stable : saw_unstable) = true;
  EXPECT_TRUE(saw_stable && saw_unstable);
}

// A benchmark's precision levels: the method walks its ladder coarse to fine, each rung judged by
// the benchmark's own criteria against the exact reference; the cheapest rung meeting a level is
// the one reported, its error within the level, and the walk stops once every level is met.
TEST(Campaign, PrecisionFindsTheCheapestRunMeetingEachLevel) {
  CampaignOptions o;
  o.scenarios = {std::string(MECHBENCH_TEST_DATA) + "/scenes/pendulum_criteria_short.yaml"};
  o.methods = {"dyn-baumgarte-rk4", "numeric"};
  o.check = o.run = o.sweep = o.stress = false;
  o.repeats = 1;
  const std::vector<json> rows = RunOnly(o, "precision/");
  ASSERT_EQ(rows.size(), 1u) << "a kinematic method has no precision case on a free scene";
  const json& r = rows[0];
  ASSERT_EQ(r["status"], "ok") << r.dump();
  ASSERT_EQ(r["levels"].size(), 2u);
  ASSERT_EQ(r["met"].size(), 2u);
  const json& rungs = r["rungs"];
  ASSERT_GE(rungs.size(), 2u);
  for (size_t k = 1; k < rungs.size(); ++k) EXPECT_LT(rungs[k]["value"].get<double>(), rungs[k - 1]["value"].get<double>());
  // Every level is met (RK4 reaches 1e-8 m over 4 s at about 2 ms), and the walk ended there.
  const json& last = rungs.back();
  EXPECT_LE(last["error"].get<double>(), 1e-8) << last.dump();
  for (size_t k = 0; k + 1 < rungs.size(); ++k) EXPECT_GT(rungs[k]["error"].get<double>(), 1e-8) << rungs[k].dump();
  for (size_t l = 0; l < 2; ++l) {
    const json& met = r["met"][l];
    ASSERT_TRUE(met.is_object()) << r.dump();
    EXPECT_LE(met["error"].get<double>(), r["levels"][l].get<double>());
    EXPECT_GT(met["cpu_seconds"].get<double>(), 0.0);
    // The cheapest: no rung coarser than it meets the level.
    for (const json& g : rungs) {
      if (g["value"].get<double>() > met["value"].get<double>()) {
        EXPECT_GT(g["error"].get<double>(), r["levels"][l].get<double>());
      }
    }
  }
  // The coarse level is met on a coarser rung than the fine one.
  EXPECT_GT(r["met"][1]["value"].get<double>(), r["met"][0]["value"].get<double>());
}

// A caller's watch on the motion (RunOptions::watch) stops every kind of integrating method at
// the sample it names: status "stopped" with the watch's words, the samples up to it kept.
TEST(RunOptions, WatchStopsEveryIntegratingMethodAtTheSampleItNames) {
  const Model m = LoadScenario(ResolveScenario("fourbar_free"));
  const double t_stop = m.analysis.TimeAt(30);
  int tried = 0;
  for (const MethodPtr& meth : AllMethods()) {
    if (meth->control() == Control::kNone || meth->Applicability(m)) continue;
    RunOptions o;
    int seen = 0;
    o.watch = [&](const Sample& s) -> std::optional<std::string> {
      ++seen;
      if (s.t < t_stop - 1e-12) return std::nullopt;
      return std::string("the test's watch saw t = ") + std::to_string(s.t);
    };
    const Result r = meth->Run(m, o);
    SCOPED_TRACE(meth->name());
    EXPECT_EQ(r.status, Status::kStopped) << r.reason;
    EXPECT_NE(r.reason.find("the test's watch saw"), std::string::npos) << r.reason;
    ASSERT_FALSE(r.trajectory.empty());
    EXPECT_NEAR(r.trajectory.back().t, t_stop, 1e-9);
    EXPECT_EQ(seen, 31) << "each sample watched once, up to the one that stopped the run";
    ++tried;
  }
  EXPECT_GE(tried, 4) << "the numeric formulations at least";
}

// A rung of a precision walk stops where the benchmark's point first passes the loosest level:
// no level can be met after that, so the rest of that run is not paid for.
TEST(Campaign, PrecisionStopsARungWhereItsPointPassesTheLoosestLevel) {
  CampaignOptions o;
  o.scenarios = {std::string(MECHBENCH_TEST_DATA) + "/scenes/pendulum_criteria_short.yaml"};
  o.methods = {"dyn-ali3p"};
  o.check = o.run = o.sweep = o.stress = false;
  o.repeats = 1;
  const std::vector<json> rows = RunOnly(o, "precision/");
  ASSERT_EQ(rows.size(), 1u);
  const json& r = rows[0];
  ASSERT_EQ(r["status"], "ok") << r.dump();
  int stopped = 0;
  for (const json& g : r["rungs"]) {
    if (g["status"] != "stopped") continue;
    ++stopped;
    EXPECT_GT(g["error"].get<double>(), 1e-4) << g.dump();
    EXPECT_LT(g["t"].get<double>(), 4.0) << g.dump();
    EXPECT_FALSE(g["complete"].get<bool>());
    EXPECT_NE(g["reason"].get<std::string>().find("loosest level"), std::string::npos) << g.dump();
  }
  EXPECT_GE(stopped, 1) << "ALI3-P's coarse rungs pass 1e-4 m before 4 s: " << r["rungs"].dump();
}

// Coordinate partitioning stops at the N-four-bar's singular position (t ≈ 0.72 s) whatever its
// tolerance: after three tolerances that diverge before the same sample the walk ends there.
TEST(Campaign, PrecisionEndsWhereEveryToleranceDivergesAtTheSameSample) {
  CampaignOptions o;
  o.scenarios = {std::string(MECHBENCH_TEST_DATA) + "/scenes/nfourbar_2_criteria.yaml"};
  o.methods = {"dyn-coordinate-partitioning"};
  o.check = o.run = o.sweep = o.stress = false;
  o.repeats = 1;
  const std::vector<json> rows = RunOnly(o, "precision/");
  ASSERT_EQ(rows.size(), 1u);
  const json& r = rows[0];
  ASSERT_EQ(r["status"], "ok") << r.dump();
  ASSERT_EQ(r["rungs"].size(), 3u) << r.dump();
  for (const json& g : r["rungs"]) {
    EXPECT_EQ(g["status"], "diverged") << g.dump();
    EXPECT_NE(g["reason"].get<std::string>().find("loses rank"), std::string::npos) << g.dump();
  }
  EXPECT_NE(r["stop"].get<std::string>().find("diverged before the same sample"), std::string::npos) << r["stop"];
  for (const json& m : r["met"]) EXPECT_TRUE(m.is_null());
}

// A method that cannot do the scene gets a precision row with its reason, and no rungs (the
// engines decline a link without mass).
TEST(Campaign, PrecisionRowOfAMethodThatCannotGivesTheReason) {
  if (!Has("ode-worldstep-default")) GTEST_SKIP() << "built without ODE";
  CampaignOptions o;
  o.scenarios = {std::string(MECHBENCH_TEST_DATA) + "/scenes/massless_coupler_criteria.yaml"};
  o.methods = {"ode-worldstep-default"};
  o.check = o.run = o.sweep = o.stress = false;
  const std::vector<json> rows = RunOnly(o, "precision/");
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0]["status"], "not-applicable") << rows[0].dump();
  EXPECT_NE(rows[0]["reason"].get<std::string>().find("body coupler has mass 0"), std::string::npos) << rows[0].dump();
  EXPECT_TRUE(rows[0]["rungs"].empty());
  ASSERT_EQ(rows[0]["met"].size(), 2u);
  for (const json& m : rows[0]["met"]) EXPECT_TRUE(m.is_null());
}

// ---- long chains (chains.h) --------------------------------------------------------------------

// The chains run only in a full report of the built-in selection: not under --quick, not when
// scenarios are named, not with chains off; one case per integrating method, none for the
// kinematic ones.
TEST(Chains, OneCasePerIntegratingMethodInTheFullReportOnly) {
  CampaignOptions o;
  o.check = o.run = o.sweep = o.stress = o.precision = false;
  o.methods = {"numeric", "dyn-ali3p", "dyn-baumgarte-rk4"};
  std::vector<Case> cases = EnumerateCases(o);
  ASSERT_EQ(cases.size(), 2u);
  EXPECT_EQ((std::set<std::string>{cases[0].id, cases[1].id}),
            (std::set<std::string>{"chain/nfourbar/dyn-ali3p", "chain/nfourbar/dyn-baumgarte-rk4"}));
  EXPECT_EQ(cases[1].kind, "chain");
  o.quick = true;
  EXPECT_TRUE(EnumerateCases(o).empty());
  o.quick = false;
  o.scenarios = {"fourbar_free"};
  EXPECT_TRUE(EnumerateCases(o).empty());
  o.scenarios.clear();
  o.chains = false;
  EXPECT_TRUE(EnumerateCases(o).empty());
}

// On a tiny ladder (N = 1, 3): a rung per N with the run's figures, each judged against the exact
// motion; a formulation follows it closely, every method keeps the loop closed, and the growth
// exponent is the slope through the rungs' own costs.
TEST(Chains, RungsAreJudgedAgainstTheExactMotionAndFitted) {
  CampaignOptions o;
  o.check = o.run = o.sweep = o.stress = o.precision = false;
  o.chain_ladder = {1, 3};
  o.chain_budget = 5;
  o.methods = {"dyn-baumgarte-rk4", "dyn-ali3p"};
  for (const char* engine : {"mujoco-euler-default", "ode-quickstep-default"})
    if (Has(engine)) o.methods.push_back(engine);
  const std::vector<json> rows = RunOnly(o, "chain/");
  ASSERT_EQ(rows.size(), o.methods.size());
  const ChainPlan plan = ChainPlanFor(o);
  for (const json& r : rows) {
    SCOPED_TRACE(r.dump());
    EXPECT_EQ(r["kind"], "chain");
    EXPECT_EQ(r["status"], "ok");
    EXPECT_EQ(r["stop"], "ladder_end");
    ASSERT_EQ(r["rungs"].size(), 2u);
    std::vector<std::pair<double, double>> fit;
    double cpu = 0;
    for (size_t k = 0; k < 2; ++k) {
      const json& g = r["rungs"][k];
      const int n = o.chain_ladder[k];
      EXPECT_EQ(g["n"], n);
      EXPECT_EQ(g["coordinates"].get<size_t>(), references::NFourBar({.n = n, .t1 = plan.t1, .samples = plan.samples}).q_layout.size());
      EXPECT_EQ(g["status"], "ok");
      ASSERT_TRUE(g["steps"].is_number() && g["steps"].get<long>() > 0);
      EXPECT_NEAR(g["step_us"].get<double>(), 1e6 * g["integration"].get<double>() / g["steps"].get<double>(), 1e-9);
      EXPECT_NEAR(g["reached_t"].get<double>(), plan.t1, 1e-12);
      ASSERT_TRUE(g["error"].is_number());
      EXPECT_LT(g["error"].get<double>(), plan.lost_error);
      EXPECT_LT(g["max_residual"].get<double>(), plan.lost_residual);
      if (r["method"].get<std::string>().rfind("dyn-", 0) == 0) {
        EXPECT_LT(g["error"].get<double>(), 1e-5);
      }
      fit.emplace_back(n, g["integration"].get<double>() / g["reached_t"].get<double>());
      cpu += g["cpu_seconds"].get<double>();
    }
    // Fewer than two rungs from N = 10 on: every rung is fitted.
    EXPECT_EQ(r["exponent_points"], 2);
    ASSERT_TRUE(r["exponent"].is_number());
    EXPECT_NEAR(r["exponent"].get<double>(), std::log(fit[1].second / fit[0].second) / std::log(3.0), 1e-9);
    EXPECT_NEAR(r["cpu_seconds"].get<double>(), cpu, 1e-12);
  }
}

// A spent budget ends the ladder as a row that says so, with the rung it stopped and the time
// that rung reached.
TEST(Chains, ASpentBudgetEndsTheLadderWithWhy) {
  CampaignOptions o;
  o.check = o.run = o.sweep = o.stress = o.precision = false;
  o.chain_ladder = {1, 3};
  o.chain_budget = 1e-9;
  o.methods = {"dyn-baumgarte-rk4"};
  const std::vector<json> rows = RunOnly(o, "chain/");
  ASSERT_EQ(rows.size(), 1u);
  const json& r = rows[0];
  EXPECT_EQ(r["stop"], "budget") << r.dump();
  ASSERT_EQ(r["rungs"].size(), 1u) << r.dump();
  EXPECT_EQ(r["rungs"][0]["status"], "over-budget");
  // Stopped at its first sample check: at most one sample interval in, or none.
  const json& reached = r["rungs"][0]["reached_t"];
  EXPECT_TRUE(reached.is_null() || reached.get<double>() < ChainPlanFor(o).t1) << r.dump();
  EXPECT_NE(r["stop_detail"].get<std::string>().find("N = 1"), std::string::npos) << r.dump();
}

TEST(Chains, GrowthExponentIsTheLogLogSlope) {
  EXPECT_NEAR(GrowthExponent({{1, 3.0}, {10, 300.0}, {100, 30000.0}}), 2.0, 1e-12);
  EXPECT_NEAR(GrowthExponent({{10, 5.0}, {30, 15.0}, {0, 1.0}, {100, kNaN}}), 1.0, 1e-12);
  EXPECT_TRUE(std::isnan(GrowthExponent({{10, 5.0}})));
}

}  // namespace
}  // namespace harness_campaign_test
}  // namespace mechbench::harness
