#include "mechbench/harness/compare.h"

#include "mechbench/harness/isolated.h"
#include "mechbench/harness/output.h"
#include "mechbench/harness/reference.h"
#include "mechbench/numeric/reference.h"

#include "mechbench/expr.h"
#include "mechbench/numeric/constraints.h"
#include "mechbench/numeric/forward_dynamics.h"
#include "mechbench/numeric/natural_data.h"
#include "mechbench/numeric/natural_model.h"

#include <algorithm>
#include <set>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <sstream>

namespace mechbench::harness {

const char* ToString(Verdict v) {
  switch (v) {
    case Verdict::kAgrees: return "agrees";
    case Verdict::kLastDigit: return "last-digit";
    case Verdict::kDiffers: return "differs";
    case Verdict::kNotComputed: return "not-computed";
  }
  return "?";
}

Verdict Judge(const BookValue& b, double computed) {
  const double diff = std::fabs(computed - b.value);
  if (b.last_digit == 0.0)  // an exact claim
    return diff <= 1e-9 * std::max(1.0, std::fabs(b.value)) ? Verdict::kAgrees : Verdict::kDiffers;
  // A hair of slack so that a value exactly on the half-unit boundary is not decided by rounding
  // noise in the 16th digit.
  const double slack = 1e-9 * b.last_digit + 1e-13 * std::fabs(b.value);
  if (diff <= 0.5 * b.last_digit + slack) return Verdict::kAgrees;
  if (diff <= 1.0 * b.last_digit + slack) return Verdict::kLastDigit;
  return Verdict::kDiffers;
}

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

std::vector<BookCheck> CheckBook(const Model& model, const std::vector<Result>& results) {
  std::vector<BookCheck> rows;
  for (const BookValue& b : model.book) {
    BookCheck row;
    row.book = b;
    std::optional<double> first;
    for (const Result& r : results) {
      std::optional<double> v;
      if (r.ok()) v = EvalQuantity(b.quantity, r.quantities, model);
      if (v) *v /= b.unit_factor;  // internal -> the book's unit
      row.computed.emplace_back(r.method, v);
      if (!v) continue;
      const Verdict verdict = Judge(b, *v);
      row.verdicts.emplace_back(r.method, verdict);
      if (!first) {
        first = v;
        row.verdict = verdict;
      } else if (std::fabs(*v - *first) > 1e-9 * std::max({1.0, std::fabs(*v), std::fabs(*first)})) {
        row.methods_agree = false;
      }
    }
    rows.push_back(std::move(row));
  }
  return rows;
}

namespace {

// Largest relative difference of one kind (q, qd or qdd) over the common samples.
struct KindError {
  double value = 0;
  double rms = 0;    // over every slot and sample, same scale
  double scale = 0;  // what the differences were divided by
  std::string slot;
  bool any = false;
};

template <class Get>
KindError CompareKind(const Model& model, const std::vector<Sample>& a, const std::vector<Sample>& b, int n,
                      Get get, double scale_floor = 0) {
  const int slots = static_cast<int>(model.q_layout.size());
  // Angles are weighted by the scene's length scale so that lengths and angles share one scale:
  // an error is judged against the largest magnitude any coordinate of its kind reaches, not
  // against its own slot (a constant-speed crank has θ̈ = 0, and noise on a zero is not 100 %).
  double length_scale = 0;
  for (const Body& body : model.bodies)
    for (const Eigen::Vector2d& p : body.p_B) length_scale = std::max(length_scale, p.norm());
  std::vector<double> weight(slots, 1.0);
  for (int i = 0; i < slots; ++i) {
    const Model::Slot& s = model.q_layout[i];
    const bool angle = s.coordinate >= 0 && model.coordinates[s.coordinate].type != CoordinateType::kDistance;
    if (angle && length_scale > 0) weight[i] = length_scale;
  }
  std::vector<double> diff(slots, 0.0);
  double scale = 0, sum_sq = 0;
  long count = 0;
  bool any = false;
  for (int k = 0; k < n; ++k) {
    const Eigen::VectorXd& x = get(a[k]);
    const Eigen::VectorXd& y = get(b[k]);
    if (x.size() != slots || y.size() != slots) continue;  // not computed (e.g. a free scene's q̈)
    any = true;
    for (int i = 0; i < slots; ++i) {
      const double d = weight[i] * std::fabs(x[i] - y[i]);
      diff[i] = std::isnan(d) ? INFINITY : std::max(diff[i], d);
      sum_sq += d * d;
      ++count;
      scale = std::max(scale, weight[i] * std::fabs(x[i]));  // the reference's own motion
    }
  }
  KindError e;
  if (!any) return e;
  e.any = true;
  e.scale = std::max(scale, scale_floor);
  e.rms = std::sqrt(sum_sq / static_cast<double>(std::max(count, 1L))) / std::max(e.scale, 1e-300);
  for (int i = 0; i < slots; ++i) {
    const double rel = diff[i] / std::max(e.scale, 1e-300);
    if (rel > e.value || e.slot.empty()) {
      e.value = rel;
      e.slot = model.q_layout[i].name;
    }
  }
  return e;
}

// The family of a quantity name: "M[0,2]" -> "M", "v.B.x" -> "v".
std::string Family(const std::string& name) { return name.substr(0, name.find_first_of(".[")); }

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
    if (!(r.ok() || partial) || r.trajectory.size() < 2) continue;
    FreeComparison c;
    c.method = r.method;
    const std::vector<Sample> ref_span(ref.trajectory.begin(),
                                       ref.trajectory.begin() + static_cast<long>(std::min(ref.trajectory.size(), r.trajectory.size())));
    const std::vector<Sample>& against = partial ? ref_span : ref.trajectory;
    // The motion's scale is the whole reference's, so that a partial run is judged alike.
    const numeric::PositionError e = numeric::ComparePositionsScaled(model, ref.trajectory, against, r.trajectory);
    c.samples = e.samples;
    c.position = e.value;
    c.worst_slot = e.slot;
    c.worst_t = e.t;
    c.problem = e.problem;
    if (partial) c.reached_t = r.trajectory.back().t;
    c.tolerance = tol.ForFree(r.method).position;
    c.energy_drift = EnergyDrift(model, r.trajectory);
    // When it first left its tolerance: on a scene with singular positions, which one it failed at.
    for (size_t k = 1; k < e.per_sample.size(); ++k)
      if (!(e.per_sample[k] <= c.tolerance)) {
        c.first_outside_t = r.trajectory[k].t;
        break;
      }
    c.within = c.problem.empty() && c.position <= c.tolerance;
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
    double e0 = kNaN, drift = 0;
    for (const Sample& s : traj) {
      if (s.q.size() != nm.n || s.qd.size() != nm.n) return kNaN;
      const double e = sys.Energy(s.q, s.qd);
      if (std::isnan(e0)) e0 = e;
      drift = std::max(drift, std::fabs(e - e0));
    }
    return drift;
  } catch (const std::exception&) {
    return kNaN;
  }
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

MotionError CompareMotion(const Model& model, const std::vector<Sample>& ref, const std::vector<Sample>& other) {
  MotionError e;
  const int n = static_cast<int>(std::min(ref.size(), other.size()));
  e.samples = n;
  if (ref.size() != other.size())
    e.problem = "different sample counts (" + std::to_string(ref.size()) + " vs " + std::to_string(other.size()) + ")";
  for (int k = 0; k < n; ++k)
    if (std::fabs(ref[k].t - other[k].t) > 1e-12 * (1 + std::fabs(ref[k].t))) {
      e.problem = "sample times differ at sample " + std::to_string(k);
      return e;
    }
  if (n == 0) return e;
  const double T = model.analysis.HasMotion() ? model.analysis.t1 - model.analysis.t0 : 1.0;
  const auto q = CompareKind(model, ref, other, n, [](const Sample& s) -> const Eigen::VectorXd& { return s.q; });
  const auto qd = CompareKind(model, ref, other, n, [](const Sample& s) -> const Eigen::VectorXd& { return s.qd; }, q.scale / T);
  const auto qdd = CompareKind(model, ref, other, n, [](const Sample& s) -> const Eigen::VectorXd& { return s.qdd; }, qd.scale / T);
  if (q.any) e.q_max = q.value, e.q_rms = q.rms;
  if (qd.any) e.qd_max = qd.value, e.qd_rms = qd.rms;
  if (qdd.any) e.qdd_max = qdd.value, e.qdd_rms = qdd.rms;
  if (model.IsFree()) {
    // Positions of a free motion as `run` judges them: against the range each kind (lengths,
    // angles) covers in the reference.
    const numeric::PositionError p = numeric::ComparePositions(model, ref, other);
    e.q_max = p.value;
    const int slots = static_cast<int>(model.q_layout.size());
    auto angle = [&](int i) {
      const Model::Slot& s = model.q_layout[i];
      return s.point < 0 && model.coordinates[s.coordinate].type != CoordinateType::kDistance;
    };
    double range[2] = {0, 0};
    for (int i = 0; i < slots; ++i) {
      double lo = INFINITY, hi = -INFINITY;
      for (int k = 0; k < n; ++k)
        if (ref[k].q.size() == slots) lo = std::min(lo, ref[k].q[i]), hi = std::max(hi, ref[k].q[i]);
      if (hi >= lo) range[angle(i)] = std::max(range[angle(i)], hi - lo);
    }
    for (double& r : range)
      if (!(r > 0)) r = 1.0;
    double sum_sq = 0;
    long count = 0;
    for (int k = 0; k < n; ++k) {
      if (ref[k].q.size() != slots || other[k].q.size() != slots) continue;
      for (int i = 0; i < slots; ++i, ++count) {
        const double d = (ref[k].q[i] - other[k].q[i]) / range[angle(i)];
        sum_sq += d * d;
      }
    }
    e.q_rms = count ? std::sqrt(sum_sq / static_cast<double>(count)) : kNaN;
  }
  return e;
}

RunReport RunScenario(const Model& model, const std::vector<MethodPtr>& methods, const RunOptions& options,
                      const Tolerances& tol, const Isolation& isolation) {
  RunReport rep;
  rep.scenario = model.name;
  rep.tolerances = tol;
  for (const MethodPtr& m : methods) {
    if (isolation.enabled && !m->Applicability(model)) {
      IsolatedRun run = RunMethodIsolated(*m, model, options, isolation.timeout, true);
      rep.startup[m->name()] = run.startup;
      rep.results.push_back(std::move(run.result));
      continue;
    }
    rep.startup[m->name()] = WarmUp(*m, model);  // its one-time costs, outside its timed run
    rep.results.push_back(m->Run(model, options));
  }

  // The residual is measured alike for every method: the numeric model's Φ on each trajectory.
  bool compiles = true;
  try {
    (void)numeric::Compile(model);
  } catch (const std::exception&) {
    compiles = false;  // no Φ to measure; the numeric row says why
  }
  for (const Result& r : rep.results) {
    if (r.status == Status::kInvalidScenario) {
      rep.invalid = true;
      rep.ok = false;
      rep.problems.push_back(r.method + ": " + r.reason);
    } else if (r.status == Status::kDiverged || r.status == Status::kFailed || r.status == Status::kCrashed ||
               r.status == Status::kTimedOut) {
      Flag(rep, r.method, r.method + " " + ToString(r.status) + ": " + r.reason);
    }
    if (!compiles || r.trajectory.empty()) continue;
    double worst = 0;
    for (double res : ScaledResiduals(model, r.trajectory)) worst = std::max(worst, res);
    rep.max_residual[r.method] = worst;
    // A free scene's motion comes from forward dynamics, whose constraint drift depends on the
    // formulation: each method has its own bound (tolerances.yaml, free:).
    const bool dynamics = model.IsFree() && r.trajectory.size() > 1;
    const double bound = dynamics ? tol.ForFree(r.method).residual : tol.For(r.method).residual;
    // A free scene's instant is only assembled approximately from its guess by nobody but the
    // numeric solver; every sample of a driven motion must close the loop.
    if (r.ok() && worst > bound) {
      std::ostringstream os;
      os << r.method << ": constraint residual " << worst << " above " << bound;
      Flag(rep, r.method, os.str());
    }
  }

  const Result* ref = nullptr;
  for (const Result& r : rep.results)
    if (r.ok() && !r.trajectory.empty()) {
      if (!ref) {
        ref = &r;
        continue;
      }
      PairComparison p;
      p.reference = ref->method;
      p.method = r.method;
      // A free scene's methods share only the instant: kinematic ones stop there, and the
      // motions of the dynamics ones are judged against the reference trajectory below.
      const size_t n = std::min({ref->trajectory.size(), r.trajectory.size(), model.IsFree() ? size_t{1} : SIZE_MAX});
      p.samples = static_cast<int>(n);
      for (size_t k = 0; k < n; ++k)
        if (std::fabs(ref->trajectory[k].t - r.trajectory[k].t) > 1e-12 * (1 + std::fabs(r.trajectory[k].t))) {
          p.problem = "sample times differ";
          break;
        }
      if (ref->trajectory.size() != r.trajectory.size() && !model.IsFree())
        p.problem = "different sample counts (" + std::to_string(ref->trajectory.size()) + " vs " +
                    std::to_string(r.trajectory.size()) + ")";
      // A kind the reference holds at zero (a constant-speed train has q̈ = 0) is judged on the
      // scale the motion gives it: q̇ ~ q / T and q̈ ~ q̇ / T over the run's duration T.
      const double T = model.analysis.HasMotion() ? model.analysis.t1 - model.analysis.t0 : 1.0;
      const auto eq = CompareKind(model, ref->trajectory, r.trajectory, p.samples, [](const Sample& s) -> const Eigen::VectorXd& { return s.q; });
      const auto ed = CompareKind(model, ref->trajectory, r.trajectory, p.samples, [](const Sample& s) -> const Eigen::VectorXd& { return s.qd; }, eq.scale / T);
      const auto ea = CompareKind(model, ref->trajectory, r.trajectory, p.samples, [](const Sample& s) -> const Eigen::VectorXd& { return s.qdd; }, ed.scale / T);
      p.q = eq.value;
      p.qd = ed.value;
      p.qdd = ea.value;
      const Agreement at = tol.For(r.method);
      p.worst_slot = eq.value / at.q >= std::max(ed.value / at.qd, ea.value / at.qdd)
                         ? "q." + eq.slot
                         : (ed.value / at.qd >= ea.value / at.qdd ? "qd." + ed.slot : "qdd." + ea.slot);
      // Every instant quantity both methods produce, judged against its family's largest value,
      // floored by the motion's own scale for its kind (the scales of q, q̇ and q̈ just measured;
      // angular families per unit of the scene's length scale), so that a family that vanishes (a
      // chain driven at constant speed has a = 0 at every point) is not judged on round-off.
      std::map<std::string, double> family_max;
      for (const auto& [name, a] : ref->quantities)
        if (auto it = r.quantities.find(name); it != r.quantities.end() && !MethodInternal(name))
          family_max[Family(name)] = std::max({family_max[Family(name)], std::fabs(a), std::fabs(it->second)});
      {
        static const std::map<std::string, int> kKind{
            {"q", 0},      {"p", 0},        {"qd", 1},       {"v", 1},          {"omega", 1},  {"vabs", 1},
            {"omegaabs", 1}, {"vslide", 1}, {"qdd", 2},      {"a", 2},          {"alpha", 2},  {"aabs", 2},
            {"aabs_chain", 2}, {"alphaabs", 2}, {"aslide", 2}, {"at", 2},       {"an", 2}};
        static const std::set<std::string> kAngular{"omega", "omegaabs", "alpha", "alphaabs"};
        double length_scale = 0;
        for (const Body& body : model.bodies)
          for (const Eigen::Vector2d& pb : body.p_B) length_scale = std::max(length_scale, pb.norm());
        const double kind_scale[3] = {eq.scale, ed.scale, ea.scale};
        for (auto& [family, largest] : family_max) {
          const auto k = kKind.find(family);
          if (k == kKind.end()) continue;
          const double floor = kind_scale[k->second] / (kAngular.count(family) && length_scale > 0 ? length_scale : 1.0);
          largest = std::max(largest, floor);
        }
      }
      // Accelerations at t0 (q̈, α, a of points, …) are judged like q̈ over the motion.
      static const std::set<std::string> kAccelerations{"qdd", "alpha", "a", "aabs", "aabs_chain", "alphaabs",
                                                       "aslide", "at", "an", "rho"};
      for (const auto& [name, a] : ref->quantities) {
        const auto it = r.quantities.find(name);
        if (it == r.quantities.end() || MethodInternal(name)) continue;
        ++p.quantities;
        const double b = it->second;
        const double rel = std::fabs(a - b) / std::max(family_max[Family(name)], 1e-300);
        const bool acc = kAccelerations.count(Family(name)) > 0;
        double& worst = acc ? p.acceleration_quantity : p.quantity;
        std::string& where = acc ? p.worst_acceleration_quantity : p.worst_quantity;
        if (rel > worst || where.empty()) {
          worst = rel;
          where = name;
        }
      }
      p.within = p.problem.empty() && p.q <= at.q && p.qd <= at.qd && p.qdd <= at.qdd && p.quantity <= at.instant &&
                 p.acceleration_quantity <= std::max(at.qdd, at.instant);
      if (!p.within) {
        std::ostringstream os;
        os << r.method << " vs " << ref->method << ": ";
        if (!p.problem.empty()) os << p.problem;
        else os << "largest relative difference at " << p.worst_slot << " (q " << p.q << ", qd " << p.qd << ", qdd " << p.qdd
                << "), at t0 " << p.worst_quantity << " " << p.quantity << ", " << p.worst_acceleration_quantity << " "
                << p.acceleration_quantity;
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
    if (about(k)) v.problems.push_back(k);
  for (const PairComparison& p : rep.pairs)
    if (p.method == method) {
      v.within = v.within && p.within;
      if (!p.known.empty()) v.known = p.known;
    }
  for (const FreeComparison& f : rep.free)
    if (f.method == method) {
      v.within = v.within && f.within;
      if (!f.known.empty()) v.known = f.known;
    }
  if (const std::string* k = rep.tolerances.KnownFailure(method); k && !v.within) v.known = *k;
  return v;
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
