#include "precision_view.h"

#include "access.h"
#include "text.h"

#include <algorithm>
#include <map>

namespace mechbench::harness::report {

std::string LevelText(double level, const std::string& unit) {
  return Fmt("g3", level) + (unit.empty() ? "" : " " + unit);
}

std::vector<PrecisionTable> PrecisionTables(const json& results) {
  std::vector<PrecisionTable> out;
  std::map<std::string, size_t> at;
  std::map<std::string, std::string> unit;
  for (const json& s : Arr(At(results, "scenarios"))) unit[Str(s, "scenario")] = Str(At(s, "drawing"), "unit");
  for (const json& r : Arr(At(results, "records"))) {
    if (Str(r, "kind") != "precision") continue;
    const std::string name = Str(r, "scenario");
    if (!at.count(name)) {
      at[name] = out.size();
      PrecisionTable t;
      t.scenario = name;
      t.point = Str(r, "point");
      t.source = Str(r, "levels_source");
      for (const json& l : Arr(At(r, "levels")))
        if (Num(l)) t.levels.push_back(*Num(l));
      t.output_steps = Num(At(r, "output_steps")) ? static_cast<int>(*Num(At(r, "output_steps"))) : 0;
      out.push_back(t);
    }
    PrecisionTable& t = out[at[name]];
    const std::string u = unit[name];
    PrecisionRow row;
    row.method = Str(r, "method");
    row.status = Str(r, "status");
    row.reason = Str(r, "reason");
    const std::string control = Str(r, "control");
    const json& rungs = Arr(At(r, "rungs"));
    row.rungs = static_cast<int>(rungs.size());
    // The smallest error any rung got, and the rung that ended the walk.
    std::optional<double> best, latest;
    std::string best_at, last, latest_at;
    for (const json& g : rungs) {
      const auto e = Num(At(g, "error"));
      if (e && Str(g, "status") == "ok" && (!best || *e < *best)) best = e, best_at = FmtRung(control, Num(At(g, "value")));
      // A rung stopped where its point passed the loosest level: how far the best of them got.
      const auto tg = Num(At(g, "t"));
      if (Str(g, "status") == "stopped" && tg && (!latest || *tg > *latest))
        latest = tg, latest_at = FmtRung(control, Num(At(g, "value")));
      if (Str(g, "status") != "ok")
        last = Str(g, "status") + " at " + FmtRung(control, Num(At(g, "value")));
    }
    const json& met = Arr(At(r, "met"));
    for (size_t l = 0; l < t.levels.size(); ++l) {
      PrecisionCell c;
      const json& m = l < met.size() ? met[l] : Null();
      if (m.is_object()) {
        c.met = true;
        c.cpu = FmtSeconds(Num(At(m, "cpu_seconds")));
        c.detail = FmtRung(control, Num(At(m, "value"))) + ", " + FmtErr(Num(At(m, "error"))) + (u.empty() ? "" : " " + u);
        const auto reps = Num(At(m, "repeats"));
        if (reps && *reps > 1) c.detail += ", median of " + Str(At(m, "repeats"));
      } else if (row.status != "ok") {
        c.cpu = kDash;
      } else {
        c.cpu = "not met";
        c.detail = best     ? "best " + FmtErr(best) + (u.empty() ? "" : " " + u) + " at " + best_at
                   : latest ? "every rung passed the loosest level before the end (the last at t = " + FmtSeconds(latest) +
                                  ", at " + latest_at + ")"
                            : "no rung completed";
        if (!Str(r, "stop").empty()) c.detail += "; stopped: " + Str(r, "stop");
        else if (!last.empty()) c.detail += "; " + last;
      }
      row.cells.push_back(c);
    }
    if (row.status == "ok") row.shared_with = Str(r, "shared_with");
    t.rows.push_back(row);
  }
  // A walk that shared runs with another method's (the same computation, run once: README "Runs
  // done once"). When its cells are that method's, it is that run, marked "(X's run)" as the
  // per-scene work–precision cells are, not a second full row; else the cells say which shared.
  for (PrecisionTable& t : out)
    for (PrecisionRow& row : t.rows) {
      if (row.shared_with.empty()) continue;
      const auto same = std::find_if(t.rows.begin(), t.rows.end(), [&](const PrecisionRow& o) {
        return o.method == row.shared_with && o.status == row.status && o.cells.size() == row.cells.size() &&
               std::equal(o.cells.begin(), o.cells.end(), row.cells.begin(), [](const PrecisionCell& a, const PrecisionCell& b) {
                 return a.met == b.met && a.cpu == b.cpu && a.detail == b.detail;
               });
      });
      for (size_t l = 0; l < row.cells.size(); ++l) {
        PrecisionCell& c = row.cells[l];
        if (same != t.rows.end()) {
          c.cpu = "(" + row.shared_with + "'s run)";
          c.detail = l == 0 ? "the same computation: its walk is " + row.shared_with + "'s, run once" : "";
        } else {
          c.detail += "; the same computation as " + row.shared_with + "'s walk, run once";
        }
      }
    }
  return out;
}

}  // namespace mechbench::harness::report
