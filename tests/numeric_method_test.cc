// The numeric method as the harness uses it: impossible scenes (status and message), redundant
// rows, singular positions, free scenes, the motion sweep, and every built-in scenario file.
#include "mechbench/errors.h"
#include "mechbench/format.h"
#include "mechbench/loader.h"
#include "mechbench/numeric/constraints.h"
#include "mechbench/numeric/natural_data.h"
#include "mechbench/numeric/natural_model.h"
#include "mechbench/numeric/numeric_method.h"
#include "mechbench/numeric/solver.h"
#include "quantity.h"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

namespace mechbench::numeric {
namespace numeric_method_test {  // this file's own names (the tests build in unity batches)
namespace {

constexpr double kPi = std::numbers::pi;

Result RunNumeric(const Model& model, bool motion = true) {
  RunOptions options;
  options.motion = motion;
  return MakeNumericMethod()->Run(model, options);
}

Model LoadBuiltin(const std::string& scenario) { return LoadScenario(ResolveScenario(scenario)); }

// A file under tests/data: "scenes/…" for test scenes, "bad/…" for files the command line refuses.
std::string Fixture(const std::string& path) { return std::string(MECHBENCH_TEST_DATA) + "/" + path; }
Model LoadFixture(const std::string& path) { return LoadScenario(Fixture(path)); }

bool Contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// The §4.5 crank-rocker (crank 2, coupler 8, rocker 5, ground 10) from the book's rough guesses,
// θ = π/3 + t through one turn, with the crank angle in each form
// (tests/data/scenes/crank_rocker_turn_{cos,cross,cos_sin}.yaml).
Model CrankRockerTurn(const std::string& form) { return LoadFixture("scenes/crank_rocker_turn_" + form + ".yaml"); }

TEST(NumericMethod, NameAndApplicability) {
  const auto m = MakeNumericMethod();
  EXPECT_EQ(m->name(), "numeric");
  EXPECT_TRUE(Contains(m->description(), "Newton"));
  EXPECT_EQ(m->Applicability(LoadBuiltin("s4_5_fourbar_position")), std::nullopt);
}

TEST(NumericMethod, TooManyDriversIsAScenarioErrorNamingTheDrivers) {
  // Inconsistent extra driver: Newton cannot meet both, the scene without drivers assembles.
  const Result r = RunNumeric(LoadFixture("bad/29_two_drivers_one_dof.yaml"));
  EXPECT_EQ(r.status, Status::kInvalidScenario);
  EXPECT_TRUE(Contains(r.reason, "n − rank Φ_q = 5 − 4 = 1 degree of freedom but 2 drivers are given")) << r.reason;
  EXPECT_TRUE(Contains(r.reason, "29_two_drivers_one_dof.yaml:20")) << r.reason;  // the first driver's line
  EXPECT_TRUE(Contains(r.reason, "remove 1 driver")) << r.reason;
  // Consistent extra driver: Newton converges, the rank check still refuses it.
  const Result r2 = RunNumeric(LoadFixture("bad/30_two_consistent_drivers.yaml"));
  EXPECT_EQ(r2.status, Status::kInvalidScenario);
  EXPECT_TRUE(Contains(r2.reason, "but 2 drivers are given")) << r2.reason;
}

TEST(NumericMethod, TooFewDriversIsAScenarioError) {
  // §4.6's double slider has two degrees of freedom; drive only one.
  Model m = LoadBuiltin("s3_3_double_slider");
  ASSERT_EQ(m.drivers.size(), 2u);
  m.drivers.pop_back();
  const Result r = RunNumeric(m);
  EXPECT_EQ(r.status, Status::kInvalidScenario);
  EXPECT_TRUE(Contains(r.reason, "4 − 2 = 2 degrees of freedom but 1 driver is given")) << r.reason;
}

TEST(NumericMethod, TooShortLinkCannotAssemble) {
  // The §4.5 crank-rocker with a coupler of 1 m: 2 + 1 + 5 < 10.
  const Model m = LoadFixture("bad/07_link_too_short.yaml");
  const Result r = RunNumeric(m);
  EXPECT_EQ(r.status, Status::kInvalidScenario);
  EXPECT_TRUE(Contains(r.reason, "07_link_too_short.yaml:")) << r.reason;
  EXPECT_TRUE(Contains(r.reason, "cannot assemble: body ")) << r.reason;
  EXPECT_TRUE(Contains(r.reason, "cannot close the loop")) << r.reason;
  EXPECT_TRUE(Contains(r.reason, "check lengths and the initial guess")) << r.reason;
  // The same through the algorithm: a ScenarioError.
  const NaturalModel nm = Compile(m);
  NaturalData d(nm);
  EXPECT_THROW(SolveInstant(nm, d, 0.0, nm.model.GuessQ()), ScenarioError);
}

TEST(NumericMethod, UnreachableDriverValueIsTold) {
  // The rocker's angle ψ driven to 0 (pointing along +x from B) puts 2 at 15 m from A, beyond
  // crank + coupler = 10; without the driver the linkage assembles.
  const Result r = RunNumeric(LoadFixture("bad/31_driver_out_of_reach.yaml"));
  EXPECT_EQ(r.status, Status::kInvalidScenario);
  const std::string driver_line = Fixture("bad/31_driver_out_of_reach.yaml") + ":21";  // ψ's driver
  EXPECT_TRUE(Contains(r.reason, "cannot reach the driven values (psi (" + driver_line + "))")) << r.reason;
  // The range the rocker reaches from the drawn position, between its limits where crank and
  // coupler are stretched out (|2 − A| = 10) and folded (6): cos ψ = (d² − 125) / 100.
  const auto deg = [](double a) { return Fmt(a, 4) + " (" + Fmt(a * 180 / kPi, 4) + " deg)"; };
  const std::string range = deg(std::acos((10.0 * 10 - 125) / 100)) + " … " + deg(std::acos((6.0 * 6 - 125) / 100));
  EXPECT_TRUE(Contains(r.reason, "psi = 0 (0 deg) is out of the mechanism's reach")) << r.reason;
  EXPECT_TRUE(Contains(r.reason, "it moves through psi = " + range)) << r.reason;
  EXPECT_TRUE(Contains(r.reason, "give psi values within " + range)) << r.reason;
}

TEST(NumericMethod, UnreachableDriverInASpatialSceneNamesTheRange) {
  // The RSSR of rssr_fourbar_angles.yaml with its input angle driven to 3 rad: its closed form
  // d2 cos φ + d3 sin φ = K(θ) (d = D − B(θ), K = (b² − c² − |d|²) / 2c) has a solution only while
  // K² ≤ d2² + d3²; the limits on either side of θ = π, found here by bisection, must be the range
  // the message gives.
  const Result r = RunNumeric(LoadFixture("bad/121_spatial_driver_out_of_reach.yaml"));
  EXPECT_EQ(r.status, Status::kInvalidScenario);
  const double a = 1, b = 3, c = 2;
  const auto closes = [&](double th) {
    const double d1 = 2 - a * std::cos(th), d2 = 1 - a * std::sin(th), d3 = 1.5;
    const double K = (b * b - c * c - (d1 * d1 + d2 * d2 + d3 * d3)) / (2 * c);
    return K * K <= d2 * d2 + d3 * d3;
  };
  const auto limit = [&](double inside, double outside) {
    EXPECT_TRUE(closes(inside));
    EXPECT_FALSE(closes(outside));
    for (int i = 0; i < 60; ++i) {
      const double mid = 0.5 * (inside + outside);
      (closes(mid) ? inside : outside) = mid;
    }
    return inside;
  };
  const double hi = limit(1.047, 3.0), lo = limit(-3.0, -kPi);
  const auto deg = [](double v) { return Fmt(v, 4) + " (" + Fmt(v * 180 / kPi, 4) + " deg)"; };
  EXPECT_TRUE(Contains(r.reason, "theta = 3 (171.9 deg) is out of the mechanism's reach")) << r.reason;
  EXPECT_TRUE(Contains(r.reason, "it moves through theta = " + deg(lo) + " … " + deg(hi))) << r.reason;
  EXPECT_TRUE(Contains(r.reason, "give theta values within " + deg(lo) + " … " + deg(hi))) << r.reason;
  // How far the position problem got: just past the limit, the rows left open and their residual.
  EXPECT_TRUE(Contains(r.reason, "just beyond, the nearest the position problem comes is ‖Φ‖ = ")) << r.reason;
}

TEST(NumericMethod, RedundantCosSinRowsGiveAMessageNotAnError) {
  const Result cs = RunNumeric(CrankRockerTurn("cos_sin"), false);
  ASSERT_TRUE(cs.ok()) << cs.reason;
  ASSERT_EQ(cs.messages.size(), 1u);
  EXPECT_TRUE(Contains(cs.messages[0], "1 redundant constraint: row 4 coordinate theta (sin)")) << cs.messages[0];
  EXPECT_TRUE(Contains(cs.messages[0], "(m = 5, rank Φ_q = 4)")) << cs.messages[0];
  EXPECT_EQ(Get(cs, "rows"), 5);
  EXPECT_EQ(Get(cs, "rank"), 4);
  EXPECT_EQ(Get(cs, "dof"), 1);
  // Same kinematics as the cos form alone.
  const Result c = RunNumeric(CrankRockerTurn("cos"), false);
  ASSERT_TRUE(c.ok()) << c.reason;
  EXPECT_TRUE(c.messages.empty());
  for (const char* name : {"q.x2", "q.y2", "qd.x2", "qd.y2", "qdd.x2", "qdd.y2"})
    EXPECT_NEAR(Get(cs, name), Get(c, name), 1e-9) << name;
}

TEST(NumericMethod, CosineFormAtZeroIsASingularPosition) {
  // §4.1 with the rod horizontal: x_B − x_A − d cos θ has no θ-derivative at θ = 0.
  const Result r = RunNumeric(LoadFixture("bad/32_cos_form_at_zero.yaml"));
  EXPECT_EQ(r.status, Status::kInvalidScenario);
  EXPECT_TRUE(Contains(r.reason, "32_cos_form_at_zero.yaml:20")) << r.reason;  // the coordinate's line
  EXPECT_TRUE(Contains(r.reason, "coordinate theta (cos)")) << r.reason;
  EXPECT_TRUE(Contains(r.reason, "loses rank")) << r.reason;
  EXPECT_TRUE(Contains(r.reason, "form: cross")) << r.reason;
}

TEST(NumericMethod, SliderCrankAtDeadCentreDrivenByTheSliderIsSingular) {
  const Result r = RunNumeric(LoadFixture("bad/33_slider_crank_dead_centre.yaml"));
  EXPECT_EQ(r.status, Status::kInvalidScenario);
  EXPECT_TRUE(Contains(r.reason, "singular position")) << r.reason;
  EXPECT_TRUE(Contains(r.reason, "rank [Φ_q; B] = 2 < n = 3")) << r.reason;
}

TEST(NumericMethod, FullCrankTurnIsConsistentWithItsOwnDerivatives) {
  // The cross form: good at every crank angle (the cos form is singular at θ = π, see below).
  const Result r = RunNumeric(CrankRockerTurn("cross"));
  ASSERT_TRUE(r.ok()) << r.reason;
  ASSERT_EQ(r.trajectory.size(), 721u);
  const double dt = 2 * kPi / 720;
  for (size_t k = 0; k < r.trajectory.size(); ++k) {
    const Sample& s = r.trajectory[k];
    EXPECT_LT(s.residual, 1e-10) << "t = " << s.t;
    EXPECT_NEAR(s.t, k * dt, 1e-12);
    EXPECT_NEAR(s.q[4], kPi / 3 + s.t, 1e-12);  // the driven crank angle
    if (k == 0 || k + 1 == r.trajectory.size()) continue;
    // Central differences of q and q̇ along the sweep, O(dt²) ≈ 1e-4 of the values.
    const Sample &a = r.trajectory[k - 1], &b = r.trajectory[k + 1];
    EXPECT_LT(((b.q - a.q) / (2 * dt) - s.qd).cwiseAbs().maxCoeff(), 2e-4 * (1 + s.qd.cwiseAbs().maxCoeff())) << "t = " << s.t;
    EXPECT_LT(((b.qd - a.qd) / (2 * dt) - s.qdd).cwiseAbs().maxCoeff(), 2e-4 * (1 + s.qdd.cwiseAbs().maxCoeff())) << "t = " << s.t;
  }
  // One turn later the linkage is back where it started, on the same branch; θ gained 2π.
  EXPECT_LT((r.trajectory.back().q.head(4) - r.trajectory.front().q.head(4)).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_NEAR(r.trajectory.back().q[4] - r.trajectory.front().q[4], 2 * kPi, 1e-12);
  EXPECT_EQ(r.settings.count("max_iterations"), 1u);
  EXPECT_EQ(r.settings.count("predictor"), 1u);
}

TEST(NumericMethod, CosineFormCrankStopsAtItsSingularAngle) {
  // With the book's cos form the crank angle θ = π/3 + t reaches π at t = 2π/3: the row
  // x1 − 2 cos θ no longer fixes y1's rate there, so the sweep stops with a reason.
  const Result r = RunNumeric(CrankRockerTurn("cos"));
  EXPECT_EQ(r.status, Status::kDiverged);
  EXPECT_TRUE(Contains(r.reason, "singular position at t = 2.0944 s")) << r.reason;
  EXPECT_EQ(r.trajectory.size(), 240u);  // samples 0..239; sample 240 is θ = π
}

TEST(NumericMethod, MotionThatLeavesTheWorkspaceIsBadInputAndKeepsTheSamplesSoFar) {
  // §4.1's slider A keeps accelerating down for 3 s: yA passes −15 m, which the rod cannot reach
  // (and θ = 0 on the way is a singular position of the cos form). The file stops at 0.6 s. A
  // motion that does not exist is bad input, as a value out of reach at t0 is.
  Model m = LoadBuiltin("s4_1_two_sliders");
  m.analysis.t1 = 3;
  m.analysis.samples = 301;
  const Result r = RunNumeric(m);
  EXPECT_EQ(r.status, Status::kInvalidScenario) << r.reason;
  EXPECT_TRUE(Contains(r.reason, "at t = ")) << r.reason;
  EXPECT_GT(r.trajectory.size(), 50u);   // the first 0.5 s are fine
  EXPECT_LT(r.trajectory.size(), 301u);
  for (const Sample& s : r.trajectory) EXPECT_LT(s.residual, 1e-8) << "t = " << s.t;
  // The instant's quantities are kept.
  EXPECT_NEAR(Get(r, "qd.theta"), -10 / (15 * std::cos(35 * kPi / 180)), 1e-9);
}

// t1 = 1e9 s in 73 samples: every sample interval turns the crank 1.4e7 times, so the prediction
// from the previous sample is no guide. The reason names the interval and the drivers' travel
// (it used to give only Newton–Raphson's residual); the same motion in 1 s runs.
// The crank-rocker turned at 1 rad/s (tests/data/scenes/crank_rocker_turn_cross.yaml) over `t1` s.
Model CrankRockerOver(double t1, int samples) {
  Model m = CrankRockerTurn("cross");
  m.analysis.t1 = t1;
  m.analysis.samples = samples;
  return m;
}

TEST(NumericMethod, ASampleIntervalBeyondThePredictionIsNamed) {
  const Result r = RunNumeric(CrankRockerOver(1e9, 73));
  EXPECT_EQ(r.status, Status::kDiverged);
  EXPECT_TRUE(Contains(r.reason, "Newton–Raphson did not converge at t = 1.38889e+07 s")) << r.reason;
  EXPECT_TRUE(Contains(r.reason, "the sample interval of 1.39e+07 s moves theta by 1.39e+07 rad (2.21e+06 turns), "
                                 "further than a prediction from the previous sample can follow"))
      << r.reason;
  EXPECT_EQ(RunNumeric(CrankRockerOver(1, 73)).status, Status::kOk);
}

// An RSSR driven past its reach during the motion (it assembles at t0): bad input, as at t0 (the
// file asks for a motion that does not exist; it was a diverged run, and every engine still ran it,
// newuser9), on the driver's line, with the time and, as at t0, the input angle's range from the
// previous sample (it used to say only "a driver beyond the mechanism's reach?").
TEST(NumericMethod, ADriverPastItsReachInTheMotionNamesItsRange) {
  const Result r = RunNumeric(LoadFixture("scenes/rssr_past_reach_in_motion.yaml"));
  EXPECT_EQ(r.status, Status::kInvalidScenario);
  EXPECT_TRUE(Contains(r.reason, "rssr_past_reach_in_motion.yaml:")) << r.reason;
  EXPECT_TRUE(Contains(r.reason, "Newton–Raphson did not converge at t = 0.8 s")) << r.reason;
  EXPECT_TRUE(Contains(r.reason, "theta = 2 (114.6 deg) is out of the mechanism's reach: from the position at t = 0.7 s "
                                 "(the previous sample) (theta = 1.75 (100.3 deg)) it moves through theta = "))
      << r.reason;
  EXPECT_TRUE(Contains(r.reason, "give theta values within ")) << r.reason;
  EXPECT_EQ(r.trajectory.size(), 8u);  // t = 0 … 0.7 s
}

// The kinematic sweep stops on its CPU budget like every stepping method, keeping its samples.
TEST(NumericMethod, StopsOnItsBudget) {
  RunOptions options;
  options.cpu_budget = 0.05;
  const Result r = MakeNumericMethod()->Run(CrankRockerOver(100, 1000000), options);
  EXPECT_EQ(r.status, Status::kOverBudget) << r.reason;
  EXPECT_TRUE(Contains(r.reason, "its CPU budget of 0.05 s ran out")) << r.reason;
  EXPECT_GT(r.trajectory.size(), 1u);
  EXPECT_LT(r.trajectory.size(), 1000000u);
}

TEST(NumericMethod, QuantitiesCoverPointsBodiesSlidersAndMatrices) {
  // §3.4 placed in the world's Y–Z plane, 5 above the origin (scenarios/s3_4_disc_slotted_bar.yaml
  // is in the XY plane).
  Model m = LoadBuiltin("s3_4_disc_slotted_bar");
  m.embedding = Embedding{.origin = {0, 0, 5}, .u = {0, 1, 0}, .v = {0, 0, 1}};
  const Result r = RunNumeric(m);
  ASSERT_TRUE(r.ok()) << r.reason;
  // Fixed points too, embedded: (x, y) ↦ origin + x u + y v.
  EXPECT_EQ(Get(r, "p.O2.x"), 0);
  EXPECT_EQ(Get(r, "p.O2.y"), 150);
  EXPECT_EQ(Get(r, "p.O2.z"), 5);
  EXPECT_EQ(Get(r, "v.O2.y"), 0);
  EXPECT_NEAR(Get(r, "v.2.y"), Get(r, "qd.x2"), 0);
  EXPECT_NEAR(Get(r, "a.2.z"), Get(r, "qdd.y2"), 0);
  EXPECT_EQ(r.quantities.count("vabs.2.x"), 0u);  // no frame rotation
  for (const char* q : {"omega.bar", "alpha.disc", "vslide.1", "aslide.1", "Phi_q[3,4]", "Phidot_q[2,3]",
                        "Phidot_q_qd[0]", "Phi[3]", "newton.1.x1", "rank", "dof", "iterations"})
    EXPECT_EQ(r.quantities.count(q), 1u) << q;
  EXPECT_EQ(r.quantities.count("Phi_q[4,0]"), 0u);  // driver rows are not part of Φ_q
  EXPECT_EQ(r.quantities.count("M[0,0]"), 0u);      // no mass, no M
  // ω of the bar from its points equals the rate of its direction angle; α likewise (α from q̈).
  const double x2 = Get(r, "q.x2"), y2 = Get(r, "q.y2");
  const double vx = Get(r, "qd.x2"), vy = Get(r, "qd.y2");
  EXPECT_NEAR(Get(r, "omega.bar"), (x2 * vy - y2 * vx) / (x2 * x2 + y2 * y2), 1e-12);
  // Φ_q q̇ = 0 and Φ_q q̈ = −Φ̇_q q̇ at the instant, through the named quantities.
  const char* slots[5] = {"x1", "y1", "x2", "y2", "theta"};
  for (int i = 0; i < 4; ++i) {
    double vel = 0, acc = 0;
    for (int j = 0; j < 5; ++j) {
      const std::string ij = "[" + std::to_string(i) + "," + std::to_string(j) + "]";
      vel += Get(r, "Phi_q" + ij) * Get(r, std::string("qd.") + slots[j]);
      acc += Get(r, "Phi_q" + ij) * Get(r, std::string("qdd.") + slots[j]);
    }
    EXPECT_NEAR(vel, 0, 1e-8) << "row " << i;
    EXPECT_NEAR(acc, -Get(r, "Phidot_q_qd[" + std::to_string(i) + "]"), 1e-6) << "row " << i;
    EXPECT_NEAR(Get(r, "Phi[" + std::to_string(i) + "]"), 0, 1e-9) << "row " << i;
  }
}

TEST(NumericMethod, SlideAndBodyRatesMatchFiniteDifferencesInTime) {
  // §4.8's bushing 1 on the slotted bar: vslide/aslide are ṡ and s̈ of s = (r1 − r_O4)·û, and
  // omega/alpha of the bar are the rates of its direction angle.
  // scenarios/disc_slotted_bar_full_turn.yaml (cross form), with a disc that accelerates.
  Model model = LoadBuiltin("disc_slotted_bar_full_turn");
  model.drivers[0].acceleration = 20;
  const Result r = MakeNumericMethod()->Run(model);
  ASSERT_TRUE(r.ok()) << r.reason;
  const NaturalModel nm = Compile(model);
  const int p1 = model.PointIndex("1"), p2 = model.PointIndex("2");
  const auto at = [&](double t) {  // (s, bar angle) at time t
    NaturalData d(nm);
    SolveInstant(nm, d, t, nm.model.GuessQ());
    const Eigen::Vector2d u = d.r[p2].normalized();
    return Eigen::Vector2d(d.r[p1].dot(u), std::atan2(d.r[p2].y(), d.r[p2].x()));
  };
  const double h = 1e-3;
  const Eigen::Vector2d f2m = at(-2 * h), fm = at(-h), f0 = at(0), fp = at(h), f2p = at(2 * h);
  const Eigen::Vector2d d1 = (-f2p + 8 * fp - 8 * fm + f2m) / (12 * h);
  const Eigen::Vector2d d2 = (-f2p + 16 * fp - 30 * f0 + 16 * fm - f2m) / (12 * h * h);
  EXPECT_NEAR(Get(r, "vslide.1"), d1[0], 1e-6 * std::abs(d1[0]));
  EXPECT_NEAR(Get(r, "aslide.1"), d2[0], 1e-5 * std::abs(d2[0]));
  EXPECT_NEAR(Get(r, "omega.bar"), d1[1], 1e-8);
  EXPECT_NEAR(Get(r, "alpha.bar"), d2[1], 1e-5);
  EXPECT_NEAR(Get(r, "alpha.disc"), 20, 1e-9);
}

TEST(NumericMethod, AbsoluteValuesMatchFiniteDifferencesOfTheTurningFrame) {
  // Two links in a plane tilted in 3-D, and the frame turning about an oblique axis: p_abs(t) =
  // R(t)(p(t) − c) + c differentiated numerically against the method's matrix form.
  const Model model = LoadFixture("scenes/thumb_tilted_plane.yaml");
  const Result r = MakeNumericMethod()->Run(model);
  ASSERT_TRUE(r.ok()) << r.reason;
  const NaturalModel nm = Compile(model);
  const FrameRotation& F = *model.frame;
  const auto p_abs = [&](double t) {
    NaturalData d(nm);
    SolveInstant(nm, d, t, nm.model.GuessQ());
    const int b = model.PointIndex("B");
    const Eigen::Vector3d p = model.embedding.origin + model.embedding.u * d.r[b].x() + model.embedding.v * d.r[b].y();
    const Eigen::Matrix3d R = Eigen::AngleAxisd(F.omega * t, F.axis).toRotationMatrix();
    return Eigen::Vector3d(R * (p - F.axis_point) + F.axis_point);
  };
  // Five-point stencils: truncation O(h⁴), so the comparison is limited by round-off only.
  const double h = 1e-3;
  const Eigen::Vector3d p2m = p_abs(-2 * h), pm = p_abs(-h), p0 = p_abs(0), pp = p_abs(h), p2p = p_abs(2 * h);
  const Eigen::Vector3d v_fd = (-p2p + 8 * pp - 8 * pm + p2m) / (12 * h);
  const Eigen::Vector3d a_fd = (-p2p + 16 * pp - 30 * p0 + 16 * pm - p2m) / (12 * h * h);
  for (int i = 0; i < 3; ++i) {
    const std::string c(1, "xyz"[i]);
    EXPECT_NEAR(Get(r, "p.B." + c), p0[i], 1e-9);
    EXPECT_NEAR(Get(r, "vabs.B." + c), v_fd[i], 1e-7) << c;
    EXPECT_NEAR(Get(r, "aabs.B." + c), a_fd[i], 1e-5) << c;
  }
}

TEST(NumericMethod, EveryBuiltinScenarioRunsOrSaysWhyNot) {
  const std::vector<std::string> files = BuiltinScenarioFiles();
  if (files.empty()) GTEST_SKIP() << "no built-in scenarios in " << BuiltinScenarioDir();
  const auto method = MakeNumericMethod();
  for (const std::string& file : files) {
    SCOPED_TRACE(file);
    Model model;
    try {
      model = LoadScenario(file);
    } catch (const ScenarioError& e) {
      ADD_FAILURE() << "does not load: " << e.what();  // the loader's own tests own this
      continue;
    }
    const Result r = method->Run(model);
    if (r.status == Status::kNotApplicable) {
      EXPECT_FALSE(r.reason.empty());
      continue;
    }
    EXPECT_EQ(r.status, Status::kOk) << r.reason;
    if (!r.ok()) continue;
    ASSERT_FALSE(r.trajectory.empty());
    EXPECT_EQ(static_cast<int>(r.trajectory.size()), model.analysis.HasMotion() && !model.drivers.empty() ? model.analysis.samples : 1);
    for (const Sample& s : r.trajectory) EXPECT_LT(s.residual, 1e-6) << "t = " << s.t;
  }
}

}  // namespace
}  // namespace numeric_method_test
}  // namespace mechbench::numeric
