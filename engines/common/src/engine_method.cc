#include "mechbench/engines/engine_method.h"

#include "mechbench/errors.h"
#include "mechbench/format.h"

#include <algorithm>

namespace mechbench::engines {
namespace {

// Samples an instant run takes for aabs at t0 (AbsoluteAccelerationsAtT0): t0 and five more.
constexpr size_t kDifferenceSamples = 6;
// Their spacing in an instant-only run: the scene's first sample interval ÷ this.
constexpr double kDifferenceRefinement = 8;

// aabs.<point>.<c> at t0 from vabs at t0 + i Δt, i = 1…5: the derivative at t0 of the quartic
// through those five, a(t0) ≈ (−77 v1 + 214 v2 − 234 v3 + 122 v4 − 25 v5) / (12 Δt). The velocity
// at t0 itself is left out: it is the assembled one the adapter set, not the engine's (a motor
// driver's velocities lag the law by half a step from the first step on).
void AbsoluteAccelerationsAtT0(const std::vector<double>& times, const std::vector<Quantities>& vabs, Quantities& out) {
  static constexpr double kWeight[kDifferenceSamples] = {0, -77, 214, -234, 122, -25};
  const double dt = times[1] - times[0];
  for (const auto& [name, v0] : vabs[0]) {
    if (name.rfind("vabs.", 0) != 0) continue;
    double sum = 0;
    for (size_t i = 1; i < kDifferenceSamples; ++i) sum += kWeight[i] * vabs[i].at(name);
    out["aabs." + name.substr(5)] = sum / (12 * dt);
  }
}

}  // namespace

std::optional<std::string> EngineMethod::SpatialApplicability(const Model& model) const {
  const std::string head = "spatial scenes: not yet in " + name();
  if (!SimulatesSpatial()) return head + " (this engine's adapter has no spatial path)";
  try {
    const SpatialGraphOrReason g = BuildSpatialGraph(model, spatial_options_);
    if (!g.graph) return head + ": " + g.reason;
    if (auto why = SpatialEngineReason(model, *g.graph)) return head + ": " + *why;
    return std::nullopt;
  } catch (const ScenarioError&) {
    return std::nullopt;  // an impossible scene: DoRun reports it as such
  }
}

void EngineMethod::SimulateSpatial(const SpatialGraph&, const std::vector<double>&, const ControlValue&,
                                   const SpatialRecorder&, const RunOptions&, Result&) const {
  MB_ASSERT(false, "SimulateSpatial called on an engine that does not simulate spatial scenes");
}

// A spatial scene: the spatial graph, sampled and observed as DoRun does a planar one (no
// platform: a spatial scene has no turning frame).
void EngineMethod::DoRunSpatial(const Model& model, const RunOptions& options, Result& result) const {
  if (auto why = SpatialApplicability(model)) {
    result.status = Status::kNotApplicable;
    result.reason = *why;
    return;
  }
  const SpatialGraphOrReason g = BuildSpatialGraph(model, spatial_options_);
  MB_ASSERT(g.graph.has_value(), "a spatial graph that was applicable is not built");
  const SpatialGraph& graph = *g.graph;
  for (const auto& [k, v] : graph.settings) result.settings[k] = v;
  result.messages.insert(result.messages.end(), graph.notes.begin(), graph.notes.end());
  // A light body the graph adds (a free scene's slider body, SpatialGraphOptions::slider_mass_ratio):
  // a failing row names it without --verbose (harness/src/main.cc), as it may be why the run failed.
  double total = 0;
  for (const SpatialGraphBody& b : graph.bodies)
    if (b.model_body >= 0) total += b.mass;
  std::string added;
  for (const SpatialGraphBody& b : graph.bodies)
    if (b.model_body < 0 && b.mass < 1e-3 * total)
      added += std::string(added.empty() ? "" : "; ") + "a " + Fmt(b.mass, 3) + " kg body (" + b.name + ")";
  if (!added.empty())
    result.settings["light_bodies"] = "the engines added " + added +
                                      " where a point of a bar or a rigid body slides on a line (--verbose: the note); a "
                                      "body that much lighter than the others may be why this run failed (on a moving line, a "
                                      "sliding rigid body that shares two non-parallel vectors with the line's body "
                                      "needs none: scenarios/FORMAT.md, Spatial scenes)";
  if (!graph.driven)
    result.messages.push_back("free scene: forward dynamics from the assembled initial state under the scene's loads");
  std::vector<double> times = graph.sample_times;
  if (!options.motion) times.resize(1);
  SpatialObserver obs(model, graph);
  size_t k = 0;
  const SpatialRecorder record = [&](const std::vector<SpatialState>& states, bool has_acc) {
    MB_ASSERT(k < times.size(), "engine recorded more samples than requested");
    Sample s = obs.Observe(times[k], states, has_acc);
    if (k == 0) result.quantities = obs.InstantQuantities(s, states, has_acc);
    result.trajectory.push_back(std::move(s));
    ++k;
    CheckBudget(options, times[k - 1]);
  };
  const ControlValue run_control = EffectiveControl(control(), default_control(), options, LargestInterval(times));
  RecordControl(run_control, result.settings);
  SimulateSpatial(graph, times, run_control, record, options, result);
  if (result.ok() && result.trajectory.size() != times.size()) {
    result.status = Status::kFailed;
    result.reason = "the engine returned " + std::to_string(result.trajectory.size()) + " of " +
                    std::to_string(times.size()) + " samples";
  }
}

std::optional<std::string> EngineMethod::Applicability(const Model& model) const {
  if (model.kind == ScenarioKind::kSpatial) return SpatialApplicability(model);
  if (auto why = GraphApplicability(model)) return why;
  try {
    const GraphOrReason g = BuildGraph(model, graph_options_);
    if (!g.graph) return g.reason;
    return EngineReason(model, *g.graph);
  } catch (const ScenarioError&) {
    return std::nullopt;  // an impossible scene: DoRun reports it as such
  }
}

std::string EngineMethod::Computation(const RunOptions& options) const {
  std::string engine;
  try {
    engine = EngineComputation(EffectiveControl(control(), default_control(), options));
  } catch (const std::invalid_argument&) {
    return {};  // an override Run refuses
  }
  if (engine.empty()) return {};
  const GraphOptions& o = graph_options_;
  return engine + "; graph: link " + FullPrecision(o.link_mass_per_length) + " kg/m, block ratio " +
         FullPrecision(o.block_mass_ratio) + ", block radius " + FullPrecision(o.block_radius) + ", point inertia ratio " +
         FullPrecision(o.point_inertia_ratio) + ", gear " + FullPrecision(o.gear_mass) + " kg radius " +
         FullPrecision(o.gear_radius) + " m";
}

void EngineMethod::DoRun(const Model& model, const RunOptions& options, Result& result) const {
  if (model.kind == ScenarioKind::kSpatial) return DoRunSpatial(model, options, result);
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
  const std::optional<std::string> no_platform = graph.platform ? PlatformReason(graph) : std::nullopt;
  const bool on_platform = graph.platform && !no_platform;
  std::vector<double> times = graph.sample_times;
  // The instant alone: one sample; on the platform five, t0 + i δ with δ an eighth of the first
  // sample interval (aabs from the velocities when the engine has no accelerations at t0), of
  // which the trajectory keeps the first.
  const size_t keep = options.motion ? times.size() : 1;
  if (!options.motion && on_platform && times.size() > 1) {
    const double delta = (times[1] - times[0]) / kDifferenceRefinement;
    times.resize(kDifferenceSamples);
    for (size_t i = 0; i < kDifferenceSamples; ++i) times[i] = graph.t0 + static_cast<double>(i) * delta;
  } else if (!options.motion) {
    times.resize(1);
  }
  Observer obs(model, graph);
  size_t k = 0;
  const Recorder::Planar planar = [&](const std::vector<PlanarState>& states, bool has_acc) {
    MB_ASSERT(k < times.size(), "engine recorded more samples than requested");
    Sample s = obs.Observe(times[k], states, has_acc);
    if (k == 0) result.quantities = obs.InstantQuantities(s, states, has_acc);
    result.trajectory.push_back(std::move(s));
    ++k;
    CheckBudget(options, times[k - 1]);  // throws out of Simulate; its RAII handles clean up
  };
  // With the platform: the planar sample relative to it, and the absolute values at t0 from the
  // world states. An engine without accelerations at t0 gets aabs from its world velocities at
  // the first samples (AbsoluteAccelerationsAtT0).
  std::vector<Quantities> first_abs;  // vabs at the first samples, when t0 had no accelerations
  bool abs_acc_at_t0 = false;
  const Recorder::Spatial spatial = [&](const SpatialState& platform, const std::vector<SpatialState>& states,
                                        bool has_acc) {
    MB_ASSERT(graph.platform, "an engine recorded world states for a graph without a platform");
    const size_t at = k;
    Quantities abs;
    if (at < kDifferenceSamples) abs = obs.AbsoluteQuantities(platform, states, has_acc && at == 0);
    planar(RelativeToPlatform(platform, states), has_acc);
    if (at == 0) {
      abs_acc_at_t0 = has_acc;
      result.quantities.insert(abs.begin(), abs.end());
    }
    if (!abs_acc_at_t0 && at < kDifferenceSamples) first_abs.push_back(std::move(abs));
  };
  if (graph.platform && no_platform)
    result.messages.push_back("the frame's own rotation (frame_rotation) is not simulated: " + *no_platform +
                              "; the engine runs the planar motion relative to the frame, which is all q holds "
                              "(absolute values vabs/aabs are not reported)");
  const ControlValue run_control = EffectiveControl(control(), default_control(), options, LargestInterval(times));
  RecordControl(run_control, result.settings);
  Simulate(graph, times, run_control, Recorder(planar, spatial), options, result);
  if (on_platform) {
    result.settings["frame_rotation"] =
        "simulated: the mechanism on a platform body turning about the file's axis (a driven hinge), observed "
        "relative to it for q and in the world for vabs/aabs/omegaabs";
    if (abs_acc_at_t0) {
      result.settings["absolute_accelerations"] = "the engine's world body accelerations at t0";
    } else if (options.motion) {
      result.settings["absolute_accelerations"] =
          "none at t0 (no engine accelerations there); an instant run (check) differences the world velocities";
    } else if (first_abs.size() == kDifferenceSamples) {
      AbsoluteAccelerationsAtT0(times, first_abs, result.quantities);
      result.settings["absolute_accelerations"] =
          "no engine accelerations at t0: aabs at t0 from its world point velocities at t0 + i Δt, i = 1…5 (Δt an "
          "eighth of the first sample interval; the velocity at t0 is the assembled one the adapter set), "
          "(−77 v1 + 214 v2 − 234 v3 + 122 v4 − 25 v5) / (12 Δt), Δt = " + FullPrecision(times[1] - times[0]) +
          " s (the quartic through them)";
    } else {
      result.settings["absolute_accelerations"] = "none: no engine accelerations at t0 and fewer than five samples";
    }
  }
  if (result.ok() && result.trajectory.size() != times.size()) {
    result.status = Status::kFailed;
    result.reason = "the engine returned " + std::to_string(result.trajectory.size()) + " of " +
                    std::to_string(times.size()) + " samples";
  }
  if (result.trajectory.size() > keep) result.trajectory.resize(keep);
}

}  // namespace mechbench::engines
