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
namespace {

using namespace testing;

// Allowed |x_engine − x_numeric| / |x_numeric| for the vectors vabs.<P> and aabs.<P> at t0, per
// variant (the test's data; measured 2026-11-26, RelWithDebInfo, worst of §3.1's D and §3.2's B
// in the comment). Velocities are the engine's own world velocities; aabs is the engine's world
// acceleration where it has one at t0 (Simbody), else a one-sided difference of its world
// velocities at t0 + i Δt (engine_method.cc). A variant not listed must not report vabs.
struct FrameTolerance {
  double vabs, aabs;
  bool aabs_known_failure = false;  // stays visible: asserted to still exceed `aabs`
};
const std::map<std::string, FrameTolerance>& Tolerances() {
  static const std::map<std::string, FrameTolerance> t{
      // Exact to round-off (its accelerations at the Acceleration stage): vabs 5.9e-16, aabs 3.0e-15.
      {"simbody-rkmerson-default", {1e-12, 1e-12}},
      {"simbody-rkmerson-tuned", {1e-12, 1e-12}},
      // vabs 4.0e-16. aabs differenced: §3.2 (open chain, drivers set each step) 2.9e-8; §3.1 0.77
      // (z 1.13 against 3.5): Euler at 2 ms with soft equalities (solref 0.02) starts with the
      // closure lagging, a known failure kept visible.
      {"mujoco-euler-default", {1e-12, 1e-7, true}},
      // RK4 at 0.1 ms, solref 2e-4: vabs 4.0e-16; aabs §3.1 4.3e-4 (the closures' stabilisation in
      // the first steps), §3.2 2.9e-8.
      {"mujoco-rk4-tuned", {1e-12, 1e-3}},
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
  ASSERT_FALSE(std::isnan(ea)) << "no aabs." << point << ": " << r.settings.at("absolute_accelerations");
  // The relative motion is unchanged: the instant's q̇ as numeric's.
  for (long i = 0; i < ref.trajectory.front().qd.size(); ++i)
    EXPECT_NEAR(r.trajectory.front().qd[i], ref.trajectory.front().qd[i], 1e-9 * (1 + std::fabs(ref.trajectory.front().qd[i])));
  if (tol->second.aabs_known_failure && m.name == "s3_1_carousel")
    EXPECT_GT(ea, tol->second.aabs) << "a known failure that no longer fails: move it into the bounds";
  else
    EXPECT_LE(ea, tol->second.aabs) << "aabs." << point;
}

std::vector<std::string> EngineNames() { return Names(harness::EngineMethods()); }

INSTANTIATE_TEST_SUITE_P(Book, EngineFrame,
                         ::testing::Combine(::testing::Values("s3_1_carousel", "s3_2_thumb"), ::testing::ValuesIn(EngineNames())),
                         ScenarioVariantName);

}  // namespace
}  // namespace mechbench::engines
