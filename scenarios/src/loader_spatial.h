// The spatial sections of a scenario file (kind: spatial; scenarios/FORMAT.md "Spatial scenes"),
// read apart from loader.cc's planar ones so that the two change independently. Internal to the
// loader: LoadScenario calls it, nothing else does.
#pragma once

#include "constant_units.h"
#include "mechbench/model.h"

#include <yaml-cpp/yaml.h>

#include <string>

namespace mechbench::detail {

// Reads points, vectors, bodies, joints, coordinates and gravity of a spatial scene into
// m.spatial and builds m.q_layout; refuses the planar-only keys. The file's constants
// (m.constants) are read before. Drivers, initial conditions, analysis and book values are
// read by the common loader afterwards, against the layout built here. `constant_units`: the
// constants written with unit words, which hold the fields that name them.
void ReadSpatialScene(const YAML::Node& root, const std::string& file, Model& m, const ConstantUnitMap& constant_units);

// After the common sections: the spatial rules that need them (a free scene's masses).
void CheckSpatialScene(const YAML::Node& root, const std::string& file, const Model& m);

}  // namespace mechbench::detail
