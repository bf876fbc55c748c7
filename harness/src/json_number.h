// Internal: a double as JSON, null when it is not finite (JSON has no NaN or infinity), one
// definition for the run records' writers.
#pragma once

#include <nlohmann/json.hpp>

#include <cmath>

namespace mechbench::harness {

inline nlohmann::json JsonNumber(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

}  // namespace mechbench::harness
