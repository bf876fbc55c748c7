// Couplings and translating bodies in the vector method: a rack driven by its pinion, a Scotch
// yoke that translates without turning, and a rack on that yoke turning a pinion, each against
// its one-line closed form (the decomposition names the steps it used).
#include "mechbench/analytic/analytic_method.h"
#include "mechbench/analytic/linkage.h"
#include "mechbench/loader.h"
#include "quantity.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

namespace mechbench::analytic {
namespace analytic_coupling_test {  // this file's own names (the tests build in unity batches)
namespace {

Model Scene(const std::string& file) { return LoadScenario(std::string(MECHBENCH_TEST_DATA) + "/scenes/" + file); }

TEST(AnalyticCoupling, RackFollowsItsPinion) {
  const Model model = Scene("rack_pinion_driven.yaml");
  const Result r = MakeAnalyticMethod()->Run(model);
  ASSERT_EQ(r.status, Status::kOk) << r.reason;
  ASSERT_EQ(r.trajectory.size(), 11u);
  EXPECT_NE(r.settings.at("decomposition").find("body rack from R1 at its fixed angle"), std::string::npos) << r.settings.at("decomposition");
  const int x = model.SlotIndex("xR1"), x2 = model.SlotIndex("xR2");
  for (const Sample& s : r.trajectory) {
    const double th = 2 * s.t + 0.5 * s.t * s.t;
    EXPECT_NEAR(s.q[x], 0.05 * th, 1e-12) << s.t;
    EXPECT_NEAR(s.q[x2], 0.05 * th + 0.2, 1e-12) << s.t;
    EXPECT_NEAR(s.qd[x], 0.05 * (2 + s.t), 1e-12) << s.t;
    EXPECT_NEAR(s.qdd[x], 0.05, 1e-12) << s.t;
  }
}

// The yoke cannot turn (Y1 and Y3 on one guide): x_Y1 = a cos θ; a rack on it turns the pinion
// by φ = −(x_Y1 − x_Y1(0))/r (reverse: a rack above its pinion).
TEST(AnalyticCoupling, ScotchYokeTranslatesAndTurnsItsPinion) {
  for (const char* file : {"scotch_yoke_translating.yaml", "scotch_yoke_rack_pinion.yaml"}) {
    SCOPED_TRACE(file);
    const Model model = Scene(file);
    const Result r = MakeAnalyticMethod()->Run(model);
    ASSERT_EQ(r.status, Status::kOk) << r.reason;
    ASSERT_EQ(r.trajectory.size(), 41u);
    std::printf("  %s: %s\n", file, r.settings.at("decomposition").c_str());
    const int x = model.SlotIndex("xY1"), phi = model.SlotIndex("phi");
    const double a = 0.1, r_p = 0.04, x0 = a * std::cos(std::numbers::pi / 6);
    double worst = 0;
    for (const Sample& s : r.trajectory) {
      const double th = std::numbers::pi / 6 + 3 * s.t, thd = 3;
      const double xe = a * std::cos(th), xde = -a * std::sin(th) * thd, xdde = -a * std::cos(th) * thd * thd;
      worst = std::max({worst, std::fabs(s.q[x] - xe), std::fabs(s.qd[x] - xde), std::fabs(s.qdd[x] - xdde)});
      if (phi >= 0)
        worst = std::max({worst, std::fabs(s.q[phi] + (xe - x0) / r_p), std::fabs(s.qd[phi] + xde / r_p),
                          std::fabs(s.qdd[phi] + xdde / r_p)});
    }
    std::printf("  %s: largest deviation from the closed form %.2e\n", file, worst);
    EXPECT_LT(worst, 1e-12);
    EXPECT_EQ(Get(r, "omega.yoke"), 0.0);
  }
}

// The free rack: the initial conditions place it at t0 through the coupling (yR1 given, θ from it).
TEST(AnalyticCoupling, FreeRackIsPlacedThroughItsCoupling) {
  const Model model = Scene("rack_pinion_free.yaml");
  const Result r = MakeAnalyticMethod()->Run(model);
  ASSERT_EQ(r.status, Status::kOk) << r.reason;
  EXPECT_NEAR(Get(r, "q.theta"), 0.0, 1e-15);
  EXPECT_NEAR(Get(r, "q.yR2"), 0.2, 1e-15);
}

// A belt between two gear-train members: its ratio propagates like a mesh's.
TEST(AnalyticCoupling, BeltAfterAGearPair) {
  const Model model = Scene("gear_belt_train.yaml");
  const Result r = MakeAnalyticMethod()->Run(model);
  ASSERT_EQ(r.status, Status::kOk) << r.reason;
  const int p = model.SlotIndex("phi_pulley");
  for (const Sample& s : r.trajectory) {
    const double pinion = 3 * s.t + 0.5 * s.t * s.t;
    EXPECT_NEAR(s.q[p], -pinion / 6, 1e-14) << s.t;
    EXPECT_NEAR(s.qd[p], -(3 + s.t) / 6, 1e-14) << s.t;
    EXPECT_NEAR(s.qdd[p], -1.0 / 6, 1e-14) << s.t;
  }
}

}  // namespace
}  // namespace analytic_coupling_test
}  // namespace mechbench::analytic
