// The engine-neutral multibody graph (engines/common): translation of the book's scenes into
// bodies, joints, a spanning tree with loop closures, driver maps and the observation map.
#include "mechbench/engines/graph.h"
#include "mechbench/loader.h"
#include "mechbench/numeric/numeric_method.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace mechbench::engines {
namespace engines_graph_test {  // this file's own names (the tests build in unity batches)
namespace {

constexpr double kPi = std::numbers::pi;

Model Load(const std::string& name) { return LoadScenario(ResolveScenario(name)); }

Graph MustBuild(const Model& m) {
  GraphOrReason g = BuildGraph(m);
  EXPECT_TRUE(g.graph.has_value()) << g.reason;
  return g.graph ? *g.graph : Graph{};
}

int CountType(const Graph& g, PairType t, bool tree) {
  int n = 0;
  for (const GraphJoint& j : g.joints) n += j.type == t && j.in_tree == tree;
  return n;
}

std::vector<PlanarState> InitialStates(const Graph& g) {
  std::vector<PlanarState> st;
  for (const GraphBody& b : g.bodies) st.push_back(b.initial);
  return st;
}

// Every joint holds at t0: revolute points coincide in position and velocity; a prismatic child
// keeps its angle relative to the parent and its point is on the axis.
void ExpectJointsHold(const Graph& g) {
  auto state = [&](int b) { return b < 0 ? PlanarState{} : g.bodies[b].initial; };
  for (const GraphJoint& j : g.joints) {
    if (j.type == PairType::kGear) continue;
    const PlanarState p = state(j.parent), c = state(j.child);
    const double scale = g.length_scale;
    EXPECT_LT((p.PointPos(j.at_parent_B) - c.PointPos(j.at_child_B)).norm(), 1e-9 * scale) << j.name;
    if (j.type == PairType::kRevolute) {
      EXPECT_LT((p.PointVel(j.at_parent_B) - c.PointVel(j.at_child_B)).norm(), 1e-9 * scale) << j.name;
      EXPECT_NEAR(std::remainder(c.angle - p.angle - j.angle0, 2 * kPi), 0, 1e-12) << j.name;
    } else {
      EXPECT_NEAR(std::remainder(c.angle - p.angle - j.angle0, 2 * kPi), 0, 1e-12) << j.name;
      EXPECT_NEAR(c.omega, p.omega, 1e-9) << j.name;
    }
  }
  // Tree order: every tree joint's parent is ground or the child of an earlier tree joint.
  std::vector<bool> placed(g.bodies.size(), false);
  for (const GraphJoint& j : g.joints) {
    if (!j.in_tree) continue;
    EXPECT_TRUE(j.parent < 0 || placed[j.parent]) << j.name;
    placed[j.child] = true;
  }
  for (size_t b = 0; b < g.bodies.size(); ++b) EXPECT_TRUE(placed[b]) << g.bodies[b].name << " not in the tree";
}

// The observation map reproduces the assembled instant (q, q̇, q̈) from the bodies' t0 states.
void ExpectObservesInstant(const Model& m, const Graph& g, double tol = 1e-10) {
  Observer obs(m, g);
  const Sample s = obs.Observe(g.t0, InitialStates(g));
  ASSERT_EQ(s.q.size(), static_cast<long>(m.q_layout.size()));
  for (size_t i = 0; i < m.q_layout.size(); ++i) {
    const double sc = std::max(1.0, std::fabs(g.initial.q[i]));
    EXPECT_NEAR(s.q[i], g.initial.q[i], tol * sc) << "q." << m.q_layout[i].name;
    EXPECT_NEAR(s.qd[i], g.initial.qd[i], tol * std::max(1.0, std::fabs(g.initial.qd[i]))) << "qd." << m.q_layout[i].name;
    if (g.driven) {
      EXPECT_NEAR(s.qdd[i], g.initial.qdd[i], tol * std::max(1.0, std::fabs(g.initial.qdd[i]))) << "qdd." << m.q_layout[i].name;
    }
  }
  // ... and the numeric method's instant.
  const Result r = numeric::MakeNumericMethod()->Run(m, {.motion = false});
  if (g.driven) {
    ASSERT_TRUE(r.ok()) << r.reason;
    EXPECT_LT((r.trajectory[0].q - s.q).cwiseAbs().maxCoeff(), 1e-9 * g.length_scale);
  }
}

TEST(EngineGraph, CrankRockerFourBar) {
  const Model m = Load("fourbar_crank_rocker");
  const Graph g = MustBuild(m);
  // crank, coupler, rocker; pins at A (ground), 1, 2, B (ground); one of them closes the loop.
  EXPECT_EQ(g.bodies.size(), 3u);
  EXPECT_EQ(CountType(g, PairType::kRevolute, true), 3);
  EXPECT_EQ(CountType(g, PairType::kRevolute, false), 1);
  ASSERT_EQ(g.drivers.size(), 1u);
  const GraphJoint& dj = g.joints[g.drivers[0].joint];
  EXPECT_EQ(dj.parent, -1);
  EXPECT_EQ(g.bodies[dj.child].name, "crank");
  EXPECT_DOUBLE_EQ(g.drivers[0].scale, 1.0);
  EXPECT_NEAR(g.drivers[0].Position(0.25, 0), 2 * kPi * 0.25, 1e-15);
  EXPECT_EQ(g.bodies[0].mass_source, "model");
  EXPECT_EQ(g.sample_times.size(), 73u);
  EXPECT_TRUE(g.driven);
  ExpectJointsHold(g);
  ExpectObservesInstant(m, g);
}

TEST(EngineGraph, TwoSlidersOfSection4_1) {
  const Model m = Load("s4_1_two_sliders");
  const Graph g = MustBuild(m);
  // rod + a block on each guide; prismatics are tree joints, one pin closes the loop.
  EXPECT_EQ(g.bodies.size(), 3u);
  EXPECT_EQ(CountType(g, PairType::kPrismatic, true), 2);
  EXPECT_EQ(CountType(g, PairType::kRevolute, true), 1);
  EXPECT_EQ(CountType(g, PairType::kRevolute, false), 1);
  EXPECT_NE(g.bodies[0].mass_source, "model");  // a kinematic scene: the stated default
  EXPECT_NEAR(g.bodies[0].mass, 15.0, 1e-12);   // 1 kg/m × 15 m
  EXPECT_NEAR(g.bodies[1].mass, 0.15, 1e-12);   // block: 1e-2 × the lightest link
  ASSERT_EQ(g.drivers.size(), 1u);
  // yA is the vertical block's displacement along (0, 1).
  const GraphJoint& dj = g.joints[g.drivers[0].joint];
  EXPECT_EQ(dj.type, PairType::kPrismatic);
  EXPECT_EQ(dj.parent, -1);
  EXPECT_NEAR(dj.axis_parent_B.y(), 1.0, 1e-15);
  EXPECT_NEAR(g.drivers[0].Rate(0, 0), -10.0, 1e-15);
  ExpectJointsHold(g);
  ExpectObservesInstant(m, g);
  // θ uses the cosine form on the negative geometric angle (A→B points down-right): σ = −1.
  Observer obs(m, g);
  const Sample s = obs.Observe(0, InitialStates(g));
  EXPECT_NEAR(s.q[m.SlotIndex("theta")], 35 * kPi / 180, 1e-12);
  EXPECT_NEAR(s.qd[m.SlotIndex("theta")], -0.81378, 1e-4);  // the book's −0.8138 rad/s
}

TEST(EngineGraph, DiscAndSlottedBarOfSection3_4) {
  const Model m = Load("s3_4_disc_slotted_bar");
  const Graph g = MustBuild(m);
  // bar, disc, and the bushing block sliding along the bar, pinned to the disc at 1.
  ASSERT_EQ(g.bodies.size(), 3u);
  EXPECT_EQ(g.bodies[2].kind, BodyKind::kSliderBlock);
  EXPECT_EQ(CountType(g, PairType::kPrismatic, true), 1);
  EXPECT_EQ(CountType(g, PairType::kRevolute, true), 2);
  EXPECT_EQ(CountType(g, PairType::kRevolute, false), 1);
  ASSERT_EQ(g.drivers.size(), 1u);
  EXPECT_EQ(g.bodies[g.joints[g.drivers[0].joint].child].name, "disc");
  EXPECT_NEAR(g.drivers[0].Rate(0, 0), -90 * 2 * kPi / 60, 1e-12);
  // mm scene: the default bar mass is 1 kg/m × 0.25 m.
  EXPECT_NEAR(g.bodies[0].mass, 0.25, 1e-12);
  ExpectJointsHold(g);
  ExpectObservesInstant(m, g);
  // The bar's angular velocity, the book's −1.28 rad/s.
  Observer obs(m, g);
  const Sample s = obs.Observe(0, InitialStates(g));
  const Quantities q = obs.InstantQuantities(s, InitialStates(g), true);
  EXPECT_NEAR(q.at("omega.bar"), -1.28, 0.005);
}

TEST(EngineGraph, CompoundGearTrain) {
  const Model m = Load("s6_3_compound_train");
  const Graph g = MustBuild(m);
  EXPECT_EQ(g.bodies.size(), 4u);
  EXPECT_EQ(CountType(g, PairType::kRevolute, true), 4);
  EXPECT_EQ(CountType(g, PairType::kGear, false), 3);
  const GraphJoint* first = nullptr;
  for (const GraphJoint& j : g.joints)
    if (j.type == PairType::kGear && !first) first = &j;
  ASSERT_NE(first, nullptr);
  EXPECT_EQ(first->z_a, 15);
  EXPECT_EQ(first->z_b, 45);
  EXPECT_EQ(first->carrier, -1);
  ASSERT_EQ(g.drivers.size(), 1u);
  EXPECT_EQ(g.bodies[g.joints[g.drivers[0].joint].child].name, "shaft1");
  ExpectObservesInstant(m, g);
  EXPECT_FALSE(g.notes.empty());  // the fixed-axes statement
}

TEST(EngineGraph, PlanetaryTrainKeepsItsCarrier) {
  const Model m = Load("s6_1_planetary_case1");
  const Graph g = MustBuild(m);
  int with_carrier = 0;
  for (const GraphJoint& j : g.joints) with_carrier += j.type == PairType::kGear && j.carrier >= 0;
  EXPECT_EQ(with_carrier, 2);
  for (const GraphJoint& j : g.joints)
    if (j.type == PairType::kGear && j.name.find("ring") != std::string::npos) {
      EXPECT_LT(j.z_b, 0);  // internal mesh
    }
  EXPECT_EQ(g.drivers.size(), 2u);
}

int BodyNamed(const Graph& g, const std::string& name) {
  for (size_t b = 0; b < g.bodies.size(); ++b)
    if (g.bodies[b].name == name) return static_cast<int>(b);
  ADD_FAILURE() << "no body " << name;
  return 0;
}

// The gear layout at module 2 mm (in m): the planet rides on the carrier, the sun, ring and carrier
// share the axis at the origin, the planet's axis is at (30 + 24)/2 · 2 mm = 54 mm, which is also
// (78 − 24)/2 · 2 mm for the internal mesh; pitch radii 30, 24 and 78 mm.
TEST(EngineGraph, GearLayoutPutsThePlanetOnItsCarrier) {
  const Graph g = MustBuild(Load("s6_1_planetary_case2"));
  const GearLayoutOrReason lay = LayOutGears(g, 2e-3);
  ASSERT_TRUE(lay.layout.has_value()) << lay.reason;
  const GearLayout& L = *lay.layout;
  const int sun = BodyNamed(g, "sun"), planet = BodyNamed(g, "planet"), ring = BodyNamed(g, "ring"),
            carrier = BodyNamed(g, "carrier");
  EXPECT_EQ(L.carrier_of[planet], carrier);
  for (int b : {sun, ring, carrier}) {
    EXPECT_EQ(L.carrier_of[b], -1) << g.bodies[b].name;
    EXPECT_NEAR(L.axis[b].norm(), 0, 1e-15) << g.bodies[b].name;
  }
  EXPECT_NEAR(L.axis[planet].x(), 0.054, 1e-15);
  EXPECT_NEAR(L.axis[planet].y(), 0, 1e-15);
  ASSERT_EQ(L.meshes.size(), 2u);
  for (const GearMeshLayout& m : L.meshes) {
    const GraphJoint& j = g.joints[m.joint];
    EXPECT_EQ(m.planet, planet);
    EXPECT_EQ(m.central, j.parent == planet ? j.child : j.parent);
    EXPECT_NEAR(m.distance, 0.054, 1e-15);
    EXPECT_NEAR(m.module, 2e-3, 1e-15);
    EXPECT_NEAR(m.r_a, 1e-3 * std::fabs(j.z_a), 1e-15);
    EXPECT_NEAR(m.r_b, 1e-3 * std::fabs(j.z_b), 1e-15);
    EXPECT_EQ(m.internal, g.bodies[j.child].name == "ring");
  }
  EXPECT_NE(L.Describe(g).find("planet-ring internal: pitch radii 24 / 78 mm (module 2 mm), centre distance 54 mm, planet on "
                               "carrier carrier"),
            std::string::npos)
      << L.Describe(g);
}

// The arm-driven train: a compound planet (16 and 67 on one shaft) between two central wheels; the
// first mesh sets the orbit, (15 + 16)/2 · 2 mm = 31 mm, and the second mesh (67 + 49 teeth) divides
// the same 31 mm, so its module is 2·31/116 mm.
TEST(EngineGraph, GearLayoutOfACompoundPlanetKeepsOneOrbit) {
  const Graph g = MustBuild(Load("s6_2_epicyclic_train"));
  const GearLayoutOrReason lay = LayOutGears(g, 2e-3);
  ASSERT_TRUE(lay.layout.has_value()) << lay.reason;
  const GearLayout& L = *lay.layout;
  const int planet = BodyNamed(g, "planet");
  EXPECT_EQ(L.carrier_of[planet], BodyNamed(g, "arm"));
  EXPECT_NEAR(L.axis[planet].x(), 0.031, 1e-15);
  ASSERT_EQ(L.meshes.size(), 2u);
  EXPECT_NEAR(L.meshes[1].distance, 0.031, 1e-15);
  EXPECT_NEAR(L.meshes[1].module, 2 * 0.031 / 116, 1e-15);
  EXPECT_NEAR(L.meshes[1].r_a / L.meshes[1].r_b, 67.0 / 49.0, 1e-14);
}

// Fixed axes: along +x from the first member at the centre distances 60, 60 and 43 mm.
TEST(EngineGraph, GearLayoutOfFixedAxesRunsAlongX) {
  const Graph g = MustBuild(Load("s6_3_compound_train"));
  const GearLayoutOrReason lay = LayOutGears(g, 2e-3);
  ASSERT_TRUE(lay.layout.has_value()) << lay.reason;
  const GearLayout& L = *lay.layout;
  const double x[4] = {0, 0.060, 0.120, 0.163};
  const char* names[4] = {"shaft1", "shaft23", "shaft45", "shaft6"};
  for (int k = 0; k < 4; ++k) {
    const int b = BodyNamed(g, names[k]);
    EXPECT_EQ(L.carrier_of[b], -1);
    EXPECT_NEAR(L.axis[b].x(), x[k], 1e-15) << names[k];
    EXPECT_EQ(L.axis[b].y(), 0) << names[k];
  }
  for (const GearMeshLayout& m : L.meshes) {
    EXPECT_EQ(m.planet, -1);
    EXPECT_FALSE(m.internal);
    EXPECT_NEAR(m.module, 2e-3, 1e-15);
  }
}

// What the layout refuses, with its reason: planets meshing on two carriers' sides (an odd cycle of
// meshes on one carrier).
TEST(EngineGraph, GearLayoutRefusesAnOddCycleOnACarrier) {
  Graph g = MustBuild(Load("s6_1_planetary_case1"));
  GraphJoint extra;
  for (const GraphJoint& j : g.joints)
    if (j.type == PairType::kGear && j.z_b > 0) extra = j;  // sun-planet
  extra.child = BodyNamed(g, "ring");                        // sun-ring on the carrier closes a triangle
  extra.name = "gear sun-ring on carrier carrier";
  g.joints.push_back(extra);
  const GearLayoutOrReason lay = LayOutGears(g, 2e-3);
  EXPECT_FALSE(lay.layout.has_value());
  EXPECT_NE(lay.reason.find("odd cycle"), std::string::npos) << lay.reason;
}

TEST(EngineGraph, QuickReturnHasBlocksOnTheRockerAndTheGuide) {
  const Model m = Load("s4_4_quick_return");
  const Graph g = MustBuild(m);
  // crank, rocker, block 1 on the rocker, block 3 on the rocker and block 3 on the guide.
  EXPECT_EQ(g.bodies.size(), 5u);
  EXPECT_EQ(CountType(g, PairType::kPrismatic, true), 3);
  ExpectJointsHold(g);
  ExpectObservesInstant(m, g);
}

TEST(EngineGraph, LinearActuatorIsACylinderAndARod) {
  const Model m = Load("s4_7_linear_actuator");
  const Graph g = MustBuild(m);
  int actuators = 0;
  for (const GraphBody& b : g.bodies) actuators += b.kind == BodyKind::kActuator;
  EXPECT_EQ(actuators, 2);
  ASSERT_EQ(g.drivers.size(), 1u);
  EXPECT_EQ(g.joints[g.drivers[0].joint].type, PairType::kPrismatic);
  EXPECT_NEAR(std::fabs(g.drivers[0].scale), 1.0, 1e-15);
  ExpectJointsHold(g);
  ExpectObservesInstant(m, g);
}

TEST(EngineGraph, RelativeAngleDriversMapToThePinBetweenTheirBodies) {
  for (const char* name : {"s4_3_coupler_motor", "s4_2_six_point_linkage", "s3_2_thumb"}) {
    SCOPED_TRACE(name);
    const Model m = Load(name);
    const Graph g = MustBuild(m);
    for (const DriverMap& d : g.drivers) EXPECT_EQ(g.joints[d.joint].type, PairType::kRevolute) << d.coordinate;
    ExpectJointsHold(g);
    ExpectObservesInstant(m, g);
  }
}

TEST(EngineGraph, FreeFourBarStartsFromItsInitialConditions) {
  const Model m = Load("fourbar_free");
  const Graph g = MustBuild(m);
  EXPECT_FALSE(g.driven);
  EXPECT_TRUE(g.drivers.empty());
  EXPECT_NEAR(g.initial.q[m.SlotIndex("theta")], kPi / 3, 1e-12);
  EXPECT_EQ(g.initial.qd.norm(), 0.0);
  EXPECT_EQ(g.sample_times.size(), 101u);
  EXPECT_NEAR(g.gravity.y(), -9.81, 0);
  ExpectJointsHold(g);
  ExpectObservesInstant(m, g);
}

TEST(EngineGraph, BushingOfSection5_1GetsItsSmallMassAndTheForce) {
  const Model m = Load("s5_1_disc_bar_bushing");
  const Graph g = MustBuild(m);
  ASSERT_EQ(g.forces.size(), 1u);
  EXPECT_EQ(g.forces[0].f_W.x(), -20);
  double block = 0;
  for (const GraphBody& b : g.bodies)
    if (b.kind == BodyKind::kSliderBlock) block = b.mass;
  EXPECT_NEAR(block, 1e-2 * 1.0, 1e-15);  // 1e-2 × the bar's 1 kg
  ExpectJointsHold(g);
}

TEST(EngineGraph, EveryBuiltinSceneTranslatesOrSaysWhy) {
  for (const std::string& f : BuiltinScenarioFiles()) {
    const Model m = LoadScenario(f);
    SCOPED_TRACE(m.name);
    const GraphOrReason g = BuildGraph(m);
    if (!g.graph) {
      EXPECT_FALSE(g.reason.empty());
      continue;
    }
    ExpectJointsHold(*g.graph);
    ExpectObservesInstant(m, *g.graph);
  }
}

}  // namespace
}  // namespace engines_graph_test
}  // namespace mechbench::engines
