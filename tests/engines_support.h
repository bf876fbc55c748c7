// Shared helpers of the engine suites: errors of an engine's trajectory against a reference and
// the constraint residual measured with the numeric Φ, as the harness measures them; the checks
// of a method's work–precision control (RunOptions::step / ::tolerance) and the step-halving order
// on the free four-bar against its reference trajectory.
#pragma once

#include "mechbench/motion_error.h"
#include "mechbench/analytic/analytic_method.h"
#include "mechbench/format.h"
#include "mechbench/harness/compare.h"
#include "mechbench/harness/reference.h"
#include "mechbench/harness/tolerances.h"
#include "mechbench/loader.h"
#include "mechbench/method.h"
#include "mechbench/numeric/constraints.h"
#include "mechbench/numeric/natural_data.h"
#include "mechbench/numeric/natural_model.h"
#include "mechbench/numeric/reference.h"
#include "mechbench/run_control.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

namespace mechbench::engines::testing {

inline Model Load(const std::string& name) { return LoadScenario(ResolveScenario(name)); }

// The built-in driven gear trains.
inline std::vector<std::string> GearScenarios() {
  std::vector<std::string> out;
  for (const std::string& f : BuiltinScenarioFiles()) {
    const Model m = LoadScenario(f);
    if (m.kind == ScenarioKind::kGearTrain && !m.IsFree()) out.push_back(m.name);
  }
  return out;
}

// The train's speed ratios at the last sample (every member's rate over the fastest driver's):
// the largest difference from the reference's, relative to the largest ratio.
inline double RatioError(const Model& m, const Result& ref, const Result& r) {
  const Driver* in = &m.drivers.front();
  for (const Driver& d : m.drivers)
    if (std::fabs(d.velocity) > std::fabs(in->velocity)) in = &d;
  const int k = m.SlotIndex(in->coordinate);
  const Sample &a = ref.trajectory.back(), &b = r.trajectory.back();
  double diff = 0, scale = 0;
  for (long i = 0; i < a.qd.size(); ++i) {
    diff = std::max(diff, std::fabs(b.qd[i] / b.qd[k] - a.qd[i] / a.qd[k]));
    scale = std::max(scale, std::fabs(a.qd[i] / a.qd[k]));
  }
  return diff / scale;
}

// MECHBENCH_VERBOSE=1 prints the measured numbers even when a test passes.
inline bool Verbose() { return std::getenv("MECHBENCH_VERBOSE") != nullptr; }

// Runs `meth` on `m`, or returns not-applicable with the method's own reason.
inline Result RunIfApplicable(const Method& meth, const Model& m) {
  if (auto why = meth.Applicability(m)) {
    Result r;
    r.status = Status::kNotApplicable;
    r.reason = *why;
    return r;
  }
  return meth.Run(m);
}

// An engine's trajectory against a reference, measured as the harness measures it: CompareMotion
// (the one error measure) and the scaled residual of ScaledResiduals.
struct Errors {
  double q = 0, qd = 0, qdd = 0;  // CompareMotion's largest relative differences (0 for a kind not compared)
  double residual = 0;            // largest scaled ‖Φ‖ over the samples (harness::ScaledResiduals)
};

inline Errors Compare(const Model& m, const Result& ref, const Result& r) {
  const MotionError me = CompareMotion(m, ref.trajectory, r.trajectory);
  EXPECT_TRUE(me.problem.empty()) << me.problem;
  const auto value = [](double v) { return std::isnan(v) ? 0.0 : v; };
  Errors e{value(me.q.max), value(me.qd.max), value(me.qdd.max), 0.0};
  for (double res : harness::ScaledResiduals(m, r.trajectory)) e.residual = std::max(e.residual, res);
  return e;
}

// The bounds a variant's run on `scenario` is held to: harness/tolerances.yaml (with any user files
// in MECHBENCH_TOLERANCES), the one source of the suites' tolerances and known failures.
inline harness::Agreement ToleranceOf(const std::string& scenario, const std::string& variant) {
  return harness::LoadTolerances(scenario).For(variant);
}
inline const std::string* KnownFailure(const std::string& scenario, const std::string& variant) {
  static std::map<std::string, harness::Tolerances> cache;
  auto it = cache.find(scenario);
  if (it == cache.end()) it = cache.emplace(scenario, harness::LoadTolerances(scenario)).first;
  return it->second.KnownFailure(variant);
}
inline double FreeResidualOf(const std::string& scenario, const std::string& variant) {
  return harness::LoadTolerances(scenario).ForFree(variant).residual;
}

inline double Final(const Model& m, const Result& r, const std::string& slot) {
  return r.trajectory.back().q[m.SlotIndex(slot)];
}

// Every built-in scenario with a driver (the driven comparisons).
inline std::vector<std::string> DrivenScenarios() {
  std::vector<std::string> out;
  for (const std::string& f : BuiltinScenarioFiles()) {
    const Model m = LoadScenario(f);
    if (!m.IsFree()) out.push_back(m.name);
  }
  return out;
}

// ---- work–precision control ---------------------------------------------------------------------

inline const Method& Variant(const std::vector<MethodPtr>& all, const std::string& name) {
  for (const auto& m : all)
    if (m->name() == name) return *m;
  throw std::runtime_error("no method " + name);
}

inline std::vector<std::string> Names(const std::vector<MethodPtr>& all) {
  std::vector<std::string> out;
  for (const auto& m : all) out.push_back(m->name());
  return out;
}

// A gtest parameter name for a method name ("ode-worldstep-default" -> "ode_worldstep_default").
inline std::string ParamName(const ::testing::TestParamInfo<std::string>& info) {
  std::string s = info.param;
  std::replace(s.begin(), s.end(), '-', '_');
  return s;
}

inline RunOptions Override(Control c, double v) {
  RunOptions o;
  (c == Control::kStep ? o.step : o.tolerance) = v;
  return o;
}

// The free four-bar cut to 0.1 s (11 samples, 10 ms apart): long enough for the step count to
// show an override, short enough for the tuned variants (0.1 ms, up to 200 iterations).
inline Model ShortFreeFourBar() {
  Model m = Load("fourbar_free");
  m.analysis.t1 = 0.1;
  m.analysis.samples = 11;
  return m;
}

// `meth` says what a sweep varies (`kind`, its own value `default_value`), records it in a default
// run ("control", "control_value", and in words under `key`), takes the RunOptions override
// `other` for that run only (another "control_value", "sweep override" in words, other steps
// taken; the next default run is the first again), ignores the override of the other kind, and
// for a step, caps one above the sample interval at the interval and says so.
inline void ExpectHonoursOverride(const Method& meth, Control kind, double default_value, double other,
                                  const std::string& key) {
  SCOPED_TRACE(meth.name());
  const Model m = ShortFreeFourBar();
  EXPECT_EQ(meth.control(), kind);
  EXPECT_EQ(meth.default_control(), default_value);
  const Result base = meth.Run(m);
  ASSERT_TRUE(base.ok()) << base.reason;
  EXPECT_EQ(base.settings.at("control"), ToString(kind));
  EXPECT_EQ(base.settings.at("control_value"), FullPrecision(default_value));
  EXPECT_EQ(base.settings.at(key).find("override"), std::string::npos) << base.settings.at(key);
  EXPECT_NE(base.settings.at(key).find(Fmt(default_value)), std::string::npos) << base.settings.at(key);

  const Result o = meth.Run(m, Override(kind, other));
  ASSERT_TRUE(o.ok()) << o.reason;
  EXPECT_EQ(o.settings.at("control_value"), FullPrecision(other));
  EXPECT_NE(o.settings.at(key).find(Fmt(other) + (kind == Control::kStep ? " s" : "") + " (sweep override; default " +
                                    Fmt(default_value)),
            std::string::npos)
      << o.settings.at(key);
  EXPECT_NE(o.settings.at("steps_taken"), base.settings.at("steps_taken"));
  if (kind == Control::kStep) {  // fixed steps of at most h, shortened evenly to end on each sample
    const long per_sample = static_cast<long>(std::ceil(0.01 / other - 1e-9));
    EXPECT_EQ(o.settings.at("steps_taken"), std::to_string(10 * per_sample));
  }

  const Result again = meth.Run(m);
  ASSERT_TRUE(again.ok()) << again.reason;
  EXPECT_EQ(again.settings, base.settings);
  EXPECT_EQ(again.trajectory.back().q, base.trajectory.back().q);
  const Result mismatched = meth.Run(m, Override(kind == Control::kStep ? Control::kTolerance : Control::kStep, 1e-2));
  ASSERT_TRUE(mismatched.ok()) << mismatched.reason;
  EXPECT_EQ(mismatched.settings, base.settings);
  EXPECT_EQ(mismatched.trajectory.back().q, base.trajectory.back().q);
  const Result bad = meth.Run(m, Override(kind, 0));
  EXPECT_EQ(bad.status, Status::kFailed);
  EXPECT_NE(bad.reason.find("positive"), std::string::npos) << bad.reason;

  if (kind != Control::kStep) return;
  const Result capped = meth.Run(m, {.step = 0.05});
  ASSERT_TRUE(capped.ok()) << capped.reason;
  EXPECT_NEAR(std::stod(capped.settings.at("control_value")), 0.01, 1e-15);
  EXPECT_NE(capped.settings.at(key).find("the requested 0.05 s (sweep override; default " + Fmt(default_value) +
                                         " s) capped by the sample interval 0.01 s"),
            std::string::npos)
      << capped.settings.at(key);
  EXPECT_EQ(capped.settings.at("steps_taken"), "10");
}

// ---- step halving on the free four-bar ---------------------------------------------------------

// The largest position error over the run, relative to the motion's scale (CompareMotion)
// against the free four-bar's reference trajectory (harness::GetReference: DOPRI5 at rtol 1e-12,
// confirmed by coordinate partitioning; cached on disk).
inline double FreeFourBarError(const Result& r) {
  static const Model m = Load("fourbar_free");
  static const harness::ReferenceRecord ref = harness::GetReference(m);
  EXPECT_TRUE(ref.confirmed) << ref.description;
  const MotionError e = CompareMotion(m, ref.trajectory, r.trajectory);
  EXPECT_TRUE(e.problem.empty()) << e.problem;
  return e.q.max;
}

struct StepHalving {
  double h = kNaN, e_h = kNaN, e_half = kNaN;
  double ratio() const { return e_h / e_half; }
  double order() const { return std::log2(ratio()); }
};

// e(h) and e(h/2) of `meth` on the free four-bar (1 s), through RunOptions::step.
inline StepHalving HalveStep(const Method& meth, double h) {
  const Model m = Load("fourbar_free");
  StepHalving s;
  s.h = h;
  const Result a = meth.Run(m, {.step = h}), b = meth.Run(m, {.step = h / 2});
  EXPECT_TRUE(a.ok()) << a.reason;
  EXPECT_TRUE(b.ok()) << b.reason;
  if (!a.ok() || !b.ok()) return s;
  s.e_h = FreeFourBarError(a);
  s.e_half = FreeFourBarError(b);
  if (Verbose())
    std::printf("%s fourbar_free: e(%g) = %.4g, e(%g) = %.4g, ratio %.4g, order %.3f\n", meth.name().c_str(), h, s.e_h,
                h / 2, s.e_half, s.ratio(), s.order());
  return s;
}

// A gear-train run against the analytic train: the harness's errors and the speed ratios at the
// end (MECHBENCH_VERBOSE=1 prints them).
struct TrainErrors {
  Errors e;
  double ratio = 0;
};
inline TrainErrors AgainstAnalyticTrain(const Model& m, const Result& r, const std::string& label) {
  const Result ref = analytic::MakeAnalyticMethod()->Run(m);
  EXPECT_TRUE(ref.ok()) << ref.reason;
  TrainErrors t{Compare(m, ref, r), RatioError(m, ref, r)};
  if (Verbose())
    std::printf("%s: q %.3g qd %.3g ratio %.3g res %.3g\n", label.c_str(), t.e.q, t.e.qd, t.ratio, t.e.residual);
  return t;
}

// Readable names for (scenario, variant) suites: "s6_3_compound_train_ode_worldstep_default".
inline std::string ScenarioVariantName(const ::testing::TestParamInfo<std::tuple<std::string, std::string>>& info) {
  std::string s = std::get<0>(info.param) + "_" + std::get<1>(info.param);
  std::replace(s.begin(), s.end(), '-', '_');
  return s;
}

}  // namespace mechbench::engines::testing
