// The part of every engine method that is not engine-specific: applicability through the graph,
// the graph's settings and notes in the Result, sampling at the model's times, and observing every
// sample in Model::q_layout through the graph's Observer. A variant that integrates in time says
// what a work–precision sweep varies (control(), default_control()); DoRun applies the RunOptions
// override to one run, records "control" and "control_value", and hands the value to Simulate.
#pragma once

#include "mechbench/engines/graph.h"
#include "mechbench/engines/spatial_graph.h"
#include "mechbench/method.h"
#include "mechbench/run_control.h"

#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace mechbench::engines {

// Called by an engine once per requested time, in order, with one state per graph body;
// `has_acc` false when the engine has no acceleration for that sample (q̈ is then left empty).
// An engine that builds the graph's platform (Graph::platform, EngineMethod::PlatformReason)
// records world states instead: the platform's and every graph body's, in the engine's world.
class Recorder {
 public:
  using Planar = std::function<void(const std::vector<PlanarState>&, bool has_acc)>;
  using Spatial = std::function<void(const SpatialState& platform, const std::vector<SpatialState>&, bool has_acc)>;
  Recorder(Planar planar, Spatial spatial) : planar_(std::move(planar)), spatial_(std::move(spatial)) {}
  void operator()(const std::vector<PlanarState>& states, bool has_acc) const { planar_(states, has_acc); }
  void operator()(const SpatialState& platform, const std::vector<SpatialState>& states, bool has_acc) const {
    spatial_(platform, states, has_acc);
  }

 private:
  Planar planar_;
  Spatial spatial_;
};

// Called by an engine on a spatial scene (SimulateSpatial) once per requested time, in order, with
// one world state per spatial graph body; `has_acc` false when it has no accelerations there.
using SpatialRecorder = std::function<void(const std::vector<SpatialState>&, bool has_acc)>;

class EngineMethod : public Method {
 public:
  // The graph's reason, then the engine's (EngineReason); nullopt when it can run. A scene that
  // cannot assemble is left to DoRun, which reports it as an invalid scenario.
  std::optional<std::string> Applicability(const Model& model) const final;
  // EngineComputation at the run's control value, and the graph's options; empty when the engine
  // does not state its computation.
  std::string Computation(const RunOptions& options) const final;

 protected:
  EngineMethod(std::string name, std::string description, GraphOptions graph_options = {})
      : Method(std::move(name), std::move(description)), graph_options_(graph_options) {}
  // The engine's part of Method::Computation at `control` (the value the run would use): the
  // stepper or integrator and every setting in use, an unset one as the engine's default read back
  // from the engine; the same text only for runs that are the same bit for bit. Empty: not stated.
  virtual std::string EngineComputation(const ControlValue& control) const {
    (void)control;
    return {};
  }
  // What this engine (variant) cannot express in `graph`, or nullopt.
  virtual std::optional<std::string> EngineReason(const Model& model, const Graph& graph) const = 0;
  // Why this engine (variant) does not build a graph's platform (Graph::platform), or nullopt when
  // it does: then Simulate mounts the mechanism on the platform and records world states (the
  // Recorder's spatial form). Otherwise the engine runs the planar motion relative to the frame
  // (what q holds), and absolute values are not reported; this reason says why in the notes.
  virtual std::optional<std::string> PlatformReason(const Graph&) const {
    return "this adapter does not build the turning frame's platform";
  }
  // Build the engine model from `graph`, then call `record` at graph.t0 and at every later entry
  // of `times` (times[0] == t0), stepping to each exactly. `control` is the run's step or accuracy
  // (the variant's own, or a RunOptions override; for a step already capped by the largest
  // sample interval): use control.value, never the variant's stored one, and describe it with
  // ControlText. Write every setting that changes the result into result.settings. Set
  // result.status/reason and return early on divergence. Mark the phases of the run's CPU time
  // (Result::cpu) with EnterPhase(options, …): building the engine's world is set-up (the phase
  // Simulate starts in), each stretch of stepping between samples is integration, reading a
  // sample back (and the engine's own work that only the output needs) is observation.
  virtual void Simulate(const Graph& graph, const std::vector<double>& times, const ControlValue& control,
                        const Recorder& record, const RunOptions& options, Result& result) const = 0;
  // Spatial scenes (kind: spatial) through the spatial graph (spatial_graph.h). An engine that
  // simulates them returns true from SimulatesSpatial, says what it cannot express in
  // SpatialEngineReason, and implements SimulateSpatial as Simulate (same times, control, phases
  // and settings), recording world states. The others keep the reason "spatial scenes: not yet
  // in <name> (this engine's adapter has no spatial path)".
  virtual bool SimulatesSpatial() const { return false; }
  virtual std::optional<std::string> SpatialEngineReason(const Model&, const SpatialGraph&) const { return std::nullopt; }
  virtual void SimulateSpatial(const SpatialGraph& graph, const std::vector<double>& times, const ControlValue& control,
                               const SpatialRecorder& record, const RunOptions& options, Result& result) const;

 private:
  void DoRun(const Model& model, const RunOptions& options, Result& result) const final;
  void DoRunSpatial(const Model& model, const RunOptions& options, Result& result) const;
  std::optional<std::string> SpatialApplicability(const Model& model) const;
  GraphOptions graph_options_;
  SpatialGraphOptions spatial_options_;
};

}  // namespace mechbench::engines
