// Prismatic pairs between moving bodies in the engines' spatial graph (issue 13, spatial_graph.cc):
// an `along` coordinate on a line of a moving body is a prismatic tree joint from that body, to the
// point's body when it shares the line body's orientation (a collar on a rod, IFToMM A05's slider on
// its shaft) or is a point mass (a bead on a crank), else to an added slider body (a ball or, for a cylindrical pair, a revolute at the
// point). The engines against the numeric method and the angular momentum about the hinge on a
// collar sliding on a freely turning rod. Figures: RelWithDebInfo, 2 cores shared with other
// builds, 2026-11-27 (MECHBENCH_VERBOSE=1 prints them).
#include "engines_spatial_support.h"
#include "mechbench/engines/spatial_graph.h"
#include "mechbench/harness/registry.h"

#include <cmath>
#include <iostream>

namespace mechbench::engines {
namespace engines_spatial_pair3d_test {  // this file's own names (the tests build in unity batches)
namespace {

using namespace mechbench::engines::testing;
using V3 = Eigen::Vector3d;

// The bodies' t0 states observed back: q (s among them) and q̇ as assembled; the prismatic joint's
// rate at t0 is ṡ(t0) (the line's direction is the joint's axis, and both turn together).
void ExpectObservesT0(const Model& m, const SpatialGraph& g) {
  std::vector<SpatialState> st;
  for (const SpatialGraphBody& b : g.bodies) st.push_back(b.initial);
  SpatialObserver obs(m, g);
  const Sample s = obs.Observe(g.t0, st, false);
  ASSERT_EQ(s.q.size(), g.initial.q.size());
  EXPECT_LE((s.q - g.initial.q).lpNorm<Eigen::Infinity>(), 1e-12);
  EXPECT_LE((s.qd - g.initial.qd).lpNorm<Eigen::Infinity>(), 1e-10 * std::max(1.0, g.initial.qd.lpNorm<Eigen::Infinity>()));
  const SpatialGraphJoint* p = Prismatic(g);
  ASSERT_NE(p, nullptr);
  EXPECT_NEAR(PrismaticRateAtT0(g, *p), g.initial.qd[m.SlotIndex("s")], 1e-10);
  EXPECT_NEAR(PrismaticTravel(*p, p->parent < 0 ? SpatialState{} : st[p->parent], st[p->child]), 0, 1e-14);
}

// The collar shares the rod's v and z: a prismatic tree joint rod → collar along w (no added body,
// no closure; the shared vectors make no other joint, nor the collar's fixed z one to ground).
TEST(SpatialGraphPair3d, ACollarSharingTheRodsOrientationIsAPrismaticTreeJoint) {
  const Model m = Scene("spatial_collar_on_turning_rod");
  const SpatialGraph g = MustBuild(m);
  ASSERT_EQ(g.bodies.size(), 2u);
  ASSERT_EQ(g.joints.size(), 2u);
  EXPECT_EQ(g.Closures(), 0);
  const SpatialGraphJoint* p = Prismatic(g);
  ASSERT_NE(p, nullptr);
  EXPECT_TRUE(p->in_tree);
  EXPECT_EQ(g.bodies[p->parent].name, "rod");
  EXPECT_EQ(g.bodies[p->child].name, "collar");
  EXPECT_LE((p->axis_B - V3(1, 0, 0)).norm(), 1e-12);
  EXPECT_EQ(g.joints[0].type, SpatialJointType::kRevolute);
  ExpectObservesT0(m, g);
}

// A point mass on a turning crank's line: its own prismatic joint from the crank (no added body),
// turning with it; its body's inertia is taken out of the crank's, so the pair's is the file's.
TEST(SpatialGraphPair3d, APointMassOnAMovingLineSlidesOnItsOwnJoint) {
  const Model m = Scene("spatial_slider_on_crank");
  const SpatialGraph g = MustBuild(m);
  ASSERT_EQ(g.bodies.size(), 2u);
  const SpatialGraphJoint* p = Prismatic(g);
  ASSERT_NE(p, nullptr);
  EXPECT_TRUE(p->in_tree);
  EXPECT_EQ(g.bodies[p->parent].name, "crank");
  EXPECT_EQ(g.bodies[p->child].name, "block");
  EXPECT_EQ(g.Closures(), 0);
  const SpatialGraphBody &crank = g.bodies[p->parent], &block = g.bodies[p->child];
  EXPECT_LE((block.initial.omega - crank.initial.omega).norm(), 1e-15);
  EXPECT_GT(block.inertia_B(0, 0), 0);  // the engines take no zero inertia
  const Eigen::Matrix3d file = Eigen::Vector3d(0.01, 0.1, 0.1).asDiagonal();  // the crank's, spatial_slider_on_crank.yaml
  EXPECT_LE((crank.inertia_B + block.inertia_B - file).norm(), 1e-15);
  ExpectObservesT0(m, g);
}

// A sleeve sharing only the rod's direction w (a cylindrical pair): an added slider on a prismatic
// joint from the rod, a revolute about w at C to the sleeve; its revolute and the slider's
// prismatic are tree joints, the sleeve's w equal to the rod's through them (no other joint).
TEST(SpatialGraphPair3d, ASleeveSharingTheDirectionOnlyTurnsOnAnAddedSlider) {
  const Model m = Scene("spatial_sleeve_on_turning_rod");
  const SpatialGraph g = MustBuild(m);
  ASSERT_EQ(g.bodies.size(), 3u);
  EXPECT_EQ(g.bodies[2].name, "slider of s");
  const SpatialGraphJoint* p = Prismatic(g);
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(g.bodies[p->parent].name, "rod");
  EXPECT_EQ(p->child, 2);
  EXPECT_EQ(g.Closures(), 0);
  const int hinge = g.TreeJointOf(1);  // the sleeve's
  ASSERT_GE(hinge, 0);
  EXPECT_EQ(g.joints[hinge].type, SpatialJointType::kRevolute);
  EXPECT_EQ(g.joints[hinge].parent, 2);
  EXPECT_LE((g.joints[hinge].axis_B - V3(1, 0, 0)).norm(), 1e-12);
  ExpectObservesT0(m, g);
}

// A collar sharing one vector across the line (it may turn about it): a reason naming the
// coordinate and the pair, never a model.
TEST(SpatialGraphPair3d, ACollarSharingOneVectorAcrossTheLineIsAReason) {
  const SpatialGraphOrReason g = BuildSpatialGraph(Scene("spatial_collar_hinged_on_rod"));
  EXPECT_FALSE(g.graph.has_value());
  EXPECT_NE(g.reason.find("coordinate s ("), std::string::npos) << g.reason;
  EXPECT_NE(g.reason.find("share a vector across the line"), std::string::npos) << g.reason;
}

// The collar on the freely turning rod against numeric's confirmed reference over 0.5 s (s from
// 0.3 to 0.704 m, θ̇ from 3 rad/s down as the collar flies out), each engine's default variant and
// MuJoCo's RK4: q's CompareMotion relative error, s's largest difference [m] and the largest drift
// of the angular momentum about z [kg·m²/s] from its t0 value 1.185 (numeric's own: 4.2e-13).
// Measured (q / s / L): simbody-rkmerson-default 4.3e-7 / 2.4e-7 / 5.0e-7; ode-worldstep-default
// 4.5e-5 / 4.0e-5 / 1.1e-3; mujoco-euler-default 2.5e-3 / 2.4e-3 / 3.6e-3; mujoco-rk4-tuned
// 8.2e-14 / 8.0e-14 / 6.0e-15; bullet-multibody-default 1.3e-3 / 1.2e-3 / 1.8e-3;
// bullet-rigidbody-default 6.0e-5 / 5.1e-5 / 1.2e-3. Bounds about 3× those (MuJoCo RK4's at
// 1e-12, rounding). 0.25 s of CPU in all.
TEST(SpatialEnginesPair3d, ACollarOnAFreelyTurningRodFollowsNumeric) {
  struct Case {
    const char* method;
    double q, s, momentum;
  };
  const std::vector<Case> cases = {
      {"simbody-rkmerson-default", 1.5e-6, 8e-7, 1.5e-6}, {"ode-worldstep-default", 1.5e-4, 1.2e-4, 3.5e-3},
      {"mujoco-euler-default", 7.5e-3, 7.5e-3, 1.1e-2},     {"mujoco-rk4-tuned", 1e-12, 1e-12, 1e-12},
      {"bullet-multibody-default", 4e-3, 4e-3, 6e-3},       {"bullet-rigidbody-default", 2e-4, 1.5e-4, 3.5e-3},
  };
  const Model m = Scene("spatial_collar_on_turning_rod");
  const harness::ReferenceRecord ref = harness::GetReference(m);  // numeric's confirmed reference, cached
  ASSERT_TRUE(ref.confirmed) << ref.description;
  // L_z = (I_A + I_c + m_c |G_c,⊥|²) θ̇: the rod's inertia about the hinge, the collar's about its
  // centre (0.1 m long: G_c = C + 0.05 w), both about z.
  const double I_A = 0.0834 + 1 * 0.5 * 0.5, I_c = 0.0005, m_c = 0.5;
  auto momentum = [&](const Sample& x) {
    const double r = x.q[m.SlotIndex("s")] + 0.05;
    return (I_A + I_c + m_c * r * r) * x.qd[m.SlotIndex("theta")];
  };
  const double L0 = momentum(ref.trajectory.front());
  int ran = 0;
  for (const Case& c : cases) {
    const Method* e = Find(c.method);
    if (!e) continue;
    SCOPED_TRACE(c.method);
    const Result r = RunIfApplicable(*e, m);
    ASSERT_TRUE(r.ok()) << r.reason;
    ASSERT_EQ(r.trajectory.size(), ref.trajectory.size());
    const MotionError err = CompareMotion(m, ref.trajectory, r.trajectory);
    ASSERT_TRUE(err.problem.empty()) << err.problem;
    double s = 0, dl = 0, dl_ref = 0;
    for (size_t k = 0; k < r.trajectory.size(); ++k) {
      s = std::max(s, std::fabs(r.trajectory[k].q[m.SlotIndex("s")] - ref.trajectory[k].q[m.SlotIndex("s")]));
      dl = std::max(dl, std::fabs(momentum(r.trajectory[k]) - L0));
      dl_ref = std::max(dl_ref, std::fabs(momentum(ref.trajectory[k]) - L0));
    }
    if (Verbose())
      std::cout << "collar " << c.method << ": q " << err.q.max << " s " << s << " L " << dl << " (numeric " << dl_ref
                << ") s(t1) " << ref.trajectory.back().q[m.SlotIndex("s")] << "\n";
    EXPECT_LE(err.q.max, c.q);
    EXPECT_LE(s, c.s);
    EXPECT_LE(dl, c.momentum);
    ++ran;
  }
  if (ran == 0) GTEST_SKIP() << "no engine with a spatial path is built";
}

// The point mass on the turning crank (spatial_slider_on_crank: free, θ̇(0) = 1 rad/s, the block
// flying out from s = 0.5 m) against numeric's confirmed reference over 0.5 s: q's CompareMotion
// relative error and the drift of the angular momentum about z, L = (I_A + m s²) θ̇ with I_A =
// 0.1 + 1 × 0.5² the crank's about the hinge (numeric's own: MECHBENCH_VERBOSE=1). It slid on a
// 1.5e-8 kg added body before, on which QuickStep and btRigidBody came apart (3.0e-2 of the range)
// and MuJoCo's RK4 stopped at 1e-8. Measured (q / L, L(0) = 0.475 kg·m²/s; numeric's 5.8e-14):
// simbody-rkmerson-default 7.1e-8 / 2.0e-8; ode-worldstep-default 3.4e-6 / 6.5e-5;
// ode-quickstep-default 2.6e-5 / 3.9e-4; bullet-multibody-default 2.9e-4 / 1.3e-4;
// bullet-rigidbody-default 1.6e-4 / 1.1e-2 (its velocities); mujoco-euler-default 5.8e-4 / 2.5e-4;
// mujoco-rk4-tuned 2.4e-14 / 7.2e-16 (the transferred inertia is exact).
// Bounds about 3× those (MuJoCo RK4's at 1e-12, rounding).
TEST(SpatialEnginesPair3d, APointMassOnATurningCrankFollowsNumeric) {
  struct Case {
    const char* method;
    double q, momentum;
  };
  const std::vector<Case> cases = {
      {"simbody-rkmerson-default", 2.5e-7, 6e-8}, {"ode-worldstep-default", 1e-5, 2e-4},
      {"ode-quickstep-default", 8e-5, 1.2e-3},     {"bullet-multibody-default", 1e-3, 4e-4},
      {"bullet-rigidbody-default", 5e-4, 3.5e-2},  {"mujoco-euler-default", 2e-3, 8e-4},
      {"mujoco-rk4-tuned", 1e-12, 1e-12},
  };
  const Model m = Scene("spatial_slider_on_crank");
  const harness::ReferenceRecord ref = harness::GetReference(m);
  ASSERT_TRUE(ref.confirmed) << ref.description;
  const double I_A = 0.1 + 1 * 0.5 * 0.5, m_b = 0.5;
  auto momentum = [&](const Sample& x) {
    const double s = x.q[m.SlotIndex("s")];
    return (I_A + m_b * s * s) * x.qd[m.SlotIndex("theta")];
  };
  const double L0 = momentum(ref.trajectory.front());
  int ran = 0;
  for (const Case& c : cases) {
    const Method* e = Find(c.method);
    if (!e) continue;
    SCOPED_TRACE(c.method);
    const Result r = RunIfApplicable(*e, m);
    ASSERT_TRUE(r.ok()) << r.reason;
    ASSERT_EQ(r.trajectory.size(), ref.trajectory.size());
    const MotionError err = CompareMotion(m, ref.trajectory, r.trajectory);
    ASSERT_TRUE(err.problem.empty()) << err.problem;
    double dl = 0, dl_ref = 0;
    for (size_t k = 0; k < r.trajectory.size(); ++k) {
      dl = std::max(dl, std::fabs(momentum(r.trajectory[k]) - L0));
      dl_ref = std::max(dl_ref, std::fabs(momentum(ref.trajectory[k]) - L0));
    }
    if (Verbose())
      std::cout << "point mass " << c.method << ": q " << err.q.max << " L " << dl << " (numeric " << dl_ref << ")\n";
    EXPECT_LE(err.q.max, c.q);
    EXPECT_LE(dl, c.momentum);
    ++ran;
  }
  if (ran == 0) GTEST_SKIP() << "no engine with a spatial path is built";
}

// The sleeve (a cylindrical pair on the turning rod, its centre of mass off the line: it swings
// about the rod under gravity) in the two tuned variants with error control or RK4, against
// numeric's reference over 0.5 s: q's CompareMotion relative error. The added slider's mass (1e-8 ×
// the scene's) sets the floor. Measured: mujoco-rk4-tuned 5.8e-9, simbody-rkmerson-tuned 5.9e-9.
// Bound 2e-8. (dWorldStep 2.3e-3 / 2.7e-4 and btMultiBody 2.4e-3 / 2.4e-4 at 1 / 0.1 ms are within
// their free bounds; the iterative solvers, QuickStep and btRigidBody, come apart on the light
// slider body as on spatial_bar_on_rail: `mechbench run` shows them.)
TEST(SpatialEnginesPair3d, ASleeveOnATurningRodFollowsNumeric) {
  const Model m = Scene("spatial_sleeve_on_turning_rod");
  const harness::ReferenceRecord ref = harness::GetReference(m);
  ASSERT_TRUE(ref.confirmed) << ref.description;
  int ran = 0;
  for (const char* name : {"mujoco-rk4-tuned", "simbody-rkmerson-tuned"}) {
    const Method* e = Find(name);
    if (!e) continue;
    SCOPED_TRACE(name);
    const Result r = RunIfApplicable(*e, m);
    ASSERT_TRUE(r.ok()) << r.reason;
    const MotionError err = CompareMotion(m, ref.trajectory, r.trajectory);
    ASSERT_TRUE(err.problem.empty()) << err.problem;
    if (Verbose()) std::cout << "sleeve " << name << ": q " << err.q.max << "\n";
    EXPECT_LE(err.q.max, 2e-8);
    ++ran;
  }
  if (ran == 0) GTEST_SKIP() << "no engine with a spatial path is built";
}

// Driven at θ and at s (spatial_collar_driven): the driver on s is the prismatic joint's own
// coordinate from the rod (scale 1), and every engine's default variant prescribes it against the
// numeric method's kinematics: q's CompareMotion relative error. Measured: simbody-rkmerson-default
// 1.1e-16, mujoco-euler-default 3.3e-16, bullet-multibody-default 3.0e-16 (their joints set to the
// law), ode-worldstep-default 1.1e-5, bullet-rigidbody-default 1.1e-5 (motors aimed at the law each
// 1 ms step, the bodies' maximal coordinates drift). Bounds: 1e-14 for the exact ones (rounding),
// about 3× the others.
TEST(SpatialEnginesPair3d, DriversOnAnglesAndOnAMovingLinesSAreFollowed) {
  const Model m = Scene("spatial_collar_driven");
  const SpatialGraph g = MustBuild(m);
  ASSERT_EQ(g.drivers.size(), 2u);
  for (const SpatialDriverMap& d : g.drivers) {
    EXPECT_EQ(d.scale, 1);
    if (d.coordinate == "s") {
      EXPECT_EQ(g.joints[d.joint].type, SpatialJointType::kPrismatic);
      EXPECT_EQ(g.bodies[g.joints[d.joint].parent].name, "rod");
    }
  }
  struct Case {
    const char* method;
    double q;
  };
  const std::vector<Case> cases = {{"simbody-rkmerson-default", 1e-14}, {"mujoco-euler-default", 1e-14},
                                   {"bullet-multibody-default", 1e-14}, {"ode-worldstep-default", 3.5e-5},
                                   {"bullet-rigidbody-default", 3.5e-5}};
  const Result ref = Find("numeric")->Run(m);
  ASSERT_TRUE(ref.ok()) << ref.reason;
  int ran = 0;
  for (const Case& c : cases) {
    const Method* e = Find(c.method);
    if (!e) continue;
    SCOPED_TRACE(c.method);
    const Result r = RunIfApplicable(*e, m);
    ASSERT_TRUE(r.ok()) << r.reason;
    ASSERT_EQ(r.trajectory.size(), ref.trajectory.size());
    const Errors err = Compare(m, ref, r);
    if (Verbose()) std::cout << "driven collar " << c.method << ": q " << err.q << " res " << err.residual << "\n";
    EXPECT_LE(err.q, c.q);
    ++ran;
  }
  if (ran == 0) GTEST_SKIP() << "no engine with a spatial path is built";
}

// A stiff spring–damper (A05's K and C on the 0.5 kg collar: c/m = 8e4 1/s) at ODE's 1 ms step:
// the explicit force blows the state up within a few steps. ODE's run stops as diverged with its
// reason. Without the guard (BlownUp in ode_spatial.cc) the process aborted in ODE's quaternion
// normalization, on A05 and on this fixture alike (checked by switching it off); here the run is in
// this process, so an abort would end the test binary.
TEST(SpatialEnginesPair3d, AStiffSpringPastOdesStabilityLimitIsADivergedRow) {
  const Model m = Scene("spatial_collar_stiff_spring");
  int ran = 0;
  for (const char* name : {"ode-worldstep-default", "ode-quickstep-default"}) {
    const Method* e = Find(name);
    if (!e) continue;
    SCOPED_TRACE(name);
    const Result r = RunIfApplicable(*e, m);
    EXPECT_EQ(r.status, Status::kDiverged) << r.reason;
    EXPECT_NE(r.reason.find("the state blew up by t = "), std::string::npos) << r.reason;
    ++ran;
  }
  if (ran == 0) GTEST_SKIP() << "ODE is not built";
}

}  // namespace
}  // namespace engines_spatial_pair3d_test
}  // namespace mechbench::engines
