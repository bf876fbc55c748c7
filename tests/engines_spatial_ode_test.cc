// ODE on spatial scenes (engines/ode/src/ode_spatial.cc): free motions against the scenes' closed
// forms or the test's own integration of the same equation, the driven RSSR and Bricard's
// redundant loop against the numeric method. ODE is first order (semi-implicit Euler): every
// bound below is from a measured figure at the stated step, and the step halving says the order.
// Figures: RelWithDebInfo, 2 cores shared with other builds, 2026-11-27.
#include "engines_support.h"
#include "mechbench/engines/spatial_graph.h"
#include "mechbench/harness/registry.h"

#include <cmath>
#include <iostream>
#include <numbers>

#ifdef MECHBENCH_WITH_ODE
#include "mechbench/engines/ode.h"
#endif

namespace mechbench::engines {
namespace engines_spatial_ode_test {  // this file's own names (the tests build in unity batches)
namespace {

using namespace mechbench::engines::testing;
using V3 = Eigen::Vector3d;

#ifdef MECHBENCH_WITH_ODE
Model Scene(const std::string& name) { return LoadScenario(std::string(MECHBENCH_TEST_DATA) + "/scenes/" + name + ".yaml"); }
std::string BricardFile() { return std::string(MECHBENCH_TEST_DATA) + "/../../scenarios/benchmarks/a04_bricard.yaml"; }

OdeOptions Ode(bool quick, double step, int iterations = -1) {
  OdeOptions o;
  o.name = quick ? "ode-quickstep-test" : "ode-worldstep-test";
  o.quick = quick;
  o.step = step;
  o.iterations = iterations;
  return o;
}
Result RunOde(const Model& m, const OdeOptions& o) {
  const Result r = RunIfApplicable(*MakeOdeMethod(o), m);
  EXPECT_TRUE(r.ok()) << r.reason;
  EXPECT_EQ(static_cast<int>(r.trajectory.size()), m.analysis.samples);
  return r;
}
V3 PointAt(const Model& m, const Sample& s, const std::string& p) {
  return {s.q[m.SlotIndex("x" + p)], s.q[m.SlotIndex("y" + p)], s.q[m.SlotIndex("z" + p)]};
}

// Every ODE variant takes the spatial fixtures (free, driven, with closures) and says how it built
// them: a revolute closure is one dHinge.
TEST(OdeSpatial, EveryVariantRunsSpatialScenes) {
  const std::vector<Model> scenes = {Scene("spherical_pendulum"), Scene("spatial_spring_chain"),
                                     Scene("rssr_fourbar_angles"), LoadScenario(BricardFile())};
  int variants = 0;
  for (const MethodPtr& e : harness::EngineMethods()) {
    if (e->name().rfind("ode-", 0) != 0) continue;
    ++variants;
    for (const Model& m : scenes) {
      const auto why = e->Applicability(m);
      EXPECT_FALSE(why.has_value()) << e->name() << " on " << m.name << ": " << *why;
    }
  }
  EXPECT_EQ(variants, 4);
  Model bricard = LoadScenario(BricardFile());
  bricard.analysis.t1 = 0.01;
  bricard.analysis.samples = 2;
  const Result r = RunOde(bricard, Ode(false, 1e-3));
  EXPECT_NE(r.settings.at("joints").find("0 × dBall, 6 × dHinge"), std::string::npos) << r.settings.at("joints");
  EXPECT_NE(r.settings.at("loop_closures").find("1 revolute closure(s) as one dHinge"), std::string::npos);
}

// A bar on a spherical joint released in a vertical plane swings as the physical pendulum
// θ̈ = −(3g/2L) sin θ, which the test integrates itself (RK4, 20 µs), over 1 s of the file's 2.
// Measured (dWorldStep): θ within 5.6e-4 rad at 0.2 ms, 2.8e-4 at 0.1 ms (ratio 2.0: first
// order); out of the plane 0 (its ω keeps one direction). Bounds 6e-4 rad at 0.1 ms, 1e-12 m, the
// ratio between 1.7 and 2.3.
TEST(OdeSpatial, BarSwingsAsThePhysicalPendulum) {
  Model m = Scene("spatial_bar_swing");
  m.analysis.t1 = 1.0;
  m.analysis.samples = 51;
  const double L = 0.6, k = 3 * 9.81 / (2 * L);
  std::map<double, double> err;
  for (const double step : {2e-4, 1e-4}) {
    const Result r = RunOde(m, Ode(false, step));
    double th = 1.2, w = 0, worst = 0, off_plane = 0;
    const double h = 2e-5;
    long steps = 0;
    for (const Sample& s : r.trajectory) {
      for (const long n = std::lround((s.t - m.analysis.t0) / h); steps < n; ++steps) {
        const auto f = [&](double a) { return -k * std::sin(a); };
        const double k1 = w, l1 = f(th), k2 = w + h / 2 * l1, l2 = f(th + h / 2 * k1), k3 = w + h / 2 * l2,
                     l3 = f(th + h / 2 * k2), k4 = w + h * l3, l4 = f(th + h * k3);
        th += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
        w += h / 6 * (l1 + 2 * l2 + 2 * l3 + l4);
      }
      const V3 p = PointAt(m, s, "P");
      worst = std::max(worst, std::fabs(std::atan2(p.x(), -p.z()) - th));
      off_plane = std::max(off_plane, std::fabs(p.y()));
    }
    if (Verbose()) std::cout << "ode bar swing h " << step << ": theta " << worst << " off plane " << off_plane << "\n";
    err[step] = worst;
    EXPECT_LE(off_plane, 1e-12);
  }
  EXPECT_LE(err[1e-4], 6e-4);
  const double ratio = err[2e-4] / err[1e-4];
  EXPECT_GT(ratio, 1.7) << "dWorldStep on a ball joint: first order";
  EXPECT_LT(ratio, 2.3) << "dWorldStep on a ball joint: no longer first order?";
}

// A bob on a zero-length spring under gravity (a free body, the spring's force added before each
// step) moves on its closed-form ellipse r(t) = c + (r0 − c) cos ωt + v0/ω sin ωt, ω² = k/m,
// c = A + m g / k. Measured over 3 s: dWorldStep at 0.1 ms 1.45e-4 m (first
// order: the explicit spring and Euler). Bound 3e-4 m.
TEST(OdeSpatial, SpringBobFollowsItsEllipse) {
  const Model m = Scene("spatial_spring_oscillator");
  const Result r = RunOde(m, Ode(false, 1e-4));
  const double mb = 0.8, k = 20, om = std::sqrt(k / mb);
  const V3 A(0.1, -0.2, 0.3), g(0, 0, -9.81), r0(0.5, 0.1, 0.2), v0(0.1, 0.6, -0.3);
  const V3 c = A + mb * g / k;
  double worst = 0;
  for (const Sample& s : r.trajectory) {
    const double t = s.t - m.analysis.t0;
    const V3 exact = c + (r0 - c) * std::cos(om * t) + v0 / om * std::sin(om * t);
    worst = std::max(worst, (PointAt(m, s, "P") - exact).norm());
  }
  if (Verbose()) std::cout << "ode spring bob: " << worst << " m\n";
  EXPECT_LE(worst, 3e-4);
}

// Constant loads (spatial_rotor_constant_loads): a world torque, a world force at a body point
// and gravity on the tilted-hinge rotor (its centre of mass off the axis, a full inertia tensor),
// against numeric's dynamics (dyn-baumgarte-rk4, 1 ms) over the file's 2 s. Measured: the hinge
// angle θ within 6.9e-4 / 3.5e-4 rad at 0.2 / 0.1 ms (first order); the run's position error vs
// the reference 1.6e-3 / 1.8e-4 of the range at 1 / 0.1 ms. Bounds 2.5× the 0.1 ms figure, the
// ratio between 1.7 and 2.3 (9e-4 rad).
TEST(OdeSpatial, ConstantLoadsOnTheTiltedRotor) {
  const Model m = Scene("spatial_rotor_constant_loads");
  const std::vector<MethodPtr> all = harness::AllMethods();
  const Result ref = Variant(all, "dyn-baumgarte-rk4").Run(m);
  ASSERT_TRUE(ref.ok()) << ref.reason;
  const int theta = m.SlotIndex("theta");
  std::map<double, double> err;
  for (const double step : {2e-4, 1e-4}) {
    const Result r = RunOde(m, Ode(false, step));
    double worst = 0;
    for (size_t k = 0; k < r.trajectory.size(); ++k)
      worst = std::max(worst, std::fabs(r.trajectory[k].q[theta] - ref.trajectory[k].q[theta]));
    if (Verbose()) std::cout << "ode rotor constant loads h " << step << ": theta " << worst << "\n";
    err[step] = worst;
  }
  EXPECT_LE(err[1e-4], 9e-4);
  EXPECT_GT(err[2e-4] / err[1e-4], 1.7);
  EXPECT_LT(err[2e-4] / err[1e-4], 2.3);
}

// FINDING (tolerances.yaml known_failures): the rigid conical pendulum (spherical_pendulum: its
// own inertia, ω about the vertical, not on a principal axis) holds its height and rate only to
// first order in ODE — the gyroscopic term ω × I ω is integrated by ODE's implicit first-order
// update (gyroscopic mode on, its default; off, the motion is wrong whatever the step: 0.15 of the
// range at 1 and 0.1 ms). Measured over one revolution at 0.2 / 0.1 ms: P's height 8.4e-5 /
// 4.2e-5 m and azimuth 3.3e-4 / 1.7e-4 rad (P's path is nearly right), the body's spin about the
// rod (|u − u_exact| of the vector u against the rigid turn) 1.7e-2 / 8.7e-3: that is what `run`
// flags (q.yu). Bounds about 2.5× the height and azimuth, 2e-2 for the spin, which must stay
// above 1e-3 (a fix is noticed).
TEST(OdeSpatial, RigidConicalPendulumIsFirstOrder) {
  const Model m = Scene("spherical_pendulum");
  const double alpha = 0.6, L = 1.0, g = 9.81;
  const double Omega = std::sqrt(2 * g * 0.6 / ((0.1 + 2 * 0.36 - 0.02) * std::cos(alpha)));
  std::map<double, std::pair<double, double>> err;
  std::map<double, double> spins;
  for (const double step : {2e-4, 1e-4}) {
    const Result r = RunOde(m, Ode(false, step));
    double height = 0, azimuth = 0, spin = 0;
    for (const Sample& s : r.trajectory) {
      const V3 p = PointAt(m, s, "P");
      const double phi = Omega * (s.t - m.analysis.t0);
      const V3 u_exact(std::cos(alpha) * std::cos(phi), std::cos(alpha) * std::sin(phi), std::sin(alpha));
      spin = std::max(spin, (PointAt(m, s, "u") - u_exact).norm());
      height = std::max(height, std::fabs(p.z() + L * std::cos(alpha)));
      const double expected = Omega * (s.t - m.analysis.t0);
      azimuth = std::max(azimuth, std::fabs(std::remainder(std::atan2(p.y(), p.x()) - expected, 2 * std::numbers::pi)));
    }
    if (Verbose())
      std::cout << "ode conical h " << step << ": height " << height << " azimuth " << azimuth << " spin " << spin << "\n";
    err[step] = {height, azimuth};
    spins[step] = spin;
  }
  EXPECT_LE(err[1e-4].first, 1e-4);
  EXPECT_LE(err[1e-4].second, 4e-4);
  EXPECT_LE(spins[1e-4], 2e-2);
  EXPECT_GT(spins[1e-4], 1e-3) << "ODE on the rigid conical pendulum's spin: better than first order now?";
  for (const double ratio : {err[2e-4].first / err[1e-4].first, err[2e-4].second / err[1e-4].second,
                             spins[2e-4] / spins[1e-4]}) {
    EXPECT_GT(ratio, 1.7);
    EXPECT_LT(ratio, 2.3);
  }
  EXPECT_TRUE(KnownFailure("spherical_pendulum", "ode-worldstep-tuned")) << "the finding is no longer listed";
}

// The driven RSSR against the numeric method (exact kinematics), 21 samples over 1 s. dWorldStep
// at 0.1 ms: q 2.3e-8, q̇ 3.7e-5, ‖Φ‖ 4.2e-8 (bounds 5e-8, 8e-5, 1e-7). dWorldQuickStep (20 iterations, 1 ms), the FINDING: its motor (FMax 1e10) on
// a closed loop is not converged by 20 SOR sweeps: q 7.8e-3, q̇ 1.8, ‖Φ‖ 5.1e-3 (known failure in
// tolerances.yaml; asserted to stay above q̇ 0.5 so that a fix is noticed).
TEST(OdeSpatial, DrivenRssrFollowsTheKinematics) {
  const Model m = Scene("rssr_fourbar_angles");
  const std::vector<MethodPtr> all = harness::AllMethods();
  const Result ref = Variant(all, "numeric").Run(m);
  ASSERT_TRUE(ref.ok()) << ref.reason;
  const Errors e = Compare(m, ref, RunOde(m, Ode(false, 1e-4)));
  const Errors eq = Compare(m, ref, RunOde(m, Ode(true, 1e-3)));
  if (Verbose())
    std::cout << "ode rssr worldstep: q " << e.q << " qd " << e.qd << " res " << e.residual << "; quickstep: q " << eq.q
              << " qd " << eq.qd << " res " << eq.residual << "\n";
  EXPECT_LE(e.q, 5e-8);
  EXPECT_LE(e.qd, 8e-5);
  EXPECT_LE(e.residual, 1e-7);
  EXPECT_GT(eq.qd, 0.5) << "QuickStep's motor on the loop now converges? update the known failure";
}

// Bricard (A04): five hinges in the tree and the revolute closure as one dHinge, 30 rows for 30
// body coordinates and still one degree of freedom (one row redundant). Against the numeric method
// (dyn-baumgarte-rk4, 1 ms) over the first second. dWorldStep (its LDLT factorisation, the
// world's CFM 1e-10 regularising the singular row) at 0.1 ms: P3 within 5.8e-5 m of numeric's
// (it moves 0.87 m; IFToMM's finest level is 1e-3 m), q 1.0e-4, ‖Φ‖ 1.0e-7 — the redundant row
// neither locks the loop nor opens it. dWorldQuickStep at 1 ms (20 iterations): P3 1.1e-3 m, ‖Φ‖
// 1.3e-3 — its iterations leave the loop open above its free bound 2e-4 (a known failure,
// asserted to stay above it). Bounds P3 1.5e-4 / 3e-3 m, ‖Φ‖ 3e-7 / 3e-3.
TEST(OdeSpatial, BricardThroughItsRedundantClosure) {
  Model m = LoadScenario(BricardFile());
  m.analysis.t1 = 1.0;
  m.analysis.samples = 101;
  const std::vector<MethodPtr> all = harness::AllMethods();
  const Result ref = Variant(all, "dyn-baumgarte-rk4").Run(m);
  ASSERT_TRUE(ref.ok()) << ref.reason;
  for (const bool quick : {false, true}) {
    const Result r = RunOde(m, quick ? Ode(true, 1e-3) : Ode(false, 1e-4));
    double worst = 0, moved = 0;
    for (size_t k = 0; k < r.trajectory.size(); ++k) {
      const V3 p = PointAt(m, r.trajectory[k], "P3"), q = PointAt(m, ref.trajectory[k], "P3");
      worst = std::max(worst, (p - q).norm());
      moved = std::max(moved, (q - V3(1, -1, 0)).norm());
    }
    const Errors e = Compare(m, ref, r);
    if (Verbose())
      std::cout << "ode bricard " << (quick ? "quickstep" : "worldstep") << ": P3 " << worst << " m (moved " << moved
                << "), q " << e.q << " res " << e.residual << "\n";
    EXPECT_GT(moved, 0.5);
    EXPECT_LE(worst, quick ? 3e-3 : 1.5e-4);
    EXPECT_LE(e.residual, quick ? 3e-3 : 3e-7);
    if (quick) {
      EXPECT_GT(e.residual, 2e-4) << "QuickStep now closes Bricard's loop: update the known failure";
    }
  }
}

#else
TEST(OdeSpatial, NotBuilt) { GTEST_SKIP() << "the ODE adapter is not built (MECHBENCH_WITH_ODE off)"; }
#endif

}  // namespace
}  // namespace engines_spatial_ode_test
}  // namespace mechbench::engines
