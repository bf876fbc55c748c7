#include "mechbench/harness/campaign.h"
#include "mechbench/harness/chains.h"

#include "mechbench/errors.h"
#include "mechbench/format.h"
#include "mechbench/harness/compare.h"
#include "mechbench/harness/criteria.h"
#include "mechbench/harness/frames.h"
#include "mechbench/harness/process.h"
#include "mechbench/harness/reference.h"
#include "mechbench/harness/registry.h"
#include "mechbench/harness/tolerances.h"
#include "mechbench/harness/timing.h"
#include "mechbench/loader.h"
#include "mechbench/references/registry.h"
#include "mechbench/numeric/forward_dynamics.h"
#include "mechbench/numeric/natural_model.h"
#include "mechbench/run_control.h"
#include "json_number.h"

#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>
#include <fcntl.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <deque>
#include <fstream>
#include <limits>
#include <map>
#include <numbers>
#include <optional>
#include <set>
#include <sstream>
#include <thread>
#include <tuple>

namespace mechbench::harness {

using nlohmann::json;

namespace {

// ---- shared state of one campaign (read-only after the first use, so forked workers share it) --

const std::vector<MethodPtr>& Methods() {
  static const std::vector<MethodPtr> methods = AllMethods();
  return methods;
}

const Method* FindMethod(const std::string& name) {
  for (const MethodPtr& m : Methods())
    if (m->name() == name) return m.get();
  return nullptr;
}

const Model& LoadCached(const std::string& file) {
  static std::map<std::string, Model> cache;
  auto it = cache.find(file);
  if (it == cache.end()) it = cache.emplace(file, references::LoadScenarioValidated(file)).first;
  return it->second;
}

const StressVariant& Variant(const std::string& id, const std::string& base) {
  for (const StressVariant& v : StressVariants())
    if (v.id == id && v.base == base) return v;
  MB_ASSERT(false, ("unknown stress variant " + base + "@" + id).c_str());
  std::abort();
}

// The model a case runs: the base scenario, or a stress variant derived from it.
Model CaseModel(const Case& c) {
  if (c.variant.empty()) return LoadCached(c.file);
  const StressVariant& v = Variant(c.variant, c.scenario);
  return v.derive(c.file.empty() ? Model{} : LoadCached(c.file));
}

// Scenes used to find each step method's largest stable step: coarse samples, so that the
// step (shortened to land on samples) can grow to a tenth of the run.
const std::vector<std::string>& StableStepScenarios(bool quick) {
  static const std::vector<std::string> full{"fourbar_free", "fourbar_crank_rocker"}, fast{"fourbar_free"};
  return quick ? fast : full;
}
constexpr int kStableStepSamples = 11;

std::vector<double> Ladder(Control c, bool quick) {
  switch (c) {
    case Control::kStep:
      if (quick) return {4e-3, 2e-3, 1e-3};
      return {1e-2, 5e-3, 2.5e-3, 1.25e-3, 6.25e-4, 3.125e-4};
    case Control::kTolerance:
      if (quick) return {1e-3, 1e-6};
      return {1e-2, 1e-4, 1e-6, 1e-8, 1e-10};
    case Control::kNone: break;
  }
  return {kNaN};
}

// The scenarios of a --quick report when none are named: one free and one driven linkage, the
// bushing of §5.1 and a gear train, which between them meet every family of method.
const std::vector<std::string> kQuickScenarios{"fourbar_free", "fourbar_crank_rocker", "s5_1_disc_bar_bushing",
                                               "s6_3_compound_train"};
const std::set<std::string> kQuickVariants{"mass_ratio=1e6", "gear_ratio=990", "input_speed=10000rpm", "change_point"};


std::string Lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char ch) { return std::tolower(ch); });
  return s;
}

// "… at t = 0.25 s …" -> 0.25
double TimeIn(const std::string& reason) {
  const size_t at = reason.find("t = ");
  if (at == std::string::npos) return kNaN;
  try {
    return std::stod(reason.substr(at + 4));
  } catch (const std::exception&) {
    return kNaN;
  }
}

json ErrorJson(const MotionError& e, const std::string& against) {
  return {{"against", against}, {"q_max", JsonNumber(e.q.max)}, {"q_rms", JsonNumber(e.q.rms)}, {"qd_max", JsonNumber(e.qd.max)},
          {"qd_rms", JsonNumber(e.qd.rms)}, {"qdd_max", JsonNumber(e.qdd.max)}, {"qdd_rms", JsonNumber(e.qdd.rms)}};
}

// What every method is judged against on `model`: the analytic (else numeric) motion of a
// driven scene, the confirmed reference trajectory of a free one.
struct Reference {
  std::vector<Sample> trajectory;
  std::string against;   // "analytic", "numeric", "reference trajectory"
  bool trusted = false;  // false: errors are shown, not judged
  std::string note;
  // A driven reference that stopped at a singular position: it covers the samples before it
  // only, and methods are compared there.
  bool partial = false;
  // Free scenes: how far the reference's two formulations were apart (relative to the motion's
  // scale). An unconfirmed reference still judges a case whose tolerance is 100 × wider.
  double agreement = kNaN;
};

// The CPU a case gives each method run and each of the reference's runs: a third of its time
// limit, so that a run too slow to finish stops as a row with the time it reached (over-budget)
// before the case is killed.
double CaseBudget(const CampaignOptions& o) { return o.timeout / 3; }

// `exclude`: a method judged against the reference must not be its own reference: the
// analytic method's motion is then judged against the numeric one (both are exact).
Reference ReferenceFor(const Model& model, double budget, const std::string& exclude = "") {
  Reference r;
  if (model.IsFree()) {
    const ReferenceRecord rec = GetReference(model, budget);
    r.trajectory = rec.trajectory;
    r.against = "reference trajectory";
    r.trusted = rec.confirmed && !rec.trajectory.empty();
    r.agreement = rec.agreement;
    if (!r.trusted) r.note = "reference unconfirmed: " + rec.description;
    return r;
  }
  for (const char* name : {"analytic", "numeric"}) {
    const Method* m = FindMethod(name);
    if (!m) continue;
    // Why a candidate is no reference, for the note when none is left (never an empty reason).
    if (name == exclude) {
      r.note += std::string(name) + " is the method judged (never its own reference); ";
      continue;
    }
    if (const auto why = m->Applicability(model)) {
      r.note += std::string(name) + " n/a: " + *why + "; ";
      continue;
    }
    Result res = m->Run(model);
    if (!res.ok()) {
      r.note += std::string(name) + " " + ToString(res.status) + ": " + res.reason + "; ";
      if (res.trajectory.size() > 1 && r.trajectory.empty()) {
        r.trajectory = std::move(res.trajectory);
        r.against = std::string(name) + " (until it stopped)";
        r.partial = true;
      }
      continue;
    }
    if (r.partial) r.trajectory.clear(), r.partial = false;
    r.note.clear();  // a reference was found: the candidates before it need no note
    r.trajectory = std::move(res.trajectory);
    r.against = name;
    r.trusted = true;
    return r;
  }
  if (r.partial) {
    r.trusted = true;
    r.note = "reference only up to t = " + Fmt(r.trajectory.back().t) + " s (" + r.note.substr(0, r.note.size() - 2) + ")";
    return r;
  }
  r.note = "no reference: " + (r.note.empty() ? std::string("neither analytic nor numeric is built; ") : r.note);
  r.note.resize(r.note.size() - 2);  // the last "; "
  return r;
}

json StartupJson(const StartupCost& c) {
  if (!c.done) return nullptr;
  return {{"first", c.first}, {"again", c.again}, {"runs", c.runs}, {"one_time", c.one_time()}};
}

json SettingsJson(const Result& r) {
  json s = json::object();
  for (const auto& [k, v] : r.settings) s[k] = v;
  return s;
}

double ControlValue(const Result& r, double fallback) {
  if (auto it = r.settings.find("control_value"); it != r.settings.end()) {
    try {
      return std::stod(it->second);
    } catch (const std::exception&) {
    }
  }
  return fallback;
}

// ---- stress outcome ----------------------------------------------------------------------------

