#include "mechbench/harness/compare.h"

#include "mechbench/harness/isolated.h"
#include "mechbench/harness/output.h"
#include "mechbench/harness/reference.h"
#include "mechbench/numeric/reference.h"

#include "mechbench/expr.h"
#include "mechbench/format.h"
#include "mechbench/motion_error.h"
#include "mechbench/numeric/constraints.h"
#include "mechbench/numeric/forward_dynamics.h"
#include "mechbench/numeric/natural_data.h"
#include "mechbench/numeric/natural_model.h"

#include <algorithm>
#include <array>
#include <map>
#include <regex>
#include <set>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <sstream>

namespace mechbench::harness {

std::optional<double> EvalQuantity(const std::string& expr, const Quantities& q, const Model& model) {
  bool missing = false;
  const double v = EvalExpr(expr, [&](const std::string& name) -> std::optional<double> {
    if (auto it = q.find(name); it != q.end()) return it->second;
    if (auto it = model.constants.find(name); it != model.constants.end()) return it->second;
    std::string alias;
    if (name.size() > 1 && (name[0] == 'x' || name[0] == 'y') && model.PointIndex(name.substr(1)) >= 0)
      alias = "p." + name.substr(1) + (name[0] == 'x' ? ".x" : ".y");
    else if (model.SlotIndex(name) >= 0)
      alias = "q." + name;
    if (!alias.empty())
      if (auto it = q.find(alias); it != q.end()) return it->second;
    static const std::set<std::string> kWords{"pi", "deg", "rpm", "rad", "s", "m"};
    if (kWords.count(name)) return std::nullopt;  // a constant or unit word of the reader
    missing = true;
    return 0.0;  // keep evaluating; the whole value is discarded below
  });
  if (missing) return std::nullopt;
  return v;
}

Quantities SampleQuantities(const Model& model, const Sample& s) {
  Quantities out;
  const auto put = [&](const char* kind, const Eigen::VectorXd& v) {
    if (v.size() != static_cast<Eigen::Index>(model.q_layout.size())) return;
    for (size_t i = 0; i < model.q_layout.size(); ++i) out[std::string(kind) + "." + model.q_layout[i].name] = v[static_cast<Eigen::Index>(i)];
  };
  put("q", s.q);
  put("qd", s.qd);
  put("qdd", s.qdd);
  if (s.q.size() == static_cast<Eigen::Index>(model.q_layout.size()))
    for (size_t p = 0; p < model.points.size(); ++p) {
      Eigen::Vector2d xy = model.points[p].p_W;
      for (int axis = 0; axis < 2; ++axis)
        if (const int slot = model.SlotOf(static_cast<int>(p), axis); slot >= 0) xy[axis] = s.q[slot];
      const Eigen::Vector3d w = model.embedding.origin + model.embedding.u * xy.x() + model.embedding.v * xy.y();
      for (int c = 0; c < 3; ++c) out["p." + model.points[p].name + "." + "xyz"[c]] = w[c];
    }
  // A spatial scene's points and vectors: their q slots over the file's values (fixed components).
  if (model.kind == ScenarioKind::kSpatial && s.q.size() == static_cast<Eigen::Index>(model.q_layout.size())) {
    std::vector<Eigen::Vector3d> r;
    for (const SpatialEntity& e : model.spatial.entities) r.push_back(e.r_W);
    for (size_t i = 0; i < model.q_layout.size(); ++i)
      if (const Model::Slot& slot = model.q_layout[i]; slot.entity >= 0) r[slot.entity][slot.axis] = s.q[static_cast<Eigen::Index>(i)];
    for (size_t e = 0; e < r.size(); ++e)
      for (int c = 0; c < 3; ++c) out["p." + model.spatial.entities[e].name + "." + "xyz"[c]] = r[e][c];
  }
  return out;
}

namespace {

// A claim on one coordinate's value, rate or acceleration (q.<slot>, qd.<slot>, qdd.<slot>): the
// relative bound of that order (by_order: q, q̇, q̈) times its kind's scale of the motion; NaN
// for any other quantity.
double CoordinateBound(const Model& model, const MotionScale& scale, const BookValue& b, const double (&by_order)[3]) {
  static const std::pair<const char*, int> kOrders[] = {{"qdd.", 2}, {"qd.", 1}, {"q.", 0}};
  for (const auto& [prefix, order] : kOrders) {
    const std::string pre = prefix;
    if (b.quantity.rfind(pre, 0) != 0) continue;
    const int slot = model.SlotIndex(b.quantity.substr(pre.size()));
    if (slot < 0) break;
    const int kind = SlotKind(model, slot);
    return by_order[order] * (order == 0 ? scale.q[kind] : order == 1 ? scale.qd[kind] : scale.qdd[kind]);
  }
  return kNaN;
}

// The reference's own uncertainty [internal unit] for a claim: its two formulations' measured
// agreement (relative, as CompareMotion measures it) times the scale it is relative to. A single
// coordinate's value, rate or acceleration uses the agreement of that order (q, q̇ or q̈; the q
// agreement where the others were not measured) and its kind's scale of the reference motion;
// any other expression the largest agreement and its own size.
double ReferenceUncertainty(const Model& model, const ReferenceRecord& ref, const MotionScale& scale, const BookValue& b) {
  const auto or_q = [&](double a) { return a == a ? a : ref.agreement; };
  const double by_order[3] = {ref.agreement, or_q(ref.agreement_qd), or_q(ref.agreement_qdd)};
  if (const double c = CoordinateBound(model, scale, b, by_order); c == c) return c;
  return std::max({by_order[0], by_order[1], by_order[2]}) * std::max(1.0, std::fabs(b.value * b.unit_factor));
}

// Why a claim got no verdict: the quantity is not one a trajectory sample holds (a claim at a
// time), no confirmed reference (a free scene's claim at a time), or no method computed it.
std::string NotComputedReason(const Model& model, const BookValue& b, const std::vector<Result>& results,
                              const ReferenceRecord* reference) {
  if (b.AtTime()) {
    Quantities names;  // every name a sample holds, to tell an unknown name from a missing run
    Sample s;
    s.q = s.qd = s.qdd = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(model.q_layout.size()));
    names = SampleQuantities(model, s);
    if (!EvalQuantity(b.quantity, names, model))
      return b.quantity + " is not read off a motion: a claim at a time may use q.<slot>, qd.<slot>, qdd.<slot> and "
                          "p.<point>.<x|y|z> of the scene's points (a spatial scene's vectors too); the other quantities (ω, v., a., a gear member's "
                          "p./v./a., M, Q, …) are at t0 only (a claim without at:)";
    if (model.IsFree()) {
      if (!reference) return "no reference trajectory was made";
      if (!reference->confirmed || reference->trajectory.empty())
        return "the reference trajectory is not confirmed: " + reference->description;
      return "the reference trajectory has no sample at t = " + Fmt(b.at, 6) + " s";
    }
  }
  // A pin's reaction a method left out: its own note on that pin (settings "reactions").
  const auto left_out = [&](const Result& r) -> std::string {
    static const std::regex kReaction(R"(^reaction\.([A-Za-z0-9_]+)\.([A-Za-z0-9_]+)\.[xy]$)");
    std::smatch m;
    const auto re = r.settings.find("reactions");
    if (!std::regex_match(b.quantity, m, kReaction) || re == r.settings.end()) return "";
    const std::string& text = re->second;
    for (size_t at = text.find("left out: "); at != std::string::npos; at = text.find("left out: ", at + 1)) {
      const size_t end = text.find("; left out: ", at + 1);
      const std::string note = text.substr(at + 10, end == std::string::npos ? std::string::npos : end - at - 10);
      if (note.find("body " + m[2].str() + " at " + m[1].str() + ":") != std::string::npos ||
          note.find("point " + m[1].str() + ":") != std::string::npos)
        return note;
    }
    return "";
  };
  std::string why;
  for (const Result& r : results) {
    const std::string note = r.ok() && !b.AtTime() ? left_out(r) : "";
    const std::string what = !r.ok() ? std::string(ToString(r.status)) + (r.reason.empty() ? "" : ": " + r.reason)
                             : b.AtTime() ? "no sample at t = " + Fmt(b.at, 6) + " s"
                             : !note.empty() ? "left out: " + note
                                             : "it does not give " + b.quantity;
    why += (why.empty() ? "" : "; ") + r.method + ": " + what;
  }
  return why.empty() ? "no method was run" : "no method computed it (" + why + ")";
}

}  // namespace

