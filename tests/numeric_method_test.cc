// The numeric method as the harness uses it: impossible scenes (status and message), redundant
// rows, singular positions, free scenes, the motion sweep, and every built-in scenario file.
#include "mechbench/errors.h"
#include "mechbench/loader.h"
#include "mechbench/numeric/constraints.h"
#include "mechbench/numeric/natural_data.h"
#include "mechbench/numeric/natural_model.h"
#include "mechbench/numeric/numeric_method.h"
#include "mechbench/numeric/solver.h"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

namespace mechbench::numeric {
namespace {

constexpr double kPi = std::numbers::pi;

Result RunNumeric(const std::string& yaml, const std::string& name, bool motion = true) {
  RunOptions options;
  options.motion = motion;
  return MakeNumericMethod()->Run(LoadScenarioFromString(yaml, name), options);
}

double Get(const Result& r, const std::string& quantity) {
  const auto it = r.quantities.find(quantity);
  EXPECT_NE(it, r.quantities.end()) << "missing quantity " << quantity;
  return it == r.quantities.end() ? std::nan("") : it->second;
}

bool Contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// The §4.5 crank-rocker (crank 2, coupler 8, rocker 5, ground 10), crank angle θ as the driver;
// `extra` is appended (more drivers, or replaces nothing). Lengths can be changed.
std::string FourBar(const std::string& coupler = "8", const std::string& form = "cos",
                    const std::string& drivers = "  - {coordinate: theta, value: pi/3, velocity: 1}\n",
                    const std::string& more = "") {
  return R"(kind: linkage
points:
  A: {fixed: [0, 0]}
  B: {fixed: [10, 0]}
  "1": {at: [1.5, 1]}
  "2": {at: [8, 4]}
bodies:
  crank: {points: [A, "1"], length: 2}
  coupler: {points: ["1", "2"], length: )" + coupler + R"(}
  rocker: {points: ["2", B], length: 5}
coordinates:
  theta: {type: angle, vector: [A, "1"], form: )" + form + R"(, guess: pi/3}
drivers:
)" + drivers + more;
}

TEST(NumericMethod, NameAndApplicability) {
  const auto m = MakeNumericMethod();
  EXPECT_EQ(m->name(), "numeric");
  EXPECT_TRUE(Contains(m->description(), "Newton"));
  EXPECT_EQ(m->Applicability(LoadScenarioFromString(FourBar(), "f.yaml")), std::nullopt);
}

TEST(NumericMethod, TooManyDriversIsAScenarioErrorNamingTheDrivers) {
  // Inconsistent extra driver: Newton cannot meet both, the scene without drivers assembles.
  const Result r = RunNumeric(FourBar("8", "cos",
                                      "  - {coordinate: theta, value: pi/3}\n"
                                      "  - {coordinate: x2, value: 8}\n"),
                              "dof.yaml");
  EXPECT_EQ(r.status, Status::kInvalidScenario);
  EXPECT_TRUE(Contains(r.reason, "n − rank Φ_q = 5 − 4 = 1 degree of freedom but 2 drivers are given")) << r.reason;
  EXPECT_TRUE(Contains(r.reason, "dof.yaml:14")) << r.reason;  // the first driver's line
  EXPECT_TRUE(Contains(r.reason, "remove 1 driver")) << r.reason;
  // Consistent extra driver: Newton converges, the rank check still refuses it.
  const Result r2 = RunNumeric(FourBar("8", "cos",
                                       "  - {coordinate: theta, value: pi/3}\n"
                                       "  - {coordinate: x1, value: 1}\n"),
                               "dof2.yaml");
  EXPECT_EQ(r2.status, Status::kInvalidScenario);
  EXPECT_TRUE(Contains(r2.reason, "but 2 drivers are given")) << r2.reason;
}

TEST(NumericMethod, TooFewDriversIsAScenarioError) {
  // §4.6's double slider has two degrees of freedom; drive only one.
  const char* yaml = R"(kind: linkage
points:
  O: {fixed: [0, 0]}
  GV: {fixed: [0, 1]}
  GH: {fixed: [1, 0]}
  "1": {at: [0, 1]}
  "2": {at: [1, 1]}
  "3": {at: [0, 0]}
bodies:
  b12: {points: ["1", "2"]}
  b32: {points: ["3", "2"]}
joints:
  - {type: slider, point: "1", line: [O, GV]}
  - {type: slider, point: "3", line: [O, GH]}
drivers:
  - {coordinate: y1, value: 1, velocity: 1}
)";
  const Result r = RunNumeric(yaml, "two_dof.yaml");
  EXPECT_EQ(r.status, Status::kInvalidScenario);
  EXPECT_TRUE(Contains(r.reason, "4 − 2 = 2 degrees of freedom but 1 driver is given")) << r.reason;
}

