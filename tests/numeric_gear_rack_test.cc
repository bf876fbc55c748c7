// A rack meshing a gear-train member in the natural-coordinate solver: the rack joint is one
// linear row (the coupling row) on the member's rotation and the rack's travel coordinate, which
// the solver then follows: against the hand-computed 5 mm per radian of the input
// (tests/data/scenes/gear_train_rack.yaml) and the analytic ratio method.
#include "mechbench/analytic/analytic_method.h"
#include "mechbench/loader.h"
#include "mechbench/numeric/natural_model.h"
#include "mechbench/numeric/numeric_method.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace mechbench::numeric {
namespace numeric_gear_rack_test {  // this file's own names (the tests build in unity batches)
namespace {

Model Scene(const std::string& file) { return LoadScenario(std::string(MECHBENCH_TEST_DATA) + "/scenes/" + file); }

TEST(NumericGearRack, OneLinearRowAndTheTravelFollowsTheTrain) {
  const Model model = Scene("gear_train_rack.yaml");
  const NaturalModel nm = Compile(model);
  int rack_rows = 0;
  for (const ConstraintRow& row : nm.rows)
    if (row.kind == RowKind::kCoupling) {
      ++rack_rows;
      EXPECT_EQ(row.slots[0], model.SlotIndex("phi4"));
      EXPECT_EQ(row.slots[1], model.SlotIndex("x_rack"));
      EXPECT_DOUBLE_EQ(row.k, 45.0);  // +r: the rack below s4, along +x
    }
  EXPECT_EQ(rack_rows, 1);
  const Result r = MakeNumericMethod()->Run(model);
  ASSERT_TRUE(r.ok()) << r.reason;
  const Result a = analytic::MakeAnalyticMethod()->Run(model);
  ASSERT_TRUE(a.ok()) << a.reason;
  ASSERT_EQ(r.trajectory.size(), a.trajectory.size());
  const int x = model.SlotIndex("x_rack");
  double worst = 0, vs_analytic = 0;
  for (size_t k = 0; k < r.trajectory.size(); ++k) {
    const Sample& s = r.trajectory[k];
    const double phi1 = 6 * s.t + s.t * s.t, w1 = 6 + 2 * s.t;
    worst = std::max({worst, std::fabs(s.q[x] - 5 * phi1) / (5 * (1 + phi1)), std::fabs(s.qd[x] - 5 * w1) / (5 * w1),
                      std::fabs(s.qdd[x] - 10) / 10});
    vs_analytic = std::max({vs_analytic, (s.q - a.trajectory[k].q).cwiseAbs().maxCoeff(),
                            (s.qd - a.trajectory[k].qd).cwiseAbs().maxCoeff()});
  }
  std::printf("  gear_train_rack: numeric vs 5 mm/rad × the input %.2e (relative), vs analytic %.2e\n", worst, vs_analytic);
  EXPECT_LT(worst, 1e-13);
  EXPECT_LT(vs_analytic, 1e-11);
}

}  // namespace
}  // namespace numeric_gear_rack_test
}  // namespace mechbench::numeric