// Which joint between two moving bodies changed side (the sign of the cross product of the two
// bodies' directions through it) between two samples, or "" when none did. Joints within 1e-3
// of collinear at either sample are left out: there the side is not decided.
std::string AssemblyFlip(const Model& m, const Sample& a, const Sample& b) {
  auto position = [&](const Sample& s, int point) {
    Eigen::Vector2d p = m.points[point].p_W;
    for (int axis = 0; axis < 2; ++axis)
      if (const int slot = m.SlotOf(point, axis); slot >= 0 && slot < s.q.size()) p[axis] = s.q[slot];
    return p;
  };
  for (size_t i = 0; i < m.points.size(); ++i) {
    if (m.points[i].fixed) continue;
    std::vector<int> others;  // the far end of each moving body through point i
    for (const Body& body : m.bodies) {
      if (body.points.size() != 2) continue;
      const bool moving = !m.points[body.points[0]].fixed || !m.points[body.points[1]].fixed;
      if (!moving) continue;
      if (body.points[0] == static_cast<int>(i)) others.push_back(body.points[1]);
      if (body.points[1] == static_cast<int>(i)) others.push_back(body.points[0]);
    }
    if (others.size() != 2) continue;
    auto side = [&](const Sample& s) {
      const Eigen::Vector2d p = position(s, static_cast<int>(i));
      const Eigen::Vector2d u = p - position(s, others[0]), v = position(s, others[1]) - p;
      const double cross = u.x() * v.y() - u.y() * v.x();
      return std::fabs(cross) > 1e-3 * u.norm() * v.norm() ? (cross > 0 ? 1 : -1) : 0;
    };
    const int sa = side(a), sb = side(b);
    if (sa && sb && sa != sb) return "the assembly at point " + m.points[i].name + " flipped";
  }
  return {};
}

struct Classified {
  std::string outcome, detail;
  double t_fail = kNaN;
  MotionError error;
  bool has_error = false;
  double max_residual = kNaN, energy_drift = kNaN;
};

constexpr double kLoopOpened = kLoopOpenedResidual;  // scaled ‖Φ‖ above which the loop has come apart
constexpr double kQualitative = 0.1;      // relative position error beyond which a run is qualitatively wrong
constexpr double kDriverAngle = 0.05;     // [rad] a driven angle this far off its law: the motor stalled
constexpr double kDriverLength = 1e-2;    // × the scene's length scale, for a driven distance

Classified Classify(const Model& model, const Result& r, const Reference& ref, double tolerance) {
  Classified c;
  c.energy_drift = EnergyDrift(model, r.trajectory);
  const std::string why = Lower(r.reason);
  switch (r.status) {
    case Status::kNotApplicable:
      c.outcome = "not_applicable";
      c.detail = r.reason;
      return c;
    case Status::kInvalidScenario:
    case Status::kDiverged:
      c.t_fail = TimeIn(r.reason);
      c.detail = r.reason;
      if (why.find("non-finite") != std::string::npos || why.find("nan") != std::string::npos ||
          why.find("inf") != std::string::npos)
        c.outcome = "diverged";
      else if (why.find("singular") != std::string::npos || why.find("assemble") != std::string::npos ||
               why.find("converge") != std::string::npos || why.find("rank") != std::string::npos)
        c.outcome = "locked_up";
      else
        c.outcome = r.status == Status::kDiverged ? "diverged" : "invalid_scenario";
      return c;
    case Status::kOverBudget:
      // Its own CPU budget ran out (RunOptions::cpu_budget): as a case killed at its time limit,
      // but with the time it reached.
      c.outcome = "timed_out";
      c.t_fail = TimeIn(r.reason);
      c.detail = r.reason;
      return c;
    case Status::kStopped:
      // Only a caller's watch stops a run (RunOptions::watch): what it saw is the detail.
      c.outcome = "inaccurate";
      c.t_fail = TimeIn(r.reason);
      c.detail = r.reason;
      return c;
    case Status::kCrashed:
    case Status::kTimedOut:
      c.outcome = r.status == Status::kCrashed ? "crashed" : "timed_out";
      c.detail = r.reason;
      return c;
    case Status::kFailed:
      c.t_fail = TimeIn(r.reason);
      // An integrator that gives up at a singular position has locked up; anything else that
      // threw inside the method aborted the run.
      if (why.find("step failed") != std::string::npos || why.find("singular") != std::string::npos) {
        c.outcome = "locked_up";
        c.detail = r.reason.substr(0, 300);
      } else {
        c.outcome = "crashed";
        c.detail = "exception inside the method: " + r.reason.substr(0, 300);
      }
      return c;
    case Status::kOk: break;
  }
  const std::vector<Sample>& traj = r.trajectory;
  // The loop: the numeric model's Φ on every sample, as `run` measures it.
  const std::vector<double> residuals = ScaledResiduals(model, traj);
  c.max_residual = 0;
  for (size_t k = 0; k < residuals.size(); ++k) {
    c.max_residual = std::max(c.max_residual, residuals[k]);
    if (residuals[k] > kLoopOpened && c.outcome.empty()) {
      c.outcome = "loop_opened";
      c.t_fail = traj[k].t;
      c.detail = "scaled ‖Φ‖ " + Fmt(residuals[k], 3) + " > " + Fmt(kLoopOpened) + " at t = " + Fmt(traj[k].t) + " s";
    }
  }
  if (!ref.trajectory.empty()) {
    if (ref.partial && traj.size() > ref.trajectory.size())
      c.error = CompareMotion(model, ref.trajectory, {traj.begin(), traj.begin() + static_cast<long>(ref.trajectory.size())});
    else
      c.error = CompareMotion(model, ref.trajectory, traj);
    c.has_error = true;
  }
  if (!c.outcome.empty()) return c;
  // A driven input that does not follow its law: the actuator stalled against the mechanism.
  double length_scale = 0;
  for (const Body& b : model.bodies)
    for (const Eigen::Vector2d& p : b.p_B) length_scale = std::max(length_scale, p.norm());
  for (const Driver& d : model.drivers) {
    const int slot = model.SlotIndex(d.coordinate);
    if (slot < 0) continue;
    const Model::Slot& s = model.q_layout[slot];
    const bool angle = s.coordinate >= 0 && model.coordinates[s.coordinate].type != CoordinateType::kDistance;
    for (const Sample& smp : traj) {
      if (smp.q.size() <= slot) continue;
      double off = smp.q[slot] - d.At(smp.t, model.analysis.t0);
      if (angle) off = std::remainder(off, 2 * std::numbers::pi);
      const double limit = angle ? kDriverAngle : kDriverLength * std::max(length_scale, 1e-300);
      if (std::fabs(off) > limit) {
        c.outcome = "locked_up";
        c.t_fail = smp.t;
        c.detail = "the driven " + d.coordinate + " is " + Fmt(off, 3) + (angle ? " rad" : "") +
                   " off its law at t = " + Fmt(smp.t) + " s: the input stalled";
        return c;
      }
    }
  }
  if (!c.has_error) {
    c.outcome = "ok";
    c.detail = ref.note.empty() ? "no reference: judged by ‖Φ‖ only" : ref.note;
    return c;
  }
  if (!c.error.problem.empty()) {
    c.outcome = "diverged";
    c.detail = "stopped early: " + c.error.problem;
    return c;
  }
  std::string err = "position error " + Fmt(c.error.q.max, 3) + " (tolerance " + Fmt(tolerance, 2) + ")";
  if (ref.partial) {
    err += " over the reference's span; " + ref.note;
    // Past the reference's singular position, the assembly itself tells whether the linkage
    // went on or jumped: the side on which each joint between two moving bodies lies.
    if (const std::string flip = AssemblyFlip(model, traj.front(), traj.back()); !flip.empty()) {
      c.outcome = "branch_switched";
      c.detail = flip + " between t0 and the end; " + err;
      return c;
    }
  }
  const bool judged = ref.trusted || (ref.agreement <= 1e-2 * tolerance && !ref.trajectory.empty());
  if (judged && !ref.trusted) err += "; judged against a reference whose two formulations agree to " + Fmt(ref.agreement, 2) + " only";
  if (!judged) {
    c.outcome = "ok";
    c.detail = err + ", not judged: " + ref.note;
    return c;
  }
  if (c.error.q.max > kQualitative && !model.IsFree()) {
    // The loop is closed and the input follows its law, yet the positions are elsewhere: the
    // other assembly of the same linkage.
    c.outcome = "branch_switched";
    c.detail = err + " with the loop closed and the input on its law: the other assembly";
    return c;
  }
  c.outcome = c.error.q.max > tolerance ? "inaccurate" : "ok";
  c.detail = err;
  return c;
}

