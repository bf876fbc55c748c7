// A rack meshing a gear-train member (tests/data/scenes/gear_train_rack.yaml): the gear-train
// ratio method gives the rack's travel, speed and acceleration from the train's ratio times the
// pinion's pitch radius, checked against the hand-computed 5 mm per radian of the input.
#include "mechbench/analytic/analytic_method.h"
#include "mechbench/loader.h"
#include "quantity.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace mechbench::analytic {
namespace analytic_gear_rack_test {  // this file's own names (the tests build in unity batches)
namespace {

Model Scene(const std::string& file) { return LoadScenario(std::string(MECHBENCH_TEST_DATA) + "/scenes/" + file); }

TEST(AnalyticGearRack, TravelIsTheTrainRatioTimesThePitchRadius) {
  const Model model = Scene("gear_train_rack.yaml");
  const Result r = MakeAnalyticMethod()->Run(model);
  ASSERT_EQ(r.status, Status::kOk) << r.reason;
  ASSERT_EQ(r.trajectory.size(), 21u);
  const int x = model.SlotIndex("x_rack"), phi4 = model.SlotIndex("phi4");
  ASSERT_GE(x, 0);
  // Two external meshes (−20/60)(−15/45) = 1/9, r4 = m Z4 / 2 = 45 mm: 5 mm per radian of s1.
  const double k = 45.0 * (20.0 / 60.0) * (15.0 / 45.0);
  EXPECT_DOUBLE_EQ(k, 5.0);
  for (const Sample& s : r.trajectory) {
    const double phi1 = 6 * s.t + s.t * s.t, w1 = 6 + 2 * s.t, a1 = 2;
    EXPECT_NEAR(s.q[x], k * phi1, 1e-12 * k * (1 + phi1)) << s.t;
    EXPECT_NEAR(s.qd[x], k * w1, 1e-12 * k * w1) << s.t;
    EXPECT_NEAR(s.qdd[x], k * a1, 1e-12 * k * a1) << s.t;
    EXPECT_NEAR(s.q[phi4], phi1 / 9, 1e-14 * (1 + phi1)) << s.t;
  }
  EXPECT_DOUBLE_EQ(Get(r, "qd.x_rack"), 30.0);  // 5 mm × 6 rad/s at t0
  EXPECT_EQ(r.quantities.count("omega.rack"), 0u) << "a rack does not turn: its speed is qd of its travel";
}

}  // namespace
}  // namespace analytic_gear_rack_test
}  // namespace mechbench::analytic
