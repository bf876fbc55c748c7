// The gate: what one (scenario, method) run means for a CI job. One rule, read alike by `run`'s
// verdict, final line and exit code, the report's exit code and summaries, JUnit and `diff`.
#pragma once

#include <string>

namespace mechbench::harness {

enum class Gate {
  kPass,               // ran to the end, within its tolerance
  kNotApplicable,      // the method cannot do the scene (with its reason)
  kKnownFailure,       // outside (or stopped), listed as a known failure: shown, not failing
  kKnownNoLongerFails, // listed as a known failure, yet within: the entry is stale; not failing
  kOutside,            // outside its tolerance (or diverged, failed): fails
  kStoppedByBudget,    // stopped by its CPU budget before the end: judged nothing past where it
                       // got, so neither a pass nor outside its tolerance; fails (not green)
  kError,              // crashed, timed out, or the scene could not be set up: fails
};

// `status`: the run's status as written (ToString(Status): "ok", "over-budget", …); `within` and
// `known`: its MethodVerdict (within its tolerance; the known failure's reason when listed and
// outside); `stale`: listed as a known failure although within (MethodVerdict::stale).
inline Gate GateOf(const std::string& status, bool within, const std::string& known, const std::string& stale) {
  if (status == "not-applicable") return Gate::kNotApplicable;
  if (!known.empty()) return Gate::kKnownFailure;
  if (status == "over-budget") return Gate::kStoppedByBudget;
  if (status == "crashed" || status == "timed_out" || status == "invalid-scenario") return Gate::kError;
  if (!within || status != "ok") return Gate::kOutside;
  if (!stale.empty()) return Gate::kKnownNoLongerFails;
  return Gate::kPass;
}

// Whether it turns the job red (exit 1, a JUnit failure or error).
inline bool GateFails(Gate g) { return g == Gate::kOutside || g == Gate::kStoppedByBudget || g == Gate::kError; }

// A few words for summaries: "ok", "outside its tolerance", "stopped by its CPU budget", …
inline const char* GateWords(Gate g) {
  switch (g) {
    case Gate::kPass: return "ok";
    case Gate::kNotApplicable: return "n/a";
    case Gate::kKnownFailure: return "known failure";
    case Gate::kKnownNoLongerFails: return "known failure no longer fails: remove the entry";
    case Gate::kOutside: return "outside its tolerance";
    case Gate::kStoppedByBudget: return "stopped by its CPU budget";
    case Gate::kError: return "crashed or timed out";
  }
  return "?";
}

}  // namespace mechbench::harness
