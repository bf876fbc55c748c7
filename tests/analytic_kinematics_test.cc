// Point kinematics of chapter 2: intrinsic coordinates, eq. 2.11 and eq. 2.12, worked on §3.2.
#include "mechbench/analytic/kinematics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace mechbench::analytic {
namespace analytic_kinematics_test {  // this file's own names (the tests build in unity batches)
namespace {

// A point on a circle of radius 2.5 with ṡ = 3 and s̈ = 0.7: R, a_t and a_n are recovered and the
// normal points at the centre.
TEST(AnalyticKinematics, IntrinsicCoordinatesOnACircleRecoverTheRadius) {
  const double R = 2.5, w = 3.0 / R, wd = 0.7 / R, phi = 0.4;
  const Vec3 c(1, -2, 0.5);
  const Vec3 er(std::cos(phi), std::sin(phi), 0), et(-std::sin(phi), std::cos(phi), 0);
  const Vec3 p = c + R * er, v = R * w * et, a = R * wd * et - R * w * w * er;
  const Intrinsic in = IntrinsicCoordinates(p, v, a);
  EXPECT_NEAR(in.speed, 3.0, 1e-14);
  EXPECT_NEAR(in.a_t, 0.7, 1e-14);
  EXPECT_NEAR(in.a_n, 9.0 / R, 1e-13);  // v²/R
  EXPECT_NEAR(in.radius, R, 1e-13);
  EXPECT_LT((in.e_t - et).norm(), 1e-14);
  EXPECT_LT((in.e_n + er).norm(), 1e-14);  // towards the centre
  EXPECT_LT((in.centre - c).norm(), 1e-13);
}

TEST(AnalyticKinematics, StraightPathHasInfiniteRadius) {
  const Intrinsic in = IntrinsicCoordinates(Vec3::Zero(), Vec3(1, 2, 0), Vec3(-2, -4, 0));
  EXPECT_TRUE(std::isinf(in.radius));
  EXPECT_NEAR(in.a_t, -std::sqrt(20.0), 1e-14);
  EXPECT_NEAR(in.a_n, 0, 1e-14);
}

// §3.2 by hand with eq. 2.11: the thumb O–A–B with ω1 = 5, α1 = 3 (OA), ω2 = 10, α2 = 4 (AB
// relative to OA). Book: vB = (−14.142, −59.142), aA = (62.225, −79.196), aB = (737.23, −100.2).
TEST(AnalyticKinematics, Section3_2ThumbByTheRigidBodyFormula) {
  const double s = std::numbers::sqrt2 / 2;
  const Vec3 k(0, 0, 1);
  PointState3 O;
  const Vec3 pA(-4 * s, 4 * s, 0), pB = pA + Vec3(-3, 0, 0);
  const PointState3 A = RigidBodyPoint(O, 5 * k, 3 * k, pA);
  const PointState3 B = RigidBodyPoint(A, 15 * k, 7 * k, pB);  // ω_AB = ω1 + ω2 (eq. 2.8)
  EXPECT_NEAR(B.v.x(), -14.142, 5e-4);
  EXPECT_NEAR(B.v.y(), -59.142, 5e-4);
  EXPECT_NEAR(A.a.x(), 62.225, 5e-4);
  EXPECT_NEAR(A.a.y(), -79.196, 5e-4);
  EXPECT_NEAR(B.a.x(), 737.23, 5e-3);
  EXPECT_NEAR(B.a.y(), -100.2, 5e-2);
  EXPECT_NEAR(B.a.x(), 88 / std::numbers::sqrt2 + 675, 1e-12);  // eq. 3.21d
  EXPECT_NEAR(B.a.y(), -112 / std::numbers::sqrt2 - 21, 1e-12);

  // Part 2, route 1 (eq. 2.12): B moves in the frame XYZ that turns at ω3 = 2j about O.
  const Vec3 w3(0, 2, 0);
  const PointState3 Babs = MovingFramePoint(O, w3, Vec3::Zero(), B.p, B.v, B.a);
  // Route 2: add ω3 to each link; its absolute angular acceleration gains ω3 × (ω k) because k
  // turns with the frame.
  const PointState3 A2 = RigidBodyPoint(O, 5 * k + w3, 3 * k + Cross(w3, Vec3(5 * k)), pA);
  const PointState3 B2 = RigidBodyPoint(A2, 15 * k + w3, 7 * k + Cross(w3, Vec3(15 * k)), pB);
  EXPECT_LT((Babs.v - B2.v).norm(), 1e-12);
  EXPECT_LT((Babs.a - B2.a).norm(), 1e-11);
  // Book eq. 3.22a prints (−14.142, 30.858, 11.657): ω3 = 2j cannot change the y component
  // (ω3 × OB ⟂ j), so vB.y stays −59.142; 30.858 = −59.142 + 90 is a slip.
  EXPECT_NEAR(Babs.v.x(), -14.142, 5e-4);
  EXPECT_NEAR(Babs.v.y(), -59.142, 5e-4);
  EXPECT_NEAR(Babs.v.z(), 11.657, 5e-4);
  // Book eq. 3.23b: (760.544, −100.2, 56.568); exactly 88/√2 + 675 + 4(3 + 4/√2) = 760.5391.
  EXPECT_NEAR(Babs.a.x(), 88 / std::numbers::sqrt2 + 675 + 4 * (3 + 4 / std::numbers::sqrt2), 1e-11);
  EXPECT_NEAR(Babs.a.x(), 760.539, 5e-4);
  EXPECT_NEAR(Babs.a.y(), -100.2, 5e-2);
  // 2ω3 × vB = 4 · 14.142 k = 40√2 = 56.5685: the book's 56.568 truncates instead of rounding.
  EXPECT_NEAR(Babs.a.z(), 40 * std::numbers::sqrt2, 1e-11);
  EXPECT_NEAR(Babs.a.z(), 56.568, 1e-3);
  // The naive route 2 (α without the ω3 × ωk term) does NOT give the same aB.
  const PointState3 A3 = RigidBodyPoint(O, 5 * k + w3, 3 * k, pA);
  const PointState3 B3 = RigidBodyPoint(A3, 15 * k + w3, 7 * k, pB);
  EXPECT_GT((B3.a - Babs.a).norm(), 1.0);
}

TEST(AnalyticKinematics, MovingFrameReducesToRigidBodyWithoutRelativeMotion) {
  PointState3 A{Vec3(1, 2, 3), Vec3(0.1, -0.2, 0.3), Vec3(-1, 0, 2)};
  const Vec3 w(0.3, -0.4, 1.2), al(2, 1, -0.5), p(2, -1, 0.5);
  const PointState3 r = RigidBodyPoint(A, w, al, p);
  const PointState3 m = MovingFramePoint(A, w, al, p, Vec3::Zero(), Vec3::Zero());
  EXPECT_LT((r.v - m.v).norm(), 1e-15);
  EXPECT_LT((r.a - m.a).norm(), 1e-15);
  // A relative velocity adds itself and the Coriolis term 2ω × v_rel.
  const Vec3 vr(0.5, 0, -1);
  const PointState3 c = MovingFramePoint(A, w, al, p, vr, Vec3::Zero());
  EXPECT_LT((c.a - r.a - 2 * Cross(w, vr)).norm(), 1e-14);
}

}  // namespace
}  // namespace analytic_kinematics_test
}  // namespace mechbench::analytic
