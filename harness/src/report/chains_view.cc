#include "chains_view.h"

#include "access.h"
#include "results_view.h"
#include "text.h"

#include <algorithm>
#include <map>

namespace mechbench::harness::report {

std::string FmtMicros(double us) { return FmtSeconds(us * 1e-6); }

std::string FmtExponent(const std::optional<double>& p) { return p ? "N^" + Fmt("f2", *p) : kDash; }

ChainTable ChainTableOf(const json& results) {
  ChainTable t;
  std::vector<const json*> records;
  std::vector<std::string> seen;
  for (const json& r : Arr(At(results, "records"))) {
    if (Str(r, "kind") != "chain") continue;
    records.push_back(&r);
    seen.push_back(Str(r, "method"));
    const json& plan = At(r, "plan");
    for (const json& n : Arr(At(plan, "ladder")))
      if (Num(n) && std::find(t.ladder.begin(), t.ladder.end(), static_cast<int>(*Num(n))) == t.ladder.end())
        t.ladder.push_back(static_cast<int>(*Num(n)));
    if (Num(At(plan, "t1"))) t.t1 = *Num(At(plan, "t1"));
    if (Num(At(plan, "budget_seconds"))) t.budget = *Num(At(plan, "budget_seconds"));
    if (Num(At(plan, "samples"))) t.samples = static_cast<int>(*Num(At(plan, "samples")));
  }
  // Rungs of a record without a plan (a process that died) still find their column.
  for (const json* r : records)
    for (const json& g : Arr(At(*r, "rungs")))
      if (Num(At(g, "n")) && std::find(t.ladder.begin(), t.ladder.end(), static_cast<int>(*Num(At(g, "n")))) == t.ladder.end())
        t.ladder.push_back(static_cast<int>(*Num(At(g, "n"))));
  std::sort(t.ladder.begin(), t.ladder.end());
  std::map<std::string, const json*> by_method;
  for (const json* r : records) by_method.emplace(Str(*r, "method"), r);
  for (const std::string& m : OrderMethods(results, seen)) {
    const json& r = *by_method.at(m);
    ChainRow row;
    row.method = m;
    row.status = Str(r, "status");
    row.stop = Str(r, "stop");
    row.stop_detail = Str(r, "stop_detail");
    row.exponent = Num(At(r, "exponent"));
    row.exponent_points = Num(At(r, "exponent_points")) ? static_cast<int>(*Num(At(r, "exponent_points"))) : 0;
    const json& from = Arr(At(r, "exponent_from"));
    if (from.size() == 2) row.exponent_range = "N = " + Str(from[0]) + " … " + Str(from[1]);
    row.cpu_seconds = Num(At(r, "cpu_seconds")).value_or(0);
    t.cpu_seconds += row.cpu_seconds;
    row.cells.resize(t.ladder.size());
    for (const json& g : Arr(At(r, "rungs"))) {
      const auto n = Num(At(g, "n"));
      if (!n) continue;
      const size_t k = static_cast<size_t>(std::find(t.ladder.begin(), t.ladder.end(), static_cast<int>(*n)) - t.ladder.begin());
      ChainCell& c = row.cells[k];
      c.ran = true;
      c.step_us = Num(At(g, "step_us"));
      c.error = Num(At(g, "error"));
      const std::string status = Str(g, "status");
      c.ok = status == "ok";
      const auto reached = Num(At(g, "reached_t"));
      const auto integration = Num(At(g, "integration"));
      if (reached && integration && *reached > 0) c.per_sim_second = *integration / *reached;
      c.text = c.step_us ? FmtMicros(*c.step_us) : status;
      if (status == "ok") c.detail = FmtErr(c.error);
      else if (reached) c.detail = status + " at t = " + Fmt("g3", *reached) + " s";
      else c.detail = status;
      if (c.ok && (row.stop == "lost_motion" || row.stop == "failed") &&
          !Arr(At(r, "rungs")).empty() && &g == &Arr(At(r, "rungs")).back())
        c.ok = false;  // finished, but outside the lost-motion limits: the rung that stopped the ladder
      if (c.ok) row.largest_n = *n;
    }
    t.rows.push_back(row);
  }
  return t;
}

}  // namespace mechbench::harness::report
