// Loads given as expressions in the engines (tests/data/scenes/bar_*.yaml): a torque law of t is
// applied by each engine its own way (ODE, Bullet and MuJoCo before every step, from the step's
// start: explicit; Simbody through Force::Custom at every stage's time); a law that reads the
// state, and a torsional spring–damper, are a reason, never a crash.
#include "engines_support.h"

#include "mechbench/engines/graph.h"

#include "mechbench/harness/registry.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

namespace mechbench::engines {
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

// A law of the state (the motor curve) and a torsion: each engine gives the reason.
TEST(EngineLoadLaws, StateLawsAndTorsionsAreAReason) {
  const std::vector<MethodPtr> engines = harness::EngineMethods();
  if (engines.empty()) GTEST_SKIP() << "built without engines";
  for (const char* file : {"bar_motor_curve.yaml", "bar_torsion_spring.yaml"}) {
    const Model m = Scene(file);
    for (const MethodPtr& e : engines) {
      SCOPED_TRACE(std::string(file) + " " + e->name());
      const auto why = e->Applicability(m);
      ASSERT_TRUE(why.has_value());
      EXPECT_NE(why->find(std::string(file) == "bar_motor_curve.yaml" ? "reads the state" : "torsional"), std::string::npos)
          << *why;
    }
  }
}

}  // namespace
}  // namespace mechbench::engines
