// Loads given as expressions, and torsional spring–dampers, in the engines (tests/data/scenes):
// each engine applies them its own way (ODE and Bullet before every step, from the step's start:
// explicit; Simbody through Force::Custom and MuJoCo through mjcb_passive at every stage), a law
// of the state and a torsion from the scene's coordinates and the bodies' relative rotation
// observed from the engine's state.
#include "engines_support.h"

#include "mechbench/engines/graph.h"

#include "mechbench/harness/registry.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>

namespace mechbench::engines {
namespace engines_load_laws_test {  // this file's own names (the tests build in unity batches)
namespace {

using namespace testing;

Model Scene(const std::string& file) { return LoadScenario(std::string(MECHBENCH_TEST_DATA) + "/scenes/" + file); }

// The bar from rest under T = a t: α = a t / I_O, ω = a t² / (2 I_O), θ = a t³ / (6 I_O);
// xA = L cos θ, yA = L sin θ.
std::vector<Sample> RampClosedForm(const Model& m, const std::vector<Sample>& at) {
  const Body& bar = m.bodies[0];
  const double I_O = bar.inertia_com + bar.mass * bar.com_B.squaredNorm(), a = m.constants.at("ramp"), L = bar.Length();
  const int x = m.SlotIndex("xA"), y = m.SlotIndex("yA"), th = m.SlotIndex("theta");
  std::vector<Sample> out;
  for (const Sample& s : at) {
    const double t = s.t, al = a * t / I_O, w = a * t * t / (2 * I_O), q = a * t * t * t / (6 * I_O);
    Sample c{t, Eigen::VectorXd::Zero(3), Eigen::VectorXd::Zero(3), Eigen::VectorXd::Zero(3), 0.0};
    c.q[x] = L * std::cos(q), c.q[y] = L * std::sin(q), c.q[th] = q;
    c.qd[x] = -L * std::sin(q) * w, c.qd[y] = L * std::cos(q) * w, c.qd[th] = w;
    c.qdd[x] = -L * (std::cos(q) * w * w + std::sin(q) * al), c.qdd[y] = L * (-std::sin(q) * w * w + std::cos(q) * al);
    c.qdd[th] = al;
    out.push_back(c);
  }
  return out;
}

TEST(EngineLoadLaws, TorqueRampFollowsTheClosedForm) {
  const std::vector<MethodPtr> engines = harness::EngineMethods();
  if (engines.empty()) GTEST_SKIP() << "built without engines";
  const Model m = Scene("bar_torque_ramp.yaml");
  for (const MethodPtr& e : engines) {
    SCOPED_TRACE(e->name());
    ASSERT_FALSE(e->Applicability(m).has_value()) << *e->Applicability(m);
    const Result r = e->Run(m);
    ASSERT_TRUE(r.ok()) << r.reason;
    ASSERT_TRUE(r.settings.count("torques"));
    const MotionError err = CompareMotion(m, RampClosedForm(m, r.trajectory), r.trajectory);
    ASSERT_TRUE(err.problem.empty()) << err.problem;
    const double bound = harness::LoadTolerances(m.name).FreePosition(e->name(), m.analysis.t1 - m.analysis.t0);
    std::printf("  %-26s torque ramp: position error %.3g (bound %.3g)\n", e->name().c_str(), err.q.max, bound);
    if (const std::string* known = KnownFailure(m.name, e->name()))
      EXPECT_GT(err.q.max, bound) << "no longer a known failure (" << *known << ")";
    else
      EXPECT_LE(err.q.max, bound);
  }
}

// The bar pinned at O (no gravity) with θ(t), ω(t), α(t) known: xA = L cos θ, yA = L sin θ.
struct BarMotion { double th, w, al; };
std::vector<Sample> BarClosedForm(const Model& m, const std::vector<Sample>& at, BarMotion (*motion)(const Model&, double)) {
  const double L = m.bodies[0].Length();
  const int x = m.SlotIndex("xA"), y = m.SlotIndex("yA"), th = m.SlotIndex("theta");
  std::vector<Sample> out;
  for (const Sample& s : at) {
    const auto [q, w, al] = motion(m, s.t);
    Sample c{s.t, Eigen::VectorXd::Zero(3), Eigen::VectorXd::Zero(3), Eigen::VectorXd::Zero(3), 0.0};
    c.q[x] = L * std::cos(q), c.q[y] = L * std::sin(q), c.q[th] = q;
    c.qd[x] = -L * std::sin(q) * w, c.qd[y] = L * std::cos(q) * w, c.qd[th] = w;
    c.qdd[x] = -L * (std::cos(q) * w * w + std::sin(q) * al), c.qdd[y] = L * (-std::sin(q) * w * w + std::cos(q) * al);
    c.qdd[th] = al;
    out.push_back(c);
  }
  return out;
}
double InertiaAtO(const Model& m) { return m.bodies[0].inertia_com + m.bodies[0].mass * m.bodies[0].com_B.squaredNorm(); }
// The torsion: θ = θ0 cos(Ω t), Ω = √(k/I_O).
BarMotion TorsionMotion(const Model& m, double t) {
  const double th0 = m.initial[0].value, W = std::sqrt(m.torsions[0].stiffness / InertiaAtO(m));
  return {th0 * std::cos(W * t), -th0 * W * std::sin(W * t), -th0 * W * W * std::cos(W * t)};
}
// The motor curve T0 (1 − ω/ω0): ω = ω0 (1 − e^(−k t)), k = T0/(ω0 I_O).
BarMotion MotorMotion(const Model& m, double t) {
  const double T0 = m.constants.at("T0"), w0 = m.constants.at("omega0"), k = T0 / (w0 * InertiaAtO(m));
  return {w0 * (t - (1 - std::exp(-k * t)) / k), w0 * (1 - std::exp(-k * t)), w0 * k * std::exp(-k * t)};
}

// Judges a position error against the scene's bound (tolerances.yaml), or a known failure.
void ExpectWithinBound(const Model& m, const std::string& variant, double error) {
  const double bound = harness::LoadTolerances(m.name).FreePosition(variant, m.analysis.t1 - m.analysis.t0);
  if (Verbose()) std::printf("  %-30s %-26s position error %.3g (bound %.3g)\n", m.name.c_str(), variant.c_str(), error, bound);
  if (const std::string* known = KnownFailure(m.name, variant))
    EXPECT_GT(error, bound) << "no longer a known failure (" << *known << ")";
  else
    EXPECT_LE(error, bound);
}

// A torsional spring on the bar's angle and a motor law of qd.theta: every engine builds them
// (settings "torsions" / "state_torques" say how) and follows the closed form.
TEST(EngineLoadLaws, TorsionAndStateLawFollowTheClosedForm) {
  const std::vector<MethodPtr> engines = harness::EngineMethods();
  if (engines.empty()) GTEST_SKIP() << "built without engines";
  const struct {
    const char* file;
    const char* setting;
    BarMotion (*motion)(const Model&, double);
  } cases[] = {{"bar_torsion_spring.yaml", "torsions", TorsionMotion}, {"bar_motor_curve.yaml", "state_torques", MotorMotion}};
  for (const auto& c : cases) {
    const Model m = Scene(c.file);
    for (const MethodPtr& e : engines) {
      SCOPED_TRACE(std::string(c.file) + " " + e->name());
      ASSERT_FALSE(e->Applicability(m).has_value()) << *e->Applicability(m);
      const Result r = e->Run(m);
      ASSERT_TRUE(r.ok()) << r.reason;
      EXPECT_TRUE(r.settings.count(c.setting));
      const MotionError err = CompareMotion(m, BarClosedForm(m, r.trajectory, c.motion), r.trajectory);
      ASSERT_TRUE(err.problem.empty()) << err.problem;
      ExpectWithinBound(m, e->name(), err.q.max);
    }
  }
}

// A torsion between two bodies (the elbow's relative angle, equal and opposite couples) and a law
// of q. and qd. on a double pendulum under gravity, against the numeric reference trajectory.
TEST(EngineLoadLaws, ElbowTorsionAndMotorFollowTheReference) {
  const std::vector<MethodPtr> engines = harness::EngineMethods();
  if (engines.empty()) GTEST_SKIP() << "built without engines";
  const Model m = Scene("double_pendulum_torsion_motor.yaml");
  const harness::ReferenceRecord ref = harness::GetReference(m);
  ASSERT_TRUE(ref.confirmed) << ref.description;
  const GraphOrReason g = BuildGraph(m);
  ASSERT_TRUE(g.graph) << g.reason;
  ASSERT_EQ(g.graph->torsions.size(), 1u);
  const GraphTorsion& ts = g.graph->torsions[0];
  EXPECT_EQ(g.graph->bodies[ts.body_vec].name, "lower");
  EXPECT_EQ(g.graph->bodies[ts.body_ref].name, "upper");
  EXPECT_EQ(g.graph->state_torques.size(), 1u);
  for (const MethodPtr& e : engines) {
    SCOPED_TRACE(e->name());
    const Result r = e->Run(m);
    ASSERT_TRUE(r.ok()) << r.reason;
    EXPECT_TRUE(r.settings.count("torsions") && r.settings.count("state_torques"));
    const MotionError err = CompareMotion(m, ref.trajectory, r.trajectory);
    ASSERT_TRUE(err.problem.empty()) << err.problem;
    if (!KnownFailure(m.name, e->name())) {
      EXPECT_LE(Compare(m, r, r).residual, FreeResidualOf(m.name, e->name()));
    }
    ExpectWithinBound(m, e->name(), err.q.max);
  }
}

// MuJoCo RK4 evaluates torque laws at its four stages (mjcb_passive): on the motor curve halving
// its step divides the error by about 16, and the ramp's θ, a cubic in t, is integrated to
// rounding. (Held over the step in xfrc_applied before every mj_step, both were first order: the
// ramp 8.26e-5 at 0.1 ms.) Steps: the scenes' sample interval, 0.1 s, and half of it.
TEST(EngineLoadLaws, MujocoRk4IsFourthOrderOnTorqueLaws) {
  const std::vector<MethodPtr> engines = harness::EngineMethods();
  const Method* rk4 = nullptr;
  for (const MethodPtr& e : engines)
    if (e->name() == "mujoco-rk4-tuned") rk4 = e.get();
  if (!rk4) GTEST_SKIP() << "built without MuJoCo";
  double e[2];
  const Model motor = Scene("bar_motor_curve.yaml");
  for (int k = 0; k < 2; ++k) {
    const Result r = rk4->Run(motor, {.step = 0.1 / (1 + k)});
    ASSERT_TRUE(r.ok()) << r.reason;
    const MotionError err = CompareMotion(motor, BarClosedForm(motor, r.trajectory, MotorMotion), r.trajectory);
    ASSERT_TRUE(err.problem.empty()) << err.problem;
    e[k] = err.q.max;
  }
  std::printf("  mujoco-rk4-tuned bar_motor_curve: e(0.1) = %.4g, e(0.05) = %.4g, order %.3f\n", e[0], e[1],
              std::log2(e[0] / e[1]));
  EXPECT_NEAR(std::log2(e[0] / e[1]), 4.0, 0.3);
  const Model ramp = Scene("bar_torque_ramp.yaml");
  const Result r = rk4->Run(ramp, {.step = 0.1});
  ASSERT_TRUE(r.ok()) << r.reason;
  const MotionError err = CompareMotion(ramp, RampClosedForm(ramp, r.trajectory), r.trajectory);
  ASSERT_TRUE(err.problem.empty()) << err.problem;
  std::printf("  mujoco-rk4-tuned bar_torque_ramp: e(0.1) = %.3g\n", err.q.max);
  EXPECT_LT(err.q.max, 1e-10);
}

// A stiff torsion (Ω = 3000 rad/s) against its closed form: applied explicitly, it is unstable
// where h Ω > 2 (ODE and Bullet at 1 ms, MuJoCo Euler at 2 ms, where the hinge's stiffness is
// explicit too); the error-controlled and RK4 variants follow it to their accuracy. The failures
// are known failures in tolerances.yaml with their figures; a run may end as diverged.
TEST(EngineLoadLaws, StiffTorsionFindings) {
  const std::vector<MethodPtr> engines = harness::EngineMethods();
  if (engines.empty()) GTEST_SKIP() << "built without engines";
  const Model m = Scene("bar_stiff_torsion.yaml");
  for (const MethodPtr& e : engines) {
    SCOPED_TRACE(e->name());
    const Result r = e->Run(m);
    ASSERT_TRUE(r.ok() || r.status == Status::kDiverged) << r.reason;
    double error = std::numeric_limits<double>::infinity();
    if (r.ok()) {
      const MotionError err = CompareMotion(m, BarClosedForm(m, r.trajectory, TorsionMotion), r.trajectory);
      ASSERT_TRUE(err.problem.empty()) << err.problem;
      error = err.q.max;
    } else if (Verbose()) {
      std::printf("  %-26s %s\n", e->name().c_str(), r.reason.c_str());
    }
    ExpectWithinBound(m, e->name(), error);
  }
}

// A torsion on an angle whose vector is fixed in no single body (O→B across both bars of a double
// pendulum): a reason in every engine, never a crash.
TEST(EngineLoadLaws, TorsionAcrossBodiesIsAReason) {
  const Model m = Scene("double_pendulum_torsion_span.yaml");
  const GraphOrReason g = BuildGraph(m);
  ASSERT_FALSE(g.graph.has_value());
  EXPECT_NE(g.reason.find("torsional spring–damper on psi"), std::string::npos) << g.reason;
  EXPECT_NE(g.reason.find("O→B is not fixed in one rigid body"), std::string::npos) << g.reason;
  for (const MethodPtr& e : harness::EngineMethods()) {
    SCOPED_TRACE(e->name());
    const auto why = e->Applicability(m);
    ASSERT_TRUE(why.has_value());
    EXPECT_EQ(*why, g.reason);
  }
}

}  // namespace
}  // namespace engines_load_laws_test
}  // namespace mechbench::engines
