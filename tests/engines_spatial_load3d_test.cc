// Torsions and load laws on the engines' spatial graph (SpatialGraph::torsions, law_loads, and
// SpatialStateLoads in engines/common/src/spatial_graph.cc): the graph maps them, the evaluator's
// wrenches at t0 against the fixtures' closed forms, and every engine's run against the numeric
// method on the same fixtures. Figures in the comments: RelWithDebInfo, 2 cores shared with other
// builds, 2026-11-27.
#include "engines_spatial_support.h"
#include "mechbench/engines/spatial_graph.h"
#include "mechbench/harness/registry.h"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <map>
#include <numbers>

namespace mechbench::engines {
namespace engines_spatial_load3d_test {  // this file's own names (the tests build in unity batches)
namespace {

using namespace mechbench::engines::testing;
using V3 = Eigen::Vector3d;

// spatial_rotor_torsion's θ1(t) (its description): J θ̈ = −K θ − C θ̇ + K θ_eq, J = m |r_G ⊥ a|² + aᵀ I_G a,
// from θ1 = 0, θ̇1 = 0.5; the largest |θ1 − θ1(t)| and |θ2 − (π/2 − θ1(t))| of a run [rad].
double TorsionClosedFormError(const Model& m, const Result& r) {
  const double beta = std::numbers::pi / 6;
  const V3 a(std::cos(beta), 0, std::sin(beta)), rG(0.05, 0.3, -0.02);
  Eigen::Matrix3d I;
  I << 0.03, 0.002, -0.001, 0.002, 0.02, 0.003, -0.001, 0.003, 0.025;
  const V3 r_perp = rG - a * a.dot(rG);
  const double J = 1.5 * r_perp.squaredNorm() + a.dot(I * a);
  const double K = 3 + 1, C = 0.05 + 0.03;
  const double eq = (3 * 0.2 + 1 * (std::numbers::pi / 2 - 1.2) + 0.1 - (-0.05)) / K;
  const double wn = std::sqrt(K / J), zeta = C / (2 * std::sqrt(K * J)), wd = wn * std::sqrt(1 - zeta * zeta);
  const double x0 = 0 - eq, v0 = 0.5, s = zeta * wn;
  double worst = 0;
  const int i1 = m.SlotIndex("theta1"), i2 = m.SlotIndex("theta2");
  for (const Sample& smp : r.trajectory) {
    const double th = eq + std::exp(-s * smp.t) * (x0 * std::cos(wd * smp.t) + (v0 + s * x0) / wd * std::sin(wd * smp.t));
    worst = std::max({worst, std::fabs(smp.q[i1] - th), std::fabs(smp.q[i2] - (std::numbers::pi / 2 - th))});
  }
  return worst;
}

// The graph takes torsions and laws (no reason); each torsion's and law's wrench at the assembled
// t0 is the fixture's own closed form (tests/data/scenes/*.yaml, their descriptions), to rounding.
TEST(SpatialStateLoads, WrenchesAtT0AreTheClosedForms) {
  constexpr double kPi = std::numbers::pi;
  const double beta = kPi / 6;
  const V3 a(std::cos(beta), 0, std::sin(beta));
  {
    // Two torsions on the tilted rotor, θ1 = 0 (the rotor their `to`) and θ2 = π/2 (the rotor their
    // `from`), θ̇1 = 0.5 = −θ̇2: (T1 − T2) a on the rotor, nothing else.
    const SpatialGraph g = MustBuild(Scene("spatial_rotor_torsion"));
    ASSERT_EQ(g.torsions.size(), 2u);
    EXPECT_TRUE(g.law_loads.empty());
    SpatialStateLoads loads(g);
    std::vector<SpatialWrench> w;
    loads.Evaluate(0.0, Initial(g), w);
    ASSERT_EQ(w.size(), 1u);
    const double T1 = -3 * (0 - 0.2) - 0.05 * 0.5 + 0.1, T2 = -1 * (kPi / 2 - 1.2) - 0.03 * (-0.5) + (-0.05);
    EXPECT_LE((w[0].torque - (T1 - T2) * a).norm(), 1e-12) << w[0].torque.transpose();
    EXPECT_LE(w[0].force.norm(), 0.0);
  }
  {
    // A law of t, T1 t a, and a drag law of θ̇, −cz θ̇ z (the constant torque stays constant).
    const SpatialGraph g = MustBuild(Scene("spatial_rotor_torque"));
    EXPECT_EQ(g.torques.size(), 1u);
    ASSERT_EQ(g.law_loads.size(), 2u);
    SpatialStateLoads loads(g);
    std::vector<SpatialWrench> w;
    const double t = 0.7;
    loads.Evaluate(t, Initial(g), w);
    const V3 expected = 0.3 * t * a + V3(0, 0, -0.2 * 0.5);
    EXPECT_LE((w[0].torque - expected).norm(), 1e-12) << w[0].torque.transpose();
  }
  {
    // A point mass: [F1 t, 0, −2] and [0, 1.5 − kk y − cc ẏ, 0] at y = 0.2, ẏ = −0.5, through its
    // centre of mass (no torque).
    const SpatialGraph g = MustBuild(Scene("spatial_point_forces"));
    ASSERT_EQ(g.law_loads.size(), 2u);
    SpatialStateLoads loads(g);
    std::vector<SpatialWrench> w;
    const double t = 0.5;
    loads.Evaluate(t, Initial(g), w);
    EXPECT_LE((w[0].force - V3(3 * t, 1.5 - 12 * 0.2 - 0.8 * (-0.5), -2)).norm(), 1e-12) << w[0].force.transpose();
    EXPECT_LE(w[0].torque.norm(), 1e-15);
  }
}

// Every engine on the three fixtures against the numeric method's index-1 formulation with
// Baumgarte stabilisation and RK4 at 1 ms (dyn-baumgarte-rk4; on the two torsions its θ1 is the
// closed form's to 1.1e-11 rad, checked here too): the engines' defaults (first order but for
// Simbody's error-controlled RK-Merson) and the tuned Simbody and MuJoCo, whose agreement says the
// model is the same, not only close. Measured (CompareMotion's q, relative to the range, 2 s):
//   rotor torsion  Simbody tuned 8.0e-9, default 1.4e-5; MuJoCo RK4 0.1 ms 1.2e-9, Euler 2 ms 2.5e-3;
//                  ODE dWorldStep 1.2e-3; Bullet btMultiBody 1.2e-3, btRigidBody 1.2e-3;
//   rotor torque   Simbody tuned 4.5e-10; MuJoCo Euler 2.0e-3; ODE 8.8e-4; Bullet 1.0e-3, 8.8e-4;
//   point forces   Simbody tuned 2.4e-10; MuJoCo Euler 1.1e-3; ODE and both Bullets 5.5e-4.
// (The first-order engines' tuned variants, a tenth of the step: ten times smaller, `mechbench run`.)
// Bounds about 3× those; a torsion or law with the wrong sign or body is off by order one.
// 0.6 s CPU in all.
TEST(SpatialEngines, TorsionsAndLoadLawsFollowNumericDynamics) {
  struct Case {
    const char* scene;
    const char* variant;
    double q;  // bound on CompareMotion's q against dyn-baumgarte-rk4
  };
  const std::vector<Case> cases = {
      {"spatial_rotor_torsion", "simbody-rkmerson-tuned", 3e-8},
      {"spatial_rotor_torsion", "mujoco-rk4-tuned", 4e-9},
      {"spatial_rotor_torsion", "simbody-rkmerson-default", 5e-5},
      {"spatial_rotor_torsion", "mujoco-euler-default", 6e-3},
      {"spatial_rotor_torsion", "ode-worldstep-default", 4e-3},
      {"spatial_rotor_torsion", "bullet-multibody-default", 4e-3},
      {"spatial_rotor_torsion", "bullet-rigidbody-default", 4e-3},
      {"spatial_rotor_torque", "simbody-rkmerson-tuned", 2e-9},
      {"spatial_rotor_torque", "mujoco-euler-default", 6e-3},
      {"spatial_rotor_torque", "ode-worldstep-default", 3e-3},
      {"spatial_rotor_torque", "bullet-multibody-default", 3e-3},
      {"spatial_rotor_torque", "bullet-rigidbody-default", 3e-3},
      {"spatial_point_forces", "simbody-rkmerson-tuned", 1e-9},
      {"spatial_point_forces", "mujoco-euler-default", 3e-3},
      {"spatial_point_forces", "ode-worldstep-default", 2e-3},
      {"spatial_point_forces", "bullet-multibody-default", 2e-3},
      {"spatial_point_forces", "bullet-rigidbody-default", 2e-3},
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
    if (std::string(c.scene) == "spatial_rotor_torsion" && std::string(c.variant) == "simbody-rkmerson-tuned") {
      const double cf = TorsionClosedFormError(m, ref);
      if (Verbose()) std::cout << "numeric vs the torsions' closed form: " << cf << " rad\n";
      EXPECT_LE(cf, 1e-10);
    }
    const Result r = RunIfApplicable(Variant(all, c.variant), m);
    ASSERT_TRUE(r.ok()) << r.reason;
    const Errors e = Compare(m, ref, r);
    if (Verbose()) std::cout << c.scene << " " << c.variant << ": q " << e.q << " qd " << e.qd << " res " << e.residual << "\n";
    EXPECT_LE(e.q, c.q);
  }
}

}  // namespace
}  // namespace engines_spatial_load3d_test
}  // namespace mechbench::engines
