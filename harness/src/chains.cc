#include "mechbench/harness/chains.h"

#include "mechbench/errors.h"
#include "mechbench/format.h"
#include "mechbench/harness/compare.h"
#include "mechbench/harness/registry.h"
#include "mechbench/harness/timing.h"
#include "mechbench/motion_error.h"
#include "mechbench/references/nfourbar.h"
#include "mechbench/references/registry.h"
#include "json_number.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <string>

namespace mechbench::harness {

using nlohmann::json;

namespace {


const Method* FindChainMethod(const std::string& name) {
  static const std::vector<MethodPtr> methods = AllMethods();
  for (const MethodPtr& m : methods)
    if (m->name() == name) return m.get();
  return nullptr;
}

json ChainCaseJson(const Case& c) {
  return {{"id", c.id}, {"index", c.index}, {"kind", c.kind}, {"scenario", c.scenario}, {"file", c.file},
          {"method", c.method}};
}

json PlanJson(const ChainPlan& p) {
  return {{"ladder", p.ladder}, {"t1", p.t1}, {"samples", p.samples}, {"budget_seconds", p.budget},
          {"lost_error", p.lost_error}, {"lost_residual", p.lost_residual}, {"fit_from", p.fit_from}};
}

// One rung: the run's figures, judged against the exact motion over the samples it reached.
struct Rung {
  json record;
  double cpu = 0;             // the run's own CPU (set-up + integration + observation) [s]
  double per_sim_second = kNaN;  // integration CPU per simulated second [s/s]
  bool ok = false;            // finished, within the lost-motion limits
  std::string stop, detail;   // why the ladder ends here ("" = it goes on)
};

// A rung cheaper than this [s] is run `repeats` times and timed by the medians (one run of a few
// milliseconds is mostly the clock's and the machine's noise); a dearer one once.
constexpr double kShortRung = 5e-3;

Rung RunRung(const Method& meth, int n, const ChainPlan& plan, double cpu_budget, int repeats) {
  Rung out;
  const Model model = references::NFourBar({.n = n, .t1 = plan.t1, .samples = plan.samples});
  const std::vector<Sample> exact = references::ExactMotionFor(model, {}).solve({}, {}).trajectory;
  RunOptions ro;
  ro.cpu_budget = cpu_budget;
  // In the case's own process (the report's unit of isolation), after its warm-up: a run in a
  // freshly forked child pays first-touch costs in its set-up (measured: Bullet 40–55 ms at N = 1
  // in a child, 1 ms here), which would hide the growth with N and spend the budget on nothing.
  const Result r = meth.Run(model, ro);
  std::vector<double> setup{r.cpu.setup}, integration{r.cpu.integration};
  out.cpu = r.cpu_seconds;
  for (int k = 1; k < repeats && r.ok() && r.cpu_seconds < kShortRung; ++k) {
    const Result again = meth.Run(model, ro);
    out.cpu += again.cpu_seconds;
    if (!again.ok()) break;
    setup.push_back(again.cpu.setup);
    integration.push_back(again.cpu.integration);
  }
  const auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  };
  json j = {{"n", n}, {"coordinates", static_cast<int>(model.q_layout.size())}, {"status", ToString(r.status)},
            {"reason", r.reason}, {"cpu_seconds", out.cpu}, {"setup", median(setup)},
            {"integration", median(integration)}, {"repeats", static_cast<int>(integration.size())},
            {"steps", r.steps >= 0 ? json(r.steps) : json(nullptr)}};
  j["step_us"] = JsonNumber(r.steps > 0 ? 1e6 * median(integration) / static_cast<double>(r.steps) : kNaN);
  const bool partial = r.status == Status::kOverBudget;
  double reached = kNaN, error = kNaN, residual = kNaN;
  if ((r.ok() || partial) && r.trajectory.size() >= 2) {
    reached = r.trajectory.back().t - model.analysis.t0;
    // Over the samples it reached, scaled by the whole exact motion (as the benchmark does).
    const size_t k = std::min(exact.size(), r.trajectory.size());
    const std::vector<Sample> span(exact.begin(), exact.begin() + static_cast<long>(k));
    error = CompareMotion(model, ScaleOfMotion(model, exact), span,
                          {r.trajectory.begin(), r.trajectory.begin() + static_cast<long>(k)})
                .q.max;
    const std::vector<double> res = ScaledResiduals(model, r.trajectory);
    if (!res.empty()) residual = *std::max_element(res.begin(), res.end());
    if (reached > 0) out.per_sim_second = median(integration) / reached;
  }
  j["reached_t"] = JsonNumber(reached);
  j["error"] = JsonNumber(error);
  j["max_residual"] = JsonNumber(residual);
  out.record = j;
  const std::string at = " at N = " + std::to_string(n);
  if (partial) {
    out.stop = "budget";
    out.detail = "its CPU budget ran out" + at + " (t = " + Fmt(reached, 3) + " s of " + Fmt(plan.t1, 3) + " s)";
  } else if (!r.ok()) {
    out.stop = r.status == Status::kDiverged || r.status == Status::kFailed ? "lost_motion" : "failed";
    out.detail = std::string(ToString(r.status)) + at + ": " + r.reason.substr(0, 300);
  } else if (!(error <= plan.lost_error)) {
    out.stop = "lost_motion";
    out.detail = "position error " + Fmt(error, 3) + " > " + Fmt(plan.lost_error) + at;
  } else if (residual > plan.lost_residual) {
    out.stop = "lost_motion";
    out.detail = "scaled ‖Φ‖ " + Fmt(residual, 3) + " > " + Fmt(plan.lost_residual) + at;
  } else {
    out.ok = true;
  }
  return out;
}

}  // namespace

