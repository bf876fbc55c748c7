// Gear geometry when the file gives it (issue 12): a mesh's module or radii, members' centres, a
// carrier's arm and planets, resolved by the loader into Model::gear_axes and each mesh's radii.
#include "mechbench/loader.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace mechbench {
namespace scenarios_gear_geometry_test {  // this file's own names (the tests build in unity batches)
namespace {

Model LoadFixture(const std::string& name) { return LoadScenario(std::string(MECHBENCH_TEST_DATA) + "/scenes/" + name); }

const Joint& MeshBetween(const Model& m, const std::string& a, const std::string& b) {
  for (const Joint& j : m.joints)
    if (j.type == JointType::kGear && j.members[0] == m.BodyIndex(a) && j.members[1] == m.BodyIndex(b)) return j;
  ADD_FAILURE() << "no mesh " << a << "-" << b;
  return m.joints.front();
}

// The book's gear trains give tooth counts only: no geometry, and none made up.
TEST(GearGeometry, BookTrainsHaveNone) {
  for (const std::string& f : BuiltinScenarioFiles()) {
    const Model m = LoadScenario(f);
    if (m.kind != ScenarioKind::kGearTrain) continue;
    SCOPED_TRACE(f);
    EXPECT_TRUE(m.gear_axes.empty());
    for (const Joint& j : m.joints) EXPECT_TRUE(std::isnan(j.radii[0]) && std::isnan(j.radii[1])) << j.name;
  }
}

// One module on both meshes: r = m Z / 2; the planet's axis rides on the carrier at the centre
// distance m (Z_sun + Z_planet) / 2, which the ring's internal mesh m (Z_ring − Z_planet) / 2 agrees with.
TEST(GearGeometry, ModuleGivesRadiiAndThePlanetsArm) {
  const Model m = LoadFixture("s6_1_planetary_module.yaml");
  const Joint& sp = MeshBetween(m, "sun", "planet");
  const Joint& pr = MeshBetween(m, "planet", "ring");
  const double module = sp.Module();
  EXPECT_DOUBLE_EQ(module, pr.Module());
  EXPECT_DOUBLE_EQ(sp.radii[0], module * sp.teeth[0] / 2);
  EXPECT_DOUBLE_EQ(sp.radii[1], module * sp.teeth[1] / 2);
  EXPECT_DOUBLE_EQ(pr.radii[1], module * pr.teeth[1] / 2);
  ASSERT_EQ(m.gear_axes.size(), m.bodies.size());
  const int planet = m.BodyIndex("planet"), carrier = m.BodyIndex("carrier");
  const Eigen::Vector2d axis = m.bodies[carrier].centre;
  EXPECT_TRUE(axis.allFinite());
  for (const char* central : {"sun", "ring", "carrier"}) {
    const GearAxis& g = m.gear_axes[m.BodyIndex(central)];
    EXPECT_EQ(g.carrier, -1) << central;
    EXPECT_TRUE(g.Known()) << central;
    EXPECT_EQ(g.centre, axis) << central;
  }
  const GearAxis& p = m.gear_axes[planet];
  EXPECT_EQ(p.carrier, carrier);
  EXPECT_EQ(p.centre, axis);
  EXPECT_NEAR(p.arm, sp.radii[0] + sp.radii[1], 1e-12);
  EXPECT_NEAR(p.arm, pr.radii[1] - pr.radii[0], 1e-12);
  EXPECT_GE(m.bodies[carrier].planets, 1);
}

// An arm without a module: each mesh takes the radii that put its centre distance at the arm,
// r = arm Z / (Z_a + Z_b), so the compound planet's two meshes have different modules.
TEST(GearGeometry, ArmGivesEachMeshItsRadii) {
  const Model m = LoadFixture("s6_2_epicyclic_arm.yaml");
  const double arm = m.bodies[m.BodyIndex("arm")].arm;
  ASSERT_GT(arm, 0);
  for (const Joint& j : m.joints) {
    SCOPED_TRACE(j.name);
    EXPECT_NEAR(j.radii[0] + j.radii[1], arm, 1e-12);
    EXPECT_NEAR(j.radii[0] / j.radii[1], static_cast<double>(j.teeth[0]) / j.teeth[1], 1e-14);
    EXPECT_NEAR(j.Module(), 2 * arm / (j.teeth[0] + j.teeth[1]), 1e-14);
  }
  EXPECT_EQ(m.gear_axes[m.BodyIndex("planet")].carrier, m.BodyIndex("arm"));
  EXPECT_DOUBLE_EQ(m.gear_axes[m.BodyIndex("planet")].arm, arm);
}

// Two fixed axes and no module: the centre distance gives the radii.
TEST(GearGeometry, CentresGiveTheRadiiOfAFixedPair) {
  const Model m = LoadFixture("gear_pair_centres.yaml");
  const Joint& j = m.joints.at(0);
  const double d = (m.bodies[j.members[1]].centre - m.bodies[j.members[0]].centre).norm();
  EXPECT_NEAR(j.radii[0] + j.radii[1], d, 1e-12);
  EXPECT_NEAR(j.radii[0] / j.radii[1], static_cast<double>(j.teeth[0]) / j.teeth[1], 1e-14);
  for (const GearAxis& g : m.gear_axes) {
    EXPECT_EQ(g.carrier, -1);
    EXPECT_TRUE(g.Known());
  }
}

}  // namespace
}  // namespace scenarios_gear_geometry_test
}  // namespace mechbench
