// Planet centres from the file's gear geometry (issue 12): the vector method's ω × r against the
// closed form written out by hand from the fixture's numbers.
#include "mechbench/analytic/analytic_method.h"
#include "mechbench/loader.h"
#include "quantity.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace mechbench::analytic {
namespace analytic_gear_geometry_test {  // this file's own names (the tests build in unity batches)
namespace {

Model LoadFixture(const std::string& name) { return LoadScenario(std::string(MECHBENCH_TEST_DATA) + "/scenes/" + name); }

const Driver& DriverOf(const Model& m, const std::string& coordinate) {
  for (const Driver& d : m.drivers)
    if (d.coordinate == coordinate) return d;
  ADD_FAILURE() << "no driver of " << coordinate;
  return m.drivers.front();
}

// s6_1 case 2 with module 1.5 mm: the planet's centre is on the arm m (Z_sun + Z_planet) / 2 from
// the carrier's axis c, at the carrier's angle φ (0.3 rad at t0, 3000 rpm, 50 rad/s²):
//   p = c + R (cos φ, sin φ),  v = R ω (−sin φ, cos φ),  a = R α (−sin φ, cos φ) − R ω² (cos φ, sin φ).
TEST(AnalyticGearGeometry, PlanetCentreOnTheCarriersArm) {
  const Model m = LoadFixture("s6_1_planetary_module.yaml");
  const Result r = MakeAnalyticMethod()->Run(m);
  ASSERT_TRUE(r.ok()) << r.reason;
  const Joint& sun_planet = m.joints.at(0);
  const double R = sun_planet.Module() * (sun_planet.teeth[0] + sun_planet.teeth[1]) / 2;
  const Eigen::Vector2d c = m.bodies[m.BodyIndex("carrier")].centre;
  const Driver& d = DriverOf(m, "phi_carrier");
  const double phi = d.value, w = d.velocity, al = d.acceleration;
  const double tol = 1e-12 * R * w * w;
  EXPECT_NEAR(Get(r, "p.planet.x"), c.x() + R * std::cos(phi), 1e-12 * R);
  EXPECT_NEAR(Get(r, "p.planet.y"), c.y() + R * std::sin(phi), 1e-12 * R);
  EXPECT_NEAR(Get(r, "p.planet.z"), 0, 0);
  EXPECT_NEAR(Get(r, "v.planet.x"), -R * w * std::sin(phi), 1e-12 * R * w);
  EXPECT_NEAR(Get(r, "v.planet.y"), R * w * std::cos(phi), 1e-12 * R * w);
  EXPECT_NEAR(Get(r, "a.planet.x"), -R * al * std::sin(phi) - R * w * w * std::cos(phi), tol);
  EXPECT_NEAR(Get(r, "a.planet.y"), R * al * std::cos(phi) - R * w * w * std::sin(phi), tol);
  // The sun, the ring and the carrier turn on the fixed axis: their centres stay at c.
  for (const std::string b : {"sun", "ring", "carrier"}) {
    EXPECT_EQ(Get(r, "p." + b + ".x"), c.x()) << b;
    EXPECT_EQ(Get(r, "p." + b + ".y"), c.y()) << b;
    EXPECT_EQ(Get(r, "v." + b + ".x"), 0) << b;
    EXPECT_EQ(Get(r, "a." + b + ".y"), 0) << b;
  }
}

// The geometry changes no rate: the members turn as in the book's file without it.
TEST(AnalyticGearGeometry, RatesAsWithoutGeometry) {
  const Result with = MakeAnalyticMethod()->Run(LoadFixture("s6_1_planetary_module.yaml"));
  const Result without = MakeAnalyticMethod()->Run(LoadScenario(ResolveScenario("s6_1_planetary_case2")));
  ASSERT_TRUE(with.ok() && without.ok());
  for (const char* q : {"qd.phi_sun", "qd.phi_planet", "qd.phi_ring", "qd.phi_carrier"})
    EXPECT_NEAR(Get(with, q), Get(without, q), 1e-12 * std::fabs(Get(without, q))) << q;
  for (const auto& [name, value] : without.quantities) EXPECT_NE(name.rfind("p.", 0), 0u) << name << ": made-up geometry";
}

// §6.2's arm-driven epicyclic train: the compound planet's centre moves at arm × ω_arm, whatever
// the planet's own spin.
TEST(AnalyticGearGeometry, EpicyclicPlanetSpeedIsArmTimesOmega) {
  const Model m = LoadFixture("s6_2_epicyclic_arm.yaml");
  const Result r = MakeAnalyticMethod()->Run(m);
  ASSERT_TRUE(r.ok()) << r.reason;
  const double arm = m.bodies[m.BodyIndex("arm")].arm, w = DriverOf(m, "phi_arm").velocity;
  EXPECT_NEAR(std::hypot(Get(r, "v.planet.x"), Get(r, "v.planet.y")), arm * w, 1e-12 * arm * w);
  EXPECT_NEAR(std::hypot(Get(r, "a.planet.x"), Get(r, "a.planet.y")), arm * w * w, 1e-12 * arm * w * w);
  EXPECT_NE(Get(r, "omega.planet"), Get(r, "omega.arm"));  // it spins on its own axis as well
}

}  // namespace
}  // namespace analytic_gear_geometry_test
}  // namespace mechbench::analytic
