// Point forces given as laws of t, in a body's frame and as laws of the state in the engines
// (tests/data/scenes/block_force_sine.yaml, bar_follower_force.yaml, block_force_spring_law.yaml,
// bar_follower_motor_curve.yaml): each engine applies them its own way (ODE and Bullet before every
// step, value and direction from the step's start: explicit; Simbody through Force::Custom and
// MuJoCo through mjcb_passive at every stage's time and state), against the closed forms.
#include "engines_support.h"

#include "mechbench/engines/graph.h"

#include "mechbench/harness/registry.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>

namespace mechbench::engines {
namespace engines_point_forces_test {  // this file's own names (the tests build in unity batches)
namespace {

using namespace testing;

Model Scene(const std::string& file) { return LoadScenario(std::string(MECHBENCH_TEST_DATA) + "/scenes/" + file); }

// The block under F0 sin ωt from rest at 0: ẍ = (F0/m) sin ωt.
std::vector<Sample> BlockClosedForm(const Model& m, const std::vector<Sample>& at) {
  const double F0 = m.constants.at("F0"), w = m.constants.at("w"), mass = m.bodies[0].mass, a = F0 / mass;
  std::vector<Sample> out;
  for (const Sample& s : at) {
    const double t = s.t;
    Sample c{t, Eigen::VectorXd::Zero(1), Eigen::VectorXd::Zero(1), Eigen::VectorXd::Zero(1), 0.0};
    c.q[0] = a / w * t - a / (w * w) * std::sin(w * t);
    c.qd[0] = a / w * (1 - std::cos(w * t));
    c.qdd[0] = a * std::sin(w * t);
    out.push_back(c);
  }
  return out;
}

// The bar turned by a constant torque F_y L from rest: θ = F_y L t²/(2 I_O); xA = L cos θ, yA = L sin θ.
std::vector<Sample> FollowerClosedForm(const Model& m, const std::vector<Sample>& at) {
  const Body& bar = m.bodies[0];
  const double I_O = bar.inertia_com + bar.mass * bar.com_B.squaredNorm(), L = bar.Length();
  const double al = m.forces[0].components.y() * L / I_O;
  const int x = m.SlotIndex("xA"), y = m.SlotIndex("yA"), th = m.SlotIndex("theta");
  std::vector<Sample> out;
  for (const Sample& s : at) {
    const double t = s.t, w = al * t, q = 0.5 * al * t * t;
    Sample c{t, Eigen::VectorXd::Zero(3), Eigen::VectorXd::Zero(3), Eigen::VectorXd::Zero(3), 0.0};
    c.q[x] = L * std::cos(q), c.q[y] = L * std::sin(q), c.q[th] = q;
    c.qd[x] = -L * std::sin(q) * w, c.qd[y] = L * std::cos(q) * w, c.qd[th] = w;
    c.qdd[x] = -L * (std::cos(q) * w * w + std::sin(q) * al), c.qdd[y] = L * (-std::sin(q) * w * w + std::cos(q) * al);
    c.qdd[th] = al;
    out.push_back(c);
  }
  return out;
}

// The block of block_force_spring_law.yaml released from x0 at rest under F = −k x − c ẋ: with
// σ = c/(2m), ω_d = √(k/m − σ²), x = x0 e^(−σt) (cos ω_d t + (σ/ω_d) sin ω_d t).
std::vector<Sample> SpringLawClosedForm(const Model& m, const std::vector<Sample>& at) {
  const double k = m.constants.at("k"), c = m.constants.at("c"), mass = m.bodies[0].mass, x0 = m.initial[0].value;
  const double s = c / (2 * mass), wd = std::sqrt(k / mass - s * s);
  std::vector<Sample> out;
  for (const Sample& x : at) {
    const double t = x.t, e = std::exp(-s * t), C = std::cos(wd * t), S = std::sin(wd * t);
    Sample c_{t, Eigen::VectorXd::Zero(1), Eigen::VectorXd::Zero(1), Eigen::VectorXd::Zero(1), 0.0};
    c_.q[0] = x0 * e * (C + s / wd * S);
    c_.qd[0] = -x0 * e * (s * s / wd + wd) * S;
    c_.qdd[0] = (-k * c_.q[0] - c * c_.qd[0]) / mass;
    out.push_back(c_);
  }
  return out;
}

// The bar of bar_follower_motor_curve.yaml pushed at its tip across it by F0 (1 − ω/ω0): with
// k = F0 L/(ω0 I_O), ω = ω0 (1 − e^(−k t)), θ = ω0 (t − (1 − e^(−k t))/k).
std::vector<Sample> FollowerMotorClosedForm(const Model& m, const std::vector<Sample>& at) {
  const Body& bar = m.bodies[0];
  const double I_O = bar.inertia_com + bar.mass * bar.com_B.squaredNorm(), L = bar.Length();
  const double w0 = m.constants.at("omega0"), k = m.constants.at("F0") * L / (w0 * I_O);
  const int x = m.SlotIndex("xA"), y = m.SlotIndex("yA"), th = m.SlotIndex("theta");
  std::vector<Sample> out;
  for (const Sample& s : at) {
    const double t = s.t, e = std::exp(-k * t), q = w0 * (t - (1 - e) / k), w = w0 * (1 - e), al = w0 * k * e;
    Sample c{t, Eigen::VectorXd::Zero(3), Eigen::VectorXd::Zero(3), Eigen::VectorXd::Zero(3), 0.0};
    c.q[x] = L * std::cos(q), c.q[y] = L * std::sin(q), c.q[th] = q;
    c.qd[x] = -L * std::sin(q) * w, c.qd[y] = L * std::cos(q) * w, c.qd[th] = w;
    c.qdd[x] = -L * (std::cos(q) * w * w + std::sin(q) * al), c.qdd[y] = L * (-std::sin(q) * w * w + std::cos(q) * al);
    c.qdd[th] = al;
    out.push_back(c);
  }
  return out;
}

using ClosedForm = std::function<std::vector<Sample>(const Model&, const std::vector<Sample>&)>;

// Every engine variant against the closed form, judged on the scene's bound (tolerances.yaml) or
// as a known failure; `setting` names the Result::settings entry that says how the engine applies it.
void ExpectClosedForm(const char* file, const ClosedForm& exact, const char* setting = nullptr) {
  const std::vector<MethodPtr> engines = harness::EngineMethods();
  if (engines.empty()) GTEST_SKIP() << "built without engines";
  const Model m = Scene(file);
  for (const MethodPtr& e : engines) {
    SCOPED_TRACE(e->name());
    ASSERT_FALSE(e->Applicability(m).has_value()) << *e->Applicability(m);
    const Result r = e->Run(m);
    ASSERT_TRUE(r.ok()) << r.reason;
    if (setting) {
      EXPECT_TRUE(r.settings.count(setting)) << setting;
    }
    const MotionError err = CompareMotion(m, exact(m, r.trajectory), r.trajectory);
    ASSERT_TRUE(err.problem.empty()) << err.problem;
    const double bound = harness::LoadTolerances(m.name).FreePosition(e->name(), m.analysis.t1 - m.analysis.t0);
    std::printf("  %-26s %s: position error %.3g (bound %.3g)\n", e->name().c_str(), file, err.q.max, bound);
    if (const std::string* known = KnownFailure(m.name, e->name()))
      EXPECT_GT(err.q.max, bound) << "no longer a known failure (" << *known << ")";
    else
      EXPECT_LE(err.q.max, bound);
  }
}

TEST(EnginePointForces, ForceLawOfTimeFollowsTheClosedForm) { ExpectClosedForm("block_force_sine.yaml", BlockClosedForm); }

TEST(EnginePointForces, FollowerForceFollowsTheClosedForm) { ExpectClosedForm("bar_follower_force.yaml", FollowerClosedForm); }

// Force laws of the state: a spring written as a world force law of q.xB and qd.xB, and a follower
// force (body frame) with a motor curve of qd.theta. The graph keeps them apart (state_forces),
// every engine applies them from its own state (setting "state_forces").
TEST(EnginePointForces, SpringLawOfTheStateFollowsTheClosedForm) {
  const GraphOrReason g = BuildGraph(Scene("block_force_spring_law.yaml"));
  ASSERT_TRUE(g.graph) << g.reason;
  EXPECT_TRUE(g.graph->forces.empty());
  ASSERT_EQ(g.graph->state_forces.size(), 1u);
  EXPECT_FALSE(g.graph->state_forces[0].in_body_frame);
  ExpectClosedForm("block_force_spring_law.yaml", SpringLawClosedForm, "state_forces");
}

TEST(EnginePointForces, FollowerMotorCurveFollowsTheClosedForm) {
  const GraphOrReason g = BuildGraph(Scene("bar_follower_motor_curve.yaml"));
  ASSERT_TRUE(g.graph) << g.reason;
  ASSERT_EQ(g.graph->state_forces.size(), 1u);
  EXPECT_TRUE(g.graph->state_forces[0].in_body_frame);
  ExpectClosedForm("bar_follower_motor_curve.yaml", FollowerMotorClosedForm, "state_forces");
}

// MuJoCo RK4 evaluates the loads at its four stages (mjcb_passive): halving its step divides the
// error by about 16. (Held over the step, as in xfrc_applied before every mj_step, it was first
// order: block_force_sine 4.78e-5 at 0.1 ms.) The steps are the scenes' sample intervals and half
// of them, where RK4's error is well above rounding.
TEST(EnginePointForces, MujocoRk4IsFourthOrderOnForceLaws) {
  const std::vector<MethodPtr> engines = harness::EngineMethods();
  const Method* rk4 = nullptr;
  for (const MethodPtr& e : engines)
    if (e->name() == "mujoco-rk4-tuned") rk4 = e.get();
  if (!rk4) GTEST_SKIP() << "built without MuJoCo";
  const struct {
    const char* file;
    ClosedForm exact;
    double h;  // [s]
  } cases[] = {{"block_force_sine.yaml", BlockClosedForm, 0.01},
               {"block_force_spring_law.yaml", SpringLawClosedForm, 0.01},
               {"bar_follower_motor_curve.yaml", FollowerMotorClosedForm, 0.1}};
  for (const auto& c : cases) {
    SCOPED_TRACE(c.file);
    const Model m = Scene(c.file);
    double e[2];
    for (int k = 0; k < 2; ++k) {
      const Result r = rk4->Run(m, {.step = c.h / (1 + k)});
      ASSERT_TRUE(r.ok()) << r.reason;
      const MotionError err = CompareMotion(m, c.exact(m, r.trajectory), r.trajectory);
      ASSERT_TRUE(err.problem.empty()) << err.problem;
      e[k] = err.q.max;
    }
    std::printf("  mujoco-rk4-tuned %s: e(%g) = %.4g, e(%g) = %.4g, order %.3f\n", c.file, c.h, e[0], c.h / 2, e[1],
                std::log2(e[0] / e[1]));
    EXPECT_NEAR(std::log2(e[0] / e[1]), 4.0, 0.3);
  }
}

}  // namespace
}  // namespace engines_point_forces_test
}  // namespace mechbench::engines
