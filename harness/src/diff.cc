#include "mechbench/harness/diff.h"

#include "mechbench/errors.h"
#include "mechbench/format.h"
#include "mechbench/harness/gate.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
#include <map>
#include <set>
#include <sstream>

namespace mechbench::harness {

namespace {

using nlohmann::json;
namespace fs = std::filesystem;

constexpr double kErrorFloor = 1e-12;

// Statuses and outcomes that say the run finished with numbers to judge.
bool Finished(const std::string& s) { return s == "ok" || s == "inaccurate" || s == "over-budget"; }

std::string Str(const json& r, const char* key) {
  const auto it = r.find(key);
  return it != r.end() && it->is_string() ? it->get<std::string>() : std::string();
}

std::optional<double> Number(const json& r, const char* a, const char* b = nullptr) {
  const auto it = r.find(a);
  if (it == r.end()) return std::nullopt;
  const json& v = b ? (it->is_object() && it->contains(b) ? (*it)[b] : json()) : *it;
  if (!v.is_number()) return std::nullopt;
  return v.get<double>();
}

int VerdictRank(const std::string& v) {
  if (v == "agrees") return 0;
  if (v == "last-digit") return 1;
  if (v == "differs") return 2;
  return 3;  // not-computed
}

std::map<std::string, const json*> ById(const json& results) {
  std::map<std::string, const json*> out;
  if (!results.contains("records")) return out;
  for (const json& r : results["records"])
    if (r.is_object() && r.contains("id") && r["id"].is_string()) out[r["id"].get<std::string>()] = &r;
  return out;
}

std::string Sci(double v) { return Fmt(v, 3); }

}  // namespace

json LoadResults(const std::string& path) {
  std::error_code ec;
  const std::string file = fs::is_directory(path, ec) ? (fs::path(path) / "results.json").string() : path;
  std::ifstream in(file);
  if (!in) throw ScenarioError({file, 0}, "cannot read the results", "give a report folder or its results.json");
  json j;
  try {
    in >> j;
  } catch (const std::exception& e) {
    throw ScenarioError({file, 0}, std::string("not JSON: ") + e.what(), "give a report folder or its results.json");
  }
  if (!j.is_object() || !j.contains("records") || !j["records"].is_array())
    throw ScenarioError({file, 0}, "not a mechbench results object (no records)", "give a report folder or its results.json");
  return j;
}

DiffResult Diff(const json& old_results, const json& new_results, const DiffOptions& o) {
  DiffResult d;
  const auto olds = ById(old_results), news = ById(new_results);
  std::map<std::string, std::vector<double>> ratios;
  for (const auto& entry : olds) {
    const std::string& id = entry.first;  // a plain reference: lambdas below capture it
    const auto* const op = entry.second;
    const auto it = news.find(id);
    if (it == news.end()) {
      d.only_old.push_back(id);
      continue;
    }
    ++d.compared;
    const json &a = *op, &b = *it->second;
    const std::string kind = Str(b, "kind");
    auto add = [&](std::string what, std::string was, std::string now, bool regression, std::string where = "") {
      d.rows.push_back({where.empty() ? id : id + " " + where, std::move(what), std::move(was), std::move(now), regression});
      d.regressions += regression;
    };
    if (kind == "check") {
      std::map<std::string, const json*> rows;
      if (a.contains("rows"))
        for (const json& row : a["rows"]) rows[Str(row, "quantity") + " (" + Str(row, "where") + ")"] = &row;
      if (!b.contains("rows")) continue;
      for (const json& row : b["rows"]) {
        const std::string key = Str(row, "quantity") + " (" + Str(row, "where") + ")";
        const auto was = rows.find(key);
        if (was == rows.end()) continue;
        const std::string va = Str(*was->second, "verdict"), vb = Str(row, "verdict");
        if (va != vb) add("verdict", va, vb, VerdictRank(vb) > VerdictRank(va), key);
        const bool agree_a = was->second->value("methods_agree", true), agree_b = row.value("methods_agree", true);
        if (agree_a != agree_b) add("methods agree", agree_a ? "yes" : "no", agree_b ? "yes" : "no", agree_a && !agree_b, key);
      }
      continue;
    }
    const char* state = kind == "stress" ? "outcome" : "status";
    const std::string sa = Str(a, state), sb = Str(b, state);
    const bool status_regression = Finished(sa) && !Finished(sb) && sb != "not-applicable" && sb != "not_applicable";
    if (sa != sb && !(kind == "stable_step")) add(state, sa, sb, status_regression);
    if (kind == "run") {
      // A regression is a run that passed the gate (gate.h) and now fails it: newly outside, a
      // known failure whose entry is gone (same numbers, other tolerances), stopped by its budget.
      const bool wa = a.value("within", true), wb = b.value("within", true);
      const Gate ga = GateOf(sa, wa, Str(a, "known"), Str(a, "known_stale")), gb = GateOf(sb, wb, Str(b, "known"), Str(b, "known_stale"));
      const bool regression = !GateFails(ga) && GateFails(gb);
      const auto words = [](bool within, Gate g) {
        return within ? std::string("yes") : g == Gate::kOutside ? std::string("no") : "no (" + std::string(GateWords(g)) + ")";
      };
      if (wa != wb) add("within tolerance", words(wa, ga), words(wb, gb), regression);
      else if (ga != gb && !(sa != sb && status_regression)) add("verdict", GateWords(ga), GateWords(gb), regression);
    }
    if (kind == "stable_step") {
      const auto ha = Number(a, "largest_stable"), hb = Number(b, "largest_stable");
      if (ha.has_value() != hb.has_value() || (ha && hb && std::fabs(*ha - *hb) > 1e-3 * std::fabs(*ha)))
        add("largest stable step", ha ? Sci(*ha) + " s" : "—", hb ? Sci(*hb) + " s" : "—", false);
      continue;
    }
    const auto ea = Number(a, "error", "q_max"), eb = Number(b, "error", "q_max");
    if (ea && eb) {
      const double lo = std::max(*ea, kErrorFloor);
      if (*eb > o.error_factor * lo && *eb > kErrorFloor)
        add("q error", Sci(*ea), Sci(*eb) + " (× " + Fmt(*eb / lo, 3) + ")", true);
      else if (*eb * o.error_factor < *ea && *ea > kErrorFloor)
        add("q error", Sci(*ea), Sci(*eb) + " (÷ " + Fmt(*ea / std::max(*eb, kErrorFloor), 3) + ")", false);
    } else if (ea.has_value() != eb.has_value()) {
      add("q error", ea ? Sci(*ea) : "—", eb ? Sci(*eb) : "—", ea.has_value() && !eb.has_value() && Finished(sa) && !Finished(sb));
    }
    if (kind == "sweep" && sa == "ok" && sb == "ok") {
      // Integration CPU when both have the phases, else the whole run's.
      const auto ca = Number(a, "cpu", "integration") ? Number(a, "cpu", "integration") : Number(a, "cpu_seconds");
      const auto cb = Number(b, "cpu", "integration") ? Number(b, "cpu", "integration") : Number(b, "cpu_seconds");
      if (ca && cb && *ca > 0 && *cb > 0) ratios[Str(b, "method")].push_back(*cb / *ca);
    }
  }
  for (const auto& [id, np] : news)
    if (!olds.count(id)) d.only_new.push_back(id);
  for (auto& [method, v] : ratios) {
    std::sort(v.begin(), v.end());
    d.cpu.push_back({method, static_cast<int>(v.size()), v[v.size() / 2], v.front(), v.back()});
  }
  // The tolerance files each report was judged by (results.json's options): a change of verdict
  // may come from them rather than from the methods.
  const auto files = [](const json& r) {
    std::string out = "harness/tolerances.yaml";
    if (r.contains("options") && r["options"].is_object() && r["options"].contains("tolerances") &&
        r["options"]["tolerances"].is_array())
      for (const json& f : r["options"]["tolerances"])
        if (f.is_string()) out += ", then " + f.get<std::string>();
    return out;
  };
  if (files(old_results) != files(new_results))
    d.tolerances_note = "the two reports were judged by different tolerance files: old " + files(old_results) + "; new " +
                        files(new_results);
  std::stable_sort(d.rows.begin(), d.rows.end(), [](const DiffRow& x, const DiffRow& y) { return x.regression > y.regression; });
  return d;
}

void PrintDiff(std::ostream& out, const DiffResult& d, bool md) {
  const auto cell = [md](const std::string& s) {
    if (!md) return s;
    std::string t;
    for (char c : s) t += c == '|' ? std::string("\\\\|") : std::string(1, c);
    return t;
  };
  if (md) out << "## mechbench diff\n\n";
  out << (md ? "" : "mechbench diff: ") << d.compared << " records compared, " << d.rows.size() << " changed, "
      << d.regressions << " regression(s)";
  if (!d.only_old.empty() || !d.only_new.empty())
    out << "; " << d.only_old.size() << " only in the old report, " << d.only_new.size() << " only in the new";
  out << (md ? "\n\n" : "\n");
  if (!d.tolerances_note.empty()) out << (md ? "" : "  ") << d.tolerances_note << (md ? "\n\n" : "\n");
  if (!d.rows.empty()) {
    if (md) {
      out << "| | case | what | old | new |\n|---|---|---|---|---|\n";
      for (const DiffRow& r : d.rows)
        out << "| " << (r.regression ? "**regression**" : "") << " | `" << cell(r.id) << "` | " << cell(r.what) << " | "
            << cell(r.old_value) << " | " << cell(r.new_value) << " |\n";
      out << "\n";
    } else {
      for (const DiffRow& r : d.rows)
        out << (r.regression ? "  REGRESSION " : "  changed    ") << r.id << ": " << r.what << " " << r.old_value << " -> "
            << r.new_value << "\n";
    }
  }
  if (!d.cpu.empty()) {
    if (md) out << "Integration CPU, new ÷ old, over the sweep rungs ok in both:\n\n| method | rungs | median | range |\n|---|---|---|---|\n";
    else out << "integration CPU, new / old, over the sweep rungs ok in both:\n";
    for (const CpuRatio& c : d.cpu) {
      if (md)
        out << "| `" << cell(c.method) << "` | " << c.rungs << " | " << Fmt(c.median, 3) << " | " << Fmt(c.lowest, 3) << " … "
            << Fmt(c.highest, 3) << " |\n";
      else
        out << "  " << c.method << std::string(c.method.size() < 30 ? 30 - c.method.size() : 1, ' ') << Fmt(c.median, 3)
            << " (" << c.rungs << " rungs, " << Fmt(c.lowest, 3) << " … " << Fmt(c.highest, 3) << ")\n";
    }
    if (md) out << "\n";
  }
  const auto list = [&](const char* title, const std::vector<std::string>& ids) {
    if (ids.empty()) return;
    out << title << " (" << ids.size() << "): ";
    for (size_t k = 0; k < ids.size() && k < 10; ++k) out << (k ? ", " : "") << (md ? "`" + ids[k] + "`" : ids[k]);
    if (ids.size() > 10) out << ", … and " << ids.size() - 10 << " more";
    out << (md ? "\n\n" : "\n");
  };
  list("only in the old report", d.only_old);
  list("only in the new report", d.only_new);
}

}  // namespace mechbench::harness
