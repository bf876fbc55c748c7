// One way to time a method, used by `run`, the report's cases and the tests alike.
//
// A run's own CPU time comes from Method::Run in phases (Result::cpu: set-up, integration,
// observation). What no single run should pay are the process-wide one-time costs of a method's
// library: dynamic symbol binding, a library's first-call initialisation, the first touch of
// memory its allocator reuses afterwards. WarmUp() pays them before any timed run, in the process
// that then times it, and measures them: the method runs twice on a short copy of the scene (its
// first sample interval), and the first run's excess over the second is the one-time cost.
#pragma once

#include "mechbench/method.h"
#include "mechbench/model.h"

#include <nlohmann/json.hpp>

namespace mechbench::harness {

struct StartupCost {
  double first = kNaN;  // [s] CPU of the short run in a process that had not run the method
  double again = kNaN;  // [s] the same run again
  bool done = false;    // false: not warmed (already warmed in this process, not applicable, or skipped)
  double one_time() const { return first > again ? first - again : 0.0; }
};

// Scenes this large (bodies) are not warmed: their set-up, paid twice more, would cost far more
// than the one-time costs it removes, which are then a negligible part of their run.
constexpr int kWarmUpMaxBodies = 50;

// Pays `method`'s one-time costs on a short copy of `model` unless this process already did
// (for any scene). Never throws; a method that fails on the short run is simply not warmed.
StartupCost WarmUp(const Method& method, const Model& model);

// {"setup", "integration", "observation"} [s] of a run, and its steps with the integration CPU per
// step [µs] ("steps", "step_us": null where the method took none).
nlohmann::json CpuJson(const CpuTimes& cpu, long steps);

}  // namespace mechbench::harness