bool Stable(const std::string& outcome, double q_max) {
  return (outcome == "ok" || outcome == "inaccurate") && !(q_max > kQualitative);
}

// ---- one case --------------------------------------------------------------------------------

json Common(const Case& c) {
  json j = {{"id", c.id}, {"index", c.index}, {"kind", c.kind}, {"scenario", c.scenario}, {"file", c.file}};
  return j;
}

std::vector<json> CheckCase(const Case& c) {
  const Model& m = LoadCached(c.file);
  std::vector<Result> results;
  // Claims at a time of the motion (book `at:`): off the motions and the confirmed reference, as `check`.
  const bool timed = std::any_of(m.book.begin(), m.book.end(), [](const BookValue& b) { return b.AtTime(); });
  for (const char* name : {"analytic", "numeric"})
    if (const Method* meth = FindMethod(name)) results.push_back(meth->Run(m, {.motion = timed}));
  std::optional<ReferenceRecord> reference;
  if (timed && m.IsFree()) reference = GetReference(m);
  json rows = json::array();
  for (const BookCheck& row : CheckBook(m, results, reference ? &*reference : nullptr)) {
    json computed = json::object();
    for (const auto& [meth, v] : row.computed) computed[meth] = v ? JsonNumber(*v) : json(nullptr);
    json r = {{"quantity", row.book.quantity}, {"where", row.book.where}, {"unit", row.book.unit},
              {"printed", row.book.printed}, {"book", JsonNumber(row.book.value)}, {"computed", computed},
              {"verdict", ToString(row.verdict)}, {"methods_agree", row.methods_agree}};
    if (!row.book.note.empty()) r["note"] = row.book.note;
    if (row.book.AtTime()) r["at"] = row.book.at, r["allowed"] = JsonNumber(row.allowed);
    if (!row.reason.empty()) r["reason"] = row.reason;
    rows.push_back(r);
  }
  json j = Common(c);
  j["rows"] = rows;
  return {j};
}

std::vector<json> RunMethodCase(const Case& c, const CampaignOptions& o) {
  const Model& m = LoadCached(c.file);
  const Method* meth = FindMethod(c.method);
  MB_ASSERT(meth, ("unknown method " + c.method).c_str());
  const Tolerances tol = LoadTolerances(m);
  // Beside the reference method, as `mechbench run` compares it.
  std::vector<MethodPtr> all = AllMethods(), pair;
  for (MethodPtr& cand : all)
    if ((cand->name() == "analytic" || cand->name() == "numeric") && cand->name() != c.method && pair.empty() &&
        !cand->Applicability(m))
      pair.push_back(std::move(cand));
  for (MethodPtr& cand : all)
    if (cand && cand->name() == c.method) pair.push_back(std::move(cand));
  const RunReport rep = RunScenario(m, pair, {.cpu_budget = CaseBudget(o)}, tol);
  const Result& r = rep.results.back();
  json j = Common(c);
  j["method"] = c.method;
  j["status"] = ToString(r.status);
  j["reason"] = r.reason;
  j["cpu_seconds"] = r.cpu_seconds;
  j["cpu"] = CpuJson(r.cpu, r.steps);
  if (const auto it = rep.startup.find(c.method); it != rep.startup.end()) j["startup"] = StartupJson(it->second);
  j["settings"] = SettingsJson(r);
  j["messages"] = r.messages;
  const auto res = rep.max_residual.find(c.method);
  j["max_residual"] = res == rep.max_residual.end() ? json(nullptr) : JsonNumber(res->second);
  const MethodVerdict verdict = VerdictOf(rep, c.method);
  j["within"] = verdict.within;
  j["known"] = verdict.known;
  // A known failure's entry (file:line), and an entry that no longer fails (gate.h).
  if (!verdict.known_where.empty()) j["known_entry"] = verdict.known_where;
  if (!verdict.stale.empty()) j["known_stale"] = verdict.stale;
  // What `run` says beside it: figures without a bound (shown, not judged), and whether anything
  // was compared at all (a method that ran alone agrees with nothing).
  if (!verdict.not_judged.empty()) j["not_judged"] = verdict.not_judged;
  if (r.ok() && !verdict.compared) j["compared"] = false;
  if (!verdict.problems.empty()) j["problems"] = verdict.problems;
  if (r.trajectory.size() > 1) {
    const Reference ref = ReferenceFor(m, CaseBudget(o), c.method);
    if (r.ok() && !ref.trajectory.empty())
      j["error"] = ErrorJson(CompareMotion(m, ref.trajectory, r.trajectory), ref.against);
    // The motion to draw: the method's (up to where it stopped, when it did) and what it is
    // judged against, at the same sample times.
    if (json frames = MotionFrames(m, r.trajectory); !frames.is_null()) {
      j["frames"] = std::move(frames);
      j["reference_frames"] = MotionFrames(m, ref.trajectory);
      j["reference_against"] = ref.against;
    }
  }
  return {j};
}

// A run of this much CPU or more is timed once, in a sweep rung or a precision walk's rung: its
// clock's noise is a few per cent, where the median of three would triple the case's cost.
constexpr double kTimeOnceAbove = 0.05;  // [s] of CPU

// Runs that are one computation for two methods (Method::Computation: Simbody's default and tuned
// variants at a swept accuracy, ODE's dWorldStep variants at a swept step) are done once in a
// process: the later method's case gets the earlier's result — its samples, settings and CPU
// times — with a message and a setting saying so, and judges it by its own tolerances. The
// campaign puts such cases next to each other in one batch (ComputationGroup). `occurrence` tells a
// case's runs apart (its k-th repeat shares the other method's k-th; a watched run shares only a
// run watched against the same reference); a run stopped by its CPU budget, or dearer than the
// caller's budget, is not shared.
struct SharedRun {
  std::string key, method;
  Result result;
};
constexpr size_t kSharedRunsKept = 64;
std::deque<SharedRun>& SharedRuns() {
  static std::deque<SharedRun> runs;
  return runs;
}

// `shared_with`, when given, gets the method whose run was shared, or "".
Result RunShared(const Method& meth, const Model& m, const std::string& file, const RunOptions& ro,
                 const std::string& occurrence, std::string* shared_with = nullptr) {
  if (shared_with) shared_with->clear();
  const std::string computation = meth.Computation(ro);
  if (computation.empty()) return meth.Run(m, ro);
  const std::string key = file + "\n" + occurrence + "\n" + computation;
  for (const SharedRun& s : SharedRuns()) {
    if (s.key != key || s.method == meth.name() || s.result.status == Status::kOverBudget ||
        s.result.cpu_seconds > ro.cpu_budget)
      continue;
    Result r = s.result;
    r.method = meth.name();
    r.messages.push_back("the same computation as " + s.method + "'s run (" + computation +
                         "): run once for both, its samples and CPU time shared");
    r.settings["shared_run"] = "run once with " + s.method + ": the same computation";
    if (shared_with) *shared_with = s.method;
    return r;
  }
  Result r = meth.Run(m, ro);
  SharedRuns().push_back({key, meth.name(), r});
  if (SharedRuns().size() > kSharedRunsKept) SharedRuns().pop_front();
  return r;
}