// The family of a quantity name: "M[0,2]" -> "M", "v.B.x" -> "v".
static std::string Family(const std::string& name) { return name.substr(0, name.find_first_of(".[")); }

// family -> (derivative order, kind of scale: 0 lengths, 1 angles, 2 the smaller of the two)
static const std::map<std::string, std::pair<int, int>>& InstantKinds() {
  static const std::map<std::string, std::pair<int, int>> k{
      {"q", {0, 2}},      {"p", {0, 0}},          {"qd", {1, 2}},      {"v", {1, 0}},       {"omega", {1, 1}},
      {"vabs", {1, 0}},   {"omegaabs", {1, 1}},   {"vslide", {1, 0}},  {"qdd", {2, 2}},     {"a", {2, 0}},
      {"alpha", {2, 1}},  {"aabs", {2, 0}},       {"aabs_chain", {2, 0}}, {"alphaabs", {2, 1}}, {"aslide", {2, 0}},
      {"at", {2, 0}},     {"an", {2, 0}}};
  return k;
}

bool IsAccelerationAtT0(const std::string& name) {
  static const std::set<std::string> kAccelerations{"qdd", "alpha", "a", "aabs", "aabs_chain", "alphaabs",
                                                   "aslide", "at", "an", "rho"};
  return kAccelerations.count(Family(name)) > 0;
}

std::map<std::string, double> InstantScales(const Quantities& base, const Quantities& other, const MotionScale& scale) {
  // Every instant quantity both methods produce is judged against its family's largest value,
  // floored by the motion's own scale for its kind (MotionScale: lengths for points' p, v, a;
  // angles for ω, α; the smaller of the two for q, q̇, q̈), so that a family that vanishes (a chain
  // driven at constant speed has a = 0 at every point) is not judged on round-off.
  std::map<std::string, double> family_max;
  for (const auto& [name, a] : base)
    if (auto it = other.find(name); it != other.end())
      family_max[Family(name)] = std::max({family_max[Family(name)], std::fabs(a), std::fabs(it->second)});
  const std::array<double, 2>* by_order[3] = {&scale.q, &scale.qd, &scale.qdd};
  for (auto& [family, largest] : family_max) {
    const auto k = InstantKinds().find(family);
    if (k == InstantKinds().end()) continue;
    const std::array<double, 2>& sc = *by_order[k->second.first];
    const double floor = k->second.second == 2 ? std::min(sc[0], sc[1]) : sc[k->second.second];
    largest = std::max(largest, floor);
  }
  return family_max;
}

// Whether an instant quantity ("p.O.x", "v.O.y") is a fixed point's or vector's: it locates nothing.
static bool OfFixedEntity(const Model& model, const std::string& name) {
  const size_t a = name.find('.'), b = a == std::string::npos ? a : name.find('.', a + 1);
  if (b == std::string::npos) return false;
  const std::string entity = name.substr(a + 1, b - a - 1);
  if (!model.spatial.entities.empty()) {
    const int e = model.spatial.EntityIndex(entity);
    return e >= 0 && model.spatial.entities[static_cast<size_t>(e)].fixed;
  }
  const int i = model.PointIndex(entity);
  return i >= 0 && model.points[static_cast<size_t>(i)].fixed;
}

double InstantDifference(const std::string& name, double base, double value, const std::map<std::string, double>& scales) {
  const auto it = scales.find(Family(name));
  return std::fabs(base - value) / std::max(it == scales.end() ? 0.0 : it->second, 1e-300);
}

