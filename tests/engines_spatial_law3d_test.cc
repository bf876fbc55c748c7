// Spring–dampers with laws and follower forces on the engines' spatial graph (SpatialGraph::law_loads
// and SpatialStateLoads in engines/common/src/spatial_graph.cc): the graph maps them, the evaluator's
// wrenches against the fixtures' closed forms, and every engine's run against the numeric method on
// the same fixtures. Figures in the comments: RelWithDebInfo, 2 cores shared with other builds,
// 2026-11-27.
#include "engines_spatial_support.h"
#include "mechbench/engines/spatial_graph.h"
#include "mechbench/harness/registry.h"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <map>
#include <numbers>

namespace mechbench::engines {
namespace engines_spatial_law3d_test {  // this file's own names (the tests build in unity batches)
namespace {

using namespace mechbench::engines::testing;
using V3 = Eigen::Vector3d;

// The graph takes both (no reason); their wrenches are the fixtures' closed forms, to rounding.
TEST(SpatialStateLoads, SpringLawsAndFollowerForcesAtTheirClosedForms) {
  {
    // The follower force F = (−0.5, 0.3, 0.2) N at the tip A = (1, 0, 0) of the bar (com (0.5, 0, 0)),
    // with the bar turned by 90° about z: R F at A, and (R (0.5, 0, 0)) × R F about the com.
    const SpatialGraph g = MustBuild(Scene("spatial_follower_force"));
    ASSERT_EQ(g.law_loads.size(), 1u);
    EXPECT_GE(g.law_loads[0].frame, 0);
    SpatialStateLoads loads(g);
    std::vector<SpatialState> st = Initial(g);
    ASSERT_EQ(st.size(), 1u);
    const Eigen::Matrix3d Rz = Eigen::AngleAxisd(std::numbers::pi / 2, V3::UnitZ()).toRotationMatrix();
    const V3 com = st[0].PointPos(g.bodies[0].com_B);
    st[0].R = Rz * st[0].R;
    st[0].p = Rz * st[0].p;
    std::vector<SpatialWrench> w;
    loads.Evaluate(0.0, st, w);
    const V3 F(-0.5, 0.3, 0.2), f = Rz * F;
    EXPECT_LE((w[0].force - f).norm(), 1e-15) << w[0].force.transpose();
    EXPECT_LE((w[0].torque - (Rz * (V3(1, 0, 0) - com)).cross(f)).norm(), 1e-15) << w[0].torque.transpose();
  }
  {
    // The spring from S = (1, 1, 0) to the tip A at t0: L = 1, L̇ = −1 (A moves at 1 m/s along +y),
    // k = 50, L0 = 0.5, c = 0.8, F0 = 2: F = 50·0.5 − 0.8 + 2 = 26.2 N, pulling A toward S (+y).
    const SpatialGraph g = MustBuild(Scene("spatial_spring_law_pendulum"));
    ASSERT_EQ(g.law_loads.size(), 1u);
    EXPECT_TRUE(g.springs.empty());
    ASSERT_TRUE(g.law_loads[0].spring.has_value());
    SpatialStateLoads loads(g);
    std::vector<SpatialWrench> w;
    const std::vector<SpatialState> st = Initial(g);
    loads.Evaluate(0.0, st, w);
    const V3 com = st[0].PointPos(g.bodies[0].com_B);
    EXPECT_LE((w[0].force - V3(0, 26.2, 0)).norm(), 1e-12) << w[0].force.transpose();
    EXPECT_LE((w[0].torque - (V3(1, 0, 0) - com).cross(V3(0, 26.2, 0))).norm(), 1e-12) << w[0].torque.transpose();
  }
}

// Every engine on the new fixtures against the numeric method's index-1 formulation with
// Baumgarte stabilisation and RK4 at 1 ms (dyn-baumgarte-rk4), as engines_spatial_load3d_test.cc.
// Measured (CompareMotion's q, relative to the range, 2 s), the planar originals' figures:
//   spring law pendulum  Simbody tuned 8.4e-10 (RK4's own error), default 1.1e-6; MuJoCo RK4 0.1 ms
//                        9.1e-10, Euler 2 ms 1.3e-2; ODE dWorldStep 6.1e-3; Bullet btMultiBody
//                        6.5e-3, btRigidBody 6.1e-3 (first order on a stiff spring: the planar
//                        scene's bounds in harness/tolerances.yaml);
//   follower force       Simbody 4.3e-12 (both), MuJoCo RK4 4.3e-12, Euler 1.4e-3; ODE 7.1e-4;
//                        Bullet 7.1e-4, 7.1e-4;
//   follower motor curve Simbody tuned 7.3e-10, default 1.1e-8; MuJoCo RK4 4.6e-12, Euler 1.5e-3;
//                        ODE 7.4e-4; Bullet 7.4e-4, 7.4e-4.
// Bounds about 3× those; a law or a frame with the wrong sign or body is off by order one (the
// follower force counted twice, once as a constant world force, was off by 0.89 of the range).
TEST(SpatialEngines, SpringLawsAndFollowerForcesFollowNumericDynamics) {
  struct Case {
    const char* scene;
    const char* variant;
    double q;  // bound on CompareMotion's q against dyn-baumgarte-rk4
  };
  const std::vector<Case> cases = {
      {"spatial_spring_law_pendulum", "simbody-rkmerson-tuned", 3e-9},
      {"spatial_spring_law_pendulum", "simbody-rkmerson-default", 3e-6},
      {"spatial_spring_law_pendulum", "mujoco-rk4-tuned", 3e-9},
      {"spatial_spring_law_pendulum", "mujoco-euler-default", 4e-2},
      {"spatial_spring_law_pendulum", "ode-worldstep-default", 1.8e-2},
      {"spatial_spring_law_pendulum", "bullet-multibody-default", 2e-2},
      {"spatial_spring_law_pendulum", "bullet-rigidbody-default", 1.8e-2},
      {"spatial_follower_force", "simbody-rkmerson-tuned", 1.5e-11},
      {"spatial_follower_force", "simbody-rkmerson-default", 1.5e-11},
      {"spatial_follower_force", "mujoco-rk4-tuned", 1.5e-11},
      {"spatial_follower_force", "mujoco-euler-default", 4e-3},
      {"spatial_follower_force", "ode-worldstep-default", 2e-3},
      {"spatial_follower_force", "bullet-multibody-default", 2e-3},
      {"spatial_follower_force", "bullet-rigidbody-default", 2e-3},
      {"spatial_follower_motor_curve", "simbody-rkmerson-tuned", 2.5e-9},
      {"spatial_follower_motor_curve", "simbody-rkmerson-default", 3.5e-8},
      {"spatial_follower_motor_curve", "mujoco-rk4-tuned", 1.5e-11},
      {"spatial_follower_motor_curve", "mujoco-euler-default", 4.5e-3},
      {"spatial_follower_motor_curve", "ode-worldstep-default", 2.2e-3},
      {"spatial_follower_motor_curve", "bullet-multibody-default", 2.2e-3},
      {"spatial_follower_motor_curve", "bullet-rigidbody-default", 2.2e-3},
  };
  const std::vector<MethodPtr> all = harness::AllMethods();
  if (harness::EngineMethods().empty()) GTEST_SKIP() << "no engine built";
  std::map<std::string, Result> refs;
  for (const Case& c : cases) {
    SCOPED_TRACE(std::string(c.scene) + " " + c.variant);
    const std::vector<std::string> names = Names(all);
    if (std::find(names.begin(), names.end(), c.variant) == names.end()) continue;  // engine not built
    const Model m = Scene(c.scene);
    if (!refs.count(c.scene)) refs[c.scene] = Variant(all, "dyn-baumgarte-rk4").Run(m);
    const Result& ref = refs[c.scene];
    ASSERT_TRUE(ref.ok()) << ref.reason;
    const Result r = RunIfApplicable(Variant(all, c.variant), m);
    ASSERT_TRUE(r.ok()) << r.reason;
    const Errors e = Compare(m, ref, r);
    if (Verbose()) std::cout << c.scene << " " << c.variant << ": q " << e.q << " qd " << e.qd << " res " << e.residual << "\n";
    EXPECT_LE(e.q, c.q);
  }
}

}  // namespace
}  // namespace engines_spatial_law3d_test
}  // namespace mechbench::engines