TEST(NumericMethod, TooShortLinkCannotAssemble) {
  const Result r = RunNumeric(FourBar("1"), "short.yaml");  // 2 + 1 + 5 < 10
  EXPECT_EQ(r.status, Status::kInvalidScenario);
  EXPECT_TRUE(Contains(r.reason, "short.yaml:")) << r.reason;
  EXPECT_TRUE(Contains(r.reason, "cannot assemble: body ")) << r.reason;
  EXPECT_TRUE(Contains(r.reason, "cannot close the loop")) << r.reason;
  EXPECT_TRUE(Contains(r.reason, "check lengths and the initial guess")) << r.reason;
  // The same through the algorithm: a ScenarioError.
  const NaturalModel nm = Compile(LoadScenarioFromString(FourBar("1"), "short.yaml"));
  NaturalData d(nm);
  EXPECT_THROW(SolveInstant(nm, d, 0.0, nm.model.GuessQ()), ScenarioError);
}

TEST(NumericMethod, UnreachableDriverValueIsTold) {
  // The rocker's angle ψ driven to 0 (pointing along +x from B) puts 2 at 15 m from A, beyond
  // crank + coupler = 10; without the driver the linkage assembles.
  std::string text = FourBar("8", "cos", "  - {coordinate: psi, value: 0}\n");
  text.insert(text.find("drivers:"), "  psi: {type: angle, vector: [B, \"2\"], form: cross, guess: 1.9}\n");
  const Result r = RunNumeric(text, "reach.yaml");
  EXPECT_EQ(r.status, Status::kInvalidScenario);
  EXPECT_TRUE(Contains(r.reason, "cannot reach the driven values (psi (reach.yaml:15))")) << r.reason;
  EXPECT_TRUE(Contains(r.reason, "check the drivers' values")) << r.reason;
}

TEST(NumericMethod, RedundantCosSinRowsGiveAMessageNotAnError) {
  const Result cs = RunNumeric(FourBar("8", "cos+sin"), "redundant.yaml", false);
  ASSERT_TRUE(cs.ok()) << cs.reason;
  ASSERT_EQ(cs.messages.size(), 1u);
  EXPECT_TRUE(Contains(cs.messages[0], "1 redundant constraint: row 4 coordinate theta (sin)")) << cs.messages[0];
  EXPECT_TRUE(Contains(cs.messages[0], "(m = 5, rank Φ_q = 4)")) << cs.messages[0];
  EXPECT_EQ(Get(cs, "rows"), 5);
  EXPECT_EQ(Get(cs, "rank"), 4);
  EXPECT_EQ(Get(cs, "dof"), 1);
  // Same kinematics as the cos form alone.
  const Result c = RunNumeric(FourBar(), "plain.yaml", false);
  ASSERT_TRUE(c.ok()) << c.reason;
  EXPECT_TRUE(c.messages.empty());
  for (const char* name : {"q.x2", "q.y2", "qd.x2", "qd.y2", "qdd.x2", "qdd.y2"})
    EXPECT_NEAR(Get(cs, name), Get(c, name), 1e-9) << name;
}