std::vector<json> SweepCase(const Case& c, const CampaignOptions& o) {
  const Model& m = LoadCached(c.file);
  const Method* meth = FindMethod(c.method);
  MB_ASSERT(meth, ("unknown method " + c.method).c_str());
  RunOptions ro;
  if (meth->control() == Control::kStep) ro.step = c.value;
  if (meth->control() == Control::kTolerance) ro.tolerance = c.value;
  const Reference ref = ReferenceFor(m, CaseBudget(o), c.method);
  // The method's one-time costs are paid first, so that no repeat pays them. Each repeat is then
  // a fresh run from the model: nothing is reused between repeats or rungs (only another method's
  // run of the same computation, RunShared). A run of kTimeOnceAbove or more is not repeated.
  const StartupCost startup = WarmUp(*meth, m);
  const int repeats = std::max(1, o.quick ? 1 : o.repeats);
  std::vector<double> cpu, setup, integration, observation;
  Result last;
  std::string shared;
  for (int k = 0; k < repeats; ++k) {
    last = RunShared(*meth, m, c.file, ro, "sweep, repeat " + std::to_string(k), k == 0 ? &shared : nullptr);
    cpu.push_back(last.cpu_seconds);
    setup.push_back(last.cpu.setup);
    integration.push_back(last.cpu.integration);
    observation.push_back(last.cpu.observation);
    if (!last.ok() || last.cpu_seconds >= kTimeOnceAbove) break;
  }
  const auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  };
  std::sort(cpu.begin(), cpu.end());
  json j = Common(c);
  j["method"] = c.method;
  j["control"] = ToString(meth->control());
  j["value"] = JsonNumber(ControlValue(last, c.value));
  j["status"] = ToString(last.status);
  j["reason"] = last.reason;
  j["cpu_seconds"] = cpu[cpu.size() / 2];
  j["cpu_min"] = cpu.front();
  j["cpu_max"] = cpu.back();
  j["cpu"] = CpuJson({median(setup), median(integration), median(observation)}, last.steps);
  j["cpu"]["integration_min"] = *std::min_element(integration.begin(), integration.end());
  j["cpu"]["integration_max"] = *std::max_element(integration.begin(), integration.end());
  j["startup"] = StartupJson(startup);
  j["repeats"] = static_cast<int>(cpu.size());
  if (!shared.empty()) j["shared_with"] = shared;
  j["settings"] = SettingsJson(last);
  double worst = kNaN;
  if (!last.trajectory.empty()) {
    const std::vector<double> res = ScaledResiduals(m, last.trajectory);
    if (!res.empty()) worst = *std::max_element(res.begin(), res.end());
  }
  j["max_residual"] = JsonNumber(worst);
  j["energy_drift"] = JsonNumber(EnergyDrift(m, last.trajectory));
  if (last.ok() && !ref.trajectory.empty())
    j["error"] = ErrorJson(CompareMotion(m, ref.trajectory, last.trajectory), ref.against);
  if (!ref.note.empty()) j["reference_note"] = ref.note;
  return {j};
}

double Seconds(std::chrono::steady_clock::time_point since);

// The ladder a published benchmark's precision search walks, coarse to fine: finer than a
// sweep's at the fine end, since a benchmark's high-precision level may need it.
std::vector<double> PrecisionLadder(Control c) {
  switch (c) {
    case Control::kStep: return {2e-2, 1e-2, 5e-3, 2.5e-3, 1.25e-3, 6.25e-4, 3.125e-4, 1.5625e-4};
    case Control::kTolerance: return {1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12};
    case Control::kNone: break;
  }
  return {kNaN};
}

// A published benchmark's precision levels (Model::criteria), as the IFToMM library compares
// solvers: each method's CPU time to a run that meets each level. The method walks its ladder
// from coarse to fine, each rung a fresh run judged by the benchmark's own criteria (criteria.h),
// until every level is met, its CPU budget (a sixth of the case's time limit, over all rungs) is
// spent (a rung stopped by the budget ends the walk, since every finer rung costs more). The CPU
// of the coarsest (cheapest) rung meeting a level is then the median of `repeats` runs of it
// (one run for a rung of kTimeOnceAbove or more; the method's own work, Result::cpu_seconds; start-up is paid before, as in a sweep).

