// Views of the results object shared by the writers: counts of verdicts, runs and outcomes, the
// scenarios in order, a scenario's records of one kind, the methods in the registry's order.
#pragma once

#include <nlohmann/json.hpp>

#include <map>
#include <string>
#include <utility>
#include <vector>

namespace mechbench::harness::report {

using json = nlohmann::json;

extern const std::vector<std::string> kVerdicts;
extern const std::vector<std::string> kOutcomes;

struct RunCounts {
  int ok = 0, outside = 0, known = 0, failed = 0, not_applicable = 0;
  int not_ok() const { return outside + failed; }
};

struct Counts {
  std::map<std::string, int> verdicts;
  RunCounts runs;
  std::map<std::string, int> outcomes;  // stress records
  int sweeps = 0, sweeps_ok = 0, stable_steps = 0;
};

// A run record: ok and within tolerance, outside it (known or not), failed, or not applicable.
void CountRun(const json& r, RunCounts& c);
// Over the records of one scenario, or of all when `scenario` is null.
Counts Count(const json& records, const std::string* scenario);
// Ordered list of the keys of a count map: the known ones in their order, then any others.
std::vector<std::pair<std::string, int>> Ordered(const std::map<std::string, int>& m,
                                                 const std::vector<std::string>& order);
std::string JoinCounts(const std::vector<std::pair<std::string, int>>& v);
std::string RunsText(const RunCounts& r);

// The scenario names in `scenarios` order, then any that only records mention.
struct ScenarioRef {
  std::string name;
  const json* info = nullptr;  // the `scenarios` entry, or null
};
std::vector<ScenarioRef> Scenarios(const json& results);
std::vector<const json*> RecordsOf(const json& results, const std::string& scenario, const std::string& kind);
// Method names in the order the `methods` list gives them, then others in first-seen order.
std::vector<std::string> OrderMethods(const json& results, const std::vector<std::string>& seen);

}  // namespace mechbench::harness::report