ChainPlan ChainPlanFor(const CampaignOptions& o) {
  ChainPlan p;
  if (!o.chain_ladder.empty()) {
    p.ladder = o.chain_ladder;
    std::sort(p.ladder.begin(), p.ladder.end());
  }
  if (std::isfinite(o.chain_budget)) p.budget = o.chain_budget;
  return p;
}

bool ChainMethod(const Method& method) { return method.control() != Control::kNone; }

Case ChainCaseFor(const std::string& method) {
  Case c;
  c.id = "chain/nfourbar/" + method;
  c.kind = "chain";
  c.scenario = "nfourbar";
  c.method = method;
  return c;
}

double LogLogSlope(const std::vector<std::pair<double, double>>& xy) {
  std::vector<std::pair<double, double>> use;
  for (const auto& [x, y] : xy) use.emplace_back(std::log(x), std::log(y));
  if (use.size() < 2) return kNaN;
  double mx = 0, my = 0;
  for (const auto& [x, y] : use) mx += x, my += y;
  mx /= static_cast<double>(use.size());
  my /= static_cast<double>(use.size());
  double sxy = 0, sxx = 0;
  for (const auto& [x, y] : use) sxy += (x - mx) * (y - my), sxx += (x - mx) * (x - mx);
  return sxx > 0 ? sxy / sxx : kNaN;
}

double GrowthExponent(const std::vector<std::pair<double, double>>& n_cost) {
  std::vector<std::pair<double, double>> use;
  for (const auto& [n, cost] : n_cost)
    if (n > 0 && cost > 0 && std::isfinite(n) && std::isfinite(cost)) use.emplace_back(n, cost);
  return LogLogSlope(use);
}

