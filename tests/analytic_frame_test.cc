// 3-D problems through the embedding and a turning frame: §3.2 (thumb) and §3.1 (carousel), each
// by the moving-frame route (eq. 2.12) and the rigid-body chain with absolute angular velocities.
#include "mechbench/analytic/analytic_method.h"
#include "mechbench/loader.h"
#include "quantity.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace mechbench::analytic {
namespace analytic_frame_test {  // this file's own names (the tests build in unity batches)
namespace {

Result RunBuiltin(const std::string& scenario) {
  const Model m = LoadScenario(ResolveScenario(scenario));
  return MakeAnalyticMethod()->Run(m);
}

void ExpectRoutesAgree(const Result& r, const std::string& pt) {
  for (const char* c : {"x", "y", "z"}) {
    EXPECT_NEAR(Get(r, "vabs." + pt + "." + c), Get(r, "vabs_chain." + pt + "." + c), 1e-11) << pt << "." << c;
    EXPECT_NEAR(Get(r, "aabs." + pt + "." + c), Get(r, "aabs_chain." + pt + "." + c), 1e-10) << pt << "." << c;
  }
}

// §3.2 (scenarios/s3_2_thumb.yaml): OA at 135° (4 cm), AB along −X (3 cm); ω1 = 5, α1 = 3;
// ω2 = 10, α2 = 4 relative to OA; then the finger turns about Y at ω3 = 2 rad/s.
TEST(AnalyticFrame, Section3_2ThumbPlanarPart) {
  const Result r = RunBuiltin("s3_2_thumb");
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_NEAR(Get(r, "v.B.x"), -14.142, 5e-4);
  EXPECT_NEAR(Get(r, "v.B.y"), -59.142, 5e-4);
  EXPECT_NEAR(Get(r, "a.A.x"), 62.225, 5e-4);
  EXPECT_NEAR(Get(r, "a.A.y"), -79.196, 5e-4);
  EXPECT_NEAR(Get(r, "a.B.x"), 737.23, 5e-3);
  EXPECT_NEAR(Get(r, "a.B.y"), -100.2, 5e-2);
  EXPECT_NEAR(Get(r, "omega.AB"), 15, 1e-12);  // ω1 + ω2
  EXPECT_NEAR(Get(r, "alpha.AB"), 7, 1e-12);
}

// Book eq. 3.22a/3.23b: vB = (−14.142, 30.858, 11.657), aB = (760.544, −100.2, 56.568).
// Both routes give vB.y = −59.142 (ω3 ∥ j cannot change a j component: 30.858 is a slip) and
// aB.x = 760.539 (the book adds rounded terms).
TEST(AnalyticFrame, Section3_2ThumbTurningFrameBothRoutes) {
  const Result r = RunBuiltin("s3_2_thumb");
  ASSERT_TRUE(r.ok()) << r.reason;
  ExpectRoutesAgree(r, "A");
  ExpectRoutesAgree(r, "B");
  EXPECT_NEAR(Get(r, "vabs.B.x"), -14.142, 5e-4);
  EXPECT_NEAR(Get(r, "vabs.B.y"), -59.142, 5e-4);
  EXPECT_NEAR(Get(r, "vabs.B.z"), 11.657, 5e-4);
  EXPECT_NEAR(Get(r, "aabs.B.x"), 760.539, 5e-4);
  EXPECT_NEAR(Get(r, "aabs.B.y"), -100.2, 5e-2);
  EXPECT_NEAR(Get(r, "aabs.B.z"), 40 * std::sqrt(2.0), 1e-11);  // book 56.568 (truncated 56.5685)
  // Eq. 3.24b: ω_AB = 15k + 2j.
  EXPECT_NEAR(Get(r, "omegaabs.AB.x"), 0, 1e-12);
  EXPECT_NEAR(Get(r, "omegaabs.AB.y"), 2, 1e-12);
  EXPECT_NEAR(Get(r, "omegaabs.AB.z"), 15, 1e-12);
  // ...whose absolute rate has the term ω3 × 15k = 30i besides 7k.
  EXPECT_NEAR(Get(r, "alphaabs.AB.x"), 30, 1e-12);
  EXPECT_NEAR(Get(r, "alphaabs.AB.z"), 7, 1e-12);
}

// §3.1 (scenarios/s3_1_carousel.yaml) with ω0 = 1 rad/s, R = 0.5 m, Ω = 0.3 rad/s, mechanism in
// the Y–Z plane.
TEST(AnalyticFrame, Section3_1CarouselConsistentAndBookAssumption) {
  const double w0 = 1, R = 0.5, W = 0.3, s3 = std::sqrt(3.0);
  const Result r = RunBuiltin("s3_1_carousel");
  ASSERT_TRUE(r.ok()) << r.reason;
  // Velocities agree with the book: ω_AC = 3ω0, v_C = −2√3 ω0 R k, v_D = ω0 R (−j − √3 k).
  EXPECT_NEAR(Get(r, "omega.bar"), 3 * w0, 1e-12);
  EXPECT_NEAR(Get(r, "omega.crank"), -w0, 1e-12);
  EXPECT_NEAR(Get(r, "v.C.y"), 0, 1e-12);
  EXPECT_NEAR(Get(r, "v.C.z"), -2 * s3 * w0 * R, 1e-12);
  EXPECT_NEAR(Get(r, "v.D.y"), -w0 * R, 1e-12);
  EXPECT_NEAR(Get(r, "v.D.z"), -s3 * w0 * R, 1e-12);
  // Consistent accelerations (constant-speed crank, C held by the slot):
  // a_A = −ω0² BA = ω0²R(−√3/2, 3/2); the slot forces α_AC = −8√3 ω0² (not 0);
  // a_D = ω0²R(−1/√3, 7).
  EXPECT_NEAR(Get(r, "a.A.y"), -s3 / 2 * w0 * w0 * R, 1e-12);
  EXPECT_NEAR(Get(r, "a.A.z"), 1.5 * w0 * w0 * R, 1e-12);
  EXPECT_NEAR(Get(r, "alpha.bar"), -8 * s3 * w0 * w0, 1e-11);
  EXPECT_NEAR(Get(r, "a.C.y"), 0, 1e-11);
  EXPECT_NEAR(Get(r, "a.D.y"), -w0 * w0 * R / s3, 1e-11);
  EXPECT_NEAR(Get(r, "a.D.z"), 7 * w0 * w0 * R, 1e-11);
  // The book's eq. 3.11c from its given a_A = ω0²R/8 (−√3 j + k) and α_AC = 0, rebuilt from the
  // computed ω_AC and positions: a_D = a_A + ω×(ω×AD) = a_A − ω² AD = ω0²R (11√3/8 j + 13/8 k).
  const double w_AC = Get(r, "omega.bar");
  EXPECT_NEAR(-s3 / 8 * w0 * w0 * R - w_AC * w_AC * (Get(r, "p.D.y") - Get(r, "p.A.y")), 11 * s3 / 8 * w0 * w0 * R, 1e-12);
  EXPECT_NEAR(1.0 / 8 * w0 * w0 * R - w_AC * w_AC * (Get(r, "p.D.z") - Get(r, "p.A.z")), 13.0 / 8 * w0 * w0 * R, 1e-12);
  // Absolute velocity (eq. 3.12c): v_D − 2Ω i.
  EXPECT_NEAR(Get(r, "vabs.D.x"), -2 * W, 1e-12);
  EXPECT_NEAR(Get(r, "vabs.D.y"), -w0 * R, 1e-12);
  EXPECT_NEAR(Get(r, "vabs.D.z"), -s3 * w0 * R, 1e-12);
  // Absolute acceleration: a_D + Ω k×(Ω k×2j) + 2Ω k×v_D = a_D − 2Ω² j + 2Ω ω0 R i.
  EXPECT_NEAR(Get(r, "aabs.D.x"), 2 * W * w0 * R, 1e-11);
  EXPECT_NEAR(Get(r, "aabs.D.y"), -w0 * w0 * R / s3 - 2 * W * W, 1e-11);
  EXPECT_NEAR(Get(r, "aabs.D.z"), 7 * w0 * w0 * R, 1e-11);
  for (const char* p : {"A", "C", "D"}) ExpectRoutesAgree(r, p);
}

}  // namespace
}  // namespace analytic_frame_test
}  // namespace mechbench::analytic
