// The harness's main job: book checks, runs, work–precision sweeps and stress cases over every
// (scenario, method), as a deterministic list of cases that can be sliced into shards, run in
// parallel worker processes with a time limit each, and merged into one results object
// (harness/report/results.schema.json) that report_render.h turns into files.
//
// A case is the unit of isolation: it runs in its own process (fork), so an engine that aborts
// or hangs costs that case's rows (status "crashed" / "timed_out"), never the report.
#pragma once

#include "mechbench/method.h"
#include "mechbench/model.h"

#include <nlohmann/json.hpp>

#include <functional>
#include <string>
#include <vector>

namespace mechbench::harness {

struct CampaignOptions {
  std::vector<std::string> scenarios;  // names or files; empty = every built-in scenario
  std::vector<std::string> methods;    // empty = every registered method
  bool check = true, run = true, sweep = true, stress = true;
  // The published benchmarks' precision levels (Model::criteria): each method's CPU time to meet
  // each level. With no scenarios named (and not --quick), the benchmark files are added for this
  // and for their book checks alone.
  bool precision = true;
  // The long-chains table (chains.h): every integrating method on the generated N-four-bar up a
  // ladder of N within a small CPU budget. Full reports with no scenarios named only (not --quick).
  bool chains = true;
  std::vector<int> chain_ladder;  // empty: ChainPlan's default ladder (tests: a tiny one)
  double chain_budget = kNaN;     // [s] CPU per method over its rungs; NaN: ChainPlan's default
  bool quick = false;        // fewer scenarios, rungs and repeats: well under a minute
  int repeats = 3;           // sweep: CPU time is the median of this many runs (quick: 1)
  double timeout = 60.0;     // per case [s]: a case still running then is killed ("timed_out")
  int jobs = 1;              // worker processes at once
  int shard = 1, shards = 1; // run the cases whose index % shards == shard − 1
  bool isolate = true;       // false: run cases in this process (tests, debugging)
  bool progress = true;      // progress on stderr (one line, refreshed; a line per 10 % without a TTY)
  // The user's tolerance files merged over harness/tolerances.yaml (--tolerances); the caller
  // installs them (SetUserTolerancesFiles), this names them in the campaign and its results.
  std::vector<std::string> tolerances;
};

struct Case {
  int index = 0;
  std::string id;        // e.g. "sweep/fourbar_free/ode-worldstep-default/step=0.001"
  std::string kind;      // check | run | sweep | stress | stable_step | precision | chain
  std::string scenario;  // the base scenario's name
  std::string file;      // its file
  std::string method;    // "" for check
  std::string variant;   // stress: the variant's id
  double value = kNaN;   // sweep: the rung (step [s] or tolerance)
};

// The cases of a campaign, in a deterministic order (the same for every shard and machine).
std::vector<Case> EnumerateCases(const CampaignOptions& options);

// Names one campaign: the same for every shard of one selection of cases on one build, different
// for another selection, options or commit (FNV-1a over the build's commit, the options that
// change a record, and every case id in order). `merge` refuses shards of different campaigns.
// `total_cases` is set to the number of cases of the whole campaign (every shard together).
std::string CampaignId(const CampaignOptions& options, size_t* total_cases = nullptr);

// Runs one case in this process and returns its records (one or more JSON objects).
std::vector<nlohmann::json> RunCase(const Case& c, const CampaignOptions& options);

// Runs `cases` (already sliced) with options.jobs worker processes; records in case order.
std::vector<nlohmann::json> ExecuteCases(const std::vector<Case>& cases, const CampaignOptions& options);

// The whole results object: build, engines, machine, scenarios (with drawings), methods,
// records and the figures derived from them (CPU time to 1e-3 / 1e-6, order, stable step).
nlohmann::json Assemble(std::vector<nlohmann::json> records, const CampaignOptions& options);

// Runs `fn` in a child process with a time limit. Returns its JSON, or an object
// {"isolation": "crashed"|"timed_out", "detail": "..."} when it died or overran.
nlohmann::json RunIsolated(const std::function<nlohmann::json()>& fn, double timeout_seconds);

// The outcome of one run of a stress case, judged against a reference motion (empty: none) as
// the stress cases judge it: not_applicable, diverged (NaN/Inf or a run that stopped early),
// locked_up (a singular position, a solver that gives up there, or a driven input that stalls),
// crashed (an exception inside the method), loop_opened (scaled ‖Φ‖ > 1e-2), branch_switched,
// inaccurate (position error > tolerance), ok.
struct StressOutcome {
  std::string outcome, detail;
  double t_fail = kNaN;  // [s] when it has one
};
StressOutcome ClassifyRun(const Model& model, const Result& result, const std::vector<Sample>& reference,
                          double tolerance);

// Stress variants: the ids for a base scenario, and the derived model.
struct StressVariant {
  std::string id;           // "mass_ratio=1e6"
  std::string family;       // "mass ratio", "gear ratio", …
  std::string base;         // base scenario name
  std::string description;  // what was changed, in words
  double tolerance = 1e-2;  // relative position error above which the outcome is "inaccurate"
  // "Steps too large": the step [s] every method with Control::kStep runs at (the others are
  // left out of the case); NaN = each method's own settings.
  double step = kNaN;
  std::function<Model(const Model&)> derive;
};
const std::vector<StressVariant>& StressVariants();

}  // namespace mechbench::harness
