// Work–precision across the scenes: per (scene, method), whether the method's sweep reached a
// q error of 1e-3 and 1e-6 and at what integration CPU (`derived`, computed from the sweep
// records by Assemble; by the same rule from the records when a results object has no row),
// and per method, on how many of the scenes it was swept on it got there.
// The report's summary figure and table (report.html) and its Markdown table (summary.md) both
// read this, so they cannot disagree.
#pragma once

#include <nlohmann/json.hpp>

#include <optional>
#include <string>
#include <vector>

namespace mechbench::harness::report {

// The accuracy levels the summary follows, with the `derived` member that holds each.
struct Level {
  const char* label;    // "1e-3"
  const char* derived;  // "cpu_to_1e-3"
};
inline constexpr Level kLevels[2] = {{"1e-3", "cpu_to_1e-3"}, {"1e-6", "cpu_to_1e-6"}};

// One method on one scene where it was swept (at least one rung that was not "not-applicable").
struct SceneReach {
  std::string scenario;
  int rungs = 0;                              // sweep rungs run
  int finished = 0;                           // of them: ok with a finite, positive q error
  std::optional<double> best_error;           // the smallest q error over the finished rungs
  std::optional<double> cpu[2];               // [s] integration CPU to each level; none: not reached
  std::optional<double> order, largest_stable;
  std::optional<double> tolerance_slope;
  std::string shared[2];  // the rung behind cpu[level] is this method's run (derived's shared_at_…), or ""  // an error-controlled method's slope against its tolerance (no order)
  // Rungs that ran ok with nothing to judge them against (no reference: e.g. a spatial scene that
  // only numeric runs, which is never its own reference), and the records' reference_note: such a
  // scene is "not judged", never "no rung finished".
  int unjudged = 0;
  std::string unjudged_note;
  bool NotJudged() const { return finished == 0 && unjudged > 0; }
};

struct MethodReach {
  std::string method;
  bool tuned = false;               // an engine's tuned variant (name ends in "-tuned")
  std::vector<SceneReach> scenes;   // in the report's scene order; empty: never swept
  int reached(int level) const;     // scenes with cpu[level]
  int not_judged() const;           // scenes with no finished rung but rungs without a reference
  std::optional<double> median_cpu(int level) const;  // over the scenes reached
};

struct Reach {
  std::vector<std::string> scenes;    // every scene some method was swept on, in report order
  std::vector<MethodReach> methods;   // every method listed or swept, in the registry's order
  bool empty() const { return scenes.empty(); }
};

Reach ReachAcrossScenes(const nlohmann::json& results);

// "2 of 3": the scenes it reached the level on, of those it was swept on ("0 of 1, 1 not judged"
// where a scene had no reference).
// The note of the first scene it was not judged on (SceneReach::unjudged_note), or "".
std::string NotJudgedNote(const MethodReach& m);
std::string ReachedOf(const MethodReach& m, int level);
// The median CPU over the scenes reached in a readable unit (with "; on k of them another method's
// run, shared" when some of those levels were reached by a rung that shared its run), or "never (best q error 5.1e-4)",
// "not judged (no reference: …)" when its rungs ran with nothing to judge them against, or "—"
// when never swept.
std::string MedianCpuText(const MethodReach& m, int level);
// Where, when it reached the level on some of its scenes but not all: "only A" or "only A, B"
// when it reached one or two, "not C" or "not C, D" when it missed one or two, else "".
std::string ReachedWhere(const MethodReach& m, int level);
// The smallest q error over every scene's finished rungs.
std::optional<double> BestError(const MethodReach& m);

// The median of the values (the mean of the middle two for an even count); none when empty.
std::optional<double> Median(std::vector<double> v);

// An engine's tuned variant, by the registry's naming ("ode-worldstep-tuned").
bool IsTuned(const std::string& method);

}  // namespace mechbench::harness::report
