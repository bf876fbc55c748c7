#include "reach.h"

#include "access.h"
#include "results_view.h"
#include "text.h"

#include <algorithm>
#include <map>
#include <set>
#include <utility>

namespace mechbench::harness::report {

bool IsTuned(const std::string& method) {
  static const std::string kSuffix = "-tuned";
  return method.size() >= kSuffix.size() && method.compare(method.size() - kSuffix.size(), kSuffix.size(), kSuffix) == 0;
}

std::optional<double> Median(std::vector<double> v) {
  if (v.empty()) return std::nullopt;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

int MethodReach::reached(int level) const {
  return static_cast<int>(std::count_if(scenes.begin(), scenes.end(), [level](const SceneReach& s) {
    return s.cpu[level].has_value();
  }));
}

std::optional<double> MethodReach::median_cpu(int level) const {
  std::vector<double> v;
  for (const SceneReach& s : scenes)
    if (s.cpu[level]) v.push_back(*s.cpu[level]);
  return Median(std::move(v));
}

int MethodReach::not_judged() const {
  return static_cast<int>(std::count_if(scenes.begin(), scenes.end(), [](const SceneReach& s) { return s.NotJudged(); }));
}

std::string NotJudgedNote(const MethodReach& m) {
  for (const SceneReach& s : m.scenes)
    if (s.NotJudged()) return s.unjudged_note.empty() ? "no reference on " + s.scenario : s.unjudged_note;
  return "";
}

std::string ReachedOf(const MethodReach& m, int level) {
  const int nj = m.not_judged();
  return std::to_string(m.reached(level)) + " of " + std::to_string(m.scenes.size()) +
         (nj ? ", " + std::to_string(nj) + " not judged" : "");
}

std::string ReachedWhere(const MethodReach& m, int level) {
  std::vector<std::string> yes, no;
  for (const SceneReach& s : m.scenes) (s.cpu[level] ? yes : no).push_back(s.scenario);
  if (yes.empty() || no.empty()) return "";
  auto join = [](const std::vector<std::string>& v) {
    std::string out;
    for (const auto& s : v) out += (out.empty() ? "" : ", ") + s;
    return out;
  };
  if (yes.size() <= 2) return "only " + join(yes);
  if (no.size() <= 2) return "not " + join(no);
  return "";
}

std::optional<double> BestError(const MethodReach& m) {
  std::optional<double> best;
  for (const SceneReach& s : m.scenes)
    if (s.best_error && (!best || *s.best_error < *best)) best = s.best_error;
  return best;
}

std::string MedianCpuText(const MethodReach& m, int level) {
  if (m.scenes.empty()) return kDash;
  if (auto median = m.median_cpu(level)) {
    // Scenes where this level's CPU is another method's run (the same computation): not a second measurement.
    std::set<std::string> with;
    int shared = 0;
    for (const SceneReach& s : m.scenes)
      if (s.cpu[level] && !s.shared[level].empty()) ++shared, with.insert(s.shared[level]);
    std::string names;
    for (const std::string& w : with) names += (names.empty() ? "" : ", ") + w;
    return FmtSeconds(median) + (shared ? " (on " + std::to_string(shared) + " of them " + names + "'s run, shared)" : "");
  }
  const auto best = BestError(m);
  if (!best && m.not_judged()) return "not judged (" + NotJudgedNote(m) + ")";
  return best ? "never (best q error " + FmtErr(best) + ")" : "never (no rung finished)";
}

Reach ReachAcrossScenes(const json& results) {
  // The sweep ladders: rungs run and finished, the best error, per (scene, method); and, for a
  // results object without `derived` (written by hand: Assemble always writes it), the CPU to
  // each level by Assemble's rule, so a missing row never reads as "never reached".
  constexpr double kLevelError[2] = {1e-3, 1e-6};
  std::map<std::pair<std::string, std::string>, SceneReach> ladder;
  std::map<std::pair<std::string, std::string>, std::optional<double>[2]> from_records;
  std::vector<std::string> seen_methods;
  for (const auto& r : Arr(At(results, "records"))) {
    if (Str(r, "kind") != "sweep") continue;
    const std::string status = Str(r, "status");
    if (status == "not-applicable") continue;
    const std::string s = Str(r, "scenario"), m = Str(r, "method");
    SceneReach& l = ladder[{s, m}];
    l.scenario = s;
    ++l.rungs;
    if (std::find(seen_methods.begin(), seen_methods.end(), m) == seen_methods.end()) seen_methods.push_back(m);
    const auto err = Num(At(At(r, "error"), "q_max"));
    const auto cpu = At(r, "cpu").is_object() ? Num(At(At(r, "cpu"), "integration")) : Num(At(r, "cpu_seconds"));
    if (status == "ok" && err && cpu)
      for (int k = 0; k < 2; ++k) {
        auto& best = from_records[{s, m}][k];
        if (*err <= kLevelError[k] && (!best || *cpu < *best)) best = cpu;
      }
    if (status == "ok" && !At(r, "error").is_object()) {
      // Ran, with nothing to judge it against: its record says why (reference_note).
      ++l.unjudged;
      if (l.unjudged_note.empty()) l.unjudged_note = Str(r, "reference_note");
    }
    if (status != "ok" || !err || *err <= 0) continue;
    ++l.finished;
    if (!l.best_error || *err < *l.best_error) l.best_error = err;
  }
  // The CPU to each level, the order and the largest stable step: `derived`.
  std::set<std::pair<std::string, std::string>> derived;
  for (const auto& d : Arr(At(results, "derived"))) {
    auto it = ladder.find({Str(d, "scenario"), Str(d, "method")});
    if (it == ladder.end()) continue;  // a stable-step figure without a sweep
    derived.insert(it->first);
    for (int k = 0; k < 2; ++k)
      if (auto v = Num(At(d, kLevels[k].derived)); v && *v >= 0) it->second.cpu[k] = v;
    it->second.order = Num(At(d, "order"));
    it->second.tolerance_slope = Num(At(d, "tolerance_slope"));
    for (int k = 0; k < 2; ++k) it->second.shared[k] = Str(d, (std::string("shared_at_") + kLevels[k].label).c_str());
    it->second.largest_stable = Num(At(d, "largest_stable"));
  }
  for (auto& [key, l] : ladder)
    if (!derived.count(key))
      for (int k = 0; k < 2; ++k) l.cpu[k] = from_records[key][k];

  Reach out;
  for (const ScenarioRef& s : Scenarios(results)) {
    const bool swept = std::any_of(ladder.begin(), ladder.end(), [&s](const auto& e) { return e.first.first == s.name; });
    if (swept) out.scenes.push_back(s.name);
  }
  std::vector<std::string> listed;
  for (const auto& m : Arr(At(results, "methods"))) listed.push_back(Str(m, "method"));
  for (const auto& m : seen_methods)
    if (std::find(listed.begin(), listed.end(), m) == listed.end()) listed.push_back(m);
  std::vector<std::string> names;
  for (const auto& m : OrderMethods(results, listed))
    if (!m.empty() && std::find(names.begin(), names.end(), m) == names.end()) names.push_back(m);
  for (const auto& m : names) {
    MethodReach mr;
    mr.method = m;
    mr.tuned = IsTuned(m);
    for (const auto& s : out.scenes)
      if (auto it = ladder.find({s, m}); it != ladder.end()) mr.scenes.push_back(it->second);
    out.methods.push_back(std::move(mr));
  }
  return out;
}

}  // namespace mechbench::harness::report
