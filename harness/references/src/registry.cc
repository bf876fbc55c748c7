#include "mechbench/references/registry.h"

#include "mechbench/errors.h"
#include "mechbench/format.h"
#include "mechbench/loader.h"
#include "mechbench/references/cranks.h"
#include "mechbench/references/nfourbar.h"
#include "mechbench/references/pendulum.h"

#include <cmath>
#include <numbers>

namespace mechbench::references {
namespace {

std::string Fmt3(double v) { return Fmt(v, 3); }

std::string Join(const std::vector<std::string>& v) {
  std::string out;
  for (const std::string& s : v) out += (out.empty() ? "" : ", ") + s;
  return out;
}

// The largest spread of the crank angles over a trajectory [rad] (0 on the parallelogram branch).
double CrankSpread(const Model& model, const ParallelCranks& pc, const std::vector<Sample>& traj) {
  double worst = 0;
  for (const Sample& s : traj) {
    double lo = INFINITY, hi = -INFINITY;
    const auto angle = [&](size_t i) {
      const Eigen::Vector2d g = model.points[pc.ground[i]].p_W;
      return std::atan2(s.q[pc.y[i]] - g.y(), s.q[pc.x[i]] - g.x());
    };
    const double th0 = angle(0);
    for (size_t i = 0; i < pc.tip.size(); ++i) {
      // Relative to crank 0, wrapped, so that ±π does not read as a spread of 2π.
      const double d = std::remainder(angle(i) - th0, 2 * std::numbers::pi);
      lo = std::min(lo, d), hi = std::max(hi, d);
    }
    worst = std::max(worst, hi - lo);
  }
  return worst;
}

numeric::ExactMotion NFourBarMotion(const Model& model, const ParallelCranks& pc, const numeric::ReferenceOptions& o) {
  numeric::ExactMotion m;
  m.method = "reference (N-four-bar reduced to its crank angle, DOPRI5 rtol " + Fmt3(o.exact_rtol) + ")";
  m.formulation = "every crank alike (the couplers translate): J θ̈ = −g K cos θ, a 1-DOF pendulum";
  m.budget_note = " (it stops every 1 ms of the motion to find the singular positions)";
  const double rtol = o.exact_rtol;
  m.solve = [&model, rtol](const std::vector<double>& extra, const RunOptions& budget) {
    NFourBarSolution s = NFourBarExact(model, rtol, extra, budget);
    numeric::ExactSolution out;
    out.trajectory = std::move(s.trajectory);
    out.extra = std::move(s.extra);
    out.singular = std::move(s.crossings);
    out.quantities["energy"] = s.energy;
    out.quantities["energy_drift"] = s.energy_drift;
    out.quantities["steps"] = static_cast<double>(s.steps);
    return out;
  };
  const int n_bars = pc.couplers;
  m.describe = [n_bars, rtol](const numeric::ExactSolution& s) {
    return "N-four-bar (N = " + std::to_string(n_bars) + "): its reduced equation, every crank alike " +
           "(a 1-DOF pendulum through the " + std::to_string(s.singular.size()) + " singular positions), DOPRI5 rtol " +
           Fmt3(rtol) + " (energy kept to " + Fmt3(s.quantities.at("energy_drift")) + " J)";
  };
  m.whole_run = true;
  m.branch_spread = [&model, pc](const std::vector<Sample>& traj) { return CrankSpread(model, pc, traj); };
  return m;
}

// The pendulum's closed form needs no integration: its confirmation, index-1 DOPRI5 on the full
// model, runs over the first kPendulumConfirmed seconds (a tenth of A01's 2000 s).
constexpr double kPendulumConfirmed = 200.0;

numeric::ExactMotion PendulumMotion(const Model& model) {
  numeric::ExactMotion m;
  m.method = "reference (the pendulum's closed form, Jacobi sn/cn/dn by the AGM)";
  m.formulation = "sin(φ/2) = k sn(ω0 t + u0 | k), φ from the downward vertical";
  m.solve = [&model](const std::vector<double>& extra, const RunOptions&) {
    std::string why;
    numeric::ExactSolution s = PendulumExact(model, extra, why);
    MB_ASSERT(!s.trajectory.empty(), "the pendulum's closed form on a scene Validate rejects");
    return s;
  };
  m.describe = [](const numeric::ExactSolution& s) {
    return "pendulum: its closed form in Jacobi's elliptic functions (k = " + Fmt(s.quantities.at("k"), 6) +
           ", period " + Fmt(s.quantities.at("period"), 9) + " s)";
  };
  m.confirm_until = model.analysis.t0 + kPendulumConfirmed;
  return m;
}

const Entry* Find(const std::string& name) {
  for (const Entry& e : Entries())
    if (e.name == name) return &e;
  return nullptr;
}

}  // namespace

const std::vector<Entry>& Entries() {
  static const std::vector<Entry> entries{
      {"nfourbar", "a row of N ≥ 1 parallelograms: N + 1 equal, parallel cranks pinned to ground, N couplers joining their tips",
       "IFToMM benchmark A02; every crank alike, J θ̈ = −g K cos θ integrated by DOPRI5 (references/nfourbar.h)"},
      {"pendulum", "one crank pinned to ground with its centre of mass on its line, or a point body at its tip (IFToMM A01)",
       "IFToMM benchmark A01; Jacobi's elliptic functions (references/pendulum.h)"},
  };
  return entries;
}

void Validate(const Model& model) {
  if (!model.exact_reference) return;
  const ExactReferenceName& named = *model.exact_reference;
  const Entry* e = Find(named.name);
  if (!e) {
    std::vector<std::string> known;
    for (const Entry& k : Entries()) known.push_back(k.name);
    throw ScenarioError(named.src, "unknown exact reference '" + named.name + "'", "known ones are: " + Join(known));
  }
  ParallelCranks pc;
  std::string why;
  bool ok = AnalyzeParallelCranks(model, pc, why);
  if (ok && e->name == "nfourbar" && pc.couplers < 1) ok = false, why = "it has one crank and no coupler";
  if (ok && e->name == "pendulum" && pc.couplers != 0)
    ok = false, why = "it has " + std::to_string(pc.couplers) + " coupler(s): that is a row of parallelograms";
  if (ok && e->name == "pendulum") {
    PendulumExact(model, {}, why);
    ok = why.empty();
  }
  if (!ok)
    throw ScenarioError(named.src, "the scene is not what the exact reference '" + named.name + "' describes: " + why,
                        "its closed form describes " + e->describes + "; remove `reference:` for a computed reference");
}

Model LoadScenarioValidated(const std::string& path) {
  Model m = LoadScenario(path);
  Validate(m);
  return m;
}

numeric::ExactMotion ExactMotionFor(const Model& model, const numeric::ReferenceOptions& options) {
  MB_ASSERT(model.exact_reference.has_value(), "ExactMotionFor needs a scene that names its exact reference");
  ParallelCranks pc;
  std::string why;
  const bool ok = AnalyzeParallelCranks(model, pc, why);
  MB_ASSERT(ok, "ExactMotionFor on a scene Validate rejects");
  if (model.exact_reference->name == "nfourbar") return NFourBarMotion(model, pc, options);
  return PendulumMotion(model);
}

numeric::Reference ReferenceFor(const Model& model, const numeric::ReferenceOptions& options) {
  if (!model.exact_reference) return numeric::ReferenceTrajectory(model, options);
  Validate(model);
  return numeric::ReferenceFromExact(model, ExactMotionFor(model, options), options);
}

}  // namespace mechbench::references
