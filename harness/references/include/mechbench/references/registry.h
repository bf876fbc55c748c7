// The registry of exact and published references: the motions known in closed form (or by a
// mechanism's own reduced equation) that a scenario names as a property of its mechanism,
// `reference: {exact: NAME}`. They live here, beside the solver and not inside it (as Drake keeps
// its closed-form benchmarks in multibody/benchmarks/ beside the plant): numeric/ stays generic
// and only confirms what the registry hands it (numeric::ReferenceFromExact, its index-1 DOPRI5
// segments). See harness/references/README.md for why the registry is a library of its own here.
#pragma once

#include "mechbench/model.h"
#include "mechbench/numeric/reference.h"

#include <string>
#include <vector>

namespace mechbench::references {

struct Entry {
  std::string name;       // the key a scenario writes: reference: {exact: NAME}
  std::string describes;  // the structure its closed form describes
  std::string source;     // where the closed form comes from
};
const std::vector<Entry>& Entries();

// Throws ScenarioError (file, line, fix) when the scene names an exact reference the registry does
// not know (with the list of known ones), or one whose structure its scene does not have (with the
// reason, found from the geometry and topology, never from names). A scene that names none passes.
void Validate(const Model& model);
// LoadScenario(path) then Validate: how the harness reads a scene.
Model LoadScenarioValidated(const std::string& path);

// The scene's named exact motion with its confirmation plan (Validate first). Pre: named.
numeric::ExactMotion ExactMotionFor(const Model& model, const numeric::ReferenceOptions& options);

// The reference of a free scene: its named exact motion, confirmed (numeric::ReferenceFromExact),
// or else numeric::ReferenceTrajectory's two formulations.
numeric::Reference ReferenceFor(const Model& model, const numeric::ReferenceOptions& options = {});

}  // namespace mechbench::references
