#include "mechbench/method.h"

#include "mechbench/errors.h"
#include "mechbench/format.h"

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <exception>

namespace mechbench {

const char* ToString(Status s) {
  switch (s) {
    case Status::kOk: return "ok";
    case Status::kNotApplicable: return "not-applicable";
    case Status::kInvalidScenario: return "invalid-scenario";
    case Status::kDiverged: return "diverged";
    case Status::kFailed: return "failed";
    case Status::kOverBudget: return "over-budget";
    case Status::kCrashed: return "crashed";
    case Status::kTimedOut: return "timed_out";
    case Status::kStopped: return "stopped";
  }
  return "?";
}

const char* ToString(Control c) {
  switch (c) {
    case Control::kNone: return "none";
    case Control::kStep: return "step";
    case Control::kTolerance: return "tolerance";
  }
  return "?";
}

namespace {
double CpuSeconds() { return static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }

// Why a budget may not reach the end: no sample yet, and how many steps the whole run is at the
// method's step (t1 = 1e9 s is 1e12 steps of 1 ms: stopped before its first sample, it said only
// "at t = 0").
std::string BudgetContext(const Model& model, const Result& r, double t) {
  const Analysis& a = model.analysis;
  if (!a.HasMotion()) return {};
  std::string s;
  if (t < a.TimeAt(1)) s = " before its first sample (t = " + Fmt(a.TimeAt(1), 4) + " s)";
  const auto control = r.settings.find("control"), value = r.settings.find("control_value");
  if (control != r.settings.end() && control->second == ToString(Control::kStep) && value != r.settings.end()) {
    const double h = std::strtod(value->second.c_str(), nullptr);
    if (h > 0) s += "; at its step of " + Fmt(h, 3) + " s the motion (" + Fmt(a.t1 - a.t0, 4) + " s) is " +
                    Fmt((a.t1 - a.t0) / h, 3) + " steps";
  }
  return s;
}
}  // namespace

void CheckBudget(const RunOptions& options, double t) {
  if (options.watched) {
    RunOptions::Watched& w = *options.watched;
    while (w.seen < w.samples->size()) {
      const Sample& s = (*w.samples)[w.seen++];
      if (std::optional<std::string> why = options.watch(s)) throw WatchStopped{s.t, *why};
    }
  }
  if (std::isnan(options.cpu_deadline)) return;
  if (options.clock && !options.clock->DueForCpuCheck()) return;
  if (CpuSeconds() > options.cpu_deadline) throw BudgetExceeded{t};
}

Result Method::Run(const Model& model, const RunOptions& options) const {
  Result r;
  r.method = name_;
  if (auto why = Applicability(model)) {
    r.status = Status::kNotApplicable;
    r.reason = *why;
    return r;
  }
  const double cpu0 = CpuSeconds();
  const auto wall0 = std::chrono::steady_clock::now();
  PhaseClock clock;
  clock.Start();
  RunOptions o = options;
  o.cpu_deadline = options.cpu_budget > 0 ? cpu0 + options.cpu_budget : kNaN;
  o.clock = &clock;
  RunOptions::Watched watched{&r.trajectory, 0};
  o.watched = options.watch ? &watched : nullptr;
  try {
    DoRun(model, o, r);
  } catch (const BudgetExceeded& b) {
    r.status = Status::kOverBudget;
    r.reason = "stopped at t = " + Fmt(b.t, 4) + " s of " + Fmt(model.analysis.t1, 4) + " s: its CPU budget of " +
               Fmt(options.cpu_budget, 3) + " s ran out" + BudgetContext(model, r, b.t);
  } catch (const WatchStopped& w) {
    r.status = Status::kStopped;
    r.reason = "stopped at t = " + Fmt(w.t, 4) + " s of " + Fmt(model.analysis.t1, 4) + " s: " + w.reason;
  } catch (const ScenarioError& e) {
    r.status = Status::kInvalidScenario;
    r.reason = e.what();
  } catch (const std::exception& e) {
    r.status = Status::kFailed;
    r.reason = e.what();
  }
  r.cpu_seconds = CpuSeconds() - cpu0;
  r.cpu = clock.Stop(r.cpu_seconds);
  r.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  // A run that produced non-finite numbers has diverged whatever the method thought.
  if (r.status == Status::kOk) {
    for (const Sample& s : r.trajectory) {
      if (!s.q.allFinite() || !s.qd.allFinite() || !s.qdd.allFinite()) {
        r.status = Status::kDiverged;
        r.reason = "non-finite value at t = " + std::to_string(s.t) + " s";
        break;
      }
    }
  }
  return r;
}

}  // namespace mechbench
