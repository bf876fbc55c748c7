#include "results_view.h"

#include "access.h"

#include <algorithm>
#include <set>

namespace mechbench::harness::report {

const std::vector<std::string> kVerdicts = {"agrees", "last-digit", "differs", "not-computed"};
const std::vector<std::string> kOutcomes = {"ok", "inaccurate", "diverged", "loop_opened", "branch_switched",
                                            "locked_up", "timed_out", "crashed", "not_applicable",
                                            "invalid_scenario"};

void CountRun(const json& r, RunCounts& c) {
  const std::string status = Str(r, "status");
  const bool within = At(r, "within").is_boolean() ? At(r, "within").get<bool>() : true;
  if (status == "ok") {
    if (within) ++c.ok;
    else {
      ++c.outside;
      if (!Str(r, "known").empty()) ++c.known;
    }
  } else if (status == "not-applicable") {
    ++c.not_applicable;
  } else {
    ++c.failed;
  }
}

Counts Count(const json& records, const std::string* scenario) {
  Counts c;
  for (const auto& r : Arr(records)) {
    if (scenario && Str(r, "scenario") != *scenario) continue;
    const std::string kind = Str(r, "kind");
    if (kind == "check") {
      for (const auto& row : Arr(At(r, "rows"))) ++c.verdicts[Str(row, "verdict")];
    } else if (kind == "run") {
      CountRun(r, c.runs);
    } else if (kind == "sweep") {
      ++c.sweeps;
      if (Str(r, "status") == "ok") ++c.sweeps_ok;
    } else if (kind == "stress") {
      ++c.outcomes[Str(r, "outcome")];
    } else if (kind == "stable_step") {
      ++c.stable_steps;
    }
  }
  return c;
}

// Ordered list of the keys of a count map: the known ones in their order, then any others.
std::vector<std::pair<std::string, int>> Ordered(const std::map<std::string, int>& m,
                                                 const std::vector<std::string>& order) {
  std::vector<std::pair<std::string, int>> out;
  for (const auto& k : order)
    if (auto it = m.find(k); it != m.end() && it->second) out.emplace_back(k, it->second);
  for (const auto& [k, n] : m)
    if (std::find(order.begin(), order.end(), k) == order.end() && n) out.emplace_back(k.empty() ? "?" : k, n);
  return out;
}

std::string JoinCounts(const std::vector<std::pair<std::string, int>>& v) {
  std::string s;
  for (const auto& [k, n] : v) s += (s.empty() ? "" : ", ") + std::to_string(n) + " " + k;
  return s.empty() ? "none" : s;
}

std::string RunsText(const RunCounts& r) {
  std::string s = std::to_string(r.ok) + " ok";
  if (r.outside) {
    s += ", " + std::to_string(r.outside) + " outside tolerance";
    if (r.known) s += " (" + std::to_string(r.known) + " known)";
  }
  if (r.failed) s += ", " + std::to_string(r.failed) + " failed";
  if (r.not_applicable) s += ", " + std::to_string(r.not_applicable) + " not applicable";
  return s;
}

std::vector<ScenarioRef> Scenarios(const json& results) {
  std::vector<ScenarioRef> out;
  std::set<std::string> seen;
  for (const auto& s : Arr(At(results, "scenarios"))) {
    const std::string n = Str(s, "scenario");
    if (seen.insert(n).second) out.push_back({n, &s});
  }
  for (const auto& r : Arr(At(results, "records"))) {
    if (Str(r, "kind") == "chain") continue;  // the generated chains have a table of their own (chains_view.h)
    const std::string n = Str(r, "scenario");
    if (seen.insert(n).second) out.push_back({n, nullptr});
  }
  for (const auto& d : Arr(At(results, "derived"))) {
    const std::string n = Str(d, "scenario");
    if (seen.insert(n).second) out.push_back({n, nullptr});
  }
  return out;
}

std::vector<const json*> RecordsOf(const json& results, const std::string& scenario, const std::string& kind) {
  std::vector<const json*> out;
  for (const auto& r : Arr(At(results, "records")))
    if (Str(r, "scenario") == scenario && Str(r, "kind") == kind) out.push_back(&r);
  return out;
}

// Method names in the order the `methods` list gives them, then others in first-seen order.
std::vector<std::string> OrderMethods(const json& results, const std::vector<std::string>& seen) {
  std::vector<std::string> out;
  std::set<std::string> want(seen.begin(), seen.end());
  for (const auto& m : Arr(At(results, "methods"))) {
    const std::string n = Str(m, "method");
    if (want.count(n) && std::find(out.begin(), out.end(), n) == out.end()) out.push_back(n);
  }
  for (const auto& n : seen)
    if (std::find(out.begin(), out.end(), n) == out.end()) out.push_back(n);
  return out;
}

}  // namespace mechbench::harness::report
