// Forward dynamics of free scenes: the assembled start, energy conservation per formulation, the
// reference confirmed by two methods, agreement with it, q̈(t0) checks, and a singular crossing.
#include "mechbench/motion_error.h"
#include "mechbench/format.h"
#include "mechbench/loader.h"
#include "mechbench/numeric/constraints.h"
#include "mechbench/numeric/dynamics_methods.h"
#include "mechbench/numeric/forward_dynamics.h"
#include "mechbench/numeric/natural_model.h"
#include "mechbench/references/nfourbar.h"
#include "mechbench/numeric/reference.h"
#include "quantity.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>

namespace mechbench::numeric {
namespace numeric_dynamics_free_test {  // this file's own names (the tests build in unity batches)
namespace {

using namespace ::mechbench::references;  // the N-four-bar's generator and exact motion

constexpr double kPi = 3.14159265358979323846;

Model FreeFourBar() { return LoadScenario(ResolveScenario("fourbar_free")); }

struct Formulation {
  std::string name;
  std::function<std::unique_ptr<Method>()> make;
  double energy_drift;  // bound over 1 s of the free four-bar at default settings [J]
  double position;      // bound on the error vs the reference (relative to the motion's scale)
};

// Measured at default settings (fourbar_free, 1 s; E ≈ 1e2 J): RK4 1.9e-9 J, DOPRI5 4.8e-8 J,
// ALI3-P 3.1e-4 J (the trapezoidal rule with projections dissipates), partitioning 3.6e-6 J.
// Position errors: 2.7e-11, 3.8e-10, 1.9e-6, 6.0e-9. Bounds leave about a factor 3-10.
std::vector<Formulation> Formulations() {
  return {{"dyn-baumgarte-rk4", [] { return MakeBaumgarteRk4Method(); }, 1e-8, 1e-9},
          {"dyn-baumgarte-dopri5", [] { return MakeBaumgarteDopri5Method(); }, 3e-7, 3e-9},
          {"dyn-ali3p", [] { return MakeAli3pMethod(); }, 1e-3, 1e-5},
          {"dyn-coordinate-partitioning", [] { return MakeCoordinatePartitioningMethod(); }, 2e-5, 5e-8}};
}

TEST(NumericDynamics, FreeStartHonoursTheInitialConditions) {
  const Model model = FreeFourBar();
  const NaturalModel nm = Compile(model);
  const FreeStart s = AssembleFreeStart(nm);
  const int th = model.SlotIndex("theta");
  EXPECT_NEAR(s.q[th], 60 * kPi / 180, 1e-12);
  EXPECT_EQ(s.qd.norm(), 0.0);  // released from rest
  NaturalData data(nm);
  EvalPhi(nm, data, s.q, 0);
  EXPECT_LT(ScaledResidual(nm, data), 1e-12);

  // With an initial rate: θ̇0 is honoured and the rest of q̇ satisfies Φ_q q̇ = 0.
  Model moving = model;
  moving.initial[0].velocity = 2.0;
  const NaturalModel nm2 = Compile(moving);
  const FreeStart s2 = AssembleFreeStart(nm2);
  EXPECT_NEAR(s2.qd[th], 2.0, 1e-12);
  EvalJacobian(nm2, data, s2.q);
  EXPECT_LT((data.Phi_q * s2.qd).cwiseAbs().maxCoeff(), 1e-10);
  EXPECT_GT(s2.qd.norm(), 2.0);  // the points move too
}

TEST(NumericDynamics, ApplicabilitySaysWhy) {
  Model driven = FreeFourBar();
  driven.drivers = driven.initial;
  driven.initial.clear();
  ASSERT_TRUE(DynamicsApplicability(driven).has_value());
  EXPECT_NE(DynamicsApplicability(driven)->find("driven"), std::string::npos);
  Model massless = FreeFourBar();
  for (Body& b : massless.bodies) b.mass = kNaN;
  ASSERT_TRUE(DynamicsApplicability(massless).has_value());
  EXPECT_FALSE(DynamicsApplicability(FreeFourBar()).has_value());
}

// The reference (index-1 DOPRI5 at rtol 1e-12) confirmed by coordinate partitioning at the same
// tolerance to the stated 1e-8 (measured 3.9e-13), and θ(1 s) ≈ −0.0154 rad as the engines
// issue gives it.
TEST(NumericDynamics, ReferenceIsConfirmedByTwoFormulations) {
  const Model model = FreeFourBar();
  const Reference ref = ReferenceTrajectory(model);
  ASSERT_TRUE(ref.primary.ok()) << ref.primary.reason;
  ASSERT_TRUE(ref.confirmation.ok()) << ref.confirmation.reason;
  EXPECT_TRUE(ref.confirmed) << ref.description;
  EXPECT_LE(ref.agreement, 1e-8) << ref.description;
  EXPECT_NE(ref.description.find("coordinate partitioning"), std::string::npos) << ref.description;
  ASSERT_EQ(static_cast<int>(ref.trajectory().size()), model.analysis.samples);
  const double theta1 = ref.trajectory().back().q[model.SlotIndex("theta")];
  EXPECT_NEAR(ref.trajectory().back().t, 1.0, 1e-15);
  EXPECT_NEAR(theta1, -0.0154, 5e-5);  // measured −0.0154244
}

TEST(NumericDynamics, EveryFormulationConservesEnergyAndAgreesWithTheReference) {
  const Model model = FreeFourBar();
  const Reference ref = ReferenceTrajectory(model);
  ASSERT_TRUE(ref.confirmed) << ref.description;
  for (const Formulation& f : Formulations()) {
    SCOPED_TRACE(f.name);
    const Result r = f.make()->Run(model);
    ASSERT_EQ(r.status, Status::kOk) << r.reason;
    EXPECT_EQ(r.method, f.name);
    EXPECT_FALSE(r.settings.empty());
    ASSERT_EQ(static_cast<int>(r.trajectory.size()), model.analysis.samples);
    for (int k = 0; k < model.analysis.samples; ++k) EXPECT_EQ(r.trajectory[k].t, model.analysis.TimeAt(k));
    EXPECT_LE(Get(r, "energy_drift"), f.energy_drift);
    EXPECT_GT(Get(r, "energy"), 0.0);
    EXPECT_LE(Get(r, "max_residual"), 1e-8);
    const MotionError e = CompareMotion(model, ref.trajectory(), r.trajectory);
    EXPECT_TRUE(e.problem.empty()) << e.problem;
    EXPECT_LE(e.q.max, f.position) << "at " << e.q.slot << ", t = " << e.q.t;
    EXPECT_NEAR(r.trajectory.back().q[model.SlotIndex("theta")], -0.0154244, 2e-5);
  }
}

// Tighter settings converge towards the reference: the error falls with the tolerance/step.
TEST(NumericDynamics, ErrorsFallWithTighterSettings) {
  const Model model = FreeFourBar();
  const Reference ref = ReferenceTrajectory(model);
  BaumgarteOptions loose, tight;
  loose.rtol = 1e-5;
  tight.rtol = 1e-9;
  const double e_loose = CompareMotion(model, ref.trajectory(), MakeBaumgarteDopri5Method(loose)->Run(model).trajectory).q.max;
  const double e_tight = CompareMotion(model, ref.trajectory(), MakeBaumgarteDopri5Method(tight)->Run(model).trajectory).q.max;
  EXPECT_LT(e_tight, 0.1 * e_loose) << e_loose << " " << e_tight;
  Ali3pOptions coarse, fine;
  coarse.h = 2e-3;
  fine.h = 5e-4;
  const double a_coarse = CompareMotion(model, ref.trajectory(), MakeAli3pMethod(coarse)->Run(model).trajectory).q.max;
  const double a_fine = CompareMotion(model, ref.trajectory(), MakeAli3pMethod(fine)->Run(model).trajectory).q.max;
  // Second order: a 4× smaller step gives ~16× less error.
  EXPECT_LT(a_fine, a_coarse / 8) << a_coarse << " " << a_fine;
}

// q̈(t0) from the index-1 system against one-sided differences of the reference's own q̇.
TEST(NumericDynamics, InitialAccelerationsMatchDifferencesOfTheTrajectory) {
  Model model = FreeFourBar();
  const double h = 1e-4;
  model.analysis.t1 = 2 * h;
  model.analysis.samples = 3;
  PartitioningOptions o;
  o.rtol = 1e-13;
  o.atol = 1e-15;
  const Result r = MakeCoordinatePartitioningMethod(o)->Run(model);
  ASSERT_TRUE(r.ok()) << r.reason;
  const auto& s = r.trajectory;
  // (−3 q̇0 + 4 q̇1 − q̇2) / 2h is second order: error ~ h² q⁗ ≈ 1e-8 × O(10).
  const Eigen::VectorXd fd = (-3 * s[0].qd + 4 * s[1].qd - s[2].qd) / (2 * h);
  const double scale = s[0].qdd.cwiseAbs().maxCoeff();
  ASSERT_GT(scale, 1.0);
  EXPECT_LT((fd - s[0].qdd).cwiseAbs().maxCoeff() / scale, 1e-6) << fd.transpose() << "\n" << s[0].qdd.transpose();
  EXPECT_EQ(Get(r, "qdd.theta"), s[0].qdd[model.SlotIndex("theta")]);
}

// §5.1 released from rest: q̈(t0) from M, Q and the constraints against Lagrange's equation in
// the disc angle φ, computed here independently: J(φ) φ̈ = Q_φ at rest, with
//   pin r(φ) = R(cos φ, sin φ), slider x2 = x1 + sqrt(L² − y1²), bar centre G = (r + p2)/2,
//   J = I_disc + m_bar |dG/dφ|² + I_bar (dψ/dφ)², Q_φ = m_bar g·dG/dφ + F·dp2/dφ.
TEST(NumericDynamics, S5_1InitialAccelerationsFromLagrangesEquation) {
  const Model model = LoadScenario(ResolveScenario("s5_1_disc_bar_bushing"));
  ASSERT_FALSE(DynamicsApplicability(model).has_value());
  Model instant = model;
  instant.analysis.t1 = kNaN;
  instant.analysis.samples = 1;
  const Result r = MakeBaumgarteRk4Method()->Run(instant);
  ASSERT_TRUE(r.ok()) << r.reason;

  const double R = 0.045, L = 0.2, m_bar = 1, I_bar = 1 * L * L / 12, I_disc = 0.5 * 10 * 0.06 * 0.06, g = -10, F = -20;
  const auto pin = [&](double p) { return Eigen::Vector2d(R * std::cos(p), R * std::sin(p)); };
  const auto slider = [&](double p) {
    const Eigen::Vector2d a = pin(p);
    return Eigen::Vector2d(a.x() + std::sqrt(L * L - a.y() * a.y()), 0);
  };
  const auto centre = [&](double p) { return Eigen::Vector2d(0.5 * (pin(p) + slider(p))); };
  const auto psi = [&](double p) { const Eigen::Vector2d d = slider(p) - pin(p); return std::atan2(d.y(), d.x()); };
  const double phi = kPi / 3, e = 1e-6;
  // Central differences; the vector one returns a value (an Eigen expression would dangle).
  const auto d = [&](auto f) { return (f(phi + e) - f(phi - e)) / (2 * e); };
  const auto dv = [&](auto f) -> Eigen::Vector2d { return (f(phi + e) - f(phi - e)) / (2 * e); };
  const Eigen::Vector2d dG = dv(centre), dP2 = dv(slider);
  const double dpsi = d(psi);
  const double J = I_disc + m_bar * dG.squaredNorm() + I_bar * dpsi * dpsi;
  const double Q_phi = m_bar * g * dG.y() + F * dP2.x();
  const double phidd = Q_phi / J;
  // At rest the point accelerations are the first derivatives times φ̈.
  const double x1dd = d([&](double p) { return pin(p).x(); }) * phidd;
  const double y1dd = d([&](double p) { return pin(p).y(); }) * phidd;
  const double x2dd = dP2.x() * phidd;
  const double scale = std::fabs(x2dd) + std::fabs(x1dd);
  EXPECT_NEAR(Get(r, "qdd.x1"), x1dd, 1e-6 * scale);
  EXPECT_NEAR(Get(r, "qdd.y1"), y1dd, 1e-6 * scale);
  EXPECT_NEAR(Get(r, "qdd.x2"), x2dd, 1e-6 * scale);
  // Every formulation starts from the same exact index-1 q̈ and multipliers.
  const Result a = MakeAli3pMethod()->Run(instant);
  ASSERT_TRUE(a.ok()) << a.reason;
  EXPECT_EQ(Get(a, "qdd.x2"), Get(r, "qdd.x2"));
  EXPECT_EQ(Get(a, "lambda[0]"), Get(r, "lambda[0]"));
}

// The N-four-bar (A02, N = 1) passes a singular position at t ≈ 0.708 s, where every bar is
// horizontal and Φ_q loses a rank. RK4 index-1 and ALI3-P at their default steps get through
// on the parallelogram branch (yP1 = yP0, xP1 − xP0 = 1, which symmetry demands); coordinate
// partitioning cannot tell the branches apart there and stops, saying where and why.
TEST(NumericDynamics, NFourBarSingularCrossing) {
  NFourBarOptions o;
  o.n = 1;
  o.t1 = 1.5;
  o.samples = 151;
  const Model model = NFourBar(o);
  const int x0 = model.SlotIndex("xP0"), y0 = model.SlotIndex("yP0"), x1 = model.SlotIndex("xP1"), y1 = model.SlotIndex("yP1");
  ASSERT_GE(std::min({x0, y0, x1, y1}), 0);
  for (const auto& make : {std::function<std::unique_ptr<Method>()>([] { return MakeBaumgarteRk4Method(); }),
                           std::function<std::unique_ptr<Method>()>([] { return MakeAli3pMethod(); })}) {
    const Result r = make()->Run(model);
    SCOPED_TRACE(r.method);
    ASSERT_EQ(r.status, Status::kOk) << r.reason;
    double parallel = 0, lowest = 1;
    for (const Sample& s : r.trajectory) {
      parallel = std::max({parallel, std::fabs(s.q[y1] - s.q[y0]), std::fabs(s.q[x1] - s.q[x0] - 1)});
      lowest = std::min(lowest, s.q[y0]);
    }
    EXPECT_LT(parallel, 1e-6);
    EXPECT_LT(lowest, -0.9);  // it really swung through the horizontal to below the pivots
    EXPECT_LT(Get(r, "energy_drift"), 1e-3);
  }
  const Result cp = MakeCoordinatePartitioningMethod()->Run(model);
  ASSERT_EQ(cp.status, Status::kDiverged);
  EXPECT_NE(cp.reason.find("loses rank"), std::string::npos) << cp.reason;
  EXPECT_NE(cp.reason.find("at t = 0.70"), std::string::npos) << cp.reason;
  // The samples before the singular position are kept.
  EXPECT_EQ(static_cast<int>(cp.trajectory.size()), 71);
}

// A rod spun up by a vertical torque (tests/data/scenes/rigid_rod_vertical_torque.yaml): ALI3-P's
// acceleration guard trips near 0.94 s at its default step while Φ_q keeps its rank, so the reason
// says what it sees (h ω, a smaller step), not "a singular position" as it used to.
TEST(NumericDynamics, AFastSpinIsNotBlamedOnASingularPosition) {
  const Model model = LoadScenario(std::string(MECHBENCH_TEST_DATA) + "/scenes/rigid_rod_vertical_torque.yaml");
  const Result r = MakeAli3pMethod()->Run(model);
  ASSERT_EQ(r.status, Status::kDiverged) << r.reason;
  EXPECT_NE(r.reason.find("Φ_q keeps its rank here"), std::string::npos) << r.reason;
  EXPECT_NE(r.reason.find("so this is not a singular position"), std::string::npos) << r.reason;
  EXPECT_NE(r.reason.find("at h ω = "), std::string::npos) << r.reason;
  EXPECT_NE(r.reason.find("give it a smaller step"), std::string::npos) << r.reason;
  EXPECT_EQ(r.reason.find("where Φ_q loses rank"), std::string::npos) << r.reason;
}

// An overflow is named as one, never as a singular position ("Φ_q lost rank" used to stand for
// both): loads beyond double range at t0 are the input's (invalid-scenario), a state that a huge
// load grew past double range in the first step is the run's (diverged), each saying what.
TEST(NumericDynamics, OverflowIsNamedNotBlamedOnRank) {
  const std::string base = R"(kind: linkage
points: {A: {fixed: [0, 0]}, B: {fixed: [10, 0]}, "1": {at: [1, 1.732]}, "2": {at: [8.6, 4.9]}}
bodies:
  crank: {points: [A, "1"], length: 2, mass: MASS, com: [1, 0], inertia: MASS*2^2/12}
  coupler: {points: ["1", "2"], length: 8, mass: 8*MASS, com: [4, 0], inertia: 8*MASS*8^2/12}
  rocker: {points: ["2", B], length: 5, mass: 5*MASS, com: [2.5, 0], inertia: 5*MASS*5^2/12}
coordinates: {theta: {type: angle, vector: [A, "1"], guess: 60 deg}}
initial: [{coordinate: theta, value: 60 deg, velocity: 0}]
gravity: [0, GRAVITY]
analysis: {t0: 0, t1: 0.01, samples: 2}
)";
  const auto scene = [&](const std::string& mass, const std::string& gravity) {
    std::string s = base;
    for (const auto& [key, value] : {std::pair<std::string, std::string>{"MASS", mass}, {"GRAVITY", gravity}})
      for (size_t at = s.find(key); at != std::string::npos; at = s.find(key, at)) s.replace(at, key.size(), value);
    return LoadScenarioFromString(s, "overflow.yaml");
  };
  for (const Formulation& f : Formulations()) {
    SCOPED_TRACE(f.name);
    // Masses of 1e90 kg (within the loader's limits) under 1e250 m/s²: m·g overflows at t0.
    const Result loads = f.make()->Run(scene("1e90", "-1e250"));
    EXPECT_EQ(loads.status, Status::kInvalidScenario) << loads.reason;
    EXPECT_NE(loads.reason.find("the dynamics overflow at t0: the loads overflow: Q["), std::string::npos) << loads.reason;
    EXPECT_EQ(loads.reason.find("lost rank"), std::string::npos) << loads.reason;
    // The same scene scaled uniformly is as good as the plain one: only the magnitudes moved.
    EXPECT_EQ(f.make()->Run(scene("1e90", "-9.81")).status, Status::kOk);
    // A gravity of −1e300: finite loads, but the first step's velocities cannot be squared.
    const Result state = f.make()->Run(scene("1", "-1e300"));
    EXPECT_EQ(state.status, Status::kDiverged) << state.reason;
    EXPECT_EQ(state.reason.find("lost rank"), std::string::npos) << state.reason;
  }
  const Result rk4 = MakeBaumgarteRk4Method()->Run(scene("1", "-1e300"));
  EXPECT_NE(rk4.reason.find("at t = 0 s: the constraint terms overflow: Φ̇_q q̇, quadratic in q̇, is not finite"),
            std::string::npos)
      << rk4.reason;
}

// t1 = 1e9 s is not bad input (each interval is well resolved), but a stepping method needs 1e12
// steps of 1 ms: its budget stops it before the first sample, and the reason says that and how
// many steps the motion is (it used to say only "at t = 0"). A motion of more steps than a count
// holds fails with that reason instead of converting out of range.
TEST(NumericDynamics, AMotionFarLongerThanTheStepSaysHowLong) {
  Model model = FreeFourBar();
  model.analysis.t1 = 1e9;
  RunOptions options;
  options.cpu_budget = 0.1;
  const Result r = MakeBaumgarteRk4Method()->Run(model, options);
  EXPECT_EQ(r.status, Status::kOverBudget) << r.reason;
  EXPECT_NE(r.reason.find("ran out before its first sample (t = 1e+07 s); at its step of 0.001 s the motion (1e+09 s) "
                          "is 1e+12 steps"),
            std::string::npos)
      << r.reason;
  model.analysis.t1 = 1e20;
  const Result endless = MakeBaumgarteRk4Method()->Run(model, options);
  EXPECT_EQ(endless.status, Status::kFailed) << endless.reason;
  EXPECT_NE(endless.reason.find("is 1e+21 steps of 0.001 s, more than a run can take"), std::string::npos) << endless.reason;
}

TEST(NumericDynamics, NFourBarGenerator) {
  for (int n : {1, 4}) {
    NFourBarOptions o;
    o.n = n;
    const Model m = NFourBar(o);
    int bodies = 0;
    double mass = 0;
    for (const Body& b : m.bodies) ++bodies, mass += b.mass;
    EXPECT_EQ(bodies, 2 * n + 1);
    EXPECT_EQ(mass, 2 * n + 1);
    EXPECT_EQ(static_cast<int>(m.q_layout.size()), 2 * (n + 1));  // the coupler points
    EXPECT_EQ(m.analysis.t1, 20.0);
    const NaturalModel nm = Compile(m);
    const FreeStart s = AssembleFreeStart(nm);
    for (int i = 0; i <= n; ++i) {  // every coupler point starts at 1 m/s along +x
      EXPECT_NEAR(s.qd[m.SlotIndex("xP" + std::to_string(i))], 1.0, 1e-12);
      EXPECT_NEAR(s.qd[m.SlotIndex("yP" + std::to_string(i))], 0.0, 1e-12);
    }
  }
}

// ---- work–precision sweeps: Method::control() and the RunOptions overrides ---------------------

struct Controlled {
  std::string name;
  std::function<std::unique_ptr<Method>()> make;
  Control control;
  double default_value;  // the formulation's own step [s] or rtol
  double other;          // an override that changes the run
  std::string key;       // the settings key that describes the value
};

std::vector<Controlled> ControlledFormulations() {
  return {{"dyn-baumgarte-rk4", [] { return MakeBaumgarteRk4Method(); }, Control::kStep, 1e-3, 2e-3, "h"},
          {"dyn-baumgarte-dopri5", [] { return MakeBaumgarteDopri5Method(); }, Control::kTolerance, 1e-8, 1e-11, "rtol"},
          {"dyn-ali3p", [] { return MakeAli3pMethod(); }, Control::kStep, 1e-3, 2e-3, "h"},
          {"dyn-coordinate-partitioning", [] { return MakeCoordinatePartitioningMethod(); }, Control::kTolerance, 1e-8,
           1e-11, "rtol"},
          {"dyn-coordinate-partitioning (rk4)", [] { return MakeCoordinatePartitioningMethod({.rk4 = true}); },
           Control::kStep, 1e-3, 2e-3, "h"}};
}

RunOptions Override(Control c, double v) {
  RunOptions o;
  (c == Control::kStep ? o.step : o.tolerance) = v;
  return o;
}

std::string Full(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

// Every formulation says what a sweep varies and its own value, records the value it used
// ("control_value", and in words under its own key), takes the RunOptions override for one run
// only (the method stays as constructed: the next default run is bit-identical to the first),
// ignores the override that does not match its control, and refuses a nonsense one.
TEST(NumericDynamicsControl, EveryFormulationHonoursItsOverride) {
  Model model = FreeFourBar();
  model.analysis.t1 = 0.2;  // 21 samples: enough to see the steps change, and quick
  model.analysis.samples = 21;
  for (const Controlled& f : ControlledFormulations()) {
    SCOPED_TRACE(f.name);
    const auto meth = f.make();
    EXPECT_EQ(meth->control(), f.control);
    EXPECT_EQ(meth->default_control(), f.default_value);
    const Result base = meth->Run(model);
    ASSERT_TRUE(base.ok()) << base.reason;
    EXPECT_EQ(base.settings.at("control"), ToString(f.control));
    EXPECT_EQ(base.settings.at("control_value"), Full(f.default_value));
    EXPECT_EQ(base.settings.at(f.key).find("override"), std::string::npos) << base.settings.at(f.key);

    const Result other = meth->Run(model, Override(f.control, f.other));
    ASSERT_TRUE(other.ok()) << other.reason;
    EXPECT_EQ(other.settings.at("control_value"), Full(f.other));
    EXPECT_NE(other.settings.at(f.key).find("(sweep override; default " + Fmt(f.default_value)), std::string::npos)
        << other.settings.at(f.key);
    if (f.control == Control::kStep) {
      EXPECT_LT(Get(other, "steps"), Get(base, "steps")) << "a larger step takes fewer steps";
    } else {  // a tighter tolerance takes more; atol keeps its ratio to rtol (1e-10 / 1e-8)
      EXPECT_GT(Get(other, "steps"), Get(base, "steps"));
      EXPECT_NE(other.settings.at("atol").find("1e-13 (rtol × 0.01"), std::string::npos) << other.settings.at("atol");
    }

    const Result again = meth->Run(model);
    ASSERT_TRUE(again.ok()) << again.reason;
    EXPECT_EQ(again.settings, base.settings);
    EXPECT_EQ(again.trajectory.back().q, base.trajectory.back().q);
    // The override of the other kind is not this method's: ignored.
    const Result mismatched = meth->Run(model, Override(f.control == Control::kStep ? Control::kTolerance : Control::kStep, 1e-2));
    EXPECT_EQ(mismatched.settings, base.settings);
    EXPECT_EQ(mismatched.trajectory.back().q, base.trajectory.back().q);
    const Result bad = meth->Run(model, Override(f.control, -1));
    EXPECT_EQ(bad.status, Status::kFailed);
    EXPECT_NE(bad.reason.find("positive"), std::string::npos) << bad.reason;
  }
}

// A step above the sample interval (10 ms here) becomes the interval, and the settings say so.
TEST(NumericDynamicsControl, StepIsCappedByTheSampleInterval) {
  Model model = FreeFourBar();
  model.analysis.t1 = 0.2;
  model.analysis.samples = 21;
  for (const Controlled& f : ControlledFormulations()) {
    if (f.control != Control::kStep) continue;
    SCOPED_TRACE(f.name);
    const Result r = f.make()->Run(model, {.step = 0.05});
    ASSERT_TRUE(r.ok()) << r.reason;
    EXPECT_NEAR(std::stod(r.settings.at("control_value")), 0.01, 1e-15);
    EXPECT_NE(r.settings.at("h").find("the requested 0.05 s (sweep override; default 0.001 s) capped by the sample interval 0.01 s"),
              std::string::npos)
        << r.settings.at("h");
    EXPECT_EQ(Get(r, "steps"), 20.0);
  }
}

// Step halving on the free four-bar (1 s) against the reference, through RunOptions::step:
// observed order log2(e(h)/e(h/2)). Measured (CompareMotion, relative to the motion's scale):
//   dyn-baumgarte-rk4  e(5e-3) = 1.74e-8, e(2.5e-3) = 1.07e-9, ratio 16.2, order 4.02
//                      (2e-3 → 1e-3: 4.38e-10 → 2.72e-11, order 4.01; below 5e-4 s round-off)
//   dyn-ali3p          e(2e-3) = 7.72e-6, e(1e-3) = 1.93e-6, ratio 3.99, order 2.00
TEST(NumericDynamicsControl, StepHalvingShowsTheOrder) {
  const Model model = FreeFourBar();
  const Reference ref = ReferenceTrajectory(model);
  ASSERT_TRUE(ref.confirmed) << ref.description;
  struct Case {
    std::function<std::unique_ptr<Method>()> make;
    double h, order;
  };
  for (const Case& c : {Case{[] { return MakeBaumgarteRk4Method(); }, 5e-3, 4.0}, Case{[] { return MakeAli3pMethod(); }, 2e-3, 2.0}}) {
    const auto meth = c.make();
    SCOPED_TRACE(meth->name());
    const Result a = meth->Run(model, {.step = c.h}), b = meth->Run(model, {.step = c.h / 2});
    ASSERT_TRUE(a.ok() && b.ok()) << a.reason << b.reason;
    const double ea = CompareMotion(model, ref.trajectory(), a.trajectory).q.max;
    const double eb = CompareMotion(model, ref.trajectory(), b.trajectory).q.max;
    const double order = std::log2(ea / eb);
    if (std::getenv("MECHBENCH_VERBOSE"))
      std::printf("%s h = %g: %.3g, h/2: %.3g, ratio %.3g, order %.3f\n", meth->name().c_str(), c.h, ea, eb, ea / eb, order);
    EXPECT_NEAR(order, c.order, 0.2) << ea << " " << eb;
  }
}

}  // namespace
}  // namespace numeric_dynamics_free_test
}  // namespace mechbench::numeric
