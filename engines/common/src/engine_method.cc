#include "mechbench/engines/engine_method.h"

#include "mechbench/errors.h"

namespace mechbench::engines {

std::optional<std::string> EngineMethod::Applicability(const Model& model) const {
  if (auto why = GraphApplicability(model)) return why;
  try {
    const GraphOrReason g = BuildGraph(model, graph_options_);
    if (!g.graph) return g.reason;
    return EngineReason(model, *g.graph);
  } catch (const ScenarioError&) {
    return std::nullopt;  // an impossible scene: DoRun reports it as such
  }
}

void EngineMethod::DoRun(const Model& model, const RunOptions& options, Result& result) const {
  const GraphOrReason g = BuildGraph(model, graph_options_);
  if (!g.graph) {
    result.status = Status::kNotApplicable;
    result.reason = g.reason;
    return;
  }
  const Graph& graph = *g.graph;
  for (const auto& [k, v] : graph.settings) result.settings[k] = v;
  result.messages.insert(result.messages.end(), graph.notes.begin(), graph.notes.end());
  if (!graph.driven)
    result.messages.push_back("free scene: forward dynamics from the assembled initial state under the scene's loads");
  std::vector<double> times = graph.sample_times;
  if (!options.motion) times.resize(1);
  Observer obs(model, graph);
  size_t k = 0;
  const Recorder record = [&](const std::vector<PlanarState>& states, bool has_acc) {
    MB_ASSERT(k < times.size(), "engine recorded more samples than requested");
    Sample s = obs.Observe(times[k], states, has_acc);
    if (k == 0) result.quantities = obs.InstantQuantities(s, states, has_acc);
    result.trajectory.push_back(std::move(s));
    ++k;
    CheckBudget(options, times[k - 1]);  // throws out of Simulate; its RAII handles clean up
  };
  const ControlValue run_control = EffectiveControl(control(), default_control(), options, LargestInterval(times));
  RecordControl(run_control, result.settings);
  Simulate(graph, times, run_control, record, options, result);
  if (result.ok() && result.trajectory.size() != times.size()) {
    result.status = Status::kFailed;
    result.reason = "the engine returned " + std::to_string(result.trajectory.size()) + " of " +
                    std::to_string(times.size()) + " samples";
  }
}

}  // namespace mechbench::engines
