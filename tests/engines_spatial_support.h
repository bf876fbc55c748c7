// What the engines' spatial-graph tests share: a fixture scene by name, its graph (a failed build
// is a test failure with the graph's reason), the bodies' t0 states, the first prismatic joint, a
// method by its registry name.
#pragma once

#include "engines_support.h"
#include "mechbench/engines/spatial_graph.h"
#include "mechbench/harness/registry.h"

#include <string>
#include <vector>

namespace mechbench::engines::testing {

inline Model Scene(const std::string& name) {
  return LoadScenario(std::string(MECHBENCH_TEST_DATA) + "/scenes/" + name + ".yaml");
}

inline SpatialGraph MustBuild(const Model& m) {
  const SpatialGraphOrReason g = BuildSpatialGraph(m);
  EXPECT_TRUE(g.graph.has_value()) << g.reason;
  return g.graph ? *g.graph : SpatialGraph{};
}

inline std::vector<SpatialState> Initial(const SpatialGraph& g) {
  std::vector<SpatialState> st;
  for (const SpatialGraphBody& b : g.bodies) st.push_back(b.initial);
  return st;
}

inline const SpatialGraphJoint* Prismatic(const SpatialGraph& g) {
  for (const SpatialGraphJoint& j : g.joints)
    if (j.type == SpatialJointType::kPrismatic) return &j;
  return nullptr;
}

// A method by its registry name, null when not built.
inline const Method* Find(const std::string& name) {
  static const std::vector<MethodPtr> all = harness::AllMethods();
  for (const MethodPtr& m : all)
    if (m->name() == name) return m.get();
  return nullptr;
}

}  // namespace mechbench::engines::testing