double InstantBound(const Agreement& a, const std::string& name) {
  return IsAccelerationAtT0(name) ? a.AccelerationAtT0() : a.instant;
}

// The relative agreement a method is held to on a book quantity at t0 (tolerances.yaml): its
// `instant` tolerance, for an expression that reads an acceleration (q̈, α, a., aabs., …) its
// bound for accelerations at t0 (Agreement::AccelerationAtT0), as RunScenario judges them. Used
// for an expression of several quantities, relative to its own size; a single quantity both
// methods give is judged as RunScenario judges it (InstantScales, InstantDifference).
static double BookAgreement(const Tolerances& tol, const std::string& method, const std::string& quantity) {
  static const std::regex kAcceleration(R"((^|[^A-Za-z0-9_.])(qdd|alpha|a|aabs|aabs_chain|alphaabs|aslide|at|an|rho)\.)");
  const Agreement a = tol.For(method);
  return std::regex_search(quantity, kAcceleration) ? a.AccelerationAtT0() : a.instant;
}

// The difference [internal unit] a method is allowed from the first method on a claim at a time
// of a driven motion (BookValue::at), as `run` judges the motion (CompareMotion): its `q`, `qd`
// or `qdd` agreement (tolerances.yaml) times that order's scale of the first method's motion —
// a coordinate's kind's, a point's position the lengths'. Any other expression: the largest
// agreement of the orders it reads, relative to its own size.
static double TimedAllowed(const Model& model, const Tolerances& tol, const std::string& method, const BookValue& b,
                           const MotionScale& scale, double value_internal) {
  const Agreement a = tol.For(method);
  const double by_order[3] = {a.q, a.qd, a.qdd};
  if (const double c = CoordinateBound(model, scale, b, by_order); c == c) return c;
  static const std::regex kPoint(R"(^p\.[A-Za-z0-9_]+\.[xyz]$)");
  if (std::regex_match(b.quantity, kPoint)) return a.q * scale.q[0];
  double rel = 0;
  static const std::regex kQdd(R"((^|[^A-Za-z0-9_.])qdd\.)"), kQd(R"((^|[^A-Za-z0-9_.])qd\.)"),
      kQ(R"((^|[^A-Za-z0-9_.])(q|p)\.)");
  if (std::regex_search(b.quantity, kQdd)) rel = std::max(rel, a.qdd);
  if (std::regex_search(b.quantity, kQd)) rel = std::max(rel, a.qd);
  if (std::regex_search(b.quantity, kQ)) rel = std::max(rel, a.q);
  return rel * std::max(1.0, std::fabs(value_internal));
}

std::vector<BookCheck> CheckBook(const Model& model, const std::vector<Result>& results, const ReferenceRecord* reference,
                                 const Tolerances* tolerances) {
  std::vector<BookCheck> rows;
  const bool have_ref = reference && reference->confirmed && !reference->trajectory.empty();
  const MotionScale ref_scale = have_ref ? ScaleOfMotion(model, reference->trajectory) : MotionScale{};
  // The quantities of a trajectory's sample k, where the sample is at its time (a run that
  // stopped early has none).
  const auto at_sample = [&](const std::vector<Sample>& traj, int k) -> std::optional<Quantities> {
    if (k < 0 || static_cast<size_t>(k) >= traj.size()) return std::nullopt;
    const double t = model.analysis.TimeAt(k);
    if (std::fabs(traj[static_cast<size_t>(k)].t - t) > 1e-12 * (1 + std::fabs(t))) return std::nullopt;
    return SampleQuantities(model, traj[static_cast<size_t>(k)]);
  };
  for (const BookValue& b : model.book) {
    BookCheck row;
    row.book = b;
    std::optional<double> first;
    std::string first_method;
    if (b.AtTime()) {
      // The source's stated precision (or, where it states none, half the last printed digit) or
      // the reference's own confirmed agreement (measured, relative to its motion's scale),
      // whichever is larger. A stated precision replaces the digits' band rather than widening it:
      // a printed "0" with precision 1e-9 claims zero to 1e-9, not to ±0.5.
      const double stated = b.precision > 0 ? b.precision * std::max(1.0, std::fabs(b.value)) : 0.5 * b.last_digit;
      row.allowed = std::max(stated, have_ref ? ReferenceUncertainty(model, *reference, ref_scale, b) / b.unit_factor : 0.0);
    }
    const std::vector<Sample>* first_motion = nullptr;  // the first method's, for a claim at a time
    const Result* first_result = nullptr;  // the first method's, for a claim about the instant
    const auto column = [&](const std::string& name, const std::optional<Quantities>& q, bool is_reference,
                            const std::vector<Sample>* motion, const Result* result) {
      std::optional<double> v;
      if (q) v = EvalQuantity(b.quantity, *q, model);
      if (v) *v /= b.unit_factor;  // internal -> the book's unit
      row.computed.emplace_back(name, v);
      if (!v) return;
      const Verdict verdict = b.AtTime() ? JudgeWithin(*v, b.value, row.allowed) : Judge(b, *v);
      row.verdicts.emplace_back(name, verdict);
      if (b.AtTime() && model.IsFree()) {
        if (is_reference) row.verdict = verdict;
        return;
      }
      if (!first) {
        first = v;
        first_method = name;
        first_motion = motion;
        first_result = result;
        row.verdict = verdict;
        return;
      }
      const double scale = std::max({1.0, std::fabs(*v), std::fabs(*first)});
      double rel = tolerances ? std::max(BookAgreement(*tolerances, name, b.quantity),
                                         BookAgreement(*tolerances, first_method, b.quantity))
                              : 1e-9;
      double allowed = rel * scale;  // [book unit]
      if (!b.AtTime() && tolerances && result && first_result && result->quantities.count(b.quantity) &&
          first_result->quantities.count(b.quantity)) {
        // One quantity both give at t0: judged as `run` judges it (RunScenario), relative to the
        // largest of its family in the two methods, floored by the first method's motion's scale.
        const std::map<std::string, double> scales =
            InstantScales(first_result->quantities, result->quantities, ScaleOfMotion(model, first_result->trajectory));
        rel = std::max(InstantBound(tolerances->For(name), b.quantity), InstantBound(tolerances->For(first_method), b.quantity));
        allowed = rel * scales.at(Family(b.quantity)) / std::fabs(b.unit_factor);
      }
      if (b.AtTime() && tolerances && first_motion && !first_motion->empty()) {
        // A claim at a time of the motion: each method to the tolerance `run` holds its motion to.
        const MotionScale ms = ScaleOfMotion(model, *first_motion);
        const double fi = *first * b.unit_factor;
        allowed = std::max(TimedAllowed(model, *tolerances, name, b, ms, fi),
                           TimedAllowed(model, *tolerances, first_method, b, ms, fi)) /
                  std::fabs(b.unit_factor);
        rel = allowed;
      }
      if (std::isinf(rel)) {
        // No bound for it (∞ in tolerances.yaml: `run` shows it, not judged): the value stays in
        // its cell, labelled as not judged (BookCheck::not_judged), and gives no verdict.
        row.not_judged.push_back(name);
        row.not_judged_values.push_back(*v);
        row.verdicts.pop_back();
        return;
      }
      if (!(std::fabs(*v - *first) <= allowed)) {
        // The value as the table prints it (10 significant digits), so that the two read alike.
        const std::string what = name + " " + Fmt(*v, 10) + " (off " + first_method + " by " + Fmt(std::fabs(*v - *first), 2) +
                                 ", allowed " + Fmt(allowed, 2) + ")";
        const std::string* known = tolerances ? tolerances->KnownFailure(name) : nullptr;
        if (known) row.known_outside.push_back(what);
        else row.outside.push_back(what), row.methods_agree = false;
      }
    };
    for (const Result& r : results) {
      std::optional<Quantities> q;
      if (r.ok()) q = b.AtTime() ? at_sample(r.trajectory, b.at_sample) : std::optional<Quantities>(r.quantities);
      column(r.method, q, false, &r.trajectory, &r);
    }
    if (reference)
      column("reference", have_ref ? at_sample(reference->trajectory, std::max(b.at_sample, 0)) : std::nullopt, true,
             have_ref ? &reference->trajectory : nullptr, nullptr);
    if (row.verdict == Verdict::kNotComputed) row.reason = NotComputedReason(model, b, results, reference);
    rows.push_back(std::move(row));
  }
  return rows;
}

