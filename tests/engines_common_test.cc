// What every engine adapter observes alike (engines/common): a sample's accelerations are the
// motion's, or absent, never a start-up transient passed off as the acceleration at t0.
#include "engines_support.h"

#include "mechbench/engines/graph.h"

#include "mechbench/harness/registry.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace mechbench::engines {
namespace engines_common_test {  // this file's own names (the tests build in unity batches)
namespace {

using namespace testing;

// max over slots of |a − b| / the largest |q̈| of the reference over the run
double QddError(const std::vector<Sample>& ref, const Sample& ref_k, const Sample& s) {
  double scale = 1e-300, worst = 0;
  for (const Sample& r : ref) scale = std::max(scale, r.qdd.cwiseAbs().maxCoeff());
  for (Eigen::Index i = 0; i < ref_k.qdd.size(); ++i) worst = std::max(worst, std::fabs(s.qdd[i] - ref_k.qdd[i]) / scale);
  return worst;
}

// On every driven scene, an engine either has no q̈ at t0 or one as good as its q̈ later on:
// MuJoCo's t0 forward pass, whose equality rows leave out J̇ q̇, gave the crank-rocker's q̈ with
// 0.37 of error against 0.05 over the rest of the motion.
TEST(EngineObservation, AccelerationsAtT0AreAbsentOrAsGoodAsLater) {
  const std::vector<MethodPtr> engines = harness::EngineMethods();
  if (engines.empty()) GTEST_SKIP() << "built without engines";
  const std::vector<MethodPtr> all = harness::AllMethods();
  const Method& analytic = Variant(all, "analytic");
  int checked = 0;
  for (const std::string& name : DrivenScenarios()) {
    const Model m = Load(name);
    if (analytic.Applicability(m) || m.kind != ScenarioKind::kLinkage) continue;
    const Result ref = analytic.Run(m);
    if (!ref.ok() || ref.trajectory.size() < 3) continue;
    for (const MethodPtr& e : engines) {
      // The default variants: the tuned ones observe alike, at ten times the steps.
      if (e->name().find("-default") == std::string::npos || e->Applicability(m)) continue;
      const Result r = e->Run(m);
      if (!r.ok() || r.trajectory.size() != ref.trajectory.size()) continue;
      SCOPED_TRACE(name + " " + e->name());
      const Sample& t0 = r.trajectory.front();
      if (t0.qdd.size() == 0) continue;  // not available: written as such
      double later = 0;
      for (size_t k = 1; k < r.trajectory.size(); ++k)
        if (r.trajectory[k].qdd.size()) later = std::max(later, QddError(ref.trajectory, ref.trajectory[k], r.trajectory[k]));
      const double at_t0 = QddError(ref.trajectory, ref.trajectory.front(), t0);
      EXPECT_LE(at_t0, std::max(2 * later, 1e-6)) << "q̈ at t0 is " << at_t0 << " off, later at most " << later;
      ++checked;
    }
  }
  EXPECT_GT(checked, 0);
}

// A link without mass is not a rigid body the engines can carry (ODE aborted on it, taking `run`
// with it): each engine says so, naming the body, and the natural-coordinate formulations, which
// need no such thing, still integrate the scene. A link with mass but no inertia (all its mass at
// its centre) runs in the engines with their substitute inertia, stated in a note (the substitute
// itself: engines_lumped_inertia_test.cc).
TEST(EngineApplicability, MasslessLinksAreAReasonNotACrash) {
  const std::vector<MethodPtr> all = harness::AllMethods();
  for (const char* file : {"massless_coupler.yaml", "point_mass_coupler.yaml"}) {
    const Model m = LoadScenario(std::string(MECHBENCH_TEST_DATA) + "/scenes/" + file);
    SCOPED_TRACE(file);
    const bool massless = std::string(file) == "massless_coupler.yaml";
    for (const MethodPtr& e : harness::EngineMethods()) {
      const auto why = e->Applicability(m);
      if (massless) {
        ASSERT_TRUE(why.has_value()) << e->name();
        EXPECT_NE(why->find("body coupler has"), std::string::npos) << *why;
      } else {
        ASSERT_FALSE(why.has_value()) << e->name() << ": " << *why;
      }
    }
    const Result r = Variant(all, "dyn-ali3p").Run(m);
    EXPECT_TRUE(r.ok()) << r.reason;
  }
  const GraphOrReason g = BuildGraph(LoadScenario(std::string(MECHBENCH_TEST_DATA) + "/scenes/point_mass_coupler.yaml"));
  ASSERT_TRUE(g.graph) << g.reason;
  bool noted = false;
  for (const std::string& n : g.graph->notes) noted = noted || n.find("link coupler (inertia 0 about its centre of mass in the file) gets a substitute inertia") != std::string::npos;
  EXPECT_TRUE(noted);
}

// ---- spring–dampers and torques in every engine variant -----------------------------------------

Model Fixture(const std::string& file) { return LoadScenario(std::string(MECHBENCH_TEST_DATA) + "/scenes/" + file); }

// The graph carries the elements in the engines' units: k and c as given, L0 in the file's unit,
// the preload and a torque divided by meters_per_unit (once, twice), so the mm scene is the m
// scene scaled; and the scene is applicable to the graph (the engines build the elements).
TEST(EngineForceElements, GraphCarriesThemInTheScenesUnits) {
  for (const char* file : {"pendulum_spring_damper.yaml", "pendulum_spring_damper_mm.yaml", "bar_torque.yaml"})
    EXPECT_FALSE(GraphApplicability(Fixture(file)).has_value()) << file;
  const GraphOrReason m = BuildGraph(Fixture("pendulum_spring_damper.yaml"));
  const GraphOrReason mm = BuildGraph(Fixture("pendulum_spring_damper_mm.yaml"));
  ASSERT_TRUE(m.graph && mm.graph) << m.reason << mm.reason;
  ASSERT_EQ(m.graph->springs.size(), 1u);
  ASSERT_EQ(mm.graph->springs.size(), 1u);
  const GraphSpring &a = m.graph->springs[0], &b = mm.graph->springs[0];
  EXPECT_EQ(a.body_a, -1);  // S is fixed: ground, at its place in the world
  EXPECT_EQ(a.at_a, Eigen::Vector2d(1, 1));
  EXPECT_EQ(b.at_a, Eigen::Vector2d(1000, 1000));
  EXPECT_EQ(a.body_b, b.body_b);
  EXPECT_EQ(b.stiffness, a.stiffness);
  EXPECT_EQ(b.damping, a.damping);
  EXPECT_DOUBLE_EQ(b.free_length, 1000 * a.free_length);
  EXPECT_DOUBLE_EQ(a.preload, 2);
  EXPECT_DOUBLE_EQ(b.preload, 2000);  // 2 N = 2000 kg·mm/s²
  // The same stretch in mm gives 1000 × the force in kg·mm/s², i.e. the same newtons.
  EXPECT_DOUBLE_EQ(b.Tension(1000 * 0.7, 1000 * 0.1), 1000 * a.Tension(0.7, 0.1));
  const GraphOrReason t = BuildGraph(Fixture("bar_torque.yaml"));
  ASSERT_TRUE(t.graph) << t.reason;
  ASSERT_EQ(t.graph->torques.size(), 1u);
  EXPECT_EQ(t.graph->torques[0].torque, 0.5);
  EXPECT_EQ(t.graph->bodies[t.graph->torques[0].body].name, "bar");
}

// The bar pinned at O and turned by T from rest: θ = T t² / (2 I_O) exactly, xA = L cos θ, yA = L sin θ.
std::vector<Sample> BarTorqueClosedForm(const Model& m, const std::vector<Sample>& at) {
  const Body& bar = m.bodies[0];
  const double I_O = bar.inertia_com + bar.mass * bar.com_B.squaredNorm(), T = m.torques[0].torque, L = bar.Length();
  const int x = m.SlotIndex("xA"), y = m.SlotIndex("yA"), th = m.SlotIndex("theta");
  std::vector<Sample> out;
  for (const Sample& s : at) {
    const double t = s.t, al = T / I_O, w = al * t, q = al * t * t / 2;
    Sample c{t, Eigen::VectorXd::Zero(3), Eigen::VectorXd::Zero(3), Eigen::VectorXd::Zero(3), 0.0};
    c.q[x] = L * std::cos(q), c.q[y] = L * std::sin(q), c.q[th] = q;
    c.qd[x] = -L * std::sin(q) * w, c.qd[y] = L * std::cos(q) * w, c.qd[th] = w;
    c.qdd[x] = -L * (std::cos(q) * w * w + std::sin(q) * al), c.qdd[y] = L * (-std::sin(q) * w * w + std::cos(q) * al);
    c.qdd[th] = al;
    out.push_back(c);
  }
  return out;
}

// Judges an engine's position error on a free scene with a force element against its bound in
// tolerances.yaml (free: per variant, grown with the motion's duration), or asserts that a known
// failure still fails.
void ExpectWithinFreeBound(const Model& m, const std::string& variant, double error) {
  const double bound = harness::LoadTolerances(m.name).FreePosition(variant, m.analysis.t1 - m.analysis.t0);
  if (Verbose()) std::printf("%-28s %-26s position %.3g (bound %.3g)\n", m.name.c_str(), variant.c_str(), error, bound);
  if (const std::string* known = KnownFailure(m.name, variant))
    EXPECT_GT(error, bound) << m.name << " " << variant << " is no longer a known failure (" << *known << ")";
  else
    EXPECT_LE(error, bound) << m.name << " " << variant;
}

// (a) A constant torque, each engine its own way (Simbody Force::ConstantTorque, MuJoCo
// xfrc_applied, ODE dBodyAddTorque, Bullet addLinkTorque / applyTorque), against the closed form.
TEST(EngineForceElements, BarTorqueFollowsTheClosedForm) {
  const std::vector<MethodPtr> engines = harness::EngineMethods();
  if (engines.empty()) GTEST_SKIP() << "built without engines";
  const Model m = Fixture("bar_torque.yaml");
  for (const MethodPtr& e : engines) {
    SCOPED_TRACE(e->name());
    ASSERT_FALSE(e->Applicability(m).has_value()) << *e->Applicability(m);
    const Result r = e->Run(m);
    ASSERT_TRUE(r.ok()) << r.reason;
    EXPECT_TRUE(r.settings.count("torques"));
    const MotionError err = CompareMotion(m, BarTorqueClosedForm(m, r.trajectory), r.trajectory);
    ASSERT_TRUE(err.problem.empty()) << err.problem;
    ExpectWithinFreeBound(m, e->name(), err.q.max);
  }
}

// (b) Spring–dampers (with a preload, a damper, a torque, in m and mm, and a stiff one) against
// the scene's reference trajectory (harness::GetReference), as `mechbench run` judges them.
TEST(EngineForceElements, SpringScenesFollowTheReference) {
  const std::vector<MethodPtr> engines = harness::EngineMethods();
  if (engines.empty()) GTEST_SKIP() << "built without engines";
  for (const char* file : {"pendulum_spring_damper.yaml", "pendulum_spring_damper_mm.yaml", "pendulum_spring_torque.yaml",
                           "pendulum_stiff_spring.yaml"}) {
    const Model m = Fixture(file);
    const harness::ReferenceRecord ref = harness::GetReference(m);
    ASSERT_TRUE(ref.confirmed) << ref.description;
    for (const MethodPtr& e : engines) {
      SCOPED_TRACE(std::string(file) + " " + e->name());
      const Result r = e->Run(m);
      ASSERT_TRUE(r.ok() || r.status == Status::kDiverged) << r.reason;
      EXPECT_TRUE(r.settings.count("spring_dampers"));
      double error = std::numeric_limits<double>::infinity();
      if (r.ok()) {
        const MotionError err = CompareMotion(m, ref.trajectory, r.trajectory);
        ASSERT_TRUE(err.problem.empty()) << err.problem;
        error = err.q.max;
        // The constraint residual as the harness judges it (a known failure may exceed it too).
        const double residual = Compare(m, r, r).residual;
        if (!KnownFailure(m.name, e->name())) {
          EXPECT_LE(residual, FreeResidualOf(m.name, e->name()));
        }
      }
      ExpectWithinFreeBound(m, e->name(), error);
    }
  }
}

// (c) Forces applied explicitly before each step of a first-order method: the error on the damped
// spring halves with the step (h = 2 ms → 1 ms; ratios in the README).
TEST(EngineForceElements, ExplicitSpringErrorIsFirstOrder) {
  const Model m = Fixture("pendulum_spring_damper.yaml");
  const harness::ReferenceRecord ref = harness::GetReference(m);
  ASSERT_TRUE(ref.confirmed) << ref.description;
  int checked = 0;
  for (const MethodPtr& e : harness::EngineMethods()) {
    const std::string& n = e->name();
    if (n.find("-default") == std::string::npos || n.rfind("simbody", 0) == 0) continue;  // first-order variants
    SCOPED_TRACE(n);
    const Result a = e->Run(m, {.step = 2e-3}), b = e->Run(m, {.step = 1e-3});
    ASSERT_TRUE(a.ok() && b.ok()) << a.reason << b.reason;
    const double e_h = CompareMotion(m, ref.trajectory, a.trajectory).q.max;
    const double e_half = CompareMotion(m, ref.trajectory, b.trajectory).q.max;
    if (Verbose()) std::printf("%s: e(2 ms) %.4g, e(1 ms) %.4g, ratio %.3f\n", n.c_str(), e_h, e_half, e_h / e_half);
    EXPECT_NEAR(std::log2(e_h / e_half), 1.0, 0.15) << "e(h) " << e_h << ", e(h/2) " << e_half;
    ++checked;
  }
  if (!harness::EngineMethods().empty()) {
    EXPECT_GT(checked, 0);
  }
}

}  // namespace
}  // namespace engines_common_test
}  // namespace mechbench::engines
