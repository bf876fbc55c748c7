// Couplings in the engines (Graph::couplings): a rack and pinion where the engine has a constraint
// for it — Simbody's Constraint::CoordinateCoupler, MuJoCo's joint equality, Bullet's
// btMultiBodyGearConstraint — and the reason where it has none (ODE, Bullet's btRigidBody).
// The free rack (gravity and a spring) against the confirmed reference and its closed form, with
// the bounds and known failures of harness/tolerances.yaml; the driven rack and the Scotch yoke's rack against numeric.
#include "engines_support.h"

#include "mechbench/engines/graph.h"
#include "mechbench/harness/registry.h"
#include "mechbench/numeric/numeric_method.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace mechbench::engines {
namespace engines_coupling_test {  // this file's own names (the tests build in unity batches)
namespace {

using namespace testing;

Model Fixture(const std::string& file) { return LoadScenario(std::string(MECHBENCH_TEST_DATA) + "/scenes/" + file); }

// An engine's position error on a free scene against its bound in tolerances.yaml (free, grown
// with the motion's duration), or a known failure that still fails (as engines_common_test).
void ExpectWithinFreeBound(const Model& m, const std::string& variant, double error) {
  const double bound = harness::LoadTolerances(m.name).FreePosition(variant, m.analysis.t1 - m.analysis.t0);
  if (const std::string* known = KnownFailure(m.name, variant))
    EXPECT_GT(error, bound) << m.name << " " << variant << " is no longer a known failure (" << *known << ")";
  else
    EXPECT_LE(error, bound) << m.name << " " << variant;
}

// Which engines express a coupling: the btRigidBody and ODE variants give their reason.
bool Expresses(const std::string& variant) {
  return variant.rfind("simbody", 0) == 0 || variant.rfind("mujoco", 0) == 0 || variant.rfind("bullet-multibody", 0) == 0;
}

TEST(EngineCoupling, GraphMapsTheRackOntoTwoTreeJoints) {
  const Model m = Fixture("rack_pinion_free.yaml");
  const GraphOrReason g = BuildGraph(m);
  ASSERT_TRUE(g.graph) << g.reason;
  ASSERT_EQ(g.graph->couplings.size(), 1u);
  const CouplingMap& c = g.graph->couplings[0];
  const GraphJoint &a = g.graph->joints[c.joint_a], &b = g.graph->joints[c.joint_b];
  EXPECT_TRUE(a.in_tree && b.in_tree);
  EXPECT_EQ(a.type, PairType::kRevolute);
  EXPECT_EQ(b.type, PairType::kPrismatic);
  // The slider's axis is the guide's (±y): its coordinate is ±y_R1, so the ratio is ±r.
  EXPECT_NEAR(std::fabs(c.ratio), 0.05, 1e-15);
  EXPECT_NEAR(c.ratio * b.axis_parent_B.y(), 0.05, 1e-15);
}

// A link whose two points slide on parallel fixed guides only translates: the graph makes it the
// prismatic link itself (its own mass on the guide, no slider blocks) and drops the second slider.
TEST(EngineCoupling, TranslatingLinkIsItsOwnPrismaticLink) {
  for (const char* file : {"rack_pinion_free.yaml", "scotch_yoke_translating.yaml"}) {
    SCOPED_TRACE(file);
    const Model m = Fixture(file);
    const GraphOrReason g = BuildGraph(m);
    ASSERT_TRUE(g.graph) << g.reason;
    const std::string link = m.bodies[1].name;  // the rack, the yoke
    int prismatic_on_link = 0, on_ground = 0;
    for (const GraphJoint& j : g.graph->joints) {
      if (j.type != PairType::kPrismatic) continue;
      on_ground += j.parent < 0;
      if (j.parent < 0 && g.graph->bodies[j.child].kind == BodyKind::kLink) {
        ++prismatic_on_link;
        EXPECT_TRUE(j.in_tree);
        const GraphBody& b = g.graph->bodies[j.child];
        EXPECT_EQ(b.name, link);
        // The joint's axis in the child frame is the guide's, whatever the link's angle.
        const Eigen::Vector2d u = Rotate(-j.angle0, j.axis_parent_B);
        EXPECT_NEAR(std::fabs(Rotate(b.initial.angle, u).dot(j.axis_parent_B)), 1.0, 1e-15);
      }
    }
    EXPECT_EQ(prismatic_on_link, 1);
    EXPECT_EQ(on_ground, 1) << "the second slider on the parallel guide is dropped";
    for (const GraphBody& b : g.graph->bodies) {
      if (b.kind == BodyKind::kSliderBlock) {
        EXPECT_EQ(b.name.find(".ground"), std::string::npos) << b.name;
      }
    }
  }
  // The rack's mass on the guide is the file's: 1 kg, nothing added.
  const GraphOrReason g = BuildGraph(Fixture("rack_pinion_free.yaml"));
  ASSERT_TRUE(g.graph) << g.reason;
  double on_guide = 0;
  for (const GraphJoint& j : g.graph->joints)
    if (j.type == PairType::kPrismatic && j.parent < 0) on_guide += g.graph->bodies[j.child].mass;
  EXPECT_EQ(on_guide, 1.0);
}

TEST(EngineCoupling, FreeRackFollowsTheReferenceOrSaysWhyNot) {
  const std::vector<MethodPtr> engines = harness::EngineMethods();
  if (engines.empty()) GTEST_SKIP() << "built without engines";
  const Model m = Fixture("rack_pinion_free.yaml");
  const harness::ReferenceRecord ref = harness::GetReference(m);
  ASSERT_TRUE(ref.confirmed) << ref.description;
  const int y = m.SlotIndex("yR1"), th = m.SlotIndex("theta");
  // The engines build the file's mechanism (the rack its own prismatic link, no slider blocks:
  // TranslatingLinkIsItsOwnPrismaticLink), whose closed form is the reference's.
  const double k = 20, w = std::sqrt(k / 2), y_eq = 0.2 - 9.81 / k;
  for (const MethodPtr& e : engines) {
    SCOPED_TRACE(e->name());
    const auto why = e->Applicability(m);
    if (!Expresses(e->name())) {
      ASSERT_TRUE(why.has_value());
      EXPECT_NE(why->find("rack yR1 by theta"), std::string::npos) << *why;
      if (Verbose()) std::printf("%-28s not applicable: %s\n", e->name().c_str(), why->c_str());
      continue;
    }
    ASSERT_FALSE(why.has_value()) << *why;
    const Result r = e->Run(m);
    ASSERT_TRUE(r.ok() || r.status == Status::kDiverged) << r.reason;
    EXPECT_TRUE(r.settings.count("couplings"));
    double error = std::numeric_limits<double>::infinity(), coupling = 0;
    if (r.ok()) {
      const MotionError err = CompareMotion(m, ref.trajectory, r.trajectory);
      ASSERT_TRUE(err.problem.empty()) << err.problem;
      error = err.q.max;
      double closed = 0;
      for (const Sample& s : r.trajectory) {
        coupling = std::max(coupling, std::fabs(s.q[y] - 0.05 * s.q[th]));
        closed = std::max(closed, std::fabs(s.q[y] - y_eq * (1 - std::cos(w * s.t))));
      }
      const double residual = Compare(m, r, r).residual;
      std::printf("  free rack, %-26s position %.3g, vs the closed form %.3g m, |y − r θ| %.3g m, residual %.3g\n",
                  e->name().c_str(), error, closed, coupling, residual);
      if (!KnownFailure(m.name, e->name())) {
        EXPECT_LE(residual, FreeResidualOf(m.name, e->name()));
      }
    }
    ExpectWithinFreeBound(m, e->name(), error);
  }
}

// Driven: the pinion prescribed, the rack follows; and the Scotch yoke's rack turning its pinion.
TEST(EngineCoupling, DrivenRacksAgreeWithNumeric) {
  const std::vector<MethodPtr> engines = harness::EngineMethods();
  if (engines.empty()) GTEST_SKIP() << "built without engines";
  for (const char* file : {"rack_pinion_driven.yaml", "scotch_yoke_rack_pinion.yaml"}) {
    const Model m = Fixture(file);
    const Result ref = numeric::MakeNumericMethod()->Run(m);
    ASSERT_TRUE(ref.ok()) << ref.reason;
    for (const MethodPtr& e : engines) {
      SCOPED_TRACE(std::string(file) + " " + e->name());
      const Result r = RunIfApplicable(*e, m);
      if (!Expresses(e->name())) {
        EXPECT_EQ(r.status, Status::kNotApplicable);
        EXPECT_NE(r.reason.find("rack"), std::string::npos) << r.reason;
        continue;
      }
      ASSERT_TRUE(r.ok()) << r.reason;
      const Errors err = Compare(m, ref, r);
      const harness::Agreement tol = ToleranceOf(m.name, e->name());
      std::printf("  %s, %-26s q %.3g qd %.3g qdd %.3g residual %.3g\n", file, e->name().c_str(), err.q, err.qd, err.qdd,
                  err.residual);
      if (KnownFailure(m.name, e->name())) continue;
      EXPECT_LE(err.q, tol.q);
      EXPECT_LE(err.qd, tol.qd);
      EXPECT_LE(err.qdd, tol.qdd);
    }
  }
}

// A rack meshing a gear-train member (gear_train_rack.yaml): the sliding member is a body on a
// prismatic joint, coupled to its pinion's hinge by the engine's coupling constraint; against
// numeric (itself against the hand-computed 5 mm per radian of the input: numeric_gear_rack_test).
TEST(EngineCoupling, GearTrainRackAgreesWithNumeric) {
  const Model m = Fixture("gear_train_rack.yaml");
  const GraphOrReason g = BuildGraph(m);
  ASSERT_TRUE(g.graph) << g.reason;
  ASSERT_EQ(g.graph->couplings.size(), 1u);
  const GraphJoint& slide = g.graph->joints[g.graph->couplings[0].joint_b];
  EXPECT_EQ(slide.type, PairType::kPrismatic);
  EXPECT_EQ(g.graph->bodies[slide.child].name, "rack");
  EXPECT_DOUBLE_EQ(g.graph->couplings[0].ratio, 45.0);
  const std::vector<MethodPtr> engines = harness::EngineMethods();
  if (engines.empty()) GTEST_SKIP() << "built without engines";
  const Result ref = numeric::MakeNumericMethod()->Run(m);
  ASSERT_TRUE(ref.ok()) << ref.reason;
  for (const MethodPtr& e : engines) {
    SCOPED_TRACE(e->name());
    const Result r = RunIfApplicable(*e, m);
    if (!Expresses(e->name())) {
      EXPECT_EQ(r.status, Status::kNotApplicable);
      EXPECT_NE(r.reason.find("rack x_rack by phi4"), std::string::npos) << r.reason;
      continue;
    }
    ASSERT_TRUE(r.ok()) << r.reason;
    const Errors err = Compare(m, ref, r);
    const harness::Agreement tol = ToleranceOf(m.name, e->name());
    std::printf("  gear_train_rack.yaml, %-26s q %.3g qd %.3g qdd %.3g residual %.3g\n", e->name().c_str(), err.q, err.qd,
                err.qdd, err.residual);
    if (KnownFailure(m.name, e->name())) continue;
    EXPECT_LE(err.q, tol.q);
    EXPECT_LE(err.qd, tol.qd);
    EXPECT_LE(err.qdd, tol.qdd);
  }
}

}  // namespace
}  // namespace engines_coupling_test
}  // namespace mechbench::engines