std::vector<json> PrecisionCase(const Case& c, const CampaignOptions& o, std::chrono::steady_clock::time_point case_start) {
  const Model& m = LoadCached(c.file);
  const Method* meth = FindMethod(c.method);
  MB_ASSERT(meth && m.criteria, ("precision case without method or criteria: " + c.id).c_str());
  const Criteria& crit = *m.criteria;
  json j = Common(c);
  j["method"] = c.method;
  j["control"] = ToString(meth->control());
  j["point"] = crit.name;
  j["levels"] = crit.levels;
  j["output_steps"] = crit.output_steps;
  j["levels_source"] = crit.source;
  j["rungs"] = json::array();
  j["met"] = json::array();
  j["reason"] = "";
  if (std::optional<std::string> why = meth->Applicability(m)) {
    j["status"] = ToString(Status::kNotApplicable);
    j["reason"] = *why;
    for (size_t i = 0; i < crit.levels.size(); ++i) j["met"].push_back(nullptr);
    return {j};
  }
  const Reference ref = ReferenceFor(m, CaseBudget(o), c.method);
  if (ref.trajectory.empty() || !ref.trusted) {
    j["status"] = ToString(Status::kFailed);
    j["reason"] = "no reference to judge against: " + ref.note;
    for (size_t i = 0; i < crit.levels.size(); ++i) j["met"].push_back(nullptr);
    return {j};
  }
  // The walk must end well inside the case's time limit, which is wall time: on a loaded machine
  // a run's wall time exceeds its CPU time, so each rung's CPU budget is the wall time left
  // scaled by the CPU share the runs so far got.
  const auto start = std::chrono::steady_clock::now();
  const double budget = o.timeout / 6;
  const double allowance = 0.7 * o.timeout - Seconds(case_start);
  j["budget_seconds"] = budget;
  const StartupCost startup = WarmUp(*meth, m);
  j["startup"] = StartupJson(startup);
  // A rung whose point has passed the loosest level at some output step can meet no level, so
  // its run stops there (RunOptions::watch) instead of following a lost motion to the end; the
  // timed repeats of a rung that met a level run whole, unwatched.
  const double loosest = *std::max_element(crit.levels.begin(), crit.levels.end());
  std::set<std::string> shared;  // the methods whose runs this walk shared (RunShared)
  const auto run_at = [&](double value, double cpu_budget, bool watch, const std::string& occurrence) {
    RunOptions ro;
    if (meth->control() == Control::kStep) ro.step = value;
    if (meth->control() == Control::kTolerance) ro.tolerance = value;
    ro.cpu_budget = cpu_budget;
    size_t k = 0;
    if (watch)
      ro.watch = [&](const Sample& s) -> std::optional<std::string> {
        const size_t i = k++;
        if (i >= ref.trajectory.size() || std::fabs(ref.trajectory[i].t - s.t) > 1e-9 * (1 + std::fabs(s.t))) return std::nullopt;
        const double d = CriteriaDistance(m, ref.trajectory[i], s);
        if (d <= loosest) return std::nullopt;
        return "the benchmark's point is " + Fmt(d, 3) + " from its reference, past the loosest level (" + Fmt(loosest, 3) +
               "): no level can be met";
      };
    std::string with;
    Result r = RunShared(*meth, m, c.file, ro, "precision " + occurrence + " against " + ref.against, &with);
    if (!with.empty()) shared.insert(with);
    return r;
  };
  struct Rung {
    double value, cpu;
    std::vector<bool> met;
    double reached = 1;  // the share of the horizon its run covered (below 1: stopped by the watch)
    double setup = 0;    // its set-up CPU, paid once whatever the horizon [s]
    // The least CPU the next rung needs to get as far as this one, or to the end of the horizon
    // when this one stopped part-way (only a whole run meets a level).
    double NextNeeds(double growth) const { return reached < 1 ? setup + growth * (cpu - setup) / reached : growth * cpu; }
  };
  std::vector<Rung> rungs;
  std::vector<double> diverged_at;  // per rung: the last sample of a diverged run [s], else NaN
  constexpr size_t kSameDivergence = 3;
  double spent = 0;
  std::string stop;  // why the walk ended
  const auto left = [&] {
    const double wall = Seconds(start);
    // Until a run has measured it, assume the machine's other work halves this process's share.
    const double share = wall > 0.5 ? std::clamp(spent / wall, 0.1, 1.0) : 0.5;
    return std::min(budget - spent, (allowance - wall) * share);
  };
  // A rung costs at least what the one before it spent (a halved step twice that) before it gets
  // as far: a rung the budget left cannot pay for would stop over budget, telling nothing, so the
  // walk ends before it. A level is met only by a rung that runs the whole horizon, so after a
  // rung the watch stopped part-way (its share `reached` of the horizon) the next one must pay for
  // the whole at that rate (Rung::NextNeeds): set-up + growth × (cpu − set-up) / reached.
  const double growth = meth->control() == Control::kStep ? 2.0 : 1.0;
  const double horizon = m.analysis.t1 - m.analysis.t0;
  for (double v : PrecisionLadder(meth->control())) {
    if (left() <= 0) break;
    if (!rungs.empty() && left() < rungs.back().NextNeeds(growth)) {
      const Rung& last = rungs.back();
      stop = "its CPU budget could not pay for the next rung (" + std::string(ToString(meth->control())) + " " + Fmt(v, 4) +
             ": at least " + Fmt(last.NextNeeds(growth), 3) + " s" +
             (last.reached < 1 ? " to run the whole horizon (the last rung stopped at " + Fmt(100 * last.reached, 3) + " % of it)"
                               : std::string()) +
             ", " + Fmt(std::max(0.0, left()), 3) + " s left)";
      break;
    }
    const Result r = run_at(v, left(), true, "walk");
    spent += r.cpu_seconds;
    json rj = {{"value", JsonNumber(ControlValue(r, v))}, {"status", ToString(r.status)}, {"reason", r.reason},
               {"cpu_seconds", r.cpu_seconds}, {"steps", r.steps >= 0 ? json(r.steps) : json(nullptr)}};
    Rung rung{v, r.cpu_seconds, std::vector<bool>(crit.levels.size(), false)};
    if (r.status == Status::kStopped) {
      // Judged on the samples it reached: the error there is a lower bound of the whole run's.
      if (!r.trajectory.empty() && horizon > 0)
        rung.reached = std::clamp((r.trajectory.back().t - m.analysis.t0) / horizon, 1e-9, 1.0);
      rung.setup = std::min(r.cpu.setup, r.cpu_seconds);
      const CriteriaVerdict verdict = JudgeCriteria(m, ref.trajectory, r.trajectory);
      rj["error"] = JsonNumber(verdict.error);
      rj["t"] = JsonNumber(verdict.t);
      rj["complete"] = false;
      rj["verdict"] = "meets neither level: past " + Fmt(loosest, 3) + " at t = " + Fmt(verdict.t, 4) + " s (stopped there)";
    }
    if (r.ok()) {
      const CriteriaVerdict verdict = JudgeCriteria(m, ref.trajectory, r.trajectory);
      rj["error"] = JsonNumber(verdict.error);
      rj["t"] = JsonNumber(verdict.t);
      rj["complete"] = verdict.complete;
      rj["verdict"] = verdict.Verdict(crit);
      rung.met = verdict.met;
    }
    j["rungs"].push_back(rj);
    rungs.push_back(rung);
    if (r.status == Status::kOverBudget) {
      stop = "its CPU budget ran out at " + std::string(ToString(meth->control())) + " " + Fmt(v, 4);
      break;
    }
    if (std::all_of(rung.met.begin(), rung.met.end(), [](bool b) { return b; })) {
      stop = "every level met";
      break;
    }
    // An error-controlled method that diverges before the same sample at three tolerances in a row
    // is stopped by the motion (a singular position its formulation cannot pass), not by its
    // accuracy: finer tolerances cost more and stop there too.
    diverged_at.push_back(r.status == Status::kDiverged && !r.trajectory.empty() ? r.trajectory.back().t : kNaN);
    if (meth->control() == Control::kTolerance && diverged_at.size() >= kSameDivergence) {
      const double t = diverged_at.back();
      if (std::all_of(diverged_at.end() - kSameDivergence, diverged_at.end(), [&](double x) { return x == t; })) {
        stop = "it diverged before the same sample (t = " + Fmt(t, 6) + " s) at " + std::to_string(kSameDivergence) +
               " tolerances in a row: the motion stops it there, not its accuracy";
        break;
      }
    }
    // No rule stops a walk whose error does not fall yet: over a long motion the coarse rungs'
    // errors saturate at the motion's size (a phase lost) until the rungs are fine enough, as
    // DOPRI5's on A01 do down to rtol 1e-6 before it meets both levels at 1e-9. Such rungs are
    // cheap: each stops where its point first passes the loosest level.
  }
  if (stop.empty()) stop = rungs.size() == PrecisionLadder(meth->control()).size() ? "the ladder's end" : "its CPU budget ran out";
  j["stop"] = stop;
  // Per level, the coarsest rung that meets it (each finer rung does more work: the cheapest,
  // without asking a noisy clock to rank runs of a few milliseconds), timed again for the median.
  std::map<size_t, std::vector<double>> times;  // rung -> CPU of its runs
  std::vector<int> best(crit.levels.size(), -1);
  for (size_t l = 0; l < crit.levels.size(); ++l)
    for (size_t k = 0; k < rungs.size() && best[l] < 0; ++k)
      if (rungs[k].met[l]) best[l] = static_cast<int>(k);
  const int repeats = std::max(1, o.quick ? 1 : o.repeats);
  for (int k : best) {
    if (k < 0 || times.count(static_cast<size_t>(k))) continue;
    std::vector<double>& t = times[static_cast<size_t>(k)];
    t.push_back(rungs[static_cast<size_t>(k)].cpu);
    // A rung of kTimeOnceAbove or more is timed once: two more runs would be most of the walk's cost.
    for (int rep = 1; rep < repeats && t.back() < kTimeOnceAbove && t.back() <= left(); ++rep) {
      const Result r = run_at(rungs[static_cast<size_t>(k)].value, left(), false, "repeat " + std::to_string(rep));
      spent += r.cpu_seconds;
      if (!r.ok()) break;
      t.push_back(r.cpu_seconds);
    }
    std::sort(t.begin(), t.end());
  }
  for (int k : best) {
    if (k < 0) {
      j["met"].push_back(nullptr);
      continue;
    }
    const std::vector<double>& t = times[static_cast<size_t>(k)];
    j["met"].push_back({{"value", j["rungs"][static_cast<size_t>(k)]["value"]}, {"cpu_seconds", t[t.size() / 2]},
                        {"cpu_min", t.front()}, {"cpu_max", t.back()}, {"repeats", static_cast<int>(t.size())},
                        {"error", j["rungs"][static_cast<size_t>(k)]["error"]}});
  }
  j["status"] = "ok";
  j["cpu_seconds"] = spent;
  if (!shared.empty()) j["shared_with"] = *shared.begin();
  return {j};
}

std::vector<json> StressCase(const Case& c, const CampaignOptions& o) {
  const StressVariant& v = Variant(c.variant, c.scenario);
  const Model m = CaseModel(c);
  const Method* meth = FindMethod(c.method);
  MB_ASSERT(meth, ("unknown method " + c.method).c_str());
  json j = Common(c);
  j["scenario"] = v.base.empty() ? m.name : v.base;
  j["case"] = v.id;
  j["family"] = v.family;
  j["description"] = v.description;
  j["method"] = c.method;
  j["tolerance"] = v.tolerance;
  std::optional<std::string> why = meth->Applicability(m);
  if (!why && m.IsFree() && meth->control() == Control::kNone)
    why = "a kinematic method gives a free scene's instant only; its motion is forward dynamics";
  if (!why && std::isfinite(v.step) && meth->control() != Control::kStep)
    why = "the case is about the step of fixed-step methods; this method has none";
  if (why) {
    j["outcome"] = "not_applicable";
    j["detail"] = *why;
    j["cpu_seconds"] = 0.0;
    return {j};
  }
  const StartupCost startup = WarmUp(*meth, m);
  const Result r = meth->Run(m, {.step = v.step, .cpu_budget = CaseBudget(o)});
  const Reference ref = r.ok() ? ReferenceFor(m, CaseBudget(o), c.method) : Reference{};
  const Classified cl = Classify(m, r, ref, v.tolerance);
  j["outcome"] = cl.outcome;
  j["detail"] = cl.detail;
  j["t_fail"] = JsonNumber(cl.t_fail);
  j["cpu_seconds"] = r.cpu_seconds;
  j["cpu"] = CpuJson(r.cpu, r.steps);
  j["startup"] = StartupJson(startup);
  j["max_residual"] = JsonNumber(cl.max_residual);
  j["energy_drift"] = JsonNumber(cl.energy_drift);
  j["settings"] = SettingsJson(r);
  if (cl.has_error) j["error"] = ErrorJson(cl.error, ref.against);
  return {j};
}

