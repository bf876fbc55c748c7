// summary.md
#include "writers.h"

#include "access.h"
#include "mechbench/harness/gate.h"
#include "chains_view.h"
#include "precision_view.h"
#include "reach.h"
#include "results_view.h"
#include "text.h"

#include <algorithm>
#include <map>
#include <optional>
#include <sstream>
#include <vector>

namespace mechbench::harness::report {

namespace {

constexpr size_t kMdRows = 10;  // rows of a list of problems before "… and N more"

// Per method: on how many of the scenes it was swept on it reached each level, and the median
// integration CPU over those; never reached: the best error it got.
void AcrossScenes(const json& results, std::ostringstream& o) {
  const Reach reach = ReachAcrossScenes(results);
  if (reach.empty()) return;
  o << "### Work–precision across the " << reach.scenes.size() << " swept scene" << (reach.scenes.size() == 1 ? "" : "s")
    << "\n\nIntegration CPU of the cheapest sweep rung whose q error (max over the run, relative) is within the level; "
       "the median is over the scenes the method reached, which differ between methods and between the levels "
       "(a median to 1e-6 below the one to 1e-3 means fewer, cheaper scenes got there).\n\n"
    << "| method | reached 1e-3 | median CPU to 1e-3 | reached 1e-6 | median CPU to 1e-6 | median order (fixed step) or tol. slope | "
       "smallest largest stable step |\n|---|---|---|---|---|---|---|\n";
  for (const MethodReach& m : reach.methods) {
    o << "| " << MdCode(m.method) << " | ";
    if (m.scenes.empty()) {
      o << "not swept | — | — | — | — | — |\n";
      continue;
    }
    std::vector<double> order, slope, stable;
    for (const SceneReach& s : m.scenes) {
      if (s.order) order.push_back(*s.order);
      if (s.tolerance_slope) slope.push_back(*s.tolerance_slope);
      if (s.largest_stable) stable.push_back(*s.largest_stable);
    }
    for (int k = 0; k < 2; ++k) {
      const std::string of = ReachedOf(m, k), where = ReachedWhere(m, k);
      // Bold: not reached on a scene that judged it (a scene without a reference is not a miss).
      o << (m.reached(k) || m.not_judged() == static_cast<int>(m.scenes.size()) ? of : "**" + of + "**") << (where.empty() ? "" : " (" + Md(where) + ")") << " | "
        << Md(MedianCpuText(m, k)) << " | ";
    }
    // An error-controlled method has no order: the median slope of its error against the tolerance.
    o << (order.empty() && !slope.empty() ? "tol. slope " + FmtOrder(Median(slope)) : FmtOrder(Median(order))) << " | "
      << FmtSeconds(stable.empty() ? std::optional<double>() : *std::min_element(stable.begin(), stable.end()))
      << " |\n";
  }
  o << "\n";
}

// Per published benchmark, per method: the CPU time of the coarsest run meeting each level.
void Benchmarks(const json& results, std::ostringstream& o) {
  for (const PrecisionTable& t : PrecisionTables(results)) {
    std::string unit;
    for (const json& s : Arr(At(results, "scenarios")))
      if (Str(s, "scenario") == t.scenario) unit = Str(At(s, "drawing"), "unit");
    o << "### Benchmark " << MdCode(t.scenario) << ": CPU time to each precision level\n\nLargest distance of "
      << Md(t.point) << " from the reference over " << t.output_steps
      << " output steps; CPU of the coarsest run within the level (the fewest steps or the loosest tolerance; the "
         "method's own work)."
      << (t.source.empty() ? std::string() : " Levels: " + Md(t.source) + ".") << "\n\n| method |";
    for (double l : t.levels) o << " " << Md(LevelText(l, unit)) << " |";
    o << " reason |\n|---|";
    for (size_t l = 0; l < t.levels.size(); ++l) o << "---|";
    o << "---|\n";
    for (const PrecisionRow& row : t.rows) {
      o << "| " << MdCode(row.method) << " |";
      for (const PrecisionCell& c : row.cells)
        o << " " << (c.met || row.status != "ok" ? Md(c.cpu) : "**" + Md(c.cpu) + "**") << (c.detail.empty() ? "" : " (" + Md(c.detail) + ")") << " |";
      o << " " << Md(row.status == "ok" ? "" : row.status + ": " + row.reason) << " |\n";
    }
    o << "\n";
  }
}

// The long chains: per method, the largest N it finished, its cost per step and error there, the
// growth exponent and why its ladder stopped.
void Chains(const json& results, std::ostringstream& o) {
  const ChainTable t = ChainTableOf(results);
  if (t.empty()) return;
  o << "### Long chains: the N-four-bar as N grows\n\nEach method at its own settings over " << FmtSeconds(t.t1)
    << " of motion, N on the ladder until a rung fails, loses the motion or the method's " << FmtSeconds(t.budget)
    << " CPU budget is spent (" << FmtSeconds(t.cpu_seconds)
    << " of CPU in all); error against the exact motion; growth: log–log slope of the integration CPU per simulated "
       "second.\n\n| method | largest N finished | CPU per step there | error there | growth | ladder stopped |\n"
       "|---|---|---|---|---|---|\n";
  for (const ChainRow& row : t.rows) {
    o << "| " << MdCode(row.method) << " | ";
    const ChainCell* last = nullptr;
    for (size_t k = 0; k < row.cells.size(); ++k)
      if (row.cells[k].ok) last = &row.cells[k];
    if (row.largest_n) o << Fmt("g6", *row.largest_n);
    else o << kDash;
    o << " | " << (last && last->step_us ? FmtMicros(*last->step_us) : kDash) << " | " << (last ? FmtErr(last->error) : kDash)
      << " | " << FmtExponent(row.exponent) << " | " << Md(row.stop.empty() ? row.status : row.stop)
      << (row.stop_detail.empty() ? "" : ": " + Md(row.stop_detail)) << " |\n";
  }
  o << "\n";
}

}  // namespace

std::string RenderSummary(const json& results) {
  std::ostringstream o;
  const json& records = At(results, "records");
  const Counts all = Count(records, nullptr);
  const json& build = At(results, "build");
  o << "## mechbench report\n\n";
  o << "Build " << MdCode(Str(build, "version")) << " (" << Md(Str(build, "build_type")) << ", "
    << Md(Str(build, "compiler")) << ")";
  std::string engines;
  for (const auto& [k, v] : Obj(At(results, "engines")).items())
    engines += (engines.empty() ? "" : ", ") + Md(k) + " " + Md(Str(v));
  if (!engines.empty()) o << " · engines: " << engines;
  o << " · " << Md(Str(At(results, "machine"), "cpu")) << " · created " << Md(Str(results, "created")) << "\n\n";

  // Only what the report has (no empty "book values:" or "stress:").
  std::vector<std::string> totals;
  if (!all.verdicts.empty()) totals.push_back("book values: " + JoinCounts(Ordered(all.verdicts, kVerdicts)));
  if (all.runs.ok + all.runs.not_ok() + all.runs.not_applicable) totals.push_back("runs: " + RunsText(all.runs));
  if (all.sweeps) totals.push_back("sweep rungs: " + std::to_string(all.sweeps_ok) + "/" + std::to_string(all.sweeps) + " ok");
  if (!all.outcomes.empty()) totals.push_back("stress: " + JoinCounts(Ordered(all.outcomes, kOutcomes)));
  o << "**Totals** — ";
  for (size_t k = 0; k < totals.size(); ++k) o << (k ? " · " : "") << totals[k];
  o << "\n\n";

  AcrossScenes(results, o);
  Benchmarks(results, o);
  Chains(results, o);

  // One line per scenario.
  o << "| scenario | kind | book values | runs | stress not ok |\n|---|---|---|---|---|\n";
  for (const auto& s : Scenarios(results)) {
    const Counts c = Count(records, &s.name);
    int stress_bad = 0, stress_all = 0;
    for (const auto& [k, n] : c.outcomes) {
      stress_all += n;
      if (k != "ok") stress_bad += n;
    }
    o << "| " << MdCode(s.name) << " | " << Md(s.info ? Str(*s.info, "kind") : "") << " | "
      << (c.verdicts.empty() ? kDash : Md(JoinCounts(Ordered(c.verdicts, kVerdicts)))) << " | "
      << (c.runs.ok + c.runs.not_ok() + c.runs.not_applicable ? Md(RunsText(c.runs)) : kDash) << " | "
      << (stress_all ? std::to_string(stress_bad) + " of " + std::to_string(stress_all) : kDash) << " |\n";
  }
  o << "\n";

  // Work–precision per scene, methods × scenes, while the table stays narrow enough to read.
  const json& derived = At(results, "derived");
  std::vector<std::string> scen, meth;
  std::map<std::pair<std::string, std::string>, const json*> cell;
  for (const auto& d : Arr(derived)) {
    const std::string s = Str(d, "scenario"), m = Str(d, "method");
    if (std::find(scen.begin(), scen.end(), s) == scen.end()) scen.push_back(s);
    if (std::find(meth.begin(), meth.end(), m) == meth.end()) meth.push_back(m);
    cell[{s, m}] = &d;
  }
  meth = OrderMethods(results, meth);
  if (!scen.empty() && scen.size() <= 4) {
    o << "### Work–precision per scene\n\nIntegration CPU to reach q error 1e-3 / 1e-6 · observed order p (fixed-step "
         "methods) or the error's slope against the tolerance (error-controlled methods, whose rungs vary the tolerance, "
         "not the step) · largest stable step h; \"(X's run)\": the same run as method X's cell (the same computation), "
         "shown twice, measured once\n\n";
    o << "| method |";
    for (const auto& s : scen) o << " " << MdCode(s) << " |";
    o << "\n|---|";
    for (size_t i = 0; i < scen.size(); ++i) o << "---|";
    o << "\n";
    for (const auto& m : meth) {
      o << "| " << MdCode(m) << " |";
      for (const auto& s : scen) {
        auto it = cell.find({s, m});
        if (it == cell.end()) {
          o << " |";
          continue;
        }
        const json& d = *it->second;
        o << " " << Md(FmtLevelCpu(d, "1e-3")) << " / " << Md(FmtLevelCpu(d, "1e-6"))
          << (Num(At(d, "order")) ? " · p " : " · ") << FmtConvergence(d);
        if (auto h = Num(At(d, "largest_stable"))) o << " · h " << FmtSeconds(h);
        o << " |";
      }
      o << "\n";
    }
    o << "\n";
  }

  // Lists of what went wrong, each capped.
  auto capped = [&o](size_t n) {
    if (n > kMdRows) o << "\n… and " << (n - kMdRows) << " more (all of them in report.html and results.json)\n";
    o << "\n";
  };
  {
    std::vector<std::string> rows;
    for (const auto& r : Arr(records)) {
      if (Str(r, "kind") != "check") continue;
      for (const auto& row : Arr(At(r, "rows"))) {
        if (Str(row, "verdict") != "differs") continue;
        rows.push_back("| " + MdCode(Str(r, "scenario")) + " | " + Md(Str(row, "quantity")) + " | " +
                       Md(Str(row, "where")) + " | " + Md(Str(row, "printed")) + " | " + Md(Str(row, "note")) + " |");
      }
    }
    if (!rows.empty()) {
      o << "### Book values that differ\n\n| scenario | quantity | where | printed | note |\n|---|---|---|---|---|\n";
      for (size_t i = 0; i < rows.size() && i < kMdRows; ++i) o << rows[i] << "\n";
      capped(rows.size());
    }
  }
  {
    // Every run that is not a plain pass, by its gate (gate.h, as `run` and the exit code judge
    // it), failing ones first, all listed (a CI job's reader needs each): why with its figure and
    // bound (the run's own line), a known failure with its entry's file and line.
    std::vector<std::pair<bool, std::string>> rows;
    for (const auto& r : Arr(records)) {
      if (Str(r, "kind") != "run") continue;
      const std::string status = Str(r, "status"), known = Str(r, "known"), stale = Str(r, "known_stale");
      const bool within = At(r, "within").is_boolean() ? At(r, "within").get<bool>() : true;
      const Gate g = GateOf(status, within, known, stale);
      if (g == Gate::kPass || g == Gate::kNotApplicable) continue;
      std::string first;  // the run's first line about it: the figure against its bound
      for (const auto& p : Arr(At(r, "problems")))
        if (p.is_string()) {
          first = p.get<std::string>();
          break;
        }
      const std::string entry = Str(r, "known_entry").empty() ? "" : " (" + Str(r, "known_entry") + ")";
      std::string why;
      if (g == Gate::kKnownFailure) {
        // The run's line ends with "(known: <reason>)": the reason is said once, first.
        const std::string suffix = " (known: " + known + ")";
        if (first.size() > suffix.size() && first.compare(first.size() - suffix.size(), suffix.size(), suffix) == 0)
          first.resize(first.size() - suffix.size());
        why = "known" + entry + ": " + known + (first.empty() ? "" : "; " + first);
      }
      else if (g == Gate::kKnownNoLongerFails) why = "within its tolerance; the entry" + entry + " says: " + stale;
      else why = first.empty() ? status + ": " + Str(r, "reason") : first;
      // A run that diverged or failed says so, rather than "outside its tolerance".
      const std::string verdict = g == Gate::kOutside && status != "ok" ? status : GateWords(g);
      rows.emplace_back(GateFails(g), "| " + MdCode(Str(r, "scenario")) + " | " + MdCode(Str(r, "method")) + " | " +
                                          (GateFails(g) ? "**" + Md(verdict) + "**" : Md(verdict)) + " | " + Md(why) + " |");
    }
    std::stable_sort(rows.begin(), rows.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
    if (!rows.empty()) {
      o << "### Runs not ok (failing the gate in bold) and known failures\n\n| scenario | method | verdict | why |\n"
           "|---|---|---|---|\n";
      for (const auto& row : rows) o << row.second << "\n";
      o << "\n";
    }
  }
  {
    std::vector<std::string> rows;
    for (const auto& r : Arr(records)) {
      if (Str(r, "kind") != "stress" || Str(r, "outcome") == "ok") continue;
      auto t = Num(At(r, "t_fail"));
      rows.push_back("| " + MdCode(Str(r, "scenario")) + " | " + Md(Str(r, "case")) + " | " + MdCode(Str(r, "method")) +
                     " | **" + Md(Str(r, "outcome")) + "** | " + Md(Str(r, "detail")) +
                     (t ? " (t = " + Fmt("g3", *t) + " s)" : "") + " |");
    }
    if (!rows.empty()) {
      o << "### Stress outcomes not ok\n\n| scenario | case | method | outcome | detail |\n|---|---|---|---|---|\n";
      for (size_t i = 0; i < rows.size() && i < kMdRows; ++i) o << rows[i] << "\n";
      capped(rows.size());
    }
  }
  o << "Full report: `report.html` (tables, drawings, work–precision plots, settings); data: `results.json`, "
       "`results.csv`.\n";
  return o.str();
}

}  // namespace mechbench::harness::report
