// Reading scenario files. Every problem is a ScenarioError naming the file, the line and a fix.
#pragma once

#include "mechbench/model.h"

#include <string>
#include <vector>

namespace mechbench {

// Loads and validates one scenario file. Throws ScenarioError.
Model LoadScenario(const std::string& path);
// Same, from text (for tests and the fuzzer); `name` stands for the file in messages.
Model LoadScenarioFromString(const std::string& text, const std::string& name);

// The folder of the built-in scenarios (MECHBENCH_SCENARIO_DIR, or $MECHBENCH_SCENARIOS).
std::string BuiltinScenarioDir();
// Paths of the built-in scenario files, sorted.
std::vector<std::string> BuiltinScenarioFiles();
// Paths of the published benchmarks' files (the folder's benchmarks/), sorted: too long or too
// large for the built-in set, run by path; a report takes their book checks and precision levels.
std::vector<std::string> BenchmarkScenarioFiles();
// A name from `mechbench list` or a path to a file -> a path. Throws ScenarioError if neither.
std::string ResolveScenario(const std::string& name_or_path);

}  // namespace mechbench