std::vector<json> StableStepCase(const Case& c, const CampaignOptions& o) {
  Model m = LoadCached(c.file);
  m.analysis.samples = kStableStepSamples;
  const Method* meth = FindMethod(c.method);
  MB_ASSERT(meth && meth->control() == Control::kStep, ("stable-step case for a method without a step: " + c.method).c_str());
  const Reference ref = ReferenceFor(m, CaseBudget(o));
  const double cap = (m.analysis.t1 - m.analysis.t0) / (m.analysis.samples - 1);  // the sample interval [s]
  json tried = json::array();
  // One probe: a run at step h in its own process (a step far too large may crash an engine).
  auto probe = [&](double h) {
    json p = RunIsolated(
        [&] {
          const Result r = meth->Run(m, {.step = h});
          const Classified cl = Classify(m, r, ref, 1e-2);
          return json{{"outcome", cl.outcome}, {"detail", cl.detail}, {"q_max", JsonNumber(cl.has_error ? cl.error.q.max : kNaN)}};
        },
        std::max(5.0, o.timeout / 4));
    if (p.contains("isolation")) p = {{"outcome", p["isolation"]}, {"detail", p["detail"]}, {"q_max", nullptr}};
    const double q = p["q_max"].is_number() ? p["q_max"].get<double>() : kNaN;
    const bool stable = Stable(p["outcome"].get<std::string>(), q);
    std::string detail = p["detail"].get<std::string>();
    if (!stable && (p["outcome"] == "ok" || p["outcome"] == "inaccurate"))
      detail = "qualitatively wrong (" + detail + ")";
    tried.push_back({{"step", h}, {"outcome", p["outcome"]}, {"detail", detail}, {"stable", stable}});
    return stable;
  };
  // Steps are tried as the sample interval / k (k whole), because a method shortens its step
  // evenly to land on every sample: any other step would run as the next such value anyway.
  long stable_k = 0, unstable_k = 0;  // the largest stable step is cap / stable_k
  const long k0 = StepsTo(0, cap, meth->default_control()).n;
  std::string limit;
  if (probe(cap / static_cast<double>(k0))) {
    stable_k = k0;
    while (stable_k > 1) {
      const long k = std::max(1L, stable_k / 2);
      if (!probe(cap / static_cast<double>(k))) {
        unstable_k = k;
        break;
      }
      stable_k = k;
    }
    if (!unstable_k) limit = "stable up to the sample interval " + Fmt(cap, 3) + " s (steps are shortened to land on samples)";
  } else {
    unstable_k = k0;
    while (unstable_k < 10000) {
      const long k = unstable_k * 4;
      if (probe(cap / static_cast<double>(k))) {
        stable_k = k;
        break;
      }
      unstable_k = k;
    }
    if (!stable_k)
      limit = "no stable step down to " + Fmt(cap / static_cast<double>(unstable_k), 3) + " s (there: " +
              tried.back()["outcome"].get<std::string>() + ", " + tried.back()["detail"].get<std::string>() + ")";
  }
  if (stable_k && unstable_k) {
    // Geometric bisection on k until the two steps are within 5 % (or adjacent k).
    while (stable_k - unstable_k > 1 && static_cast<double>(stable_k) / static_cast<double>(unstable_k) > 1.05) {
      long mid = std::lround(std::sqrt(static_cast<double>(stable_k) * static_cast<double>(unstable_k)));
      mid = std::clamp(mid, unstable_k + 1, stable_k - 1);
      (probe(cap / static_cast<double>(mid)) ? stable_k : unstable_k) = mid;
    }
    limit = "bisected to within " + Fmt(100.0 * (static_cast<double>(stable_k) / static_cast<double>(unstable_k) - 1), 3) + " %";
  }
  const double lo = stable_k ? cap / static_cast<double>(stable_k) : kNaN;
  const double hi = unstable_k ? cap / static_cast<double>(unstable_k) : kNaN;
  json j = Common(c);
  j["method"] = c.method;
  j["largest_stable"] = JsonNumber(lo);
  j["first_unstable"] = JsonNumber(hi);
  j["limit"] = limit + "; " + std::to_string(kStableStepSamples) + " samples over " +
               Fmt(m.analysis.t1 - m.analysis.t0) + " s; stable = ok or inaccurate with position error ≤ " +
               Fmt(kQualitative);
  j["tried"] = tried;
  if (!ref.note.empty()) j["reference_note"] = ref.note;
  return {j};
}

// The records a case stands for when its process died or overran.
std::vector<json> FallbackRecords(const Case& c, const std::string& what, const std::string& detail, double wall) {
  json j = Common(c);
  j["isolation"] = detail;
  if (c.kind == "check") {
    j["rows"] = json::array();
  } else if (c.kind == "run" || c.kind == "sweep") {
    j["method"] = c.method;
    j["status"] = what;
    j["reason"] = detail;
    j["cpu_seconds"] = wall;
    j["cpu"] = nullptr;  // the process died: no phases
    j["settings"] = json::object();
    j["max_residual"] = nullptr;
    if (c.kind == "run") {
      j["within"] = false;
      j["known"] = "";
    } else {
      const Method* m = FindMethod(c.method);
      j["control"] = ToString(m ? m->control() : Control::kNone);
      j["value"] = JsonNumber(c.value);
      j["cpu_min"] = wall;
      j["cpu_max"] = wall;
      j["repeats"] = 1;
      j["energy_drift"] = nullptr;
    }
  } else if (c.kind == "precision") {
    const Model& m = LoadCached(c.file);
    const Method* meth = FindMethod(c.method);
    j["method"] = c.method;
    j["control"] = ToString(meth ? meth->control() : Control::kNone);
    j["point"] = m.criteria ? m.criteria->name : "";
    j["levels"] = m.criteria ? m.criteria->levels : std::vector<double>{};
    j["output_steps"] = m.criteria ? m.criteria->output_steps : 0;
    j["rungs"] = json::array();
    j["met"] = json::array();
    for (size_t i = 0; m.criteria && i < m.criteria->levels.size(); ++i) j["met"].push_back(nullptr);
    j["status"] = what;
    j["reason"] = detail;
    j["cpu_seconds"] = wall;
  } else if (c.kind == "stress") {
    const StressVariant& v = Variant(c.variant, c.scenario);
    if (v.base.empty()) j["scenario"] = v.derive(Model{}).name;
    j["case"] = c.variant;
    j["family"] = v.family;
    j["description"] = v.description;
    j["method"] = c.method;
    j["outcome"] = what;
    j["detail"] = detail;
    j["t_fail"] = nullptr;
    j["cpu_seconds"] = wall;
    j["tolerance"] = v.tolerance;
  } else if (c.kind == "chain") {
    return {ChainFallback(c, what, detail, wall)};
  } else {
    j["method"] = c.method;
    j["largest_stable"] = nullptr;
    j["first_unstable"] = nullptr;
    j["limit"] = what + ": " + detail;
    j["tried"] = json::array();
  }
  return {j};
}

// ---- processes (process.h) ------------------------------------------------------------------------

ChildProcess Spawn(const std::function<json()>& fn) {
  return ChildProcess::Spawn([fn] { return fn().dump(); });
}

// A finished child's JSON, or why there is none: {"isolation": "crashed"|"timed_out", "detail"}.
json Finish(ChildProcess& c, bool kill, double timeout) {
  const ChildOutcome o = c.Finish(kill, timeout);
  if (o.kind == ChildOutcome::kTimedOut) return {{"isolation", "timed_out"}, {"detail", o.detail}};
  if (o.kind == ChildOutcome::kCrashed) return {{"isolation", "crashed"}, {"detail", o.detail}};
  try {
    return json::parse(o.payload);
  } catch (const std::exception& e) {
    return {{"isolation", "crashed"}, {"detail", std::string("unreadable output: ") + e.what()}};
  }
}

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

