// Vector algebra of Part I (§1.3–§1.5).
#include "mechbench/analytic/vector.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace mechbench::analytic {
namespace analytic_vector_test {  // this file's own names (the tests build in unity batches)
namespace {

constexpr double kDeg = std::numbers::pi / 180;

// Example 1.1: the angle between (2, −3, 5) and (−1, 1, 2) is 70.66°.
TEST(AnalyticVector, Example1_1AngleBetweenVectorsIs70_66Deg) {
  const Vec3 r1(2, -3, 5), r2(-1, 1, 2);
  EXPECT_DOUBLE_EQ(r1.dot(r2), 5.0);
  EXPECT_NEAR(AngleBetween(r1, r2) / kDeg, 70.66, 0.005);
  EXPECT_NEAR(std::cos(AngleBetween(r1, r2)), 5 / std::sqrt(6.0 * 38.0), 1e-15);
}

// Example 1.2: 10i × (10i × 3k) = −300k, by the determinant, by [r]x and by eq. 1.18.
TEST(AnalyticVector, Example1_2TripleProductIsMinus300k) {
  const Vec3 a(10, 0, 0), c(0, 0, 3);
  EXPECT_EQ(Cross(a, c), Vec3(0, -30, 0));
  EXPECT_EQ(TripleCross(a, a, c), Vec3(0, 0, -300));
  EXPECT_EQ(Skew(a) * (Skew(a) * c), Vec3(0, 0, -300));
  EXPECT_EQ(TripleCross(a, a, c), -a.squaredNorm() * c);  // eq. 1.18 for a ⟂ c
}

// Example 1.3 (no answer printed): 4j × 2k = 8i is parallel to 5i, so 5i × (4j × 2k) = 0.
// Geometrically, b × c is normal to the plane of b and c, which here is the direction of a.
TEST(AnalyticVector, Example1_3TripleProductIsZeroBecause4jx2kIsAlong_i) {
  const Vec3 a(5, 0, 0), b(0, 4, 0), c(0, 0, 2);
  EXPECT_EQ(Cross(b, c), Vec3(8, 0, 0));
  EXPECT_EQ(TripleCross(a, b, c), Vec3::Zero());
  // The parentheses matter (eq. 1.15): i × (i × j) = −j but (i × i) × j = 0.
  const Vec3 i(1, 0, 0), j(0, 1, 0);
  EXPECT_EQ(TripleCross(i, i, j), -j);
  EXPECT_EQ(Cross(Cross(i, i), j), Vec3::Zero());
}

TEST(AnalyticVector, UnitVectorsAndBaseProducts) {
  const Vec3 i(1, 0, 0), j(0, 1, 0), k(0, 0, 1);
  EXPECT_EQ(Cross(i, j), k);  // eq. 1.13
  EXPECT_EQ(Cross(j, k), i);
  EXPECT_EQ(Cross(k, i), j);
  EXPECT_EQ(Cross(j, i), -k);
  EXPECT_EQ(TripleCross(k, k, Vec3(-1, 0, 0)), i);  // eq. 1.16
  EXPECT_EQ(TripleCross(Vec3(0, 0, 5), Vec3(0, 0, 5), Vec3(4, 0, 0)), Vec3(-100, 0, 0));  // eq. 1.19
  EXPECT_NEAR(Unit(Vec3(3, 2, 1)).norm(), 1.0, 1e-15);
  EXPECT_DOUBLE_EQ(TripleScalar(i, j, k), 1.0);
  const Vec3 r(0.3, -1.7, 2.2), s(-4, 0.5, 1);
  EXPECT_LT((Skew(r) * s - Cross(r, s)).norm(), 1e-15);
  EXPECT_LT((Skew(r) + Skew(r).transpose()).norm(), 1e-15);  // skew-symmetric
}

TEST(AnalyticVector, PlanarHelpersAndCramer) {
  EXPECT_EQ(Perp(Vec2(1, 0)), Vec2(0, 1));  // k × i = j
  EXPECT_DOUBLE_EQ(Cross2(Vec2(1, 0), Vec2(0, 1)), 1.0);
  double x1 = 0, x2 = 0;
  ASSERT_TRUE(SolveCramer2(Vec2(2, 1), Vec2(-1, 3), Vec2(3, 11), x1, x2));
  EXPECT_NEAR(x1, 20.0 / 7, 1e-14);  // 2x1 − x2 = 3, x1 + 3x2 = 11
  EXPECT_NEAR(x2, 19.0 / 7, 1e-14);
  EXPECT_FALSE(SolveCramer2(Vec2(1, 1), Vec2(2, 2), Vec2(1, 0), x1, x2));  // parallel: a toggle
}

}  // namespace
}  // namespace analytic_vector_test
}  // namespace mechbench::analytic
