// Planar linkages by closed-form dyads: book instants (§3.3, §3.4, §4.1, §4.3, §4.7), full turns
// checked against finite differences, and the failure paths (cannot assemble, loop breaks during
// a motion, not applicable).
#include "mechbench/analytic/analytic_method.h"
#include "mechbench/analytic/linkage.h"
#include "mechbench/loader.h"
#include "quantity.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

namespace mechbench::analytic {
namespace analytic_linkage_test {  // this file's own names (the tests build in unity batches)
namespace {

Model Load(const std::string& scenario) { return LoadScenario(ResolveScenario(scenario)); }

std::string Fixture(const std::string& path) { return std::string(MECHBENCH_TEST_DATA) + "/" + path; }

Result RunAnalytic(const Model& m, bool motion = true) {
  RunOptions o;
  o.motion = motion;
  return MakeAnalyticMethod()->Run(m, o);
}

// Along a motion, q̇ and q̈ must be the time derivatives of q and q̇: central differences with a
// small step, from independent closed-form solves at t ± h.
void ExpectRatesMatchFiniteDifferences(const Model& m, double tol) {
  const LinkageSolver solver(m);
  LinkageState prev = solver.Solve(m.analysis.t0);
  const double h = 1e-5;
  for (int k = 0; k < m.analysis.samples; ++k) {
    const double t = m.analysis.TimeAt(k);
    const LinkageState s = solver.Solve(t, &prev);
    const LinkageState sp = solver.Solve(t + h, &s), sm = solver.Solve(t - h, &s);
    Eigen::VectorXd q, qd, qdd, qp, qdp, qddp, qm, qdm, qddm;
    solver.ToLayout(s, q, qd, qdd);
    solver.ToLayout(sp, qp, qdp, qddp);
    solver.ToLayout(sm, qm, qdm, qddm);
    EXPECT_LT(s.residual, 1e-9) << "t = " << t;
    EXPECT_LT(((qp - qm) / (2 * h) - qd).cwiseAbs().maxCoeff(), tol * (1 + qd.cwiseAbs().maxCoeff())) << "t = " << t;
    EXPECT_LT(((qdp - qdm) / (2 * h) - qdd).cwiseAbs().maxCoeff(), tol * (1 + qdd.cwiseAbs().maxCoeff())) << "t = " << t;
    prev = s;
  }
}

// §3.3 (scenarios/s3_3_double_slider.yaml): v2 = (0, 1), ω12 = 0, ω32 = 1; a2 = (0, −1), α12 = −2,
// α32 = 0 (all as printed).
// Signs checked by hand: 2 = 1 + (1, 0) on bar 12, so v2 = v1 + ω12 k×(1, 0) = (0, 1 + ω12) and
// v2 = v3 + ω32 k×(1, 1) = (1 − ω32, ω32) give ω32 = 1, ω12 = 0; then a2 = (0, 1 + α12) =
// (1 − α32 − ω32², α32 − ω32²) gives α32 = 0, α12 = −2, a2 = (0, −1).
TEST(AnalyticLinkage, Section3_3DoubleSliderMatchesTheBook) {
  const Model m = Load("s3_3_double_slider");
  const Result r = RunAnalytic(m, false);
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_NEAR(Get(r, "qd.x2"), 0, 1e-12);
  EXPECT_NEAR(Get(r, "qd.y2"), 1, 1e-12);
  EXPECT_NEAR(Get(r, "omega.b12"), 0, 1e-12);
  EXPECT_NEAR(Get(r, "omega.b32"), 1, 1e-12);
  EXPECT_NEAR(Get(r, "qdd.x2"), 0, 1e-12);
  EXPECT_NEAR(Get(r, "qdd.y2"), -1, 1e-12);
  EXPECT_NEAR(Get(r, "alpha.b12"), -2, 1e-12);
  EXPECT_NEAR(Get(r, "alpha.b32"), 0, 1e-12);
  EXPECT_NEAR(Get(r, "residual"), 0, 1e-12);
  ASSERT_EQ(r.trajectory.size(), 1u);
  EXPECT_EQ(r.trajectory[0].q.size(), static_cast<Eigen::Index>(m.q_layout.size()));
}

TEST(AnalyticLinkage, Section3_3DoubleSliderMotionRatesAreDerivatives) {
  const Model m = Load("s3_3_double_slider");
  const Result r = RunAnalytic(m);
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_EQ(r.trajectory.size(), 51u);  // the file's 0.5 s in 51 samples
  ExpectRatesMatchFiniteDifferences(m, 1e-6);
}

// §3.4 (scenarios/s3_4_disc_slotted_bar.yaml): ω_O42 = −1.28 rad/s, v_rel = −365.82 mm/s (book's
// sign: vslide is along O4→2, the opposite), v2 = (82.8221, −309.0963) = 320 mm/s at −75°. The
// book's v2 uses ω rounded to −1.28 and the bar at exactly 15°; at 74.6° the bar is at 14.997° and
// ω = −1.27994, so v2 = (82.800, −309.087), 319.985 mm/s.
TEST(AnalyticLinkage, Section3_4SlottedBarMatchesTheBook) {
  const Model m = Load("s3_4_disc_slotted_bar");
  const Result r = RunAnalytic(m, false);
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_NEAR(Get(r, "omega.bar"), -1.28, 0.005);
  EXPECT_NEAR(Get(r, "omega.bar") * 180 / std::numbers::pi, -73.34, 0.005);
  EXPECT_NEAR(Get(r, "vslide.1"), 365.82, 0.005);
  EXPECT_NEAR(Get(r, "qd.x2"), 82.800, 0.001);
  EXPECT_NEAR(Get(r, "qd.y2"), -309.087, 0.001);
  EXPECT_NEAR(std::hypot(Get(r, "qd.x2"), Get(r, "qd.y2")), 320, 0.05);
  // Eq. 3.33 with the book's rounded ω reproduces its printed digits.
  EXPECT_NEAR(1.28 * 250 * std::sin(15 * std::numbers::pi / 180), 82.8221, 5e-5);
  // The disc turns at a constant rate: 1 has only centripetal acceleration about O2.
  EXPECT_NEAR(Get(r, "an.1"), 45 * std::pow(3 * std::numbers::pi, 2), 1e-6);
  EXPECT_NEAR(Get(r, "at.1"), 0, 1e-9);
  EXPECT_NEAR(Get(r, "rho.1"), 45, 1e-9);
}

// The same scene with its cosine-form disc angle (eq. 4.85) through one whole disc turn: the file
// stops at 0.12 s, where that form turns singular for Newton; the closed form follows its branch.
TEST(AnalyticLinkage, Section3_4SlottedBarFullTurnRatesAreDerivatives) {
  Model m = Load("s3_4_disc_slotted_bar");
  m.analysis.t1 = 0.6666666666666666;  // one turn at 90 rpm, 49 samples as in the file
  const Result r = RunAnalytic(m);
  ASSERT_TRUE(r.ok()) << r.reason;
  ASSERT_EQ(r.trajectory.size(), 49u);
  ExpectRatesMatchFiniteDifferences(m, 1e-6);
}

// §4.1 (scenarios/s4_1_two_sliders.yaml): the book's θ satisfies x_B = d cos θ with θ = 35°, while
// A→B points at −35°: the cos form is on its mirrored branch, and θ̇ = −0.8138 rad/s carries that
// sign. ẋB = 7.002 m/s; ẍB = −8.6277 (book −8.6278 from its rounded Φ̇q q̇ = 298.06),
// θ̈ = 0.0569 rad/s².
TEST(AnalyticLinkage, Section4_1TwoSlidersCosFormBranch) {
  const Model m = Load("s4_1_two_sliders");
  const Result r = RunAnalytic(m);
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_NEAR(Get(r, "q.theta"), 35 * std::numbers::pi / 180, 1e-12);
  EXPECT_NEAR(Get(r, "qd.theta"), -0.8138, 5e-5);
  EXPECT_NEAR(Get(r, "qd.xB"), 7.002, 5e-4);
  const double yA = 15 * std::sin(35 * std::numbers::pi / 180), xB = 15 * std::cos(35 * std::numbers::pi / 180);
  const double xBd = 10 * yA / xB;  // from xB² + yA² = d²
  EXPECT_NEAR(Get(r, "qdd.xB"), -(100 + yA * -5 + xBd * xBd) / xB, 1e-10);
  EXPECT_NEAR(Get(r, "qdd.xB"), -8.6277, 5e-5);
  EXPECT_NEAR(Get(r, "qdd.theta"), 0.0569, 5e-5);
  // The rod turns counter-clockwise (its true angle −35° grows): ω = −θ̇.
  EXPECT_NEAR(Get(r, "omega.rod"), -Get(r, "qd.theta"), 1e-12);
}

// §4.3 (scenarios/s4_3_coupler_motor.yaml, φ from 39° to 125° in 1.5 s): motor on the coupler, φ
// between A→1 and 1→2 (dot form) at φ̇ = 1 rad/s: the triangle A-1-2 is rigid for a given φ, so 2
// is found at |A2|(φ) from A and 5 from B.
// Book: φ = 39.094°, q̇ = (−2.2857, 1.7143, −1.8571, 0).
TEST(AnalyticLinkage, Section4_3CouplerMotorByTheRigidTriangle) {
  const Model m = Load("s4_3_coupler_motor");
  const Result r = RunAnalytic(m);
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_NEAR(Get(r, "q.phi") * 180 / std::numbers::pi, 39.094, 5e-4);
  EXPECT_NEAR(Get(r, "q.x1"), 3, 1e-12);
  EXPECT_NEAR(Get(r, "q.y2"), 5, 1e-12);
  EXPECT_NEAR(Get(r, "qd.x1"), -16.0 / 7, 1e-12);  // −2.2857
  EXPECT_NEAR(Get(r, "qd.y1"), 12.0 / 7, 1e-12);   // 1.7143
  EXPECT_NEAR(Get(r, "qd.x2"), -13.0 / 7, 1e-12);  // −1.8571
  EXPECT_NEAR(Get(r, "qd.y2"), 0, 1e-12);
  // The dot form measures |angle|: from A→1 = (3, 4) to 1→2 = (4, 1) the signed angle is −39.094°,
  // so φ is on its mirrored branch and φ̇ = 1 means the coupler turns clockwise relative to the
  // crank: ω12 − ωA1 = −φ̇.
  EXPECT_NEAR(Get(r, "omega.b12") - Get(r, "omega.bA1"), -1.0, 1e-12);
  ExpectRatesMatchFiniteDifferences(m, 1e-6);
}

// §4.7 (scenarios/s4_7_linear_actuator.yaml): the actuator A–2 (length s, ṡ = 1 m/s) closes the
// four-bar A-1-2-B; L = 1.
// Book: q̇ = (3.3461, 0, 3.3461, −1.9318, 1), ω_A1 = 3.3461/L clockwise.
TEST(AnalyticLinkage, Section4_7LinearActuatorTimeVaryingDistance) {
  Model m = Load("s4_7_linear_actuator");
  // The file extends at a constant ṡ; an acceleration too, so that q̈ carries the driver's own
  // term (s stays below 1.54 m in the file's 0.12 s, short of the lock at 1.577 m).
  m.drivers[0].acceleration = 0.5;
  const Result r = RunAnalytic(m);
  ASSERT_TRUE(r.ok()) << r.reason;
  EXPECT_NEAR(Get(r, "qd.x1"), 3.3461, 5e-5);
  EXPECT_NEAR(Get(r, "qd.y1"), 0, 1e-12);
  EXPECT_NEAR(Get(r, "qd.x2"), 3.3461, 5e-5);
  EXPECT_NEAR(Get(r, "qd.y2"), -2 * std::cos(std::numbers::pi / 12), 1e-12);  // −1.93185
  EXPECT_NEAR(Get(r, "qd.y2"), -1.9318, 1e-4);  // the book truncates −1.93185
  EXPECT_NEAR(Get(r, "qd.s"), 1, 1e-15);
  EXPECT_NEAR(Get(r, "omega.bA1"), -3.3461, 5e-5);
  ExpectRatesMatchFiniteDifferences(m, 1e-6);
}

// The §4.5 crank-rocker (2/8/5 on a 10 m base) over a full turn, with the book's cos-form crank
// angle (tests/data/scenes/crank_rocker_cos_accelerating.yaml): velocity matches a finite
// difference of position, acceleration one of velocity, and every loop closes.
TEST(AnalyticLinkage, CrankRockerFullTurnRatesAreDerivatives) {
  const Model m = LoadScenario(Fixture("scenes/crank_rocker_cos_accelerating.yaml"));
  const Result r = RunAnalytic(m);
  ASSERT_TRUE(r.ok()) << r.reason;
  ASSERT_EQ(r.trajectory.size(), 73u);
  for (const Sample& s : r.trajectory) {
    EXPECT_LT(s.residual, 1e-10);
    EXPECT_GT(s.q[m.SlotIndex("y2")], 0) << "left the upper assembly branch at t = " << s.t;
  }
  ExpectRatesMatchFiniteDifferences(m, 1e-6);
  // At θ = π/3 the crank pin is at (1, √3) and 2 is on the branch of the drawing (y2 > 0).
  EXPECT_NEAR(Get(r, "q.x1"), 1, 1e-12);
  EXPECT_NEAR(Get(r, "q.y1"), std::sqrt(3.0), 1e-12);
}

// Quick-return (shaper) mechanism: crank B-1, rocker A-2 along which 1 slides, and point 3 on the
// rocker's line and a horizontal guide (line–line on a turning line, with Coriolis terms).
TEST(AnalyticLinkage, QuickReturnLineLineOnATurningLine) {
  const Model m = LoadScenario(Fixture("scenes/quick_return_line_line.yaml"));
  const Result r = RunAnalytic(m);
  ASSERT_TRUE(r.ok()) << r.reason;
  ExpectRatesMatchFiniteDifferences(m, 1e-6);
  // At θ = 0, 1 = (1, 2): the rocker points along (1, 2) and 3 = (1.75, 3.5).
  EXPECT_NEAR(Get(r, "q.x3"), 1.75, 1e-12);
  EXPECT_NEAR(Get(r, "q.x2"), 4 / std::sqrt(5.0), 1e-12);
  // 1 slides along the rocker: its slip is the part of v1 along A→2 (A is at rest).
  EXPECT_NEAR(Get(r, "vslide.1"), Get(r, "qd.x1") / std::sqrt(5.0) + Get(r, "qd.y1") * 2 / std::sqrt(5.0), 1e-12);
}

// A coupler too short to close the loop (the command line refuses the same file, see
// tests/expect_bad_input.cmake): a ScenarioError naming the body, reported as invalid.
TEST(AnalyticLinkage, CannotAssembleIsAnInvalidScenario) {
  const Model m = LoadScenario(Fixture("bad/07_link_too_short.yaml"));
  const Result r = RunAnalytic(m);
  EXPECT_EQ(r.status, Status::kInvalidScenario);
  EXPECT_NE(r.reason.find("cannot assemble"), std::string::npos) << r.reason;
  EXPECT_NE(r.reason.find("07_link_too_short.yaml:"), std::string::npos) << r.reason;
}

// A non-Grashof linkage driven round: the loop cannot close part-way, so the driven input is past
// the mechanism's reach there — bad input as at t0 and as numeric says it, on the driver's line
// (line 21) with the time (it was a kDiverged row without a file and line; newuser8).
TEST(AnalyticLinkage, LoopThatCannotCloseDuringAMotionIsBadInputOnTheDriversLine) {
  const Model m = LoadScenario(Fixture("scenes/fourbar_non_grashof_turn.yaml"));
  const Result r = RunAnalytic(m);
  EXPECT_EQ(r.status, Status::kInvalidScenario);
  EXPECT_NE(r.reason.find("fourbar_non_grashof_turn.yaml:21: the driven theta at t = 2.35619 s is out of the mechanism's "
                          "reach: the loop cannot close there (cannot assemble: "),
            std::string::npos)
      << r.reason;
}

TEST(AnalyticLinkage, NotApplicableSaysWhy) {
  // No drivers: a dynamics scene.
  Model m = LoadScenario(Fixture("scenes/crank_rocker_cos_accelerating.yaml"));
  m.drivers.clear();
  auto why = MakeAnalyticMethod()->Applicability(m);
  ASSERT_TRUE(why.has_value());
  EXPECT_NE(why->find("no drivers"), std::string::npos);
  // A free two-slider rod with one driver removed: points remain.
  Model m3 = Load("s3_3_double_slider");
  m3.drivers.pop_back();
  why = MakeAnalyticMethod()->Applicability(m3);
  ASSERT_TRUE(why.has_value());
  EXPECT_NE(why->find("no closed-form decomposition"), std::string::npos) << *why;
}

// A third driver on a coordinate the two sliders already fix: right position, wrong rate. The
// rate residual of the unused equation (bar 3-2) shows it.
TEST(AnalyticLinkage, OverSpecifiedDriversAreAnInvalidScenario) {
  Model m = Load("s3_3_double_slider");
  Driver d = m.drivers[0];
  d.coordinate = "y2", d.value = 1, d.velocity = 0.5;  // consistent ẏ2 would be 1
  m.drivers.push_back(d);
  const Result r = RunAnalytic(m);
  EXPECT_EQ(r.status, Status::kInvalidScenario);
  EXPECT_NE(r.reason.find("drivers disagree"), std::string::npos) << r.reason;
}

TEST(AnalyticLinkage, NotApplicableWithoutAnInputToStartFrom) {
  Model m3 = Load("s3_3_double_slider");
  m3.drivers.pop_back();
  m3.drivers.pop_back();
  m3.drivers.push_back(Driver{"x2", 1, 0, 0, nullptr, {}});
  const auto why = MakeAnalyticMethod()->Applicability(m3);
  ASSERT_TRUE(why.has_value());
  EXPECT_NE(why->find("points 1, 2, 3 remain"), std::string::npos) << *why;
}

}  // namespace
}  // namespace analytic_linkage_test
}  // namespace mechbench::analytic
