// Gear trains: §6.3 compound train by mesh ratios, §6.1 planetary by Willis' formula.
#include "mechbench/analytic/analytic_method.h"
#include "mechbench/analytic/gears.h"
#include "mechbench/loader.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

namespace mechbench::analytic {
namespace {

constexpr double kRpm = 2 * std::numbers::pi / 60;

double Get(const Result& r, const std::string& name) {
  const auto it = r.quantities.find(name);
  EXPECT_NE(it, r.quantities.end()) << "missing quantity " << name;
  return it == r.quantities.end() ? kNaN : it->second;
}

// §6.3: Z = 15, 45, 20, 40, 10, 33, all external, 2000 rpm in.
// Book: 2000, −666.67, 333.33, −101.01 rpm; ω_in/ω_out = −19.8.
TEST(AnalyticGears, Section6_3CompoundTrain) {
  const Model m = LoadScenarioFromString(R"(
kind: gear_train
bodies: {shaft1: {}, shaft23: {}, shaft45: {}, shaft6: {}}
joints:
  - {type: gear, members: [shaft1, shaft23], teeth: [15, 45], mesh: external}
  - {type: gear, members: [shaft23, shaft45], teeth: [20, 40], mesh: external}
  - {type: gear, members: [shaft45, shaft6], teeth: [10, 33], mesh: external}
coordinates:
  phi1: {type: rotation, member: shaft1}
  phi23: {type: rotation, member: shaft23}
  phi45: {type: rotation, member: shaft45}
  phi6: {type: rotation, member: shaft6, guess: 0.5}
drivers:
  - {coordinate: phi1, value: 0.2, velocity: 2000 rpm, acceleration: 10}
analysis: {t0: 0, t1: 0.03, samples: 31}
)", "gears.yaml");
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

std::string Planetary(const std::string& drivers) {
  return R"(
kind: gear_train
bodies: {sun: {}, planet: {}, ring: {}, carrier: {}}
joints:
  - {type: gear, members: [sun, planet], teeth: [30, 24], mesh: external, carrier: carrier}
  - {type: gear, members: [planet, ring], teeth: [24, 78], mesh: internal, carrier: carrier}
coordinates:
  phi_sun: {type: rotation, member: sun}
  phi_planet: {type: rotation, member: planet}
  phi_ring: {type: rotation, member: ring}
  phi_carrier: {type: rotation, member: carrier}
drivers:
)" + drivers;
}

// §6.1 (Willis: (ω_sun − ω_c)/(ω_ring − ω_c) = −78/30): MG1 = −1859, 3871, −3288 rpm.
TEST(AnalyticGears, Section6_1PlanetaryThreeCases) {
  struct Case { double carrier, ring, sun_book; };
  for (const Case c : {Case{0, 715, -1859}, Case{3000, 2665, 3871}, Case{2185, 4290, -3288}}) {
    const Model m = LoadScenarioFromString(
        Planetary("  - {coordinate: phi_carrier, value: 0, velocity: " + std::to_string(c.carrier) + " rpm}\n" +
                  "  - {coordinate: phi_ring, value: 0, velocity: " + std::to_string(c.ring) + " rpm}\n"),
        "planetary.yaml");
    const Result r = MakeAnalyticMethod()->Run(m);
    ASSERT_TRUE(r.ok()) << r.reason;
    const double sun = Get(r, "qd.phi_sun") / kRpm;
    EXPECT_NEAR(sun, c.carrier - 78.0 / 30 * (c.ring - c.carrier), 1e-9);
    EXPECT_NEAR(sun, c.sun_book, 0.5) << "carrier " << c.carrier << " ring " << c.ring;
  }
}

// Willis across the carrier: sun and ring known, carrier and planet found.
TEST(AnalyticGears, CarrierFromSunAndRingByWillis) {
  const Model m = LoadScenarioFromString(
      Planetary("  - {coordinate: phi_sun, value: 0, velocity: -1859 rpm}\n  - {coordinate: phi_ring, value: 0, velocity: 715 rpm}\n"),
      "planetary.yaml");
  const Result r = MakeAnalyticMethod()->Run(m);
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_NEAR(Get(r, "qd.phi_carrier") / kRpm, (-1859 + 78.0 / 30 * 715) / (1 + 78.0 / 30), 1e-9);
  // The planet in the carrier frame: (ω_p − ω_c) = −30/24 (ω_sun − ω_c).
  const double wc = Get(r, "qd.phi_carrier"), ws = Get(r, "qd.phi_sun");
  EXPECT_NEAR(Get(r, "qd.phi_planet") - wc, -30.0 / 24 * (ws - wc), 1e-9);
}

TEST(AnalyticGears, UndeterminedMemberIsNotApplicable) {
  const Model m = LoadScenarioFromString(Planetary("  - {coordinate: phi_ring, value: 0, velocity: 715 rpm}\n"), "planetary.yaml");
  const auto why = MakeAnalyticMethod()->Applicability(m);
  ASSERT_TRUE(why.has_value());
  EXPECT_NE(why->find("sun"), std::string::npos) << *why;
}

}  // namespace
}  // namespace mechbench::analytic
