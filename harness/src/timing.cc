#include "mechbench/harness/timing.h"

#include <algorithm>
#include <cmath>
#include <vector>
#include <mutex>
#include <set>
#include <string>

namespace mechbench::harness {

namespace {

// The methods this process has warmed, by name.
struct WarmedSet {
  std::mutex mutex;
  std::set<std::string> names;
};
WarmedSet& Warmed() {
  static WarmedSet set;
  return set;
}

}  // namespace

StartupCost WarmUp(const Method& method, const Model& model) {
  {
    std::lock_guard<std::mutex> lock(Warmed().mutex);
    if (!Warmed().names.insert(method.name()).second) return {};
  }
  return MeasureStartup(method, model);
}

bool WarmedInThisProcess(const Method& method) {
  std::lock_guard<std::mutex> lock(Warmed().mutex);
  return Warmed().names.count(method.name()) > 0;
}

StartupCost MeasureStartup(const Method& method, const Model& model) {
  StartupCost cost;
  if (static_cast<int>(model.bodies.size()) > kWarmUpMaxBodies || method.Applicability(model)) return cost;
  Model shortened = model;
  RunOptions options;
  if (model.analysis.HasMotion()) {
    shortened.analysis.samples = 2;
    shortened.analysis.t1 = model.analysis.TimeAt(1);
  } else {
    options.motion = false;
  }
  // A warm-up never holds a run up: its short runs pay the one-time costs in their first
  // milliseconds, and a first sample interval that takes long (a scene followed for 1e6 s in 100
  // samples) is cut short by this budget, which is then what each run costs (no excess).
  options.cpu_budget = kWarmUpRunBudget;
  try {
    std::vector<double> cpu;
    while (static_cast<int>(cpu.size()) < kWarmUpRuns) {
      cpu.push_back(method.Run(shortened, options).cpu_seconds);
      const size_t n = cpu.size();
      if (n >= 2 && cpu[n - 1] <= 1.2 * cpu[n - 2] && cpu[n - 2] <= 1.2 * cpu[n - 1]) break;
    }
    cost.first = cpu.front();
    cost.again = cpu.back();
    cost.runs = static_cast<int>(cpu.size());
    for (size_t k = 0; k + 1 < cpu.size(); ++k) cost.excess += std::max(0.0, cpu[k] - cpu.back());
    cost.done = true;
  } catch (const std::exception&) {
    // Method::Run does not throw for a failing run; anything else leaves the method unwarmed.
  }
  return cost;
}

nlohmann::json CpuJson(const CpuTimes& cpu, long steps) {
  nlohmann::json j = {{"setup", cpu.setup}, {"integration", cpu.integration}, {"observation", cpu.observation}};
  if (steps > 0) {
    j["steps"] = steps;
    j["step_us"] = cpu.integration / static_cast<double>(steps) * 1e6;
  } else {
    j["steps"] = nullptr;
    j["step_us"] = nullptr;
  }
  return j;
}

}  // namespace mechbench::harness