namespace {

// Names a method reports about its own run rather than about the mechanism, and the joint
// reactions, which CompareReactions judges on their own scale: none is compared instant to instant.
bool MethodInternal(const std::string& name) {
  const std::string f = Family(name);
  return f == "residual" || f == "residual_rate" || f == "iterations" || f == "newton" || f == "energy_drift" ||
         f == "max_residual" || f == "max_residual_rate" || f == "steps" || f == "evaluations" || f == "reaction";
}

// Records a method outside its tolerance: a problem that fails the run, or — when tolerances.yaml
// lists it as a known failure on this scenario — a finding shown with its reason.
void Flag(RunReport& rep, const std::string& method, const std::string& what, std::string* known_out = nullptr) {
  if (const std::string* why = rep.tolerances.KnownFailure(method)) {
    rep.known.push_back(what + " (known: " + *why + ")");
    if (known_out) *known_out = *why;
    return;
  }
  rep.ok = false;
  rep.problems.push_back(what);
}

// The reason RunScenario gives a run whose mechanism came apart (kLoopOpenedResidual).
constexpr const char* kCameApart = "the mechanism came apart";

// A run that went to the end of the motion but came apart on the way: diverged, still a row
// against the reference (how far off it went is the finding).
bool CameApart(const Result& r) { return r.status == Status::kDiverged && r.reason.rfind(kCameApart, 0) == 0; }

// Free scenes with a motion: every ok method that integrated it, against the reference trajectory.
void CompareFreeMotions(const Model& model, const Tolerances& tol, double cpu_budget, RunReport& rep) {
  if (!model.IsFree() || !model.analysis.HasMotion()) return;
  const bool any = std::any_of(rep.results.begin(), rep.results.end(),
                               [](const Result& r) {
                                 return (r.ok() || r.status == Status::kOverBudget) && r.trajectory.size() > 1;
                               });
  if (!any) return;
  const ReferenceRecord ref = GetReference(model, cpu_budget);
  rep.reference = ref.description;
  rep.reference_confirmed = ref.confirmed;
  rep.reference_from_cache = ref.from_cache;
  if (!ref.confirmed) {
    rep.ok = false;
    rep.problems.push_back("reference trajectory: " + ref.description);
  }
  if (ref.trajectory.empty()) return;
  for (const Result& r : rep.results) {
    // A run stopped by its CPU budget is judged over the samples it reached.
    const bool partial = r.status == Status::kOverBudget;
    if (!(r.ok() || partial || CameApart(r)) || r.trajectory.size() < 2) continue;
    FreeComparison c;
    c.method = r.method;
    const std::vector<Sample> ref_span(ref.trajectory.begin(),
                                       ref.trajectory.begin() + static_cast<long>(std::min(ref.trajectory.size(), r.trajectory.size())));
    const std::vector<Sample>& against = partial ? ref_span : ref.trajectory;
    // The motion's scale is the whole reference's, so that a partial run is judged alike.
    const MotionError e = CompareMotion(model, ScaleOfMotion(model, ref.trajectory), against, r.trajectory);
    c.samples = e.samples;
    c.position = e.q.max;
    c.worst_slot = e.q.slot;
    c.worst_t = e.q.t;
    c.problem = e.problem;
    if (partial) c.reached_t = r.trajectory.back().t;
    c.tolerance = tol.FreePosition(r.method, model.analysis.t1 - model.analysis.t0);
    c.energy_drift = EnergyDrift(model, r.trajectory);
    // When it first left its tolerance: on a scene with singular positions, which one it failed at.
    for (size_t k = 1; k < e.q_per_sample.size(); ++k)
      if (!(e.q_per_sample[k] <= c.tolerance)) {
        c.first_outside_t = r.trajectory[k].t;
        break;
      }
    c.within = c.problem.empty() && c.position <= c.tolerance;
    if (model.criteria) c.criteria = JudgeCriteria(model, ref.trajectory, r.trajectory);
    if (!c.within) {
      std::ostringstream os;
      os << r.method << " vs the reference: ";
      if (!c.problem.empty()) os << c.problem;
      else os << "position error " << c.position << " (q." << c.worst_slot << " at t = " << c.worst_t << " s) above " << c.tolerance
              << ", first outside at t = " << c.first_outside_t << " s";
      Flag(rep, r.method, os.str(), &c.known);
    }
    rep.free.push_back(c);
  }
}

// The scene's force scale [N]: its weight plus its applied loads (ReactionComparison::relative).
double ForceScale(const Model& m) {
  double meters_per_unit = 1;
  try {
    meters_per_unit = numeric::Compile(m).meters_per_unit;
  } catch (const std::exception&) {
  }
  double mass = 0, loads = 0;
  for (const Body& b : m.bodies)
    if (b.HasMass()) mass += std::fabs(b.mass);
  for (const PointForce& f : m.forces) loads += f.f_W.norm();
  // Force elements at the scene's positions in the file (q̇ = 0): the springs' tension, each
  // torque as the pair of forces T/L at its body's first two points.
  for (const SpringDamper& s : m.springs)
    loads += std::fabs(s.stiffness * ((m.points[s.points[1]].p_W - m.points[s.points[0]].p_W).norm() - s.free_length) *
                           meters_per_unit +
                       s.preload);
  for (const BodyTorque& t : m.torques) loads += std::fabs(t.torque) / (m.bodies[t.body].Length() * meters_per_unit);
  return mass * m.gravity.norm() * meters_per_unit + loads;
}

void CompareReactions(const Model& model, RunReport& rep) {
  const double floor = 1e-3 * ForceScale(model);
  const auto is_reaction = [](const std::string& name) { return name.rfind("reaction.", 0) == 0; };
  const Result* ref = nullptr;
  for (const Result& r : rep.results) {
    if (r.trajectory.empty() || r.status == Status::kNotApplicable || r.status == Status::kInvalidScenario) continue;
    const bool has = std::any_of(r.quantities.begin(), r.quantities.end(), [&](const auto& kv) { return is_reaction(kv.first); });
    if (!has) continue;
    if (!ref) {
      ref = &r;
      continue;
    }
    ReactionComparison c;
    c.reference = ref->method;
    c.method = r.method;
    double largest = 0, worst = -1;
    for (const auto& [name, v] : ref->quantities)
      if (is_reaction(name)) largest = std::max(largest, std::fabs(v));
    for (const auto& [name, v] : ref->quantities) {
      if (!is_reaction(name)) continue;
      const auto it = r.quantities.find(name);
      if (it == r.quantities.end()) continue;
      ++c.components;
      const double d = std::fabs(it->second - v);
      if (!(d <= worst)) worst = d, c.worst = name;
    }
    c.absolute = c.components ? worst : kNaN;
    // A scene with no force at all (no mass under gravity, no load): differences stand alone.
    const double scale = std::max(largest, floor);
    c.relative = !c.components ? kNaN : scale > 0 ? worst / scale : worst == 0 ? 0.0 : kNaN;
    rep.reactions.push_back(c);
  }
}

}  // namespace

