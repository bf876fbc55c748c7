// IFToMM A01, the simple pendulum (scenarios/benchmarks/a01_pendulum.yaml), and the registry's
// `pendulum`: its elliptic functions against the library's K and against the pendulum's equation
// integrated independently, the reference built from it, and the benchmark's own criteria.
#include "mechbench/errors.h"
#include "mechbench/format.h"
#include "mechbench/harness/compare.h"
#include "mechbench/harness/criteria.h"
#include "mechbench/loader.h"
#include "mechbench/motion_error.h"
#include "mechbench/numeric/dynamics_methods.h"
#include "mechbench/numeric/forward_dynamics.h"
#include "mechbench/references/cranks.h"
#include "mechbench/references/pendulum.h"
#include "mechbench/references/registry.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <string>

namespace mechbench::harness {
namespace harness_pendulum_test {  // this file's own names (the tests build in unity batches)
namespace {

using references::AnalyzeParallelCranks;
using references::EllipticK;
using references::JacobiElliptic;
using references::ParallelCranks;

const Model& A01() {
  static const Model m = references::LoadScenarioValidated(std::string(MECHBENCH_TEST_DATA) +
                                                           "/../../scenarios/benchmarks/a01_pendulum.yaml");
  return m;
}

// K(k) by the AGM against the standard library's, and sn, cn, dn against their identities and
// special values (sn(K) = 1, cn(K) = 0, dn(K) = k', period 4K), over the moduli a pendulum swings with.
TEST(HarnessPendulum, EllipticFunctionsAgreeWithTheLibraryAndTheirIdentities) {
  for (double k : {0.0, 0.1, 0.5, std::sqrt(0.5), 0.9, 0.99}) {
    const double K = EllipticK(k);
    EXPECT_NEAR(K, std::comp_ellint_1(k), 4e-16 * K) << "k = " << k;
    const references::Jacobi atK = JacobiElliptic(K, k);
    EXPECT_NEAR(atK.sn, 1, 1e-15);
    EXPECT_NEAR(atK.cn, 0, 1e-7);  // cn ~ √(1 − sn): 1e-7 when sn is 1 to round-off
    EXPECT_NEAR(atK.dn, std::sqrt(1 - k * k), 1e-15);
    for (double u : {0.3, 1.7, -2.2, 7.5, 6000.1}) {
      const references::Jacobi j = JacobiElliptic(u, k), p = JacobiElliptic(u + 4 * K, k);
      EXPECT_NEAR(j.sn * j.sn + j.cn * j.cn, 1, 1e-15);
      EXPECT_NEAR(j.dn * j.dn + k * k * j.sn * j.sn, 1, 1e-15);
      EXPECT_NEAR(p.sn, j.sn, 1e-11 * std::max(1.0, std::fabs(u)));
      // u = F(am u): the incomplete integral of the library returns u from sn (|u| < K).
      if (std::fabs(u) < K) {
        EXPECT_NEAR(std::ellint_1(k, std::asin(j.sn)), u, 1e-14);
      }
    }
  }
}

// The A01 file is the registry's pendulum: one crank, J = K = 1 kg·m² (a point mass at 1 m),
// released horizontal at rest (k = sin 45°). Its closed form over the whole 2000 s against the
// pendulum's equation θ̈ = −g cos θ integrated independently (DOPRI5 on (θ, θ̇)).
TEST(HarnessPendulum, ClosedFormIsThePendulumsEquationOver2000s) {
  const Model& m = A01();
  ASSERT_TRUE(m.exact_reference.has_value());
  ParallelCranks pc;
  std::string why;
  ASSERT_TRUE(AnalyzeParallelCranks(m, pc, why)) << why;
  EXPECT_EQ(pc.couplers, 0);
  EXPECT_DOUBLE_EQ(pc.J, 1.0);
  EXPECT_DOUBLE_EQ(pc.K, 1.0);
  EXPECT_DOUBLE_EQ(pc.theta0, 0.0);
  const numeric::ExactSolution exact = references::PendulumExact(m, {}, why);
  ASSERT_EQ(static_cast<int>(exact.trajectory.size()), m.analysis.samples) << why;
  EXPECT_NEAR(exact.quantities.at("k"), std::sin(std::numbers::pi / 4), 1e-16);
  const int sx = m.SlotIndex("xP1"), sy = m.SlotIndex("yP1");
  // The largest distance of P1 [m] and of its velocity [m/s] over the 4001 samples.
  const auto against_dopri5 = [&](double rtol, double& worst, double& worst_v) {
    numeric::Dopri5Options opt;
    opt.rtol = rtol;
    opt.atol = Eigen::VectorXd::Constant(2, rtol * 1e-2);
    numeric::Dopri5 dopri(opt);
    const numeric::OdeRhs f = [&](double, const Eigen::VectorXd& y, Eigen::VectorXd& dy, std::string&) {
      dy.resize(2);
      dy << y[1], -pc.g * pc.K / pc.J * std::cos(y[0]);
      return true;
    };
    Eigen::VectorXd y(2);
    y << pc.theta0, pc.omega0;
    double t = 0;
    worst = worst_v = 0;
    for (int k = 1; k < m.analysis.samples; ++k) {
      ASSERT_TRUE(dopri.Advance(f, {}, t, m.analysis.TimeAt(k), y, why)) << why;
      const Sample& s = exact.trajectory[k];
      worst = std::max(worst, std::hypot(s.q[sx] - std::cos(y[0]), s.q[sy] - std::sin(y[0])));
      worst_v = std::max(worst_v, std::hypot(s.qd[sx] + std::sin(y[0]) * y[1], s.qd[sy] - std::cos(y[0]) * y[1]));
    }
  };
  // The difference is the integration's phase error: it shrinks with rtol (measured 3.0e-7 m at
  // rtol 1e-13, 10 × more at 1e-12), 300 times below the benchmark's finest level.
  double w13 = 0, v13 = 0, w12 = 0, v12 = 0;
  against_dopri5(1e-13, w13, v13);
  against_dopri5(1e-12, w12, v12);
  if (std::getenv("MECHBENCH_PRINT_ERRORS")) std::printf("rtol 1e-12: %.3g m, %.3g m/s; 1e-13: %.3g m, %.3g m/s\n", w12, v12, w13, v13);
  EXPECT_LT(w13, 1e-6);
  EXPECT_LT(v13, 5e-6);
  EXPECT_LT(w13, 0.3 * w12);
  // Energy: E = ½ v² + g y is the same at every sample (the closed form has no drift).
  double drift = 0;
  for (const Sample& s : exact.trajectory)
    drift = std::max(drift, std::fabs(0.5 * s.qd.squaredNorm() + pc.g * s.q[sy]));
  EXPECT_LT(drift, 1e-12);
}

// A point body at a crank's tip on a massless rod is the pendulum of the registry too: J = m L²,
// K = m L, and the reference is its closed form, confirmed on the full model like A01's.
TEST(HarnessPendulum, APointMassAtTheTipIsThePendulum) {
  const Model m = references::LoadScenarioValidated(std::string(MECHBENCH_TEST_DATA) + "/scenes/pendulum_point_mass_exact.yaml");
  ParallelCranks pc;
  std::string why;
  ASSERT_TRUE(AnalyzeParallelCranks(m, pc, why)) << why;
  EXPECT_EQ(pc.couplers, 0);
  EXPECT_DOUBLE_EQ(pc.J, 12.0);  // 3 kg at 2 m
  EXPECT_DOUBLE_EQ(pc.K, 6.0);
  EXPECT_NEAR(pc.theta0, -std::numbers::pi / 6, 1e-15);
  const numeric::Reference ref = references::ReferenceFor(m);
  EXPECT_TRUE(ref.confirmed) << ref.description;
  EXPECT_LT(ref.agreement, 1e-8) << ref.description;
  // The period of a pendulum of length L = J / K released 30° below the horizontal (amplitude
  // 60° from the vertical): 4 √(L/g) K(sin 30°); P returns to its start after one period.
  const double L = pc.J / pc.K, T = 4 * std::sqrt(L / pc.g) * EllipticK(std::sin(std::numbers::pi / 6));
  Model at_period = m;
  at_period.analysis.t0 = 0, at_period.analysis.t1 = T, at_period.analysis.samples = 2;
  const numeric::ExactSolution back = references::PendulumExact(at_period, {}, why);
  ASSERT_EQ(back.trajectory.size(), 2u) << why;
  EXPECT_NEAR(back.trajectory[1].q[m.SlotIndex("xP")], 2 * std::cos(-std::numbers::pi / 6), 1e-12);
  EXPECT_NEAR(back.trajectory[1].q[m.SlotIndex("yP")], 2 * std::sin(-std::numbers::pi / 6), 1e-12);
  EXPECT_NEAR(back.trajectory[1].qd.norm(), 0, 1e-11);
}

// The reference the harness builds for A01 is the closed form, confirmed by index-1 DOPRI5 on
// the full model over the first 200 s (1.7e-9 measured, stated 1e-8).
TEST(HarnessPendulum, ReferenceIsTheClosedFormConfirmed) {
  const numeric::Reference ref = references::ReferenceFor(A01());
  EXPECT_TRUE(ref.confirmed) << ref.description;
  EXPECT_LT(ref.agreement, 1e-8);
  EXPECT_EQ(ref.compared_samples, 401);
  EXPECT_NE(ref.description.find("Jacobi"), std::string::npos) << ref.description;
}

// The criteria: the largest distance of P1 over the output steps, and the levels met. ALI3-P at
// its default step is judged against the closed form; a run shifted by 2e-3 m meets only 0.1; a
// run that stopped early is not judged.
TEST(HarnessPendulum, CriteriaJudgeThePointOverTheOutputSteps) {
  const Model& m = A01();
  ASSERT_TRUE(m.criteria.has_value());
  EXPECT_EQ(m.criteria->output_steps, 4000);
  ASSERT_EQ(m.criteria->levels.size(), 2u);
  std::string why;
  const numeric::ExactSolution exact = references::PendulumExact(m, {}, why);
  const CriteriaVerdict same = JudgeCriteria(m, exact.trajectory, exact.trajectory);
  EXPECT_EQ(same.error, 0);
  EXPECT_TRUE(same.complete);
  EXPECT_EQ(same.Verdict(*m.criteria), "meets 0.001, 0.1");
  std::vector<Sample> shifted = exact.trajectory;
  shifted[1234].q[m.SlotIndex("yP1")] += 2e-3;
  const CriteriaVerdict off = JudgeCriteria(m, exact.trajectory, shifted);
  EXPECT_NEAR(off.error, 2e-3, 1e-12);
  EXPECT_EQ(off.t, m.analysis.TimeAt(1234));
  EXPECT_EQ(off.Verdict(*m.criteria), "meets 0.1, not 0.001");
  shifted[10].q[m.SlotIndex("xP1")] += 0.5;
  EXPECT_EQ(JudgeCriteria(m, exact.trajectory, shifted).Verdict(*m.criteria), "meets neither level (0.001, 0.1)");
  const std::vector<Sample> partial(exact.trajectory.begin(), exact.trajectory.begin() + 100);
  EXPECT_FALSE(JudgeCriteria(m, exact.trajectory, partial).complete);
}

// A spatial scene's criteria judge its point's distance in 3-D (A04, Bricard, criteria on P3): a
// trajectory held at the file's pose, then P3 moved by (3, 0, 4) mm at one output step (5 mm in
// space: the z component counts), and by 0.2 m along z alone at another.
TEST(HarnessPendulum, CriteriaOnASpatialPointJudgeItsDistanceIn3D) {
  const Model m = references::LoadScenarioValidated(std::string(MECHBENCH_TEST_DATA) +
                                                    "/../../scenarios/benchmarks/a04_bricard.yaml");
  ASSERT_TRUE(m.criteria.has_value());
  EXPECT_EQ(m.criteria->name, "P3");
  ASSERT_EQ(CriteriaSlots(m).size(), 3u);
  std::vector<Sample> still;
  for (int k = 0; k < m.analysis.samples; ++k) {
    Sample s;
    s.t = m.analysis.TimeAt(k);
    s.q = m.GuessQ();
    still.push_back(s);
  }
  EXPECT_EQ(JudgeCriteria(m, still, still).Verdict(*m.criteria), "meets 0.001, 0.1");
  std::vector<Sample> moved = still;
  moved[500].q[m.SlotIndex("xP3")] += 3e-3;
  moved[500].q[m.SlotIndex("zP3")] += 4e-3;
  const CriteriaVerdict off = JudgeCriteria(m, still, moved);
  EXPECT_NEAR(off.error, 5e-3, 1e-12);
  EXPECT_EQ(off.t, m.analysis.TimeAt(500));
  EXPECT_EQ(off.Verdict(*m.criteria), "meets 0.1, not 0.001");
  moved[900].q[m.SlotIndex("zP3")] += 0.2;
  EXPECT_EQ(JudgeCriteria(m, still, moved).Verdict(*m.criteria), "meets neither level (0.001, 0.1)");
}

}  // namespace
}  // namespace harness_pendulum_test
}  // namespace mechbench::harness

