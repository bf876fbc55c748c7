// Spring–dampers with laws in the engines (tests/data/scenes/block_spring_*.yaml,
// pendulum_spring_law.yaml): the graph keeps them apart from the engines' own spring elements
// (Graph::state_springs, one state_forces entry per moving end) and every engine applies the pair
// of forces where it applies the state's force laws (ODE and Bullet before every step, from the
// step's start: explicit; Simbody through Force::Custom and MuJoCo through mjcb_passive at every
// stage), against the closed forms and the numeric reference.
#include "engines_support.h"

#include "mechbench/engines/graph.h"

#include "mechbench/harness/registry.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>

namespace mechbench::engines {
namespace engines_spring_laws_test {  // this file's own names (the tests build in unity batches)
namespace {

using namespace testing;

Model Scene(const std::string& file) { return LoadScenario(std::string(MECHBENCH_TEST_DATA) + "/scenes/" + file); }

// x(t) and its two derivatives, sampled at the engine's times.
using Motion = std::function<std::array<double, 3>(const Model&, double)>;

// The preload ramp F0 = a t: m ẍ = −k x − a t, x = x0 cos ωt + a/(k ω) sin ωt − a t/k.
std::array<double, 3> RampMotion(const Model& m, double t) {
  const double k = m.springs[0].stiffness, a = m.constants.at("a"), mass = m.bodies[0].mass, w = std::sqrt(k / mass);
  const double x0 = m.initial[0].value, C = std::cos(w * t), S = std::sin(w * t);
  const double x = x0 * C + a / (k * w) * S - a * t / k, v = -x0 * w * S + a / k * C - a / k;
  return {x, v, (-k * x - a * t) / mass};
}
// L0 = 2 + a q.xB, F0 = c qd.xB: a damped oscillator of stiffness k (1 − a), from rest at x0.
std::array<double, 3> StateLawMotion(const Model& m, double t) {
  const double k = m.constants.at("k") * (1 - m.constants.at("a")), c = m.constants.at("c"), mass = m.bodies[0].mass;
  const double s = c / (2 * mass), wd = std::sqrt(k / mass - s * s), x0 = m.initial[0].value;
  const double e = std::exp(-s * t), C = std::cos(wd * t), S = std::sin(wd * t);
  const double x = x0 * e * (C + s / wd * S), v = -x0 * e * (s * s / wd + wd) * S;
  return {x, v, (-k * x - c * v) / mass};
}

std::vector<Sample> ClosedForm(const Model& m, const std::vector<Sample>& at, const Motion& motion) {
  std::vector<Sample> out;
  for (const Sample& s : at) {
    const auto [x, v, a] = motion(m, s.t);
    Sample c{s.t, Eigen::VectorXd::Constant(1, x), Eigen::VectorXd::Constant(1, v), Eigen::VectorXd::Constant(1, a), 0.0};
    out.push_back(c);
  }
  return out;
}

// Judges a position error against the scene's bound (tolerances.yaml), or a known failure.
void ExpectWithinBound(const Model& m, const std::string& variant, double error) {
  const double bound = harness::LoadTolerances(m.name).FreePosition(variant, m.analysis.t1 - m.analysis.t0);
  std::printf("  %-28s %-26s position error %.3g (bound %.3g)\n", m.name.c_str(), variant.c_str(), error, bound);
  if (const std::string* known = KnownFailure(m.name, variant))
    EXPECT_GT(error, bound) << "no longer a known failure (" << *known << ")";
  else
    EXPECT_LE(error, bound);
}

TEST(EngineSpringLaws, TheGraphAppliesThemAtTheMovingEnds) {
  const GraphOrReason g = BuildGraph(Scene("block_spring_preload_ramp.yaml"));
  ASSERT_TRUE(g.graph) << g.reason;
  EXPECT_TRUE(g.graph->springs.empty());
  ASSERT_EQ(g.graph->state_springs.size(), 1u);
  EXPECT_TRUE(g.graph->state_springs[0].HasLaw());
  ASSERT_EQ(g.graph->state_forces.size(), 1u);  // A is fixed: only B's end
  EXPECT_EQ(g.graph->state_forces[0].spring, 0);
  EXPECT_EQ(g.graph->state_forces[0].end, 1);
  EXPECT_EQ(StateForceLaws(*g.graph), 0u);
  // A constant spring stays the engines' own element.
  const GraphOrReason c = BuildGraph(Scene("pendulum_spring_damper.yaml"));
  ASSERT_TRUE(c.graph) << c.reason;
  EXPECT_EQ(c.graph->springs.size(), 1u);
  EXPECT_TRUE(c.graph->state_springs.empty() && c.graph->state_forces.empty());
}

TEST(EngineSpringLaws, PreloadRampAndStateLawFollowTheClosedForms) {
  const std::vector<MethodPtr> engines = harness::EngineMethods();
  if (engines.empty()) GTEST_SKIP() << "built without engines";
  const struct {
    const char* file;
    Motion motion;
  } cases[] = {{"block_spring_preload_ramp.yaml", RampMotion}, {"block_spring_state_law.yaml", StateLawMotion}};
  for (const auto& c : cases) {
    const Model m = Scene(c.file);
    for (const MethodPtr& e : engines) {
      SCOPED_TRACE(std::string(c.file) + " " + e->name());
      ASSERT_FALSE(e->Applicability(m).has_value()) << *e->Applicability(m);
      const Result r = e->Run(m);
      ASSERT_TRUE(r.ok()) << r.reason;
      EXPECT_TRUE(r.settings.count("state_springs"));
      EXPECT_FALSE(r.settings.count("state_forces"));
      const MotionError err = CompareMotion(m, ClosedForm(m, r.trajectory, c.motion), r.trajectory);
      ASSERT_TRUE(err.problem.empty()) << err.problem;
      ExpectWithinBound(m, e->name(), err.q.max);
    }
  }
}

// Laws of t and of the state on a pendulum (a progressive spring, a moving anchor, a preload
// ramp), against the numeric reference trajectory.
TEST(EngineSpringLaws, PendulumFollowsTheReference) {
  const std::vector<MethodPtr> engines = harness::EngineMethods();
  if (engines.empty()) GTEST_SKIP() << "built without engines";
  const Model m = Scene("pendulum_spring_law.yaml");
  const harness::ReferenceRecord ref = harness::GetReference(m);
  ASSERT_TRUE(ref.confirmed) << ref.description;
  for (const MethodPtr& e : engines) {
    SCOPED_TRACE(e->name());
    const Result r = e->Run(m);
    ASSERT_TRUE(r.ok()) << r.reason;
    EXPECT_TRUE(r.settings.count("state_springs"));
    const MotionError err = CompareMotion(m, ref.trajectory, r.trajectory);
    ASSERT_TRUE(err.problem.empty()) << err.problem;
    ExpectWithinBound(m, e->name(), err.q.max);
    const double residual = Compare(m, r, r).residual;
    std::printf("  %-28s %-26s ‖Φ‖ %.3g (bound %.3g)\n", m.name.c_str(), e->name().c_str(), residual,
                FreeResidualOf(m.name, e->name()));
    if (!KnownFailure(m.name, e->name())) {
      EXPECT_LE(residual, FreeResidualOf(m.name, e->name()));
    }
  }
}

}  // namespace
}  // namespace engines_spring_laws_test
}  // namespace mechbench::engines
