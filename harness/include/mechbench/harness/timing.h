// One way to time a method, used by `run`, the report's cases and the tests alike.
//
// A run's own CPU time comes from Method::Run in phases (Result::cpu: set-up, integration,
// observation). What no single run should pay are the process-wide one-time costs of a method's
// library: dynamic symbol binding, a library's first-call initialisation, the first touch of
// memory its allocator reuses afterwards. WarmUp() pays them before any timed run, in the process
// that then times it, and measures them: the method runs on a short copy of the scene (its first
// sample interval) until two runs in a row cost the same within 20 % (at most kWarmUpRuns), and the
// earlier runs' excess over the last is the one-time cost. One run is not always enough: Bullet's
// first two runs in a fresh process cost 3.7 and 2.7 ms and the third 0.24 ms (glibc raises its
// mmap threshold after the first run frees its large blocks, so the second run's fresh heap pages
// are touched for the first time).
#pragma once

#include "mechbench/method.h"
#include "mechbench/model.h"

#include <nlohmann/json.hpp>

namespace mechbench::harness {

constexpr int kWarmUpRuns = 5;
constexpr double kWarmUpRunBudget = 0.25;  // [s] CPU of each short run at most

struct StartupCost {
  double first = kNaN;   // [s] CPU of the short run in a process that had not run the method
  double again = kNaN;   // [s] the same run once it costs the same twice in a row (the last run)
  double excess = 0;     // [s] Σ over the runs before the last of (run − last): the one-time cost
  int runs = 0;          // short runs made
  bool done = false;     // false: not warmed (already warmed in this process, not applicable, or skipped)
  double one_time() const { return excess; }
};

// Scenes this large (bodies) are not warmed: their set-up, paid twice more, would cost far more
// than the one-time costs it removes, which are then a negligible part of their run.
constexpr int kWarmUpMaxBodies = 50;

// Pays `method`'s one-time costs on a short copy of `model` unless this process already did
// (for any scene). Never throws; a method that fails on the short run is simply not warmed.
StartupCost WarmUp(const Method& method, const Model& model);
// Whether WarmUp has run for this method in this process (a forked child inherits the answer).
bool WarmedInThisProcess(const Method& method);
// What WarmUp does once per method and process, every time it is called: the short runs, each
// stopped by kWarmUpRunBudget at most.
StartupCost MeasureStartup(const Method& method, const Model& model);

// {"setup", "integration", "observation"} [s] of a run, and its steps with the integration CPU per
// step [µs] ("steps", "step_us": null where the method took none).
nlohmann::json CpuJson(const CpuTimes& cpu, long steps);

}  // namespace mechbench::harness