namespace mechbench::harness {
namespace harness_pendulum_test {  // this file's own names (the tests build in unity batches)
namespace {

// The same pendulum written with the rod's angle as a coordinate (pendulum_angle_exact.yaml, the
// initial condition on theta) is the registry's pendulum too: the closed form gives theta beside
// the tip, theta is the tip's direction from the pivot at every sample, the tip moves exactly as in
// the points-only file (pendulum_point_mass_exact.yaml), and the reference is confirmed on the
// full model by index-1 DOPRI5, theta included.
TEST(HarnessPendulum, TheCranksAngleAsACoordinateIsThePendulum) {
  const std::string dir = std::string(MECHBENCH_TEST_DATA) + "/scenes/";
  const Model m = references::LoadScenarioValidated(dir + "pendulum_angle_exact.yaml");
  const Model points_only = references::LoadScenarioValidated(dir + "pendulum_point_mass_exact.yaml");
  ParallelCranks pc;
  std::string why;
  ASSERT_TRUE(AnalyzeParallelCranks(m, pc, why)) << why;
  const int th = m.SlotIndex("theta"), x = m.SlotIndex("xP"), y = m.SlotIndex("yP");
  EXPECT_EQ(pc.angle_slot, th);
  EXPECT_NEAR(pc.angle0, -std::numbers::pi / 6, 1e-15);
  const numeric::ExactSolution a = references::PendulumExact(m, {}, why);
  const numeric::ExactSolution b = references::PendulumExact(points_only, {}, why);
  ASSERT_EQ(a.trajectory.size(), b.trajectory.size()) << why;
  for (size_t k = 0; k < a.trajectory.size(); ++k) {
    const Sample &s = a.trajectory[k], &r = b.trajectory[k];
    EXPECT_NEAR(s.q[x], r.q[points_only.SlotIndex("xP")], 1e-14);
    EXPECT_NEAR(s.q[y], r.q[points_only.SlotIndex("yP")], 1e-14);
    EXPECT_NEAR(s.q[th], std::atan2(s.q[y], s.q[x]), 1e-12) << "t = " << s.t;
    // ẋ = −L sin θ θ̇, ẏ = L cos θ θ̇ (L = 2)
    EXPECT_NEAR(s.qd[x], -2 * std::sin(s.q[th]) * s.qd[th], 1e-12);
    EXPECT_NEAR(s.qd[y], 2 * std::cos(s.q[th]) * s.qd[th], 1e-12);
  }
  const numeric::Reference ref = references::ReferenceFor(m);
  EXPECT_TRUE(ref.confirmed) << ref.description;
  EXPECT_LT(ref.agreement, 1e-8) << ref.description;
}

// An angle that is not along the crank, or measured from another vector, is refused with what
// the closed form describes (the first difference found, as for any other structure).
TEST(HarnessPendulum, AnAngleNotAlongTheCrankIsRefused) {
  Model m = LoadScenario(std::string(MECHBENCH_TEST_DATA) + "/scenes/pendulum_angle_exact.yaml");
  m.coordinates[0].ref = {0, 1};  // from O towards P instead of the ground x axis
  EXPECT_THROW(references::Validate(m), ScenarioError);
  ParallelCranks pc;
  std::string why;
  EXPECT_FALSE(AnalyzeParallelCranks(m, pc, why));
  EXPECT_NE(why.find("not the crank's angle from the ground x axis"), std::string::npos) << why;
}

}  // namespace
}  // namespace harness_pendulum_test
}  // namespace mechbench::harness