double EnergyDrift(const Model& model, const std::vector<Sample>& traj) {
  if (!model.IsFree() || !model.HasMass() || traj.size() < 2) return kNaN;
  try {
    const numeric::NaturalModel nm = numeric::Compile(model);
    const numeric::DynamicsSystem sys(nm);
    numeric::EnergyBalance balance(sys);  // E − torque work + damper dissipation
    double e0 = kNaN, drift = 0;
    for (const Sample& s : traj) {
      if (s.q.size() != nm.n || s.qd.size() != nm.n) return kNaN;
      const double e = balance.Next(s.t, s.q, s.qd, s.qdd);
      if (std::isnan(e0)) e0 = e;
      drift = std::max(drift, std::fabs(e - e0));
    }
    return drift;
  } catch (const std::exception&) {
    return kNaN;
  }
}

std::string EnergyDriftNote(const Model& model) {
  if (!model.IsFree() || !model.analysis.HasMotion()) return "";
  bool integrated = model.HasVaryingPointForces();
  for (const SpringDamper& s : model.springs) integrated = integrated || s.damping > 0 || s.HasLaw();
  for (const TorsionSpring& s : model.torsions) integrated = integrated || s.damping > 0;
  for (const BodyTorque& t : model.torques) integrated = integrated || t.law;
  for (const SpringDamper& s : model.spatial.springs) integrated = integrated || s.damping > 0 || s.HasLaw();
  integrated = integrated || !model.spatial.torques.empty();  // a 3-D torque's work is ∫ T·ω dt
  if (!integrated) return "";
  const double h = (model.analysis.t1 - model.analysis.t0) / (model.analysis.samples - 1);
  return "the loads' work and the dampers' dissipation enter the energy drift by the cubic Hermite rule on the samples, " +
         Fmt(h, 3) + " s apart: the drift includes that rule's error, O(h⁴) (more analysis samples make it "
         "smaller), not the method's alone";
}

std::vector<double> ScaledResiduals(const Model& model, const std::vector<Sample>& trajectory) {
  std::optional<numeric::NaturalModel> nm;
  try {
    nm = numeric::Compile(model);
  } catch (const std::exception&) {
    return {};
  }
  numeric::NaturalData data(*nm);
  std::vector<double> out;
  out.reserve(trajectory.size());
  for (const Sample& s : trajectory) {
    if (s.q.size() != nm->n) {
      out.push_back(kNaN);
      continue;
    }
    numeric::EvalPhi(*nm, data, s.q, s.t);
    out.push_back(numeric::ScaledResidual(*nm, data));
  }
  return out;
}