std::vector<json> ChainCase(const Case& c, const CampaignOptions& o) {
  constexpr double kNoise = 5e-3;  // [s]
  const ChainPlan plan = ChainPlanFor(o);
  const Method* meth = FindChainMethod(c.method);
  MB_ASSERT(meth, ("unknown method " + c.method).c_str());
  json j = ChainCaseJson(c);
  j["control"] = ToString(meth->control());
  j["plan"] = PlanJson(plan);
  j["rungs"] = json::array();
  j["exponent"] = nullptr;
  j["exponent_points"] = 0;
  j["cpu_seconds"] = 0.0;
  const Model first = references::NFourBar({.n = plan.ladder.front(), .t1 = plan.t1, .samples = plan.samples});
  if (std::optional<std::string> why = meth->Applicability(first)) {
    j["status"] = ToString(Status::kNotApplicable);
    j["stop"] = "not_applicable";
    j["stop_detail"] = *why;
    return {j};
  }
  // The method's one-time costs, paid here on the smallest chain: every rung's process inherits them.
  j["startup"] = nullptr;
  if (const StartupCost s = WarmUp(*meth, first); s.done)
    j["startup"] = {{"first", s.first}, {"again", s.again}, {"runs", s.runs}, {"one_time", s.one_time()}};
  double spent = 0;
  std::string stop = "ladder_end", detail = "every rung of the ladder ran";
  std::vector<std::pair<double, double>> fit_all, fit_big;  // (N, integration CPU per simulated second)
  std::vector<std::pair<int, double>> costs;                // (N, the rung's CPU, repeats included)
  for (int n : plan.ladder) {
    const double left = plan.budget - spent;
    // The next rung's cost from the last two (at least linear, at most cubic in N): a rung that
    // would not finish in what is left is not started. Runs of a few milliseconds are mostly the
    // clock's and the allocator's noise: below kNoise the growth is taken as linear.
    if (!costs.empty()) {
      double p = 1;
      if (costs.size() >= 2) {
        const auto& [n0, c0] = costs[costs.size() - 2];
        const auto& [n1, c1] = costs.back();
        if (c0 > kNoise && c1 > kNoise && n1 > n0) p = std::log(c1 / c0) / std::log(static_cast<double>(n1) / n0);
      }
      p = std::clamp(p, 1.0, 3.0);
      const double predicted = costs.back().second * std::pow(static_cast<double>(n) / costs.back().first, p);
      if (predicted > left) {
        stop = "budget";
        detail = "N = " + std::to_string(n) + " would take about " + Fmt(predicted, 2) + " s of CPU (N^" + Fmt(p, 2) +
                 " from the last rungs); " + Fmt(std::max(left, 0.0), 2) + " s of the " + Fmt(plan.budget, 2) + " s budget left";
        break;
      }
    }
    Rung r = RunRung(*meth, n, plan, left, std::max(1, o.repeats));
    spent += r.cpu;
    costs.emplace_back(n, r.cpu);
    if (std::isfinite(r.per_sim_second)) {
      fit_all.emplace_back(n, r.per_sim_second);
      if (n >= plan.fit_from) fit_big.emplace_back(n, r.per_sim_second);
    }
    j["rungs"].push_back(r.record);
    if (!r.ok) {
      stop = r.stop;
      detail = r.detail;
      break;
    }
  }
  const std::vector<std::pair<double, double>>& fit = fit_big.size() >= 2 ? fit_big : fit_all;
  const double exponent = GrowthExponent(fit);
  j["exponent"] = JsonNumber(exponent);
  j["exponent_points"] = std::isfinite(exponent) ? static_cast<int>(fit.size()) : 0;
  if (std::isfinite(exponent)) j["exponent_from"] = {fit.front().first, fit.back().first};
  j["status"] = "ok";
  j["stop"] = stop;
  j["stop_detail"] = detail;
  j["cpu_seconds"] = spent;
  return {j};
}

json ChainFallback(const Case& c, const std::string& what, const std::string& detail, double wall) {
  json j = ChainCaseJson(c);
  const Method* meth = FindChainMethod(c.method);
  j["control"] = ToString(meth ? meth->control() : Control::kNone);
  j["rungs"] = json::array();
  j["exponent"] = nullptr;
  j["exponent_points"] = 0;
  j["status"] = what;
  j["stop"] = "failed";
  j["stop_detail"] = detail;
  j["cpu_seconds"] = wall;
  j["isolation"] = detail;
  return j;
}

}  // namespace mechbench::harness
