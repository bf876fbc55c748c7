// summary.md
#include "writers.h"

#include "access.h"
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

  o << "**Totals** — book values: " << JoinCounts(Ordered(all.verdicts, kVerdicts))
    << " · runs: " << RunsText(all.runs) << " · sweep rungs: " << all.sweeps_ok << "/" << all.sweeps << " ok"
    << " · stress: " << JoinCounts(Ordered(all.outcomes, kOutcomes)) << "\n\n";

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

  // Work–precision: methods × scenarios.
  const json& derived = At(results, "derived");
  if (!Arr(derived).empty()) {
    std::vector<std::string> scen, meth;
    std::map<std::pair<std::string, std::string>, const json*> cell;
    for (const auto& d : Arr(derived)) {
      const std::string s = Str(d, "scenario"), m = Str(d, "method");
      if (std::find(scen.begin(), scen.end(), s) == scen.end()) scen.push_back(s);
      if (std::find(meth.begin(), meth.end(), m) == meth.end()) meth.push_back(m);
      cell[{s, m}] = &d;
    }
    meth = OrderMethods(results, meth);
    if (scen.size() > 4) {
      // Many scenes: one aggregate line per method keeps the summary narrow.
      auto median = [](std::vector<double> v) -> std::optional<double> {
        if (v.empty()) return std::nullopt;
        std::sort(v.begin(), v.end());
        return v[v.size() / 2];
      };
      o << "### Work–precision (over " << scen.size() << " scenes; per scene in report.html)\n\n"
        << "| method | reach 1e-3 | median CPU to 1e-3 | reach 1e-6 | median CPU to 1e-6 | median order | smallest largest-stable step (of the scenes where one was found) |\n"
        << "|---|---|---|---|---|---|---|\n";
      for (const auto& m : meth) {
        std::vector<double> to3, to6, order, stable;
        int swept = 0;
        for (const auto& sc : scen) {
          auto it = cell.find({sc, m});
          if (it == cell.end()) continue;
          const json& d = *it->second;
          ++swept;
          if (auto v = Num(At(d, "cpu_to_1e-3"))) to3.push_back(*v);
          if (auto v = Num(At(d, "cpu_to_1e-6"))) to6.push_back(*v);
          if (auto v = Num(At(d, "order"))) order.push_back(*v);
          if (auto v = Num(At(d, "largest_stable"))) stable.push_back(*v);
        }
        const auto min_stable = stable.empty() ? std::optional<double>() : *std::min_element(stable.begin(), stable.end());
        o << "| " << MdCode(m) << " | " << to3.size() << " of " << swept << " | " << FmtSeconds(median(to3)) << " | "
          << to6.size() << " of " << swept << " | " << FmtSeconds(median(to6)) << " | " << FmtOrder(median(order)) << " | "
          << FmtSeconds(min_stable) << " |\n";
      }
      o << "\n";
    } else {
    o << "### Work–precision\n\nCPU time to reach q error 1e-3 / 1e-6 · observed order p · largest stable step h\n\n";
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
        o << " " << FmtSeconds(Num(At(d, "cpu_to_1e-3"))) << " / " << FmtSeconds(Num(At(d, "cpu_to_1e-6")))
          << " · p " << FmtOrder(Num(At(d, "order")));
        if (auto h = Num(At(d, "largest_stable"))) o << " · h " << FmtSeconds(h);
        o << " |";
      }
      o << "\n";
    }
    o << "\n";
    }
  }

  // Lists of what went wrong, each capped.
  auto capped = [&o](size_t n) {
    if (n > kMdRows) o << "\n… and " << (n - kMdRows) << " more (see report.html)\n";
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
    std::vector<std::string> rows;
    for (const auto& r : Arr(records)) {
      if (Str(r, "kind") != "run") continue;
      RunCounts c;
      CountRun(r, c);
      if (!c.not_ok()) continue;
      std::string why = Str(r, "reason");
      if (c.outside) {
        const std::string known = Str(r, "known");
        why = (known.empty() ? std::string("not known") : "known: " + known) + (why.empty() ? "" : "; " + why);
      }
      rows.push_back("| " + MdCode(Str(r, "scenario")) + " | " + MdCode(Str(r, "method")) + " | " +
                     Md(c.outside ? std::string("outside tolerance") : Str(r, "status")) + " | " + Md(why) + " |");
    }
    if (!rows.empty()) {
      o << "### Runs not ok\n\n| scenario | method | status | why |\n|---|---|---|---|\n";
      for (size_t i = 0; i < rows.size() && i < kMdRows; ++i) o << rows[i] << "\n";
      capped(rows.size());
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
