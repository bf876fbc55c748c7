// One-point bodies in the engines (engines/common graph): a point body on a guide is its slider's
// block with the file's mass, a point mass at a pin rides on the first link that holds it, and the
// scenes with a massive piston, a block on a turning guide and a bar with a point mass follow the
// numeric reference in every engine variant, as `mechbench run` judges them.
#include "engines_support.h"

#include "mechbench/engines/graph.h"

#include "mechbench/harness/compare.h"
#include "mechbench/harness/reference.h"
#include "mechbench/harness/registry.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>

namespace mechbench::engines {
namespace engines_point_body_test {  // this file's own names (the tests build in unity batches)
namespace {

using namespace testing;

Model Fixture(const std::string& file) { return LoadScenario(std::string(MECHBENCH_TEST_DATA) + "/scenes/" + file); }

const GraphBody* Block(const Graph& g) {
  for (const GraphBody& b : g.bodies)
    if (b.kind == BodyKind::kSliderBlock) return &b;
  return nullptr;
}

// The piston's block has the file's 2 kg, its com and inertia; without the piston's body the
// block is the substitute of 1 % of the lightest link, stated as before.
TEST(EnginePointBody, BlockTakesThePistonsMass) {
  const GraphOrReason heavy = BuildGraph(Fixture("slider_crank_piston_free.yaml"));
  ASSERT_TRUE(heavy.graph) << heavy.reason;
  const GraphBody* b = Block(*heavy.graph);
  ASSERT_NE(b, nullptr);
  EXPECT_EQ(b->mass, 2.0);
  EXPECT_EQ(b->mass_source, "model");
  EXPECT_DOUBLE_EQ(b->inertia_com, 2 * 0.04 * 0.04 / 2);
  const GraphOrReason light = BuildGraph(Fixture("slider_crank_massless_piston_free.yaml"));
  ASSERT_TRUE(light.graph) << light.reason;
  const GraphBody* s = Block(*light.graph);
  ASSERT_NE(s, nullptr);
  EXPECT_NE(s->mass_source, "model");
  EXPECT_NEAR(s->mass, 0.01 * 0.5, 1e-15);  // 1 % of the rod, the lightest link
  // On the turning rocker the block keeps its com off the point and its inertia.
  const GraphOrReason inv = BuildGraph(Fixture("inverted_slider_crank_block_free.yaml"));
  ASSERT_TRUE(inv.graph) << inv.reason;
  const GraphBody* k = Block(*inv.graph);
  ASSERT_NE(k, nullptr);
  EXPECT_EQ(k->mass, 0.5);
  EXPECT_EQ(k->com_B, Eigen::Vector2d(0.02, 0.01));
  EXPECT_EQ(k->inertia_com, 2e-4);
}

// A point mass at a pin rides on the bar: its mass, com and inertia are those of the bar merged
// by hand (pendulum_bar_point_mass_merged.yaml), and a note says so. On a massless rod the merged
// body has its mass at the tip and no inertia: the engines give it their substitute inertia and a
// note names the rod and the point body folded into it (engines_lumped_inertia_test.cc).
TEST(EnginePointBody, PointMassRidesOnTheLinkAtItsPin) {
  const GraphOrReason g = BuildGraph(Fixture("pendulum_bar_point_mass.yaml"));
  const GraphOrReason h = BuildGraph(Fixture("pendulum_bar_point_mass_merged.yaml"));
  ASSERT_TRUE(g.graph) << g.reason;
  ASSERT_TRUE(h.graph) << h.reason;
  ASSERT_EQ(g.graph->bodies.size(), 1u);
  const GraphBody &a = g.graph->bodies[0], &b = h.graph->bodies[0];
  EXPECT_NEAR(a.mass, b.mass, 1e-15);
  EXPECT_NEAR((a.com_B - b.com_B).norm(), 0.0, 1e-15);
  EXPECT_NEAR(a.inertia_com, b.inertia_com, 1e-15);
  bool noted = false;
  for (const std::string& n : g.graph->notes) noted = noted || n.find("point body bob") != std::string::npos;
  EXPECT_TRUE(noted);
  const auto substitute_named = [](const GraphOrReason& r) {
    if (!r.graph) return false;
    for (const std::string& n : r.graph->notes)
      if (n.find("link rod (massless, point body bob (3 kg at 1) folded into it") != std::string::npos &&
          n.find("substitute inertia") != std::string::npos)
        return true;
    return false;
  };
  const GraphOrReason point = BuildGraph(Fixture("pendulum_point_mass.yaml"));
  EXPECT_TRUE(substitute_named(point)) << point.reason;
  for (const MethodPtr& e : harness::EngineMethods()) {
    const auto why = e->Applicability(Fixture("pendulum_point_mass.yaml"));
    EXPECT_FALSE(why.has_value()) << e->name() << ": " << *why;
  }
  // Written with no `mass:` key at all, the rod of a free scene is massless for the engines too
  // (not their default bar of driven scenes, which would make a different pendulum): the same
  // substitute and note.
  const GraphOrReason no_key = BuildGraph(Fixture("pendulum_point_mass_no_mass_key.yaml"));
  EXPECT_TRUE(substitute_named(no_key)) << no_key.reason;
  ASSERT_TRUE(no_key.graph);
  EXPECT_DOUBLE_EQ(no_key.graph->bodies[0].mass, 3.0);
}

// Every engine variant on the scenes with point bodies, against the scene's reference trajectory
// (harness::GetReference), with the bounds and known failures of harness/tolerances.yaml.
TEST(EnginePointBody, ScenesFollowTheReference) {
  const std::vector<MethodPtr> engines = harness::EngineMethods();
  if (engines.empty()) GTEST_SKIP() << "built without engines";
  for (const char* file : {"pendulum_bar_point_mass.yaml", "slider_crank_piston_free.yaml",
                           "inverted_slider_crank_block_free.yaml", "slider_crank_massless_piston_free.yaml"}) {
    const Model m = Fixture(file);
    const harness::ReferenceRecord ref = harness::GetReference(m);
    ASSERT_TRUE(ref.confirmed) << ref.description;
    for (const MethodPtr& e : engines) {
      SCOPED_TRACE(std::string(file) + " " + e->name());
      const Result r = e->Run(m);
      ASSERT_TRUE(r.ok() || r.status == Status::kDiverged) << r.reason;
      double error = std::numeric_limits<double>::infinity(), residual = error;
      if (r.ok()) {
        const MotionError err = CompareMotion(m, ref.trajectory, r.trajectory);
        ASSERT_TRUE(err.problem.empty()) << err.problem;
        error = err.q.max;
        residual = Compare(m, r, r).residual;
      }
      const double bound = harness::LoadTolerances(m.name).FreePosition(e->name(), m.analysis.t1 - m.analysis.t0);
      if (Verbose())
        std::printf("%-36s %-26s position %.3g residual %.3g (bound %.3g)\n", m.name.c_str(), e->name().c_str(), error,
                    residual, bound);
      if (const std::string* known = KnownFailure(m.name, e->name())) {
        EXPECT_GT(error, bound) << m.name << " " << e->name() << " is no longer a known failure (" << *known << ")";
      } else {
        EXPECT_LE(error, bound);
        EXPECT_LE(residual, FreeResidualOf(m.name, e->name()));
      }
    }
  }
}

// The §4.4 shaper with blocks of 0.2 and 2 kg (point bodies) instead of the 1.5 g substitutes:
// every engine variant against the analytic kinematics, as `mechbench run` judges it; the known
// failures (QuickStep, Bullet rigid body, MuJoCo Euler) must still fail, the rest hold their
// bounds (Bullet multibody at its default iterations among them, a known failure with the
// substitute blocks).
TEST(EnginePointBody, HeavyBlocksOnTheQuickReturn) {
  const Model m = Fixture("quick_return_massive_blocks.yaml");
  const harness::Tolerances tol = harness::LoadTolerances(m.name);
  for (const MethodPtr& e : harness::EngineMethods()) {
    SCOPED_TRACE(e->name());
    std::vector<MethodPtr> two;
    for (MethodPtr& x : harness::AllMethods())
      if (x->name() == "analytic" || x->name() == e->name()) two.push_back(std::move(x));
    const harness::RunReport rep = harness::RunScenario(m, two, {}, tol);
    if (tol.KnownFailure(e->name())) {
      EXPECT_FALSE(rep.known.empty()) << e->name() << " now meets its tolerance";
      continue;
    }
    for (const auto& p : rep.problems) ADD_FAILURE() << p;
  }
}

}  // namespace
}  // namespace engines_point_body_test
}  // namespace mechbench::engines
