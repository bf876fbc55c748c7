// The turning frame (frame_rotation, issue 13's first slice): an engine that mounts the mechanism
// on its platform (Graph::platform) reports the absolute velocity and acceleration of the book's
// points, and they agree with numeric's AbsolutePoint (numeric/derived.h) at t0; an engine that
// does not says why and reports none.
#include "engines_support.h"

#include "mechbench/harness/registry.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <tuple>

namespace mechbench::engines {
namespace engines_frame_test {  // this file's own names (the tests build in unity batches)
namespace {

using namespace testing;

// Allowed |x_engine − x_numeric| / |x_numeric| for the vectors vabs.<P> and aabs.<P> at t0, per
// variant and scene (the test's data; measured 2026-11-26, RelWithDebInfo, in the comments; the
// tilted thumb within the thumb's bounds in every variant).
// Velocities are the engine's own world velocities; aabs is the engine's world acceleration where
// it has one at t0 (Simbody), else the derivative at t0 of its world velocities at t0 + i Δt,
// i = 1…5 (engine_method.cc). A variant not listed must not report vabs. A known failure stays
// visible: asserted to still exceed its bound.
struct FrameTolerance {
  double vabs = 1e-12;
  double aabs[2];                 // §3.1 carousel's D, §3.2 thumb's B
  bool known_failure[2] = {false, false};
};
// The thumb's bounds hold for its twin in a tilted plane turning about an oblique axis
// (tests/data/scenes/thumb_tilted_plane.yaml), which has no book values.
int SceneIndex(const std::string& scene) { return scene == "s3_1_carousel" ? 0 : 1; }
const std::string kTiltedThumb = std::string(MECHBENCH_TEST_DATA) + "/scenes/thumb_tilted_plane.yaml";
const std::map<std::string, FrameTolerance>& Tolerances() {
  static const std::map<std::string, FrameTolerance> t{
      // Exact to round-off (accelerations at the Acceleration stage): vabs 5.9e-16, aabs 3.0e-15 / 1.8e-16.
      {"simbody-rkmerson-default", {1e-12, {1e-12, 1e-12}}},
      {"simbody-rkmerson-tuned", {1e-12, {1e-12, 1e-12}}},
      // vabs 4.0e-16. aabs: §3.2 (open chain, drivers set every step) 3.3e-7; §3.1 0.78 (z 1.10
      // against 3.5): Euler at 2 ms with soft equalities (solref 0.02) starts with the closure
      // lagging — a known failure against the tuned variant's bound.
      {"mujoco-euler-default", {1e-12, {3e-4, 1e-6}, {true, false}}},
      // RK4 at 0.1 ms, solref 2e-4: aabs §3.1 9.9e-5, §3.2 3.3e-7.
      {"mujoco-rk4-tuned", {1e-12, {3e-4, 1e-6}}},
      // ODE's bounds are its q̈ agreement in harness/tolerances.yaml (an acceleration at t0 is
      // judged like q̈). dWorldStep at 1 ms (first order, motor drivers): 0.13 / 7.7e-2.
      {"ode-worldstep-default", {1e-12, {0.2, 0.2}}},
      // 0.1 ms: 6.1e-4 / 8.2e-3.
      {"ode-worldstep-tuned", {1e-12, {1e-2, 1e-2}}},
      // dWorldQuickStep: its q̈ is noise (not judged in tolerances.yaml), so are velocities
      // differenced over 3 ms: 0.76 / 0.34 at 20 iterations (known failures against dWorldStep's
      // 0.2), and at 200 iterations 10.5 on §3.1 (known failure against its q̈ bound 0.1), 8.2e-3 on §3.2.
      {"ode-quickstep-default", {1e-12, {0.2, 0.2}, {true, true}}},
      {"ode-quickstep-tuned", {1e-12, {0.1, 0.1}, {true, false}}},
      // btMultiBody with the platform as its first link (motor-driven), velocities differenced as
      // ODE's. At 1 ms its q̈ is not judged in tolerances.yaml (one step's difference), so its
      // aabs is held to the other 1 ms first-order stepper's q̈ bound (dWorldStep's 0.2), as
      // QuickStep's is: 8.3e-2 / 3.8e-3 (tilted thumb 4.0e-3).
      {"bullet-multibody-default", {1e-12, {0.2, 0.2}}},
      // 0.1 ms, 100 iterations; its q̈ bound 0.1: 5.4e-4 / 2.3e-5 (tilted thumb 2.4e-5).
      {"bullet-multibody-tuned", {1e-12, {0.1, 0.1}}},
      // btRigidBody unlocked in 3-D on a motor-hinged platform body. 10 sequential-impulse
      // iterations at 1 ms: its differenced velocities are noise as QuickStep's, 0.86 / 0.201 (tilted
      // 0.31), known failures against the same 0.2 (the thumb's only just).
      {"bullet-rigidbody-default", {1e-12, {0.2, 0.2}, {true, true}}},
      // 0.1 ms, 100 iterations; its q̈ bound 0.1: 5.8e-4 / 8.3e-3 (tilted 8.2e-3).
      {"bullet-rigidbody-tuned", {1e-12, {0.1, 0.1}}},
  };
  return t;
}

double VectorError(const Quantities& ref, const Quantities& q, const std::string& prefix) {
  Eigen::Vector3d a, b;
  const char* ax[3] = {".x", ".y", ".z"};
  for (int k = 0; k < 3; ++k) {
    a[k] = ref.at(prefix + ax[k]);
    const auto it = q.find(prefix + ax[k]);
    if (it == q.end()) return kNaN;
    b[k] = it->second;
  }
  return (b - a).norm() / a.norm();
}

class EngineFrame : public ::testing::TestWithParam<std::tuple<std::string, std::string>> {};

TEST_P(EngineFrame, AbsoluteVelocityAndAccelerationAgreeWithNumeric) {
  const auto& [file, variant] = GetParam();
  const Model m = LoadScenario(ResolveScenario(file));
  ASSERT_TRUE(m.frame);
  const std::string point = m.name == "s3_1_carousel" ? "D" : "B";
  const std::vector<MethodPtr> all = harness::AllMethods();
  const Method& engine = Variant(all, variant);
  if (auto why = engine.Applicability(m)) GTEST_SKIP() << *why;
  const RunOptions instant{.motion = false};
  const Result ref = Variant(all, "numeric").Run(m, instant);
  ASSERT_TRUE(ref.ok()) << ref.reason;
  const Result r = engine.Run(m, instant);
  ASSERT_TRUE(r.ok()) << r.reason;
  const auto tol = Tolerances().find(variant);
  if (tol == Tolerances().end()) {
    // Not mounted on the platform: no absolute values, and a message that says why.
    EXPECT_EQ(r.quantities.count("vabs." + point + ".x"), 0u);
    std::string why;
    for (const std::string& msg : r.messages)
      if (msg.find("frame_rotation") != std::string::npos) why = msg;
    ASSERT_FALSE(why.empty()) << "no message on the frame's rotation";
    GTEST_SKIP() << why;
  }
  const double ev = VectorError(ref.quantities, r.quantities, "vabs." + point);
  const double ea = VectorError(ref.quantities, r.quantities, "aabs." + point);
  if (Verbose()) std::printf("%s %s: vabs.%s %.3g aabs.%s %.3g\n", m.name.c_str(), variant.c_str(), point.c_str(), ev,
                             point.c_str(), ea);
  EXPECT_LE(ev, tol->second.vabs) << "vabs." << point;
  const int scene = SceneIndex(m.name);
  ASSERT_FALSE(std::isnan(ea)) << "no aabs." << point << ": " << r.settings.at("absolute_accelerations");
  // The relative motion is unchanged: the instant's q̇ as numeric's.
  for (long i = 0; i < ref.trajectory.front().qd.size(); ++i)
    EXPECT_NEAR(r.trajectory.front().qd[i], ref.trajectory.front().qd[i], 1e-9 * (1 + std::fabs(ref.trajectory.front().qd[i])));
  if (tol->second.known_failure[scene])
    EXPECT_GT(ea, tol->second.aabs[scene]) << "a known failure that no longer fails: move it into the bounds";
  else
    EXPECT_LE(ea, tol->second.aabs[scene]) << "aabs." << point;
}

std::vector<std::string> EngineNames() { return Names(harness::EngineMethods()); }

// A fixture file is named by its stem.
std::string FrameTestName(const ::testing::TestParamInfo<std::tuple<std::string, std::string>>& info) {
  std::string file = std::get<0>(info.param);
  if (const size_t slash = file.rfind('/'); slash != std::string::npos) file = file.substr(slash + 1);
  if (const size_t dot = file.rfind(".yaml"); dot != std::string::npos) file.resize(dot);
  return ScenarioVariantName({std::make_tuple(file, std::get<1>(info.param)), info.index});
}

INSTANTIATE_TEST_SUITE_P(Book, EngineFrame,
                         ::testing::Combine(::testing::Values("s3_1_carousel", "s3_2_thumb", kTiltedThumb),
                                            ::testing::ValuesIn(EngineNames())),
                         FrameTestName);

}  // namespace
}  // namespace engines_frame_test
}  // namespace mechbench::engines