double ResidualRoundOff(const Model& model, const std::vector<Sample>& trajectory) {
  std::optional<numeric::NaturalModel> nm;
  try {
    nm = numeric::Compile(model);
  } catch (const std::exception&) {
    return 0;
  }
  numeric::NaturalData data(*nm);
  double worst = 0;
  Eigen::VectorXd w;
  for (const Sample& s : trajectory) {
    if (s.q.size() != nm->n) continue;
    numeric::EvalJacobian(*nm, data, s.q);
    if (data.sparse) w = data.jac.J().cwiseAbs() * s.q.cwiseAbs();
    else w = data.Phi_q.cwiseAbs() * s.q.cwiseAbs();
    for (Eigen::Index i = 0; i < w.size() && i < nm->m(); ++i)
      worst = std::max(worst, 2 * std::numeric_limits<double>::epsilon() * w[i] / nm->rows[i].scale);
  }
  return worst;
}

std::vector<Result> RunMethods(const Model& model, const std::vector<MethodPtr>& methods, const RunOptions& options,
                               const Isolation& isolation, bool warm_up, std::map<std::string, StartupCost>* startup) {
  std::vector<size_t> order(methods.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_partition(order.begin(), order.end(), [&](size_t i) { return methods[i]->name() == "numeric"; });
  std::vector<Result> results(methods.size());
  const Result* invalid = nullptr;
  for (const size_t i : order) {
    const Method& m = *methods[i];
    Result& r = results[i];
    if (invalid) {
      r.method = m.name();
      r.status = Status::kInvalidScenario;
      r.reason = invalid->reason;
      r.messages.push_back("not run: " + invalid->method + " found the scene to be bad input, which stops every method");
      continue;
    }
    if (isolation.enabled && !m.Applicability(model)) {
      IsolatedRun run = RunMethodIsolated(m, model, options, isolation.timeout, warm_up);
      if (startup && warm_up) (*startup)[m.name()] = run.startup;
      r = std::move(run.result);
    } else {
      if (warm_up) {
        const StartupCost cost = WarmUp(m, model);  // its one-time costs, outside its timed run
        if (startup) (*startup)[m.name()] = cost;
      }
      r = m.Run(model, options);
    }
    if (r.status == Status::kInvalidScenario) invalid = &r;
  }
  return results;
}

RunReport RunScenario(const Model& model, const std::vector<MethodPtr>& methods, const RunOptions& options,
                      const Tolerances& tol, const Isolation& isolation) {
  RunReport rep;
  rep.scenario = model.name;
  rep.tolerances = tol;
  rep.results = RunMethods(model, methods, options, isolation, true, &rep.startup);

  // On a turning frame (frame_rotation), a method whose motion run gives absolute velocities at
  // t0 but no absolute accelerations (an engine without accelerations at t0) gives them from an
  // instant run, which differences its world velocities just after t0: the number `check` judges
  // (CheckBook). The same instant run is made here and its aabs taken, so that `run` and `check`
  // judge one quantity; it is not part of the timed run.
  if (model.frame && options.motion && model.analysis.HasMotion())
    for (size_t i = 0; i < rep.results.size() && i < methods.size(); ++i) {
      Result& r = rep.results[i];
      const auto has = [&](const char* prefix) {
        return std::any_of(r.quantities.begin(), r.quantities.end(),
                           [&](const auto& kv) { return kv.first.rfind(prefix, 0) == 0; });
      };
      if (!r.ok() || !has("vabs.") || has("aabs.")) continue;
      RunOptions instant = options;
      instant.motion = false;
      const Method& m = *methods[i];
      const Result ir = isolation.enabled && !m.Applicability(model)
                            ? RunMethodIsolated(m, model, instant, isolation.timeout, false).result
                            : m.Run(model, instant);
      if (!ir.ok()) {
        r.messages.push_back("absolute accelerations at t0: its instant run " + std::string(ToString(ir.status)) + ": " + ir.reason);
        continue;
      }
      int taken = 0;
      for (const auto& [name, v] : ir.quantities)
        if ((name.rfind("aabs.", 0) == 0 || name.rfind("alphaabs.", 0) == 0) && !r.quantities.count(name))
          r.quantities[name] = v, ++taken;
      if (const auto it = ir.settings.find("absolute_accelerations"); taken && it != ir.settings.end())
        r.settings["absolute_accelerations"] =
            it->second + " — from a separate instant run, as `check` takes them (not part of the timed run)";
    }

  // The residual is measured alike for every method: the numeric model's Φ on each trajectory.
  bool compiles = true;
  try {
    (void)numeric::Compile(model);
  } catch (const std::exception&) {
    compiles = false;  // no Φ to measure; the numeric row says why
  }
  std::set<std::string> over_bound;  // methods whose residual is above their bound: never the base
  for (Result& r : rep.results) {
    if (r.status == Status::kInvalidScenario) {
      rep.invalid = true;
      rep.ok = false;
      rep.problems.push_back(r.method + ": " + r.reason);
    } else if (r.status == Status::kDiverged || r.status == Status::kFailed || r.status == Status::kCrashed ||
               r.status == Status::kTimedOut) {
      Flag(rep, r.method, r.method + " " + ToString(r.status) + ": " + r.reason);
    }
    if (!compiles || r.trajectory.empty()) continue;
    double worst = 0, opened_t = kNaN;
    const std::vector<double> residuals = ScaledResiduals(model, r.trajectory);
    for (size_t k = 0; k < residuals.size(); ++k) {
      worst = std::max(worst, residuals[k]);
      if (residuals[k] > kLoopOpenedResidual && std::isnan(opened_t)) opened_t = r.trajectory[k].t;
    }
    rep.max_residual[r.method] = worst;
    // A free scene's motion comes from forward dynamics, whose constraint drift depends on the
    // formulation: each method has its own bound (tolerances.yaml, free:).
    const bool dynamics = model.IsFree() && r.trajectory.size() > 1;
    double bound = dynamics ? tol.ForFree(r.method).residual : tol.For(r.method).residual;
    // A residual at the coordinates' round-off is no drift (ResidualRoundOff; measured only when
    // the bound is passed, which is rare).
    if (r.ok() && worst > bound && worst <= kLoopOpenedResidual) bound = std::max(bound, ResidualRoundOff(model, r.trajectory));
    // A free scene's instant is only assembled approximately from its guess by nobody but the
    // numeric solver; every sample of a driven motion must close the loop.
    if (r.ok() && worst > bound) {
      over_bound.insert(r.method);
      if (worst > kLoopOpenedResidual) {
        // The mechanism came apart: its positions mean nothing, whatever the method reported.
        r.status = Status::kDiverged;
        r.reason = std::string(kCameApart) + ": constraint residual ‖Φ‖ " + Fmt(worst, 2) + " (scaled; above " +
                   Fmt(kLoopOpenedResidual) + " from t = " + Fmt(opened_t, 4) + " s, bound " + Fmt(bound, 2) + ")";
        Flag(rep, r.method, r.method + " diverged: " + r.reason);
        continue;
      }
      // The bound is the method's drift at its default settings on the built-in scenes
      // (tolerances.yaml); a stepper's drift grows with the scene's accelerations.
      std::ostringstream os;
      os << r.method << ": constraint residual " << worst << " above " << bound << " (the bound: its joints' drift at "
         << "its settings on the built-in scenes, harness/tolerances.yaml; a faster or smaller scene drifts more, a "
         << "finer step less: a scene of yours may need its own entry, --tolerances FILE)";
      Flag(rep, r.method, os.str());
    }
  }

  // The base of the comparison: of the ok methods trusted here (not a known failure on this scene,
  // within its residual bound) analytic, else numeric (the exact kinematics), else the one held to
  // the tightest q bound (tolerances.yaml; the first of equals); the first ok one only when none is
  // trusted. With only engines asked for, a tuned variant is the base, not the coarse default.
  const Result* ref = nullptr;
  const auto exact = [](const Result& r) { return r.method == "analytic" || r.method == "numeric"; };
  for (const Result& r : rep.results)
    if (r.ok() && !r.trajectory.empty() && !tol.KnownFailure(r.method) && !over_bound.count(r.method) &&
        (!ref || (exact(r) && !exact(*ref)) ||
         (exact(r) == exact(*ref) && !exact(r) && tol.For(r.method).q < tol.For(ref->method).q)))
      ref = &r;
  if (!ref)
    for (const Result& r : rep.results)
      if (r.ok() && !r.trajectory.empty()) {
        ref = &r;
        break;
      }
  for (const Result& r : rep.results)
    if (ref && (r.ok() || CameApart(r)) && !r.trajectory.empty() && &r != ref) {
      PairComparison p;
      p.reference = ref->method;
      p.method = r.method;
      // A free scene's methods share only the instant: kinematic ones stop there, and the
      // motions of the dynamics ones are judged against the reference trajectory below.
      const size_t n = std::min({ref->trajectory.size(), r.trajectory.size(), model.IsFree() ? size_t{1} : SIZE_MAX});
      const std::vector<Sample> ref_span(ref->trajectory.begin(), ref->trajectory.begin() + static_cast<long>(n));
      const std::vector<Sample> span(r.trajectory.begin(), r.trajectory.begin() + static_cast<long>(n));
      // The motion's scale is the reference's whole run (one sample on a free scene: its instant).
      const MotionError e = CompareMotion(model, ScaleOfMotion(model, ref_span), ref_span, span);
      p.samples = e.samples;
      p.problem = e.problem;
      if (ref->trajectory.size() != r.trajectory.size() && !model.IsFree())
        p.problem = "different sample counts (" + std::to_string(ref->trajectory.size()) + " vs " +
                    std::to_string(r.trajectory.size()) + ")";
      // A kind a method does not give (an engine's q̈ at t0) is not compared: 0 here.
      p.q = std::isnan(e.q.max) ? 0 : e.q.max;
      p.qd = std::isnan(e.qd.max) ? 0 : e.qd.max;
      p.qdd = std::isnan(e.qdd.max) ? 0 : e.qdd.max;
      p.qdd_compared = !std::isnan(e.qdd.max);
      p.instant_only = model.IsFree();
      const Agreement at = tol.For(r.method);
      p.worst_slot = p.q / at.q >= std::max(p.qd / at.qd, p.qdd / at.qdd)
                         ? "q." + e.q.slot
                         : (p.qd / at.qd >= p.qdd / at.qdd ? "qd." + e.qd.slot : "qdd." + e.qdd.slot);
      const std::map<std::string, double> family_max = InstantScales(ref->quantities, r.quantities, e.scale);
      // The quantity named is the one that differs most; among those within round-off of it (all
      // of them when the methods agree at t0) the one that moves most (a position by its rate),
      // never a fixed point's ("at t0 p.O.x 0" located nothing). Judged on the largest of all.
      double largest = 0, largest_acceleration = 0, named_size = 0, named_acceleration_size = 0;
      for (const auto& [name, a] : ref->quantities) {
        const auto it = r.quantities.find(name);
        if (it == r.quantities.end() || MethodInternal(name)) continue;
        ++p.quantities;
        const double rel = InstantDifference(name, a, it->second, family_max);
        const bool acc = IsAccelerationAtT0(name);
        (acc ? largest_acceleration : largest) = std::max(acc ? largest_acceleration : largest, rel);
        // How much it moves: a position's (p., q.) by its rate (v., qd.) when given, else its own size.
        double size = -1;
        if (!OfFixedEntity(model, name)) {
          const std::string family = Family(name), rate_family = family == "p" ? "v" : family == "q" ? "qd" : "";
          const auto rate = rate_family.empty() ? ref->quantities.end()
                                                : ref->quantities.find(rate_family + name.substr(family.size()));
          size = rate != ref->quantities.end() ? InstantDifference(rate->first, rate->second, 0, family_max)
                                               : InstantDifference(name, a, 0, family_max);
        }
        double& worst = acc ? p.acceleration_quantity : p.quantity;
        double& worst_size = acc ? named_acceleration_size : named_size;
        std::string& where = acc ? p.worst_acceleration_quantity : p.worst_quantity;
        constexpr double kRoundOff = 1e-12;  // relative to the family's scale
        if (where.empty() || rel > worst + kRoundOff || (rel >= worst - kRoundOff && size > worst_size)) {
          worst = rel;
          worst_size = size;
          where = name;
        }
      }
      p.within = p.problem.empty() && p.q <= at.q && p.qd <= at.qd && p.qdd <= at.qdd && largest <= at.instant &&
                 largest_acceleration <= at.AccelerationAtT0();
      // What has no bound is measured and shown, never counted as within.
      if (p.qdd_compared && std::isinf(at.qdd)) p.not_judged.push_back("q̈ " + Fmt(p.qdd, 2));
      if (!p.worst_acceleration_quantity.empty() && std::isinf(at.AccelerationAtT0()))
        p.not_judged.push_back("accelerations at t0 (" + p.worst_acceleration_quantity + " " + Fmt(p.acceleration_quantity, 2) + ")");
      if (!p.within) {
        std::ostringstream os;
        os << r.method << " vs " << ref->method << ": ";
        if (!p.problem.empty()) os << p.problem;
        else {
          os << "largest relative difference at " << p.worst_slot << " (q " << p.q << ", qd " << p.qd << ", qdd "
             << (p.qdd_compared ? Fmt(p.qdd, 6) : std::string("not given")) << ")";
          // The quantities at t0 only where there are some (no stray "name value, 0" fragment).
          if (!p.worst_quantity.empty()) os << "; at t0 " << p.worst_quantity << " " << p.quantity;
          if (!p.worst_acceleration_quantity.empty())
            os << (p.worst_quantity.empty() ? "; at t0 " : ", ") << p.worst_acceleration_quantity << " " << p.acceleration_quantity;
        }
        Flag(rep, r.method, os.str(), &p.known);
      }
      rep.pairs.push_back(p);
    }
  CompareFreeMotions(model, tol, options.cpu_budget, rep);
  CompareReactions(model, rep);
  return rep;
}

MethodVerdict VerdictOf(const RunReport& rep, const std::string& method) {
  MethodVerdict v;
  const auto about = [&](const std::string& line) { return line.rfind(method + " ", 0) == 0 || line.rfind(method + ":", 0) == 0; };
  for (const Result& r : rep.results)
    if (r.method == method) v.within = r.ok() || r.status == Status::kNotApplicable;
  for (const std::string& p : rep.problems)
    if (about(p)) v.within = false, v.problems.push_back(p);
  for (const std::string& k : rep.known)
    if (about(k)) v.problems.push_back(k), v.within = false;  // outside, listed as known (a residual, a pair)
  for (const PairComparison& p : rep.pairs) {
    if (p.reference == method) v.compared = true;
    if (p.method == method) {
      v.compared = true;
      v.within = v.within && p.within;
      v.not_judged.insert(v.not_judged.end(), p.not_judged.begin(), p.not_judged.end());
      v.base = p.reference;
      if (!p.known.empty()) v.known = p.known;
    }
  }
  for (const FreeComparison& f : rep.free)
    if (f.method == method) {
      v.compared = true;
      v.within = v.within && f.within;
      if (!f.known.empty()) v.known = f.known;
    }
  if (const std::string* k = rep.tolerances.KnownFailure(method); k && !v.within) v.known = *k;
  if (const std::string* k = rep.tolerances.KnownFailure(method)) {
    const bool ran = std::any_of(rep.results.begin(), rep.results.end(),
                                 [&](const Result& r) { return r.method == method && r.ok(); });
    if (v.within && ran && v.compared) v.stale = *k;
    if (!v.known.empty() || !v.stale.empty()) v.known_where = rep.tolerances.KnownWhere(method);
  }
  return v;
}

std::vector<std::string> KnownFailures(const RunReport& rep) {
  std::vector<std::string> known;
  for (const Result& r : rep.results)
    if (const MethodVerdict v = VerdictOf(rep, r.method); !v.within && !v.known.empty()) known.push_back(r.method);
  return known;
}

void WriteTrajectoryCsv(std::ostream& out, const Model& model, const RunReport& report) {
  char num[40];
  const auto cell = [&num](double v) -> const char* {
    if (!std::isfinite(v)) return std::isnan(v) ? "nan" : (v > 0 ? "inf" : "-inf");
    std::snprintf(num, sizeof num, "%.17g", v);
    return num;
  };
  const std::string scenario = CsvField(model.name);
  std::vector<std::string> slots;
  for (const Model::Slot& s : model.q_layout) slots.push_back(CsvField(s.name));
  for (const Result& r : report.results) {
    const std::string method = CsvField(r.method);
    const std::vector<double> residuals = ScaledResiduals(model, r.trajectory);
    for (size_t k = 0; k < r.trajectory.size(); ++k) {
      const Sample& s = r.trajectory[k];
      for (size_t i = 0; i < slots.size(); ++i) {
        out << scenario << ',' << method << ',' << k << ',' << cell(s.t) << ',' << slots[i] << ',';
        if (static_cast<size_t>(s.q.size()) > i) out << cell(s.q[static_cast<Eigen::Index>(i)]);
        out << ',';
        if (static_cast<size_t>(s.qd.size()) > i) out << cell(s.qd[static_cast<Eigen::Index>(i)]);
        out << ',';
        if (static_cast<size_t>(s.qdd.size()) > i) out << cell(s.qdd[static_cast<Eigen::Index>(i)]);
        out << ',';
        if (k < residuals.size() && !std::isnan(residuals[k])) out << cell(residuals[k]);
        out << '\n';
      }
    }
  }
}

}  // namespace mechbench::harness
