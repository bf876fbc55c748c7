// `run` and `check` run each method in its own process (process.h), as the report runs each case:
// an engine that aborts, segfaults or hangs is a row (Status::kCrashed, kTimedOut) with what it
// said on stderr, and the other methods still run. The child pays the method's one-time costs
// first (timing.h) and sends the Result back whole (trajectory included) in a binary form.
#pragma once

#include "mechbench/harness/timing.h"
#include "mechbench/method.h"
#include "mechbench/model.h"

#include <string>

namespace mechbench::harness {

struct IsolatedRun {
  Result result;
  StartupCost startup;
};

// `timeout_seconds` ≤ 0 or NaN: no time limit.
IsolatedRun RunMethodIsolated(const Method& method, const Model& model, const RunOptions& options,
                              double timeout_seconds, bool warm_up);

// The binary form of a Result (and its StartupCost) between processes; Decode throws
// std::runtime_error on a truncated or malformed message.
std::string EncodeRun(const IsolatedRun& run);
IsolatedRun DecodeRun(const std::string& bytes);

}  // namespace mechbench::harness
