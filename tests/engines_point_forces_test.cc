// Point forces given as laws of t and in a body's frame in the engines (tests/data/scenes/
// block_force_sine.yaml, bar_follower_force.yaml): each engine applies them its own way (ODE,
// Bullet and MuJoCo before every step, value and direction from the step's start: explicit;
// Simbody through Force::Custom at every stage's time and pose), against the closed forms; a
// force law that reads the state is a reason, never a crash.
#include "engines_support.h"

#include "mechbench/engines/graph.h"

#include "mechbench/harness/registry.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>

namespace mechbench::engines {
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

void ExpectClosedForm(const char* file, const std::function<std::vector<Sample>(const Model&, const std::vector<Sample>&)>& exact) {
  const std::vector<MethodPtr> engines = harness::EngineMethods();
  if (engines.empty()) GTEST_SKIP() << "built without engines";
  const Model m = Scene(file);
  for (const MethodPtr& e : engines) {
    SCOPED_TRACE(e->name());
    ASSERT_FALSE(e->Applicability(m).has_value()) << *e->Applicability(m);
    const Result r = e->Run(m);
    ASSERT_TRUE(r.ok()) << r.reason;
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

// Force laws of the state (a spring written as a law, a follower motor curve): each engine gives the reason.
TEST(EnginePointForces, StateLawsAreAReason) {
  const std::vector<MethodPtr> engines = harness::EngineMethods();
  if (engines.empty()) GTEST_SKIP() << "built without engines";
  for (const char* file : {"block_force_spring_law.yaml", "bar_follower_motor_curve.yaml"}) {
    const Model m = Scene(file);
    for (const MethodPtr& e : engines) {
      SCOPED_TRACE(std::string(file) + " " + e->name());
      const auto why = e->Applicability(m);
      ASSERT_TRUE(why.has_value());
      EXPECT_NE(why->find("reads the state"), std::string::npos) << *why;
    }
  }
}

}  // namespace
}  // namespace mechbench::engines