TEST(NumericMethod, CosineFormAtZeroIsASingularPosition) {
  // §4.1 with the rod horizontal: x_B − x_A − d cos θ has no θ-derivative at θ = 0.
  const char* yaml = R"(kind: linkage
points:
  O: {fixed: [0, 0]}
  GV: {fixed: [0, 1]}
  GH: {fixed: [1, 0]}
  A: {at: [0, 0]}
  B: {at: [15, 0]}
bodies:
  rod: {points: [A, B]}
joints:
  - {type: slider, point: A, line: [O, GV]}
  - {type: slider, point: B, line: [O, GH]}
coordinates:
  theta: {type: angle, vector: [A, B], form: cos, guess: 0}
drivers:
  - {coordinate: yA, value: 0, velocity: -10}
)";
  const Result r = RunNumeric(yaml, "flat.yaml");
  EXPECT_EQ(r.status, Status::kInvalidScenario);
  EXPECT_TRUE(Contains(r.reason, "flat.yaml:14")) << r.reason;  // the coordinate's line
  EXPECT_TRUE(Contains(r.reason, "coordinate theta (cos)")) << r.reason;
  EXPECT_TRUE(Contains(r.reason, "loses rank")) << r.reason;
  EXPECT_TRUE(Contains(r.reason, "form: cross")) << r.reason;
}

TEST(NumericMethod, SliderCrankAtDeadCentreDrivenByTheSliderIsSingular) {
  const char* yaml = R"(kind: linkage
points:
  A: {fixed: [0, 0]}
  G: {fixed: [1, 0]}
  "1": {at: [2, 0]}
  "2": {at: [7, 0]}
bodies:
  crank: {points: [A, "1"]}
  rod: {points: ["1", "2"]}
joints:
  - {type: slider, point: "2", line: [A, G]}
drivers:
  - {coordinate: x2, value: 7, velocity: -1}
)";
  const Result r = RunNumeric(yaml, "toggle.yaml");
  EXPECT_EQ(r.status, Status::kInvalidScenario);
  EXPECT_TRUE(Contains(r.reason, "singular position")) << r.reason;
  EXPECT_TRUE(Contains(r.reason, "rank [Φ_q; B] = 2 < n = 3")) << r.reason;
}

TEST(NumericMethod, FullCrankTurnIsConsistentWithItsOwnDerivatives) {
  // The cross form: good at every crank angle (the cos form is singular at θ = π, see below).
  const std::string yaml = FourBar("8", "cross") + "analysis: {t0: 0, t1: 2*pi, samples: 721}\n";
  const Result r = RunNumeric(yaml, "turn.yaml");
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
  const std::string yaml = FourBar("8", "cos") + "analysis: {t0: 0, t1: 2*pi, samples: 721}\n";
  const Result r = RunNumeric(yaml, "cos_turn.yaml");
  EXPECT_EQ(r.status, Status::kDiverged);
  EXPECT_TRUE(Contains(r.reason, "singular position at t = 2.0944 s")) << r.reason;
  EXPECT_EQ(r.trajectory.size(), 240u);  // samples 0..239; sample 240 is θ = π
}

TEST(NumericMethod, MotionThatLeavesTheWorkspaceDivergesAndKeepsTheSamplesSoFar) {
  // §4.1's slider A keeps accelerating down for 3 s: yA passes −15 m, which the rod cannot reach
  // (and θ = 0 on the way is a singular position of the cos form).
  const char* yaml = R"(kind: linkage
points:
  O: {fixed: [0, 0]}
  GV: {fixed: [0, 1]}
  GH: {fixed: [1, 0]}
  A: {at: [0, 15*sin(35 deg)]}
  B: {at: [15*cos(35 deg), 0]}
bodies:
  rod: {points: [A, B], length: 15}
joints:
  - {type: slider, point: A, line: [O, GV]}
  - {type: slider, point: B, line: [O, GH]}
coordinates:
  theta: {type: angle, vector: [A, B], form: cos, guess: 35 deg}
drivers:
  - {coordinate: yA, value: 15*sin(35 deg), velocity: -10, acceleration: -5}
analysis: {t0: 0, t1: 3, samples: 301}
)";
  const Result r = RunNumeric(yaml, "away.yaml");
  EXPECT_EQ(r.status, Status::kDiverged) << r.reason;
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
TEST(NumericMethod, ASampleIntervalBeyondThePredictionIsNamed) {
  const Result r = RunNumeric(FourBar("8", "cross") + "analysis: {t0: 0, t1: 1e9, samples: 73}\n", "long.yaml");
  EXPECT_EQ(r.status, Status::kDiverged);
  EXPECT_TRUE(Contains(r.reason, "Newton–Raphson did not converge at t = 1.38889e+07 s")) << r.reason;
  EXPECT_TRUE(Contains(r.reason, "the sample interval of 1.39e+07 s moves theta by 1.39e+07 rad (2.21e+06 turns), "
                                 "further than a prediction from the previous sample can follow"))
      << r.reason;
  EXPECT_EQ(RunNumeric(FourBar("8", "cross") + "analysis: {t0: 0, t1: 1, samples: 73}\n", "short.yaml").status,
            Status::kOk);
}