std::string Clock(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%d:%02d", static_cast<int>(s) / 60, static_cast<int>(s) % 60);
  return buf;
}

}  // namespace

StressOutcome ClassifyRun(const Model& model, const Result& result, const std::vector<Sample>& reference,
                          double tolerance) {
  Reference ref;
  ref.trajectory = reference;
  ref.against = "the given reference";
  ref.trusted = !reference.empty();
  const Classified c = Classify(model, result, ref, tolerance);
  return {c.outcome, c.detail, c.t_fail};
}

json RunIsolated(const std::function<json()>& fn, double timeout) {
  const ChildOutcome o = RunInChild([&fn] { return fn().dump(); }, timeout);
  if (o.kind == ChildOutcome::kTimedOut) return {{"isolation", "timed_out"}, {"detail", o.detail}};
  if (o.kind == ChildOutcome::kCrashed) return {{"isolation", "crashed"}, {"detail", o.detail}};
  try {
    return json::parse(o.payload);
  } catch (const std::exception& e) {
    return {{"isolation", "crashed"}, {"detail", std::string("unreadable output: ") + e.what()}};
  }
}

std::vector<Case> EnumerateCases(const CampaignOptions& o) {
  std::vector<std::string> files;
  if (!o.scenarios.empty()) {
    for (const std::string& s : o.scenarios) files.push_back(ResolveScenario(s));
  } else if (o.quick) {
    for (const std::string& s : kQuickScenarios) files.push_back(ResolveScenario(s));
  } else {
    files = BuiltinScenarioFiles();
  }
  std::vector<const Method*> methods;
  const std::set<std::string> wanted(o.methods.begin(), o.methods.end());
  std::set<std::string> unknown = wanted;
  for (const MethodPtr& m : Methods())
    if (wanted.empty() || wanted.count(m->name())) {
      methods.push_back(m.get());
      unknown.erase(m->name());
    }
  if (!unknown.empty()) {
    std::string known;
    for (const MethodPtr& m : Methods()) known += " " + m->name();
    throw ScenarioError({"--method", 0}, "unknown method '" + *unknown.begin() + "'", "built-in methods:" + known);
  }
  std::vector<Case> cases;
  auto add = [&](Case c) {
    c.index = static_cast<int>(cases.size());
    cases.push_back(std::move(c));
  };
  std::map<std::string, std::string> file_of;  // scenario name -> file
  for (const std::string& f : files) file_of[LoadCached(f).name] = f;
  if (o.check)
    for (const std::string& f : files) {
      const Model& m = LoadCached(f);
      if (!m.book.empty()) add({0, "check/" + m.name, "check", m.name, f, "", "", kNaN});
    }
  if (o.run)
    for (const std::string& f : files)
      for (const Method* meth : methods) {
        const Model& m = LoadCached(f);
        add({0, "run/" + m.name + "/" + meth->name(), "run", m.name, f, meth->name(), "", kNaN});
      }
  if (o.sweep)
    for (const std::string& f : files) {
      const Model& m = LoadCached(f);
      if (!m.analysis.HasMotion()) continue;
      for (const Method* meth : methods) {
        if (meth->Applicability(m)) continue;
        // Kinematic methods do not integrate a free scene's motion: nothing to sweep there.
        if (meth->control() == Control::kNone && m.IsFree()) continue;
        for (double v : Ladder(meth->control(), o.quick)) {
          const std::string rung = meth->control() == Control::kNone ? "exact"
                                                                      : std::string(ToString(meth->control())) + "=" + Fmt(v, 4);
          add({0, "sweep/" + m.name + "/" + meth->name() + "/" + rung, "sweep", m.name, f, meth->name(), "", v});
        }
      }
    }
  if (o.precision) {
    // The benchmark files come in for their precision levels and book checks only (their runs
    // and sweeps are long: `run` them by path).
    std::vector<std::string> with = files;
    if (o.scenarios.empty() && !o.quick)
      for (const std::string& f : BenchmarkScenarioFiles()) {
        const Model& m = LoadCached(f);
        if (o.check && !m.book.empty()) add({0, "check/" + m.name, "check", m.name, f, "", "", kNaN});
        with.push_back(f);
      }
    for (const std::string& f : with) {
      const Model& m = LoadCached(f);
      if (!m.criteria || !m.analysis.HasMotion()) continue;
      for (const Method* meth : methods) {
        if (meth->control() == Control::kNone && m.IsFree()) continue;
        add({0, "precision/" + m.name + "/" + meth->name(), "precision", m.name, f, meth->name(), "", kNaN});
      }
    }
  }
  if (o.stress) {
    for (const StressVariant& v : StressVariants()) {
      if (o.quick && !kQuickVariants.count(v.id)) continue;
      std::string file;
      if (!v.base.empty()) {
        auto it = file_of.find(v.base);
        if (it == file_of.end()) continue;  // its family's base is not in the selection
        file = it->second;
      } else if (!o.scenarios.empty()) {
        continue;  // generated scenes join only the full report
      }
      for (const Method* meth : methods)
        add({0, "stress/" + (v.base.empty() ? "generated" : v.base) + "/" + v.id + "/" + meth->name(), "stress", v.base,
             file, meth->name(), v.id, kNaN});
    }
    for (const std::string& name : StableStepScenarios(o.quick)) {
      auto it = file_of.find(name);
      if (it == file_of.end()) continue;
      for (const Method* meth : methods)
        if (meth->control() == Control::kStep && !meth->Applicability(LoadCached(it->second)))
          add({0, "stable_step/" + name + "/" + meth->name(), "stable_step", name, it->second, meth->name(), "", kNaN});
    }
  }
  if (o.chains && !o.quick && o.scenarios.empty())
    for (const Method* meth : methods)
      if (ChainMethod(*meth)) add(ChainCaseFor(meth->name()));
  if (o.shards > 1) {
    std::vector<Case> mine;
    for (const Case& c : cases)
      if (c.index % o.shards == o.shard - 1) mine.push_back(c);
    return mine;
  }
  return cases;
}

