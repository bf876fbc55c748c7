// §6.2 ratio synthesis: i = 221/1005 with spur gears, 10 ≤ Z ≤ 100, at most 5:1 per pair.
#include "mechbench/analytic/analytic_method.h"
#include "mechbench/analytic/synthesis.h"
#include "mechbench/loader.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace mechbench::analytic {
namespace analytic_synthesis_test {  // this file's own names (the tests build in unity batches)
namespace {

const Fraction kI{221, 1005};
const GearLimits kLimits{10, 100, 5.0};

TEST(AnalyticSynthesis, RecoversTheFractionFromADouble) {
  const auto f = RecoverFraction(221.0 / 1005.0);
  ASSERT_TRUE(f.has_value());
  EXPECT_EQ(*f, kI);
  EXPECT_EQ(Reduced(442, 2010), kI);
}

// Apartado 1: 221/1005 = (13·17)/(3·5·67) = 17/67 · 13/15, the only two-pair split within the
// limits. The book's alternative (NOTE 1) 13/67 · 17/15 breaks the 5:1 limit (67/13 = 5.15).
TEST(AnalyticSynthesis, OrdinaryTrainIs17Over67Times13Over15) {
  const auto sols = FewestPairs(kI, kLimits);
  ASSERT_EQ(sols.size(), 1u);
  ASSERT_EQ(sols[0].size(), 2u);
  EXPECT_EQ(sols[0][0], (GearPair{17, 67}));
  EXPECT_EQ(sols[0][1], (GearPair{13, 15}));
  EXPECT_FALSE(kLimits.Fits(GearPair{13, 67}));
  // Coaxial condition m2/m1 = (Z1 + Z2)/(Z3 + Z4) = 84/28 = 3 (the book's "13+65" is 13+15).
  EXPECT_DOUBLE_EQ(CoaxialModuleRatio(sols[0][0], sols[0][1]), 3.0);
  // NOTE 2: with wheels of 14 teeth or more, 13/15 becomes 26/30 and m2/m1 = 84/56 = 1.5.
  const auto big = FewestPairs(kI, GearLimits{14, 100, 5.0});
  ASSERT_FALSE(big.empty());
  EXPECT_EQ(big[0][1], (GearPair{26, 30}));
  EXPECT_DOUBLE_EQ(CoaxialModuleRatio(big[0][0], big[0][1]), 1.5);
}

// Apartado 2: μA = 1/(1 − i) = 1005/784 = (15/16)(67/49). Which wheel is fixed decides the sign:
// with the 16- or the 49-tooth wheel fixed (and the other central wheel, 67 or 15, the output)
// i = +221/1005; swapping fixed and output wheels gives i = 1 − μA = −221/784.
TEST(AnalyticSynthesis, ArmDrivenEpicyclicTrain) {
  const Fraction mu = ApparentRatio(kI);
  EXPECT_EQ(mu, (Fraction{1005, 784}));
  const auto sols = FactorizeIntoPairs(mu, 2, kLimits);
  const std::vector<GearPair> book{{67, 49}, {15, 16}};  // sorted as the solver sorts (driven first)
  EXPECT_NE(std::find(sols.begin(), sols.end(), book), sols.end());
  // The most balanced split is (67/56)(15/14), also within the limits; the book's is one of several.
  EXPECT_EQ(sols.front(), (std::vector<GearPair>{{67, 56}, {15, 14}}));
  // Central wheels 16 (fixed) and 67 (output), planet 15 + 49.
  EXPECT_EQ(EpicyclicRatio(/*fixed*/ 16, /*p1*/ 15, /*p2*/ 49, /*out*/ 67), kI);
  // Central wheels 49 (fixed) and 15 (output), planet 67 + 16 (the scenario file's choice).
  EXPECT_EQ(EpicyclicRatio(49, 67, 16, 15), kI);
  // Fixed and output swapped.
  EXPECT_EQ(EpicyclicRatio(67, 49, 15, 16), (Fraction{-221, 784}));
  EXPECT_EQ(EpicyclicRatio(15, 16, 67, 49), (Fraction{-221, 784}));
}

// Apartado 3: [0; 4, 1, 1, 4, 1, 3, 5], convergents and errors; 11/50 is the first within 1e-4.
// Book errors: 3.009951e-2, 1.99004910e-2, 2.32173e-3, 3.883e-4, 9.9502e-5, 5.21e-6. The second
// is 1.99004975e-2 exactly (= 1/5 − ... = 20/1005): the book's "…4910" is a slip.
TEST(AnalyticSynthesis, ContinuedFractionConvergentsAndErrors) {
  EXPECT_EQ(ContinuedFraction(kI), (std::vector<std::int64_t>{0, 4, 1, 1, 4, 1, 3, 5}));
  const auto c = Convergents(kI);
  ASSERT_EQ(c.size(), 7u);
  const std::int64_t num[] = {1, 1, 2, 9, 11, 42, 221}, den[] = {4, 5, 9, 41, 50, 191, 1005};
  for (size_t k = 0; k < c.size(); ++k) {
    EXPECT_EQ(c[k].num, num[k]);
    EXPECT_EQ(c[k].den, den[k]);
  }
  // Exactly 121/4020 = 3.00995025e-2; the book's 3.009951e-2 is 0.25 − 0.21990049 (i rounded to
  // 8 decimals first, as the statement asks).
  EXPECT_NEAR(c[0].error, 121.0 / 4020, 1e-17);
  EXPECT_NEAR(0.25 - 0.21990049, 3.009951e-2, 1e-12);
  EXPECT_NEAR(c[1].error, 20.0 / 1005, 1e-17);
  EXPECT_NEAR(c[1].error, 1.99004975e-2, 5e-11);
  EXPECT_GT(std::fabs(c[1].error - 1.99004910e-2), 5e-10);  // the printed digits are off
  EXPECT_NEAR(c[2].error, 21.0 / 9045, 1e-17);  // 2.321725e-3; the book rounds i first: 2.32173e-3
  EXPECT_NEAR(c[3].error, 3.883e-4, 5e-8);
  EXPECT_NEAR(c[4].error, 9.9502e-5, 5e-10);
  EXPECT_NEAR(c[5].error, 5.21e-6, 5e-9);
  EXPECT_EQ(c[6].error, 0.0);
  const auto p = PairWithin(kI, 1e-4, kLimits);
  ASSERT_TRUE(p.has_value());
  EXPECT_EQ(*p, (GearPair{11, 50}));
}

// The method exposes all of it for a gear-train model with a synthesis goal (§6.2 part 1).
TEST(AnalyticSynthesis, MethodQuantities) {
  const Model m = LoadScenario(ResolveScenario("s6_2_ordinary_train"));  // 17/67 · 13/15 at 1000 rpm
  const Result r = MakeAnalyticMethod()->Run(m);
  ASSERT_TRUE(r.ok()) << r.reason;
  const auto& q = r.quantities;
  EXPECT_NEAR(q.at("qd.phi_out") / q.at("qd.phi_in"), 221.0 / 1005, 1e-15);
  EXPECT_EQ(q.at("synthesis.cf.5.num"), 11);
  EXPECT_EQ(q.at("synthesis.cf.5.den"), 50);
  EXPECT_NEAR(q.at("synthesis.cf.5.error"), 5.0 / 50250, 1e-18);
  EXPECT_EQ(q.at("synthesis.pair_within_1e4.num"), 11);
  EXPECT_EQ(q.at("synthesis.pair_within_1e4.den"), 50);
  EXPECT_DOUBLE_EQ(q.at("synthesis.coaxial.module_ratio"), 3.0);
  EXPECT_DOUBLE_EQ(q.at("synthesis.epicyclic.mu_A"), 1005.0 / 784);
  EXPECT_DOUBLE_EQ(q.at("synthesis.epicyclic.ratio_check"), 221.0 / 1005);
}

}  // namespace
}  // namespace analytic_synthesis_test
}  // namespace mechbench::analytic
