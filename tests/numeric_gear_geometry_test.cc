// Planet centres from the file's gear geometry (issue 12): the natural-coordinate method's
// p = c + A(φ) s and its derivatives, against the closed form and against the vector method.
#include "mechbench/analytic/analytic_method.h"
#include "mechbench/loader.h"
#include "mechbench/numeric/numeric_method.h"
#include "quantity.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>

namespace mechbench::numeric {
namespace numeric_gear_geometry_test {  // this file's own names (the tests build in unity batches)
namespace {

Model LoadFixture(const std::string& name) { return LoadScenario(std::string(MECHBENCH_TEST_DATA) + "/scenes/" + name); }

TEST(NumericGearGeometry, PlanetCentreOnTheCarriersArm) {
  const Model m = LoadFixture("s6_1_planetary_module.yaml");
  const Result r = MakeNumericMethod()->Run(m);
  ASSERT_TRUE(r.ok()) << r.reason;
  const Joint& sun_planet = m.joints.at(0);
  const double R = sun_planet.Module() * (sun_planet.teeth[0] + sun_planet.teeth[1]) / 2;
  const Eigen::Vector2d c = m.bodies[m.BodyIndex("carrier")].centre;
  const Driver& d = m.drivers.at(0);
  ASSERT_EQ(d.coordinate, "phi_carrier");
  const double phi = d.value, w = d.velocity, al = d.acceleration;
  EXPECT_NEAR(Get(r, "p.planet.x"), c.x() + R * std::cos(phi), 1e-12 * R);
  EXPECT_NEAR(Get(r, "p.planet.y"), c.y() + R * std::sin(phi), 1e-12 * R);
  EXPECT_NEAR(Get(r, "v.planet.x"), -R * w * std::sin(phi), 1e-12 * R * w);
  EXPECT_NEAR(Get(r, "v.planet.y"), R * w * std::cos(phi), 1e-12 * R * w);
  EXPECT_NEAR(Get(r, "a.planet.x"), -R * al * std::sin(phi) - R * w * w * std::cos(phi), 1e-12 * R * w * w);
  EXPECT_NEAR(Get(r, "a.planet.y"), R * al * std::cos(phi) - R * w * w * std::sin(phi), 1e-12 * R * w * w);
}

// Every centre quantity the two methods give, on each fixture with geometry, and none on a file without.
TEST(NumericGearGeometry, AgreesWithTheVectorMethod) {
  for (const char* f : {"s6_1_planetary_module.yaml", "s6_2_epicyclic_arm.yaml", "gear_pair_centres.yaml"}) {
    SCOPED_TRACE(f);
    const Model m = LoadFixture(f);
    const Result num = MakeNumericMethod()->Run(m);
    const Result ana = analytic::MakeAnalyticMethod()->Run(m);
    ASSERT_TRUE(num.ok() && ana.ok()) << num.reason << ana.reason;
    // Relative to the largest of its family (all p.*, all v.*, all a.*), as the harness compares.
    const auto centre = [](const std::string& name) {
      return name.size() > 2 && (name[0] == 'p' || name[0] == 'v' || name[0] == 'a') && name[1] == '.';
    };
    std::map<char, double> largest;
    for (const auto& [name, value] : ana.quantities)
      if (centre(name)) largest[name[0]] = std::max(largest[name[0]], std::fabs(value));
    int compared = 0;
    for (const auto& [name, value] : ana.quantities) {
      if (!centre(name)) continue;
      EXPECT_NEAR(Get(num, name), value, 1e-12 * std::max(1.0, largest[name[0]])) << name;
      ++compared;
    }
    EXPECT_EQ(compared, 9 * static_cast<int>(m.bodies.size()));
  }
  const Result plain = MakeNumericMethod()->Run(LoadScenario(ResolveScenario("s6_1_planetary_case2")));
  for (const auto& [name, value] : plain.quantities) EXPECT_NE(name.rfind("p.", 0), 0u) << name << ": made-up geometry";
}

}  // namespace
}  // namespace numeric_gear_geometry_test
}  // namespace mechbench::numeric
