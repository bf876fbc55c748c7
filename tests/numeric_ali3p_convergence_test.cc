// ALI3-P's second order on the IFToMM N-four-bar at the benchmark's size (N = 40, x up to 41 m):
// the error against the exact motion shrinks by 4 per halving of h. It did not before three
// round-off and stopping fixes in ali3p.cc (its header comment): the penalty's part of the
// tangent matrix is 1600 times that of one bay there (cond W̄ 4.9e6), so solving W̄ q̇ = M q̇* for
// the whole q̇ left ~ε cond(W̄) |q̇| in the tangent directions each step; q̇* = (2/h) q_{n+1} − q̂̇
// cancelled coordinates of 40 m; and a Newton step within the tolerance left a quadratic remainder
// that q̈ = (4/h²)(…) magnified. The error then grew as h shrank.
#include "mechbench/motion_error.h"
#include "mechbench/numeric/dynamics_methods.h"
#include "mechbench/references/nfourbar.h"
#include "mechbench/numeric/reference.h"

#include <gtest/gtest.h>

#include <vector>

namespace mechbench::numeric {
namespace numeric_ali3p_convergence_test {  // this file's own names (the tests build in unity batches)
namespace {

using namespace ::mechbench::references;  // the N-four-bar's generator and exact motion

std::vector<double> Errors(const Model& model, const std::vector<double>& steps) {
  const NFourBarSolution exact = NFourBarExact(model);
  std::vector<double> e;
  for (double h : steps) {
    Ali3pOptions o;
    o.h = h;
    const Result r = MakeAli3pMethod(o)->Run(model);
    EXPECT_EQ(r.status, Status::kOk) << r.reason;
    e.push_back(CompareMotion(model, exact.trajectory, r.trajectory).q.max);
  }
  return e;
}

// Before the first singular position (0.72 s), at the small steps where round-off used to win:
// measured 3.70e-8 and 9.26e-9 at 0.25 and 0.125 ms (ratio 4.00; it was 6.8e-8 and 1.9e-7).
TEST(NumericAli3pConvergence, SecondOrderAtSmallStepsOnTheFortyFourBar) {
  const Model model = NFourBar({.n = 40, .t1 = 0.5, .samples = 6});
  const std::vector<double> e = Errors(model, {2.5e-4, 1.25e-4});
  EXPECT_LT(e[1], 2e-8);
  EXPECT_GT(e[0] / e[1], 3.6);
  EXPECT_LT(e[0] / e[1], 4.4);
}

// Through the first singular position, at the default step and two halvings: measured 8.90e-6,
// 2.21e-6, 5.56e-7 (ratios 4.02, 3.98; it was 1.16e-5, 4.1e-7, 2.0e-7: ratios 28, 2.0).
TEST(NumericAli3pConvergence, SecondOrderThroughTheFirstSingularPosition) {
  const Model model = NFourBar({.n = 40, .t1 = 1.0, .samples = 11});
  const std::vector<double> e = Errors(model, {1e-3, 5e-4, 2.5e-4});
  EXPECT_LT(e[2], 1e-6);
  for (int k = 0; k < 2; ++k) {
    EXPECT_GT(e[k] / e[k + 1], 3.6) << "halving " << k;
    EXPECT_LT(e[k] / e[k + 1], 4.4) << "halving " << k;
  }
}

}  // namespace
}  // namespace numeric_ali3p_convergence_test
}  // namespace mechbench::numeric