std::vector<json> RunCase(const Case& c, const CampaignOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  // Fault injection for the isolation tests: MECHBENCH_FAULT="abort:<case id>" or
  // "hang:<case id>" makes that case abort or hang, as a misbehaving engine would.
  if (const char* fault = std::getenv("MECHBENCH_FAULT")) {
    const std::string f = fault;
    if (f == "abort:" + c.id) std::abort();
    if (f == "hang:" + c.id)
      for (;;) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  std::vector<json> out;
  if (c.kind == "check") out = CheckCase(c);
  else if (c.kind == "run") out = RunMethodCase(c, o);
  else if (c.kind == "sweep") out = SweepCase(c, o);
  else if (c.kind == "stress") out = StressCase(c, o);
  else if (c.kind == "stable_step") out = StableStepCase(c, o);
  else if (c.kind == "precision") out = PrecisionCase(c, o, t0);
  else if (c.kind == "chain") out = ChainCase(c, o);
  else MB_ASSERT(false, ("unknown case kind " + c.kind).c_str());
  for (json& j : out) j["wall_seconds"] = Seconds(t0);
  return out;
}

std::vector<json> ExecuteCases(const std::vector<Case>& cases, const CampaignOptions& o) {
  std::vector<std::vector<json>> done(cases.size());
  const auto start = std::chrono::steady_clock::now();
  const bool tty = ::isatty(2);
  size_t finished = 0;
  int last_decile = 0;
  double last_line = 0;
  auto progress = [&](const Case& c) {
    if (!o.progress) return;
    ++finished;
    const double el = Seconds(start);
    if (tty) {
      std::fprintf(stderr, "\r\033[K[%zu/%zu] %s %s", finished, cases.size(), Clock(el).c_str(), c.id.c_str());
      if (finished == cases.size()) std::fprintf(stderr, "\n");
    } else {
      const int decile = static_cast<int>(10 * finished / cases.size());
      if (decile > last_decile || el - last_line > 30 || finished == cases.size()) {
        std::fprintf(stderr, "[%zu/%zu] %s elapsed, %zu left; last: %s\n", finished, cases.size(), Clock(el).c_str(),
                     cases.size() - finished, c.id.c_str());
        last_decile = decile;
        last_line = el;
      }
    }
  };
  // Free scenes' reference trajectories first, one process each, so that the workers find them
  // in the cache instead of each computing the same one.
  if (o.isolate && !ReferenceCacheDir().empty()) {
    std::set<std::string> seen;
    std::vector<Case> refs;
    for (const Case& c : cases) {
      if (c.kind == "check" || c.kind == "chain" || seen.count(c.scenario + "@" + c.variant)) continue;
      seen.insert(c.scenario + "@" + c.variant);
      refs.push_back(c);
    }
    std::vector<ChildProcess> running;
    size_t next = 0;
    while (next < refs.size() || !running.empty()) {
      while (static_cast<int>(running.size()) < std::max(1, o.jobs) && next < refs.size()) {
        const Case c = refs[next++];
        running.push_back(Spawn([c, &o] {
          const Model m = CaseModel(c);
          if (m.IsFree() && m.analysis.HasMotion() && m.HasMass()) GetReference(m, CaseBudget(o));
          return json::object();
        }));
      }
      for (size_t i = 0; i < running.size();) {
        const bool done_now = running[i].Pump();
        if (done_now || running[i].Elapsed() > o.timeout) {
          running[i].Finish(!done_now, o.timeout);  // a reference not done in time is computed by the cases
          running.erase(running.begin() + static_cast<long>(i));
        } else {
          ++i;
        }
      }
      if (!running.empty()) ::usleep(20000);
    }
  }
  if (!o.isolate) {
    for (size_t i = 0; i < cases.size(); ++i) {
      done[i] = RunCase(cases[i], o);
      progress(cases[i]);
    }
  } else {
    // Cases run in batches, one process per batch: a method's runs, sweep rungs, stress and
    // stable-step cases (each kind apart) share a process, so that the engines' first-use costs after the fork
    // (MuJoCo's model compiler, Bullet's allocations touching memory again: ~50 ms a process)
    // are paid once per batch instead of once per rung. Each answer comes back when its case is
    // done; a case that crashes or overruns is that case's row, and the batch's remaining cases
    // go on in a new process. A method's start-up is measured where it is first used in a
    // process (WarmUp), so the batch's first case carries it (the report's start-up figures are
    // per method, over the cases that measured them). Checks, precision walks and chains keep a
    // process each.
    const auto rank = [](const std::string& kind) { return kind == "precision" ? 0 : kind == "stress" || kind == "stable_step" ? 1 : 2; };
    const auto batched = [](const std::string& kind) {
      return kind == "sweep" || kind == "run" || kind == "stress" || kind == "stable_step" || kind == "precision";
    };
    // The batch a case joins: its method's, or, for the kinds whose runs override the control, the
    // computation its method does under an override (Method::Computation at a probe value), which
    // two methods may share: their cases then go side by side into one batch, and the runs they
    // have in common are done once (RunShared). A precision walk is long: it shares a batch only
    // with the same walk on the same scene.
    std::map<std::string, std::string> computation;  // method -> its computation under an override
    const auto group_of = [&](const Case& c) {
      if (c.kind != "sweep" && c.kind != "precision") return c.method;
      auto it = computation.find(c.method);
      if (it == computation.end()) {
        std::string text;
        if (const Method* meth = FindMethod(c.method)) {
          RunOptions probe;
          probe.step = probe.tolerance = 1.2345678901234e-4;  // any override: the text holds it
          text = meth->Computation(probe);
        }
        it = computation.emplace(c.method, text.empty() ? c.method : text).first;
      }
      return c.kind == "precision" ? c.file + "\n" + it->second : it->second;
    };
    constexpr size_t kMaxBatch = 24;
    std::vector<size_t> order(cases.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    // The long kinds start first (a benchmark's precision walk, a stress case, a stable-step
    // search take seconds where a sweep rung takes milliseconds), so that no worker is left with
    // one of them while the others have nothing to do. Records keep the cases' order.
    // Within a rank, a method's batchable cases of one kind come together.
    std::vector<std::string> group(cases.size());
    for (size_t i = 0; i < cases.size(); ++i) group[i] = batched(cases[i].kind) ? cases[i].kind + "|" + group_of(cases[i]) : "";
    // Within a group, a scene's cases at one control value come together (the runs two methods
    // share follow each other).
    const auto key = [&](size_t i) {
      const Case& c = cases[i];
      const bool b = batched(c.kind);
      return std::make_tuple(rank(c.kind), group[i], b ? c.file : std::string(), b && !std::isnan(c.value) ? c.value : 0.0);
    };
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return key(a) < key(b); });
    std::deque<std::vector<size_t>> queue;
    std::map<std::string, size_t> open;  // group -> its batch still taking cases
    for (size_t i : order) {
      const Case& c = cases[i];
      auto it = open.find(group[i]);
      if (batched(c.kind) && it != open.end() && queue[it->second].size() < kMaxBatch) {
        queue[it->second].push_back(i);
        continue;
      }
      queue.push_back({i});
      if (batched(c.kind)) open[group[i]] = queue.size() - 1;
    }
    struct Running {
      ChildProcess child;
      std::vector<size_t> batch;
      size_t answered = 0;
      std::chrono::steady_clock::time_point since;  // the current case's start
    };
    std::vector<Running> running;
    while (!queue.empty() || !running.empty()) {
      while (static_cast<int>(running.size()) < std::max(1, o.jobs) && !queue.empty()) {
        std::vector<size_t> batch = std::move(queue.front());
        queue.pop_front();
        ChildProcess child = ChildProcess::SpawnStreaming([&cases, &o, batch](const ChildProcess::Send& send) {
          for (size_t i : batch) {
            json arr = json::array();
            for (json& j : RunCase(cases[i], o)) arr.push_back(std::move(j));
            send(arr.dump());
          }
        });
        running.push_back({std::move(child), std::move(batch), 0, std::chrono::steady_clock::now()});
      }
      std::vector<pollfd> fds;
      for (const Running& r : running) {
        fds.push_back({r.child.fd(), POLLIN, 0});
        if (r.child.err_fd() >= 0) fds.push_back({r.child.err_fd(), POLLIN, 0});
      }
      ::poll(fds.data(), fds.size(), 200);
      for (size_t k = 0; k < running.size();) {
        Running& r = running[k];
        const bool eof = r.child.Pump();
        std::string answer;
        while (r.answered < r.batch.size() && r.child.NextAnswer(answer)) {
          const size_t i = r.batch[r.answered++];
          try {
            for (json& j : json::parse(answer)) done[i].push_back(std::move(j));
          } catch (const std::exception& e) {
            done[i] = FallbackRecords(cases[i], "crashed", std::string("unreadable output: ") + e.what(), Seconds(r.since));
          }
          r.since = std::chrono::steady_clock::now();
          progress(cases[i]);
        }
        const double wall = Seconds(r.since);
        const bool late = !eof && wall > o.timeout;
        if (!eof && !late) {
          ++k;
          continue;
        }
        const json got = Finish(r.child, late, o.timeout);
        if (r.answered < r.batch.size()) {
          // The case under way is the one that died or overran; the rest go on in a new process.
          const size_t i = r.batch[r.answered];
          const std::string what = got.value("isolation", "crashed");
          const std::string detail = got.is_object() && got.contains("detail") ? got.value("detail", "")
                                                                               : "the process ended before its answer";
          done[i] = FallbackRecords(cases[i], what, detail, wall);
          for (json& j : done[i]) j["wall_seconds"] = wall;
          progress(cases[i]);
          if (r.answered + 1 < r.batch.size())
            queue.push_front(std::vector<size_t>(r.batch.begin() + static_cast<long>(r.answered) + 1, r.batch.end()));
        }
        running.erase(running.begin() + static_cast<long>(k));
      }
    }
  }
  std::vector<json> records;
  for (auto& v : done)
    for (json& j : v) records.push_back(std::move(j));
  return records;
}

}  // namespace mechbench::harness