// The kinematic sweep stops on its CPU budget like every stepping method, keeping its samples.
TEST(NumericMethod, StopsOnItsBudget) {
  RunOptions options;
  options.cpu_budget = 0.05;
  const Result r = MakeNumericMethod()->Run(
      LoadScenarioFromString(FourBar("8", "cross") + "analysis: {t0: 0, t1: 100, samples: 1000000}\n", "many.yaml"),
      options);
  EXPECT_EQ(r.status, Status::kOverBudget) << r.reason;
  EXPECT_TRUE(Contains(r.reason, "its CPU budget of 0.05 s ran out")) << r.reason;
  EXPECT_GT(r.trajectory.size(), 1u);
  EXPECT_LT(r.trajectory.size(), 1000000u);
}

TEST(NumericMethod, QuantitiesCoverPointsBodiesSlidersAndMatrices) {
  const char* yaml = R"(kind: linkage
units: {length: mm}
points:
  O4: {fixed: [0, 0]}
  O2: {fixed: [150, 0]}
  "1": {at: [150 + 45*cos(74.6 deg), 45*sin(74.6 deg)]}
  "2": {at: [250*cos(15 deg), 250*sin(15 deg)]}
bodies:
  bar: {points: [O4, "2"], length: 250}
  disc: {points: [O2, "1"], length: 45}
joints:
  - {type: slider, point: "1", body: bar}
coordinates:
  theta: {type: angle, vector: [O2, "1"], form: cos}
drivers:
  - {coordinate: theta, value: 74.6 deg, velocity: -90 rpm}
plane: {origin: [0, 0, 5], u: [0, 1, 0], v: [0, 0, 1]}
)";
  const Result r = RunNumeric(yaml, "names.yaml");
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
  const char* yaml = R"(kind: linkage
units: {length: mm}
points:
  O4: {fixed: [0, 0]}
  O2: {fixed: [150, 0]}
  "1": {at: [150 + 45*cos(74.6 deg), 45*sin(74.6 deg)]}
  "2": {at: [250*cos(15 deg), 250*sin(15 deg)]}
bodies:
  bar: {points: [O4, "2"], length: 250}
  disc: {points: [O2, "1"], length: 45}
joints:
  - {type: slider, point: "1", body: bar}
coordinates:
  theta: {type: angle, vector: [O2, "1"], form: cross}
drivers:
  - {coordinate: theta, value: 74.6 deg, velocity: -90 rpm, acceleration: 20}
)";
  const Model model = LoadScenarioFromString(yaml, "slide.yaml");
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
  const char* yaml = R"(kind: linkage
points:
  O: {fixed: [0.2, -0.1]}
  A: {at: [0.2 + 4*cos(135 deg), -0.1 + 4*sin(135 deg)]}
  B: {at: [0.2 + 4*cos(135 deg) - 3, -0.1 + 4*sin(135 deg)]}
bodies:
  OA: {points: [O, A]}
  AB: {points: [A, B]}
coordinates:
  th1: {type: angle, vector: [O, A], guess: 135 deg}
  th2: {type: angle, vector: [A, B], reference: [O, A], guess: 45 deg}
drivers:
  - {coordinate: th1, value: 135 deg, velocity: 5, acceleration: 3}
  - {coordinate: th2, value: 45 deg, velocity: 10, acceleration: 4}
plane: {origin: [1, 2, 3], u: [0.6, 0.8, 0], v: [0, 0, 1]}
frame_rotation: {axis_point: [0.5, -1, 2], axis: [1, 2, 2], omega: 0.7}
)";
  const Model model = LoadScenarioFromString(yaml, "frame.yaml");
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
}  // namespace mechbench::numeric
