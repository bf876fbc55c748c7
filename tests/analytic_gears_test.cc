// Gear trains: §6.3 compound train by mesh ratios, §6.1 planetary by Willis' formula.
#include "mechbench/analytic/analytic_method.h"
#include "mechbench/analytic/gears.h"
#include "mechbench/loader.h"
#include "quantity.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

namespace mechbench::analytic {
namespace analytic_gears_test {  // this file's own names (the tests build in unity batches)
namespace {

constexpr double kRpm = 2 * std::numbers::pi / 60;

Model LoadFixture(const std::string& name) {
  return LoadScenario(std::string(MECHBENCH_TEST_DATA) + "/scenes/" + name);
}

// §6.3: Z = 15, 45, 20, 40, 10, 33, all external, 2000 rpm in, here from 0.2 rad with 10 rad/s²
// and the output guessed at 0.5 rad (tests/data/scenes/s6_3_compound_train_accelerating.yaml).
// Book: 2000, −666.67, 333.33, −101.01 rpm; ω_in/ω_out = −19.8.
TEST(AnalyticGears, Section6_3CompoundTrain) {
  const Model m = LoadFixture("s6_3_compound_train_accelerating.yaml");
  const Result r = MakeAnalyticMethod()->Run(m);
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_NEAR(Get(r, "qd.phi1") / kRpm, 2000, 1e-9);
  EXPECT_NEAR(Get(r, "qd.phi23") / kRpm, -2000.0 / 3, 1e-9);
  EXPECT_NEAR(Get(r, "qd.phi45") / kRpm, 2000.0 / 6, 1e-9);
  EXPECT_NEAR(Get(r, "qd.phi6") / kRpm, -2000.0 * 10 / 198, 1e-9);
  EXPECT_NEAR(Get(r, "qd.phi1") / Get(r, "qd.phi6"), -19.8, 1e-12);
  EXPECT_NEAR(Get(r, "qdd.phi6"), -10.0 * 10 / 198, 1e-12);
  EXPECT_NEAR(Get(r, "omega.shaft45"), Get(r, "qd.phi45"), 0);
  // Angles: the output starts at its guess and turns by ratio × the input's displacement.
  ASSERT_EQ(r.trajectory.size(), 31u);
  const Sample& last = r.trajectory.back();
  const double t = last.t, d_in = 2000 * kRpm * t + 0.5 * 10 * t * t;
  EXPECT_NEAR(last.q[m.SlotIndex("phi1")], 0.2 + d_in, 1e-12);
  EXPECT_NEAR(last.q[m.SlotIndex("phi6")], 0.5 + 0.2 * (-10.0 / 198) + d_in * (-10.0 / 198), 1e-12);
}

// §6.1 (Willis: (ω_sun − ω_c)/(ω_ring − ω_c) = −78/30): MG1 = −1859, 3871, −3288 rpm.
TEST(AnalyticGears, Section6_1PlanetaryThreeCases) {
  struct Case { const char* scenario; double carrier, ring, sun_book; };
  for (const Case c : {Case{"s6_1_planetary_case1", 0, 715, -1859}, Case{"s6_1_planetary_case2", 3000, 2665, 3871},
                       Case{"s6_1_planetary_case3", 2185, 4290, -3288}}) {
    SCOPED_TRACE(c.scenario);
    const Model m = LoadScenario(ResolveScenario(c.scenario));
    // The file drives the carrier and the ring at the case's speeds.
    ASSERT_EQ(m.drivers.size(), 2u);
    EXPECT_EQ(m.drivers[0].coordinate, "phi_carrier");
    EXPECT_NEAR(m.drivers[0].velocity / kRpm, c.carrier, 1e-9);
    EXPECT_EQ(m.drivers[1].coordinate, "phi_ring");
    EXPECT_NEAR(m.drivers[1].velocity / kRpm, c.ring, 1e-9);
    const Result r = MakeAnalyticMethod()->Run(m);
    ASSERT_TRUE(r.ok()) << r.reason;
    const double sun = Get(r, "qd.phi_sun") / kRpm;
    EXPECT_NEAR(sun, c.carrier - 78.0 / 30 * (c.ring - c.carrier), 1e-9);
    EXPECT_NEAR(sun, c.sun_book, 0.5) << "carrier " << c.carrier << " ring " << c.ring;
  }
}

// Willis across the carrier: sun and ring known, carrier and planet found.
TEST(AnalyticGears, CarrierFromSunAndRingByWillis) {
  // §6.1 case 1 the other way round: its sun speed (MG1, −1859 rpm) driven instead of the carrier.
  Model m = LoadScenario(ResolveScenario("s6_1_planetary_case1"));
  ASSERT_EQ(m.drivers[0].coordinate, "phi_carrier");
  m.drivers[0].coordinate = "phi_sun";
  m.drivers[0].velocity = -1859 * kRpm;
  const Result r = MakeAnalyticMethod()->Run(m);
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_NEAR(Get(r, "qd.phi_carrier") / kRpm, (-1859 + 78.0 / 30 * 715) / (1 + 78.0 / 30), 1e-9);
  // The planet in the carrier frame: (ω_p − ω_c) = −30/24 (ω_sun − ω_c).
  const double wc = Get(r, "qd.phi_carrier"), ws = Get(r, "qd.phi_sun");
  EXPECT_NEAR(Get(r, "qd.phi_planet") - wc, -30.0 / 24 * (ws - wc), 1e-9);
}

TEST(AnalyticGears, UndeterminedMemberIsNotApplicable) {
  // §6.1 case 1 with only the ring driven: two degrees of freedom, one input.
  Model m = LoadScenario(ResolveScenario("s6_1_planetary_case1"));
  ASSERT_EQ(m.drivers[0].coordinate, "phi_carrier");
  m.drivers.erase(m.drivers.begin());
  const auto why = MakeAnalyticMethod()->Applicability(m);
  ASSERT_TRUE(why.has_value());
  EXPECT_NE(why->find("sun"), std::string::npos) << *why;
}

}  // namespace
}  // namespace analytic_gears_test
}  // namespace mechbench::analytic
