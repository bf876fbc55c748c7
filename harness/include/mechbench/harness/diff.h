// `mechbench diff OLD NEW`: what changed between a baseline report and a new one (two report
// folders or two results.json), the way a team gates an engine upgrade or an edit to its own
// scenarios. Records are matched by their case id.
//
// A regression (exit code 1): a run that passed the gate (gate.h) and fails it now — newly outside
// its tolerance (and not a listed known failure), a known failure no longer listed, a run stopped
// by its CPU budget —
// a record whose status or stress outcome went from ok (or inaccurate) to one that did not finish
// (diverged, failed, crashed, timed_out, …), an error in q that grew past `error_factor` (above a
// floor of 1e-12, round-off), a book value whose methods now disagree or whose verdict got worse.
// Improvements and CPU ratios are shown, never failing: timings are not compared against a limit.
#pragma once

#include <nlohmann/json.hpp>

#include <ostream>
#include <string>
#include <vector>

namespace mechbench::harness {

struct DiffOptions {
  double error_factor = 2.0;
};

struct DiffRow {
  std::string id;        // the case id (and the book row for check records)
  std::string what;      // "status", "within", "outcome", "q error", "verdict", …
  std::string old_value, new_value;
  bool regression = false;
};

struct CpuRatio {
  std::string method;
  int rungs = 0;                         // sweep rungs ok in both, matched by id
  double median = 0, lowest = 0, highest = 0;  // new / old integration CPU
};

struct DiffResult {
  std::vector<DiffRow> rows;
  std::vector<CpuRatio> cpu;
  std::vector<std::string> only_old, only_new;  // case ids found in one report only
  int regressions = 0;
  int compared = 0;  // records found in both
  // Set when the two reports were judged by different tolerance files (results.json options):
  // "the two reports were judged by different tolerance files: old …; new …".
  std::string tolerances_note;
};

// A results.json, or the results.json inside a report folder. Throws ScenarioError naming the
// path when it cannot be read or is not a mechbench results object.
nlohmann::json LoadResults(const std::string& path);

DiffResult Diff(const nlohmann::json& old_results, const nlohmann::json& new_results, const DiffOptions& options = {});

// A table for a terminal, or Markdown for a CI job summary ($GITHUB_STEP_SUMMARY).
void PrintDiff(std::ostream& out, const DiffResult& diff, bool markdown);

}  // namespace mechbench::harness
