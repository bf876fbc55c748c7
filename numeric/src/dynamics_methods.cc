#include "mechbench/format.h"
#include "mechbench/numeric/dynamics_methods.h"

#include "mechbench/errors.h"
#include "mechbench/numeric/ali3p.h"
#include "mechbench/numeric/constraints.h"
#include "mechbench/numeric/forward_dynamics.h"
#include "mechbench/numeric/natural_model.h"
#include "mechbench/numeric/reactions.h"
#include "mechbench/numeric/solver.h"
#include "mechbench/run_control.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>

namespace mechbench::numeric {
namespace {

// Where Φ_q loses rank (the N-four-bar's horizontal positions), a motion that stays on its branch
// keeps bounded accelerations, while an integrator that resolves the crossing finely follows the
// perturbed constraint surface Φ = δ, a hyperbola that turns onto another branch, with constraint
// forces that grow without bound. Measured on the N-four-bar (N = 1 … 40, 20 s): runs that stayed
// on the branch peaked at 1.6 … 8.2 × the run's acceleration scale (RK4 at 0.5 … 5 ms, DOPRI5 at
// rtol 1e-6, ALI3-P at 1 … 2 ms); every run that switched or was about to (DOPRI5 at rtol 1e-8,
// N = 2, 4, 5, 8, 20, 40; RK4 at 0.5 ms, N = 3) passed 1.1e3 (DOPRI5 at N = 40 went on to 2e7 ×).
// Between the two, 100.
constexpr double kSingularGuard = 100;

// A product of two doubles overflows only when a factor is beyond √DBL_MAX ≈ 1.3e154, so at t0
// (the file's own values, before any step) an entry of the file beyond it is the one at fault.
constexpr double kOverflowFactor = 1.3e154;

// The file's entries that may hold what overflowed at t0 (`why`: DynamicsSystem's reason), as
// "what (line N)": those of the kind that overflowed beyond kOverflowFactor when there are some
// (the culprits), else every entry of that kind (the candidates). `at` is the first one's line.
std::string OverflowSuspects(const Model& m, const std::string& why, SourceRef& at, bool& pinned) {
  const auto has = [&](const char* s) { return why.find(s) != std::string::npos; };
  const bool masses = has("mass matrix"), constant_loads = has("gravity × mass"),
             state_loads = has("spring–damper"), solve = has("the solve overflows");
  const bool velocities = !masses && !constant_loads && !state_loads && !solve;  // the state, Φ̇_q q̇
  std::vector<std::pair<SourceRef, std::string>> big, all;
  const auto add = [&](const SourceRef& src, const std::string& what, double size) {
    if (src.line <= 0) return;
    all.emplace_back(src, what);
    if (std::isfinite(size) ? std::fabs(size) > kOverflowFactor : !std::isnan(size)) big.emplace_back(src, what);
  };
  const bool spatial = m.kind == ScenarioKind::kSpatial;
  const double g = spatial ? m.spatial.gravity.cwiseAbs().maxCoeff() : m.gravity.cwiseAbs().maxCoeff();  // no |g|² to overflow
  if ((constant_loads || solve) && g > 0) add(m.gravity_src, "gravity of " + Fmt(g, 3), g);
  if (constant_loads || masses || solve) {
    if (spatial) {
      for (const auto& b : m.spatial.bodies)
        if (b.HasMass()) add(b.src, "body " + b.name + "'s mass " + Fmt(b.mass, 3), std::max(b.mass, b.inertia_W.cwiseAbs().maxCoeff()));
    } else {
      for (const Body& b : m.bodies)
        if (b.HasMass()) add(b.src, "body " + b.name + "'s mass " + Fmt(b.mass, 3), std::max(b.mass, std::fabs(b.inertia_com)));
    }
  }
  if (constant_loads)
    for (const PointForce& f : m.forces) add(f.src, "a point force", f.f_W.norm());
  if (state_loads || velocities)
    for (const Driver& d : m.initial)
      add(d.src, "the initial velocity of " + d.coordinate + ", " + Fmt(d.velocity, 3), d.velocity),
          add(d.src, "the initial value of " + d.coordinate + ", " + Fmt(d.value, 3), d.value);
  if (state_loads && big.empty()) {
    for (const SpringDamper& e : m.springs) add(e.src, "a spring–damper", 0);
    for (const BodyTorque& e : m.torques) add(e.src, "a torque", 0);
    for (const TorsionSpring& e : m.torsions) add(e.src, "a torsion spring", 0);
    for (const SpringDamper& e : m.spatial.springs) add(e.src, "a spring–damper", 0);
    for (const SpatialLoad& e : m.spatial.torques) add(e.src, "a torque", 0);
  }
  pinned = !big.empty();
  const auto& list = pinned ? big : all;
  std::string text;
  std::set<std::string> seen;
  for (const auto& [src, what] : list) {
    const std::string item = what + " (line " + std::to_string(src.line) + ")";
    if (seen.insert(item).second) text += (text.empty() ? "" : ", ") + item;
  }
  if (!list.empty()) at = list.front().first;
  return text;
}

// The state of one run: samples, statistics at the samples, and how it ended.
struct RunState {
  const Model& model;
  DynamicsSystem& sys;
  Result& result;
  // The run's step or tolerance: the method's own, or the RunOptions override (never stored in
  // the method, which stays as constructed).
  ControlValue control;
  RunOptions options;  // for its CPU budget (CheckBudget at every sample)
  double E0 = 0;
  EnergyBalance balance{sys};  // E − torque work + damper dissipation (forward_dynamics.h)
  double energy_drift = 0, max_residual = 0, max_residual_rate = 0;
  long steps = 0, iterations = 0, evaluations = 0;
  // The singular-position guard (kSingularGuard): the acceleration scale (largest scaled ‖q̈‖∞
  // at the samples so far, at least the loads' Q_j / M_jj) and the largest ratio met.
  double acc_scale = 0, acc_peak = 0, acc_peak_t = 0, last_ratio = 0;

  static double ScaledNorm(const Eigen::VectorXd& v, const Eigen::VectorXd& scale) {
    return v.cwiseAbs().cwiseQuotient(scale).maxCoeff();
  }
  void InitGuard() {
    const Eigen::VectorXd& M = sys.M_diagonal();
    for (int j = 0; j < sys.n(); ++j)
      if (M[j] > 0) acc_scale = std::max(acc_scale, std::fabs(sys.Q()[j]) / M[j] / sys.model().q_scale[j]);
  }
  // False (and `why`) when the accelerations at t exceed kSingularGuard × the run's scale: the
  // constraint forces of a branch switch at a singular position, which a smooth motion never needs.
  // ALI3-P's guard (at the state q, q̇ after a step h): when it trips, Φ_q's rank there tells a
  // singular position (the rank drops from t0's) from a step too coarse for the motion (the rank
  // kept: the message then gives h ω, ω the fastest coordinate's rate, and asks for a smaller step).
  bool Guard(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& qd, const Eigen::VectorXd& qdd, double h,
             std::string& why) {
    const double scaled = ScaledNorm(qdd, sys.model().q_scale);
    if (GuardScaled(t, scaled, why)) return true;
    const NaturalModel& nm = sys.model();
    int rank = 0;
    if (RankDrops(q, rank, why)) return false;
    const double omega = ScaledNorm(qd, nm.q_scale);  // [1/s]: the fastest coordinate's rate over its scale
    why = "the accelerations reach " + Fmt(scaled / acc_scale, 3) + " × their scale along the run (guard " +
          Fmt(kSingularGuard) + "), but Φ_q keeps its rank here (" + std::to_string(rank) + ", as at t0), so this is not "
          "a singular position: the fixed step does not follow the motion, at h ω = " + Fmt(h * omega, 3) + " (h = " +
          Fmt(h) + " s, ω = " + Fmt(omega, 3) + " 1/s, the fastest coordinate's rate over its scale, max_j |q̇_j| / "
          "scale_j), where the trapezoidal rule's iteration no longer settles on the motion; give it a smaller step "
          "(e.g. h = " + Fmt(std::min(h / 10, 0.01 / std::max(omega, 1e-300)), 2) + " s; mechbench sweep FILE --method "
          "dyn-ali3p runs it over steps)";
    return false;
  }
  // Φ_q's rank at q against t0's (`rank` gets q's): when it drops, a singular position, said in `why`.
  bool RankDrops(const Eigen::VectorXd& q, int& rank, std::string& why) const {
    const NaturalModel& nm = sys.model();
    NaturalData d(nm);
    d.q = result.trajectory.front().q;
    const int rank0 = AnalyzeRank(nm, d).rank;
    d.q = q;
    rank = AnalyzeRank(nm, d).rank;
    if (rank >= rank0) return false;
    why += " (Φ_q's rank drops from " + std::to_string(rank0) + " at t0 to " + std::to_string(rank) + " here)";
    return true;
  }
  // After the guard trips in a fixed-step explicit run (RK4, step h, at the state's q): a rank drop
  // from t0's says a singular position; a kept rank does not rule one out (near it Φ_q still has
  // full rank to kRankTolerance), and a step past the explicit method's stability limit (stiff
  // spring–dampers: IFToMM A05's) trips the guard too. The message then says both, and how a
  // smaller step tells them apart.
  void ExplainExplicitTrip(const Eigen::VectorXd& q, double h, std::string& why) const {
    const NaturalModel& nm = sys.model();
    int rank = 0;
    if (RankDrops(q, rank, why)) return;
    why = "the accelerations reach " + Fmt(last_ratio, 3) + " × their scale along the run (guard " + Fmt(kSingularGuard) +
          ") with Φ_q of full rank here (" + std::to_string(rank) + ", as at t0): either a singular position close by, "
          "or the fixed step h = " + Fmt(h) + " s past explicit RK4's stability limit on this motion" +
          (nm.model.HasForceElements() ? " (the scene's force elements may be stiff: RK4 is stable for h |λ| ≲ 2.8, λ the "
                                         "fastest mode's rate, e.g. c/m of a stiff damper)"
                                       : std::string()) +
          ", so the run stops here; a smaller step tells them apart (a stability limit goes away below it, a singular "
          "position does not): e.g. h = " + Fmt(h / 10, 2) + " s, or mechbench sweep FILE --method dyn-baumgarte-rk4";
  }
  bool GuardScaled(double t, double scaled_qdd, std::string& why) {
    if (!(acc_scale > 0)) return true;
    const double ratio = scaled_qdd / acc_scale;
    last_ratio = ratio;
    if (ratio > acc_peak) acc_peak = ratio, acc_peak_t = t;
    if (ratio <= kSingularGuard) return true;
    why = "the accelerations reach " + Fmt(ratio, 3) + " × their scale along the run (guard " + Fmt(kSingularGuard) +
          "): a singular position where Φ_q loses rank and the constraint forces grow without bound; past it the "
          "motion could continue on another assembly branch, so the run stops here";
    return false;
  }

  void Record(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& qd, const Eigen::VectorXd& qdd) {
    Observing();
    acc_scale = std::max(acc_scale, ScaledNorm(qdd, sys.model().q_scale));
    const double res = sys.ScaledPhi(q);
    const double rate = sys.ScaledPhiDot(q, qd);
    const double E = balance.Next(t, q, qd, qdd);
    energy_drift = std::max(energy_drift, std::fabs(E - E0));
    max_residual = std::max(max_residual, res);
    max_residual_rate = std::max(max_residual_rate, rate);
    result.trajectory.push_back(Sample{t, q, qd, qdd, sys.data().Phi.norm()});
    CheckBudget(options, t);
  }
  void Fail(double t, const std::string& why) {
    result.status = Status::kDiverged;
    result.reason = "at t = " + Fmt(t) + " s: " + why;
  }
  // Where the run's work changes phase (Result::cpu): stepping to the next sample is integration;
  // the sample's q̈ (when it is solved for the output only) and Record are observation.
  void Integrating() const { EnterPhase(options, Phase::kIntegration); }
  void Observing() const { EnterPhase(options, Phase::kObservation); }
};

class FreeDynamicsMethod : public Method {
 public:
  using Method::Method;
  std::optional<std::string> Applicability(const Model& model) const override { return DynamicsApplicability(model); }

 protected:
  // Settings and integration use the method's options with `control` (the run's effective step
  // or tolerance) in place of its own value.
  virtual void Settings(const NaturalModel& nm, const ControlValue& control, std::map<std::string, std::string>& s) const = 0;
  // Integrates from the state in run.result.trajectory[0] over the analysis samples.
  virtual void Integrate(RunState& run, const Eigen::VectorXd& lambda0) const = 0;
  // Dense or sparse (DynamicsSystem), and settings["linear_solver"] for each.
  virtual LinearAlgebra linear_algebra() const = 0;
  virtual int sparse_from() const { return kSparseIndex1FromCoordinates; }
  virtual std::string DenseSolverText() const = 0;
  virtual std::string SparseSolverText() const = 0;

  void DoRun(const Model& model, const RunOptions& options, Result& result) const final {
    const NaturalModel nm = Compile(model);
    const FreeStart start = AssembleFreeStart(nm);
    result.messages.insert(result.messages.end(), start.instant.messages.begin(), start.instant.messages.end());
    DynamicsSystem sys(nm, linear_algebra(), sparse_from());
    sys.ChooseRows(start.q);
    Eigen::VectorXd qdd0, lambda0;
    std::string why;
    // At t0 the state is assembled to round-off, so the Baumgarte terms are left out: q̈ and λ
    // are the exact index-1 values every formulation starts from, solved alike (the index-1
    // formulations' dense/sparse rule) so that they are the same numbers to the bit.
    std::optional<DynamicsSystem> index1;
    if (UseSparse(linear_algebra(), nm.n, kSparseIndex1FromCoordinates) != sys.sparse()) {
      index1.emplace(nm, linear_algebra(), kSparseIndex1FromCoordinates);
      index1->ChooseRows(start.q);
    }
    DynamicsSystem& at_t0 = index1 ? *index1 : sys;
    if (!at_t0.Accelerations(start.q, start.qd, 0, 0, qdd0, lambda0, &why)) {
      if (at_t0.overflowed()) {
        SourceRef at{model.source_file, 0};
        bool pinned = false;
        const std::string suspects = OverflowSuspects(model, why, at, pinned);
        throw ScenarioError(at,
                            "the dynamics overflow at t0: " + why +
                                (suspects.empty() ? std::string()
                                 : pinned         ? "; beyond double range (over 1e154, so its products overflow): " + suspects
                                                  : "; the file's entries that enter it: " + suspects),
                            (pinned ? "bring it within the limits masses and loads keep, 1e-100 … 1e100" : "give masses, inertias, lengths and loads that double precision can multiply") +
                                std::string(" (scenarios/FORMAT.md, limits)"));
      }
      throw ScenarioError({model.source_file, 0}, "singular position at t0: " + why,
                          "start the free scene away from a position where Φ_q loses rank");
    }
    // Without a motion no step is taken: the interval cap does not apply.
    const bool motion = options.motion && model.analysis.HasMotion();
    RunState run{model, sys, result,
                 EffectiveControl(control(), default_control(), options, motion ? LargestInterval(model.analysis) : kNaN),
                 options};
    Settings(nm, run.control, result.settings);
    result.settings["linear_solver"] = sys.LinearAlgebraText(DenseSolverText(), SparseSolverText());
    RecordControl(run.control, result.settings);
    result.settings["statistics"] = "energy drift and residuals measured at the output samples";
    if (!sys.dropped_rows().empty())
      result.settings["dropped_rows"] = std::to_string(sys.dropped_rows().size()) + " redundant row(s) left out of the dynamics";
    Quantities& out = result.quantities;
    for (int s = 0; s < nm.n; ++s) {
      const std::string& name = model.q_layout[s].name;
      out["q." + name] = start.q[s];
      out["qd." + name] = start.qd[s];
      out["qdd." + name] = qdd0[s];
    }
    const Eigen::VectorXd lam = sys.FullLambda(lambda0);
    for (int i = 0; i < nm.m(); ++i) out["lambda[" + std::to_string(i) + "]"] = lam[i];
    // Joint reactions at t0 (reactions.h) from the same q̈ and λ.
    const Reactions reactions = JointReactions(nm, start.q, start.qd, qdd0, lam, sys.dropped_rows());
    AddReactionQuantities(model, reactions, out);
    std::string reaction_text =
        "reaction.<point>.<body>.x|y at t0 from the index-1 q̈ and λ, body by body: M_e r̈ + G_bᵀ λ_b − Q_b (" +
        std::to_string(reactions.pins.size()) + " pin force(s))";
    for (const std::string& note : reactions.notes) reaction_text += "; left out: " + note;
    result.settings["reactions"] = reaction_text;
    run.E0 = sys.Energy(start.q, start.qd);
    out["energy"] = run.E0;
    run.InitGuard();
    // A run stopped by its CPU budget still reports its statistics over the samples it reached.
    std::optional<BudgetExceeded> over;
    try {
      run.Record(model.analysis.t0, start.q, start.qd, qdd0);
      if (motion) Integrate(run, lambda0);
    } catch (const BudgetExceeded& b) {
      over = b;
    }
    if (motion && run.acc_peak > 0)
      result.settings["singular_guard"] = "largest ‖q̈‖ " + Fmt(run.acc_peak, 3) + " × the run's scale (at t = " +
                                          Fmt(run.acc_peak_t, 6) + " s); the run stops above " + Fmt(kSingularGuard);
    out["energy_drift"] = run.energy_drift;
    out["max_residual"] = run.max_residual;
    out["max_residual_rate"] = run.max_residual_rate;
    out["steps"] = static_cast<double>(run.steps);
    out["evaluations"] = static_cast<double>(run.evaluations);
    out["iterations"] = static_cast<double>(run.iterations);
    result.settings["steps"] = std::to_string(run.steps);
    result.steps = run.steps;
    if (over) throw *over;
  }
};

// ---- index-1 with Baumgarte -------------------------------------------------------------------

// The index-1 right-hand side y = [q; q̇] → [q̇; q̈]. `peak`, when given, collects the largest
// scaled ‖q̈‖∞ of the evaluations (the singular-position guard of fixed-step RK4).
OdeRhs Index1Rhs(DynamicsSystem& sys, double alpha, double beta, double* peak = nullptr) {
  return [&sys, alpha, beta, peak, q = Eigen::VectorXd(), qd = Eigen::VectorXd(), qdd = Eigen::VectorXd(),
          lambda = Eigen::VectorXd()](double t, const Eigen::VectorXd& y, Eigen::VectorXd& dy, std::string& why) mutable {
    const int n = sys.n();
    sys.SetTime(t);  // loads given as laws of t
    q = y.head(n);
    qd = y.tail(n);
    if (!sys.Accelerations(q, qd, alpha, beta, qdd, lambda, &why)) return false;
    if (peak) *peak = std::max(*peak, RunState::ScaledNorm(qdd, sys.model().q_scale));
    dy.resize(2 * n);
    dy.head(n) = qd;
    dy.tail(n) = qdd;
    return true;
  };
}

void BaumgarteSettings(const BaumgarteOptions& o, std::map<std::string, std::string>& s) {
  s["formulation"] = "index-1 Lagrange multipliers [M Φ_qᵀ; Φ_q 0][q̈; λ] = [Q; −Φ̇_q q̇ − 2αΦ̇ − β²Φ]";
  s["alpha"] = Fmt(o.alpha) + " 1/s";
  s["beta"] = Fmt(o.beta) + " 1/s";
}

const char* kIndex1Dense = "dense LU with partial pivoting (Eigen) on [M Φ_qᵀ; Φ_q 0], singular when its residual exceeds 1e-8";
const char* kIndex1Sparse =
    "sparse LU (SuiteSparse KLU: AMD ordering and pivots from the first factorization, then refactored with them; "
    "fresh pivots when a solve's residual is not at round-off) on [M Φ_qᵀ; Φ_q 0] with Φ_q's fixed pattern, "
    "singular when its residual exceeds 1e-8";

// Accelerations at a sample (for the output) with the method's own Baumgarte terms.
bool SampleAccelerations(RunState& run, double t, const Eigen::VectorXd& y, double alpha, double beta,
                         Eigen::VectorXd& qdd, std::string& why) {
  run.Observing();
  run.sys.SetTime(t);
  const int n = run.sys.n();
  Eigen::VectorXd lambda;
  return run.sys.Accelerations(y.head(n), y.tail(n), alpha, beta, qdd, lambda, &why);
}

class BaumgarteRk4 final : public FreeDynamicsMethod {
 public:
  explicit BaumgarteRk4(BaumgarteOptions o)
      : FreeDynamicsMethod("dyn-baumgarte-rk4", "forward dynamics: index-1 multipliers, Baumgarte, classic RK4 at a fixed step"),
        o_(o) {}
  Control control() const override { return Control::kStep; }
  double default_control() const override { return o_.h; }

 protected:
  LinearAlgebra linear_algebra() const override { return o_.linear_algebra; }
  std::string DenseSolverText() const override { return kIndex1Dense; }
  std::string SparseSolverText() const override { return kIndex1Sparse; }
  void Settings(const NaturalModel&, const ControlValue& c, std::map<std::string, std::string>& s) const override {
    BaumgarteSettings(o_, s);
    s["integrator"] = "classic RK4, fixed step";
    s["h"] = ControlText(c, " s") + ", the largest (equal steps landing on every sample)";
  }
  void Integrate(RunState& run, const Eigen::VectorXd&) const override {
    const Analysis& a = run.model.analysis;
    const int n = run.sys.n();
    const double h_max = run.control.value;
    Eigen::VectorXd y(2 * n);
    y << run.result.trajectory[0].q, run.result.trajectory[0].qd;
    double peak = 0;  // the step's largest stage acceleration, for the singular-position guard
    const OdeRhs f = Index1Rhs(run.sys, o_.alpha, o_.beta, &peak);
    Rk4Scratch scratch;
    OdeStats stats;
    std::string why;
    double t = a.t0;
    for (int k = 1; k < a.samples; ++k) {
      run.Integrating();
      const double t_next = a.TimeAt(k);
      const auto [sub, h] = StepsTo(t, t_next, h_max);
      for (long i = 0; i < sub; ++i) {
        CheckBudgetInStep(run.options, i, a.TimeAt(k - 1));
        peak = 0;
        const bool stepped = Rk4Step(f, {}, t, h, y, why, stats, &scratch);
        if (!stepped || !run.GuardScaled(t, peak, why)) {
          if (stepped) run.ExplainExplicitTrip(y.head(n), h, why);
          run.steps = stats.steps;
          run.evaluations = stats.evaluations;
          return run.Fail(t, why);
        }
        t = i + 1 == sub ? t_next : t + h;
      }
      Eigen::VectorXd qdd;
      if (!SampleAccelerations(run, t, y, o_.alpha, o_.beta, qdd, why)) return run.Fail(t, why);
      run.Record(t, y.head(n), y.tail(n), qdd);
    }
    run.steps = stats.steps;
    run.evaluations = stats.evaluations;
  }

 private:
  BaumgarteOptions o_;
};

// A tolerance override keeps the method's atol/rtol ratio: atol = rtol × (default atol / default rtol).
double EffectiveAtol(const ControlValue& c, double rtol, double atol) {
  return c.overridden ? c.value * (atol / rtol) : atol;
}
std::string AtolText(const ControlValue& c, double rtol, double atol) {
  if (!c.overridden) return Fmt(atol);
  return Fmt(EffectiveAtol(c, rtol, atol)) + " (rtol × " + Fmt(atol / rtol) + ", the default atol/rtol = " + Fmt(atol) +
         "/" + Fmt(rtol) + ")";
}

Eigen::VectorXd StateAtol(const NaturalModel& nm, double atol) {
  Eigen::VectorXd v(2 * nm.n);
  v << atol * nm.q_scale, atol * nm.q_scale;  // q̇ per second
  return v;
}

class BaumgarteDopri5 final : public FreeDynamicsMethod {
 public:
  explicit BaumgarteDopri5(BaumgarteOptions o)
      : FreeDynamicsMethod("dyn-baumgarte-dopri5",
                           "forward dynamics: index-1 multipliers, Baumgarte, error-controlled Dormand–Prince 5(4)"),
        o_(o) {}
  Control control() const override { return Control::kTolerance; }
  double default_control() const override { return o_.rtol; }

 protected:
  LinearAlgebra linear_algebra() const override { return o_.linear_algebra; }
  std::string DenseSolverText() const override { return kIndex1Dense; }
  std::string SparseSolverText() const override { return kIndex1Sparse; }
  void Settings(const NaturalModel&, const ControlValue& c, std::map<std::string, std::string>& s) const override {
    BaumgarteSettings(o_, s);
    s["integrator"] = "Dormand–Prince 5(4), error per step ≤ atol + rtol |y|, steps shortened to land on samples";
    s["rtol"] = ControlText(c, "");
    s["atol"] = AtolText(c, o_.rtol, o_.atol) + " × coordinate scale (q) and × scale/s (q̇)";
  }
  void Integrate(RunState& run, const Eigen::VectorXd&) const override {
    const Analysis& a = run.model.analysis;
    const int n = run.sys.n();
    Eigen::VectorXd y(2 * n);
    y << run.result.trajectory[0].q, run.result.trajectory[0].qd;
    Dopri5Options opt;
    opt.rtol = run.control.value;
    opt.atol = StateAtol(run.sys.model(), EffectiveAtol(run.control, o_.rtol, o_.atol));
    // The singular-position guard on every accepted step, with its FSAL derivative (q̈ at the end).
    const Dopri5* accepted = nullptr;
    opt.on_accept = [&](double ta, const Eigen::VectorXd&, Eigen::VectorXd&, std::string& stop) {
      CheckBudgetInStep(run.options, accepted->stats().steps, run.result.trajectory.back().t);
      return run.GuardScaled(ta, RunState::ScaledNorm(accepted->derivative().tail(n), run.sys.model().q_scale), stop);
    };
    Dopri5 dopri(opt);
    accepted = &dopri;
    const OdeRhs f = Index1Rhs(run.sys, o_.alpha, o_.beta);
    std::string why;
    double t = a.t0;
    for (int k = 1; k < a.samples; ++k) {
      run.Integrating();
      const bool ok = dopri.Advance(f, {}, t, a.TimeAt(k), y, why);
      run.steps = dopri.stats().steps;
      run.evaluations = dopri.stats().evaluations;
      if (!ok) return run.Fail(t, why);
      Eigen::VectorXd qdd;
      if (!SampleAccelerations(run, t, y, o_.alpha, o_.beta, qdd, why)) return run.Fail(t, why);
      run.Record(t, y.head(n), y.tail(n), qdd);
    }
    run.result.settings["rejected_steps"] = std::to_string(dopri.stats().rejected);
    run.result.settings["h_range"] = Fmt(dopri.stats().h_min) + " … " + Fmt(dopri.stats().h_max) + " s";
  }

 private:
  BaumgarteOptions o_;
};

// ---- ALI3-P -----------------------------------------------------------------------------------

class Ali3p final : public FreeDynamicsMethod {
 public:
  explicit Ali3p(Ali3pOptions o)
      : FreeDynamicsMethod("dyn-ali3p",
                           "forward dynamics: index-3 augmented Lagrangian, trapezoidal rule, mass-orthogonal projections"),
        o_(o) {}
  Control control() const override { return Control::kStep; }
  double default_control() const override { return o_.h; }

 protected:
  void Settings(const NaturalModel&, const ControlValue& c, std::map<std::string, std::string>& s) const override {
    s["formulation"] = "index-3 augmented Lagrangian M q̈ + Φ_qᵀ(αΦ + λ) = Q, λ ← λ + αΦ per iteration";
    s["integrator"] = "trapezoidal rule, fixed step, Newton on the step's increment q_{n+1} − q_n with "
                      "M + (h²/4)(α Φ_qᵀΦ_q + Σ(αΦ+λ)_i ∂²Φ_i/∂q² of distance rows)";
    s["projections"] = "mass-orthogonal: W q̇ = M q̇*, W q̈ = M q̈* − (h²/4) Φ_qᵀ α Φ̇_q q̇, solved for q̇ − q̇* and q̈ − q̈*";
    s["h"] = ControlText(c, " s") + ", the largest (equal steps landing on every sample)";
    s["penalty"] = "α h²/4 = " + Fmt(o_.penalty) + " × max diag M at the largest h (α in 1/s² × kg, rows scaled to " +
                   "length units; the ratio, not α, is kept when h changes)";
    s["tolerance"] = Fmt(o_.tolerance) + " (max |Δq_j| / coordinate scale), then the same on one more pass with that " +
                     "factorization on the residual at the new iterate (W⁻¹ f, λ updated there); near singular positions also " +
                     Fmt(o_.singular_tolerance) + " on the remaining error |Δq| ρ/(1 − ρ) of a linearly contracting iteration";
    s["max_iterations"] = std::to_string(o_.max_iterations) + "; a step that fails is redone in 4 sub-steps (α h²/4 kept), " +
                          std::to_string(o_.retry_levels) + " level(s) deep";
  }
  LinearAlgebra linear_algebra() const override { return o_.linear_algebra; }
  int sparse_from() const override { return kSparseAli3pFromCoordinates; }
  std::string DenseSolverText() const override {
    return "dense LDLᵀ (Eigen, Newton) and LLᵀ (projections) on the tangent matrix";
  }
  std::string SparseSolverText() const override {
    return "sparse LDLᵀ (Eigen SimplicialLDLT, AMD ordering computed once per run) on the tangent matrix, "
           "assembled into a fixed pattern (M, Φ_qᵀΦ_q, the distance rows' Hessians)";
  }

  void Integrate(RunState& run, const Eigen::VectorXd& lambda0) const override {
    const Analysis& a = run.model.analysis;
    const double h_max = run.control.value;
    Eigen::VectorXd q = run.result.trajectory[0].q, qd = run.result.trajectory[0].qd;
    Eigen::VectorXd qdd = run.result.trajectory[0].qdd;
    Ali3pStepper stepper(run.sys, o_, h_max, lambda0);
    std::string why;
    double t = a.t0;
    const auto finish = [&] {
      run.iterations = stepper.iterations();
      if (stepper.retries() > 0)
        run.result.settings["retried_steps"] = std::to_string(stepper.retries()) +
                                               " interval(s) redone in sub-steps after Newton failed (near singular positions)";
      if (stepper.slow_steps() > 0)
        run.result.settings["slow_steps"] = std::to_string(stepper.slow_steps()) +
                                            " step(s) accepted by singular_tolerance (linear contraction near a singular position)";
    };
    for (int k = 1; k < a.samples; ++k) {
      run.Integrating();
      const double t_next = a.TimeAt(k);
      const auto [sub, h] = StepsTo(t, t_next, h_max);
      for (long i = 0; i < sub; ++i) {
        CheckBudgetInStep(run.options, i, a.TimeAt(k - 1));
        run.sys.SetTime(t);  // the stepper evaluates loads given as laws at t + h
        if (!stepper.Advance(h, q, qd, qdd, why)) {
          finish();
          return run.Fail(t, why + " (in the step from t to t + " + Fmt(h) + " s)");
        }
        ++run.steps;
        t = i + 1 == sub ? t_next : t + h;
        if (!run.Guard(t, q, qd, qdd, h, why)) {
          finish();
          return run.Fail(t, why);
        }
      }
      run.Record(t, q, qd, qdd);
    }
    finish();
  }

 private:
  Ali3pOptions o_;
};

// ---- coordinate partitioning ------------------------------------------------------------------

class Partition {
 public:
  explicit Partition(DynamicsSystem& sys) : sys_(sys) {}

  // Dependent coordinates = the pivot columns of a full-pivoting LU of the row-normalized Φ_q.
  void Choose(const Eigen::VectorXd& q, const Eigen::VectorXd& qd) {
    sys_.Evaluate(q, qd, false);
    Pick(Normalized(sys_.J()), dep_, ind_);
    ++choices_;
  }

  // Re-chooses when the current dependent block is much worse conditioned than a fresh choice.
  bool MaybeRechoose(const Eigen::VectorXd& q, const Eigen::VectorXd& qd, double ratio) {
    sys_.Evaluate(q, qd, false);
    const Eigen::MatrixXd Jn = Normalized(sys_.J());
    std::vector<int> dep, ind;
    const double fresh = Pick(Jn, dep, ind);
    best_quality_ = fresh;
    if (dep == dep_ || Quality(Jn, dep_) >= ratio * fresh) return false;
    dep_ = dep;
    ind_ = ind;
    ++choices_;
    return true;
  }

  // Dependent q by Newton–Raphson with the independent ones fixed, then dependent q̇.
  bool Project(Eigen::VectorXd& y, double tolerance, std::string& why, long& iterations) {
    if (dep_.empty()) return true;  // no constraint rows (a block on a guide that q leaves out): all independent
    const int n = sys_.n();
    Eigen::VectorXd q = y.head(n), qd = y.tail(n);
    const NaturalModel& nm = sys_.model();
    double prev = INFINITY;
    for (int it = 0;; ++it) {
      sys_.Evaluate(q, qd, false);
      const double res = ScaledResidual(nm, sys_.data());
      if (!std::isfinite(res)) {
        why = "coordinate partitioning: NaN/Inf in the dependent coordinates";
        return false;
      }
      if (res <= tolerance || (res <= 1e-10 && res > 0.5 * prev)) break;
      if (it >= 25) {
        why = "coordinate partitioning: Newton–Raphson for the dependent coordinates did not converge (scaled ‖Φ‖ = " +
              Fmt(res) + "); the dependent block is singular here";
        return false;
      }
      prev = res;
      const Eigen::MatrixXd D = Columns(sys_.J(), dep_);
      const Eigen::VectorXd dx = D.colPivHouseholderQr().solve(sys_.phi());
      for (size_t k = 0; k < dep_.size(); ++k) q[dep_[k]] -= dx[k];
      ++iterations;
    }
    const Eigen::MatrixXd D = Columns(sys_.J(), dep_);
    Eigen::VectorXd qd_ind(ind_.size());
    for (size_t k = 0; k < ind_.size(); ++k) qd_ind[k] = qd[ind_[k]];
    const Eigen::VectorXd qd_dep = D.colPivHouseholderQr().solve(-(Columns(sys_.J(), ind_) * qd_ind));
    for (size_t k = 0; k < dep_.size(); ++k) qd[dep_[k]] = qd_dep[k];
    y << q, qd;
    return true;
  }

  const std::vector<int>& independent() const { return ind_; }
  // The best dependent block's pivot ratio at the last check: near 0 where Φ_q loses rank, and
  // then no choice of independent coordinates determines the dependent ones (a bifurcation).
  double best_quality() const { return best_quality_; }
  int choices() const { return choices_; }

 private:
  static Eigen::MatrixXd Normalized(const Eigen::MatrixXd& J) {
    Eigen::MatrixXd Jn = J;
    for (Eigen::Index i = 0; i < Jn.rows(); ++i) {
      const double nrm = Jn.row(i).norm();
      if (nrm > 0) Jn.row(i) /= nrm;
    }
    return Jn;
  }
  static Eigen::MatrixXd Columns(const Eigen::MatrixXd& J, const std::vector<int>& cols) {
    Eigen::MatrixXd out(J.rows(), static_cast<Eigen::Index>(cols.size()));
    for (size_t k = 0; k < cols.size(); ++k) out.col(static_cast<Eigen::Index>(k)) = J.col(cols[k]);
    return out;
  }
  // The smallest |R_kk| of the dependent block's pivoted QR, the rows of Φ_q normalized to unit
  // length: 0 = singular, 1 = ideal. Not min/max of |R_kk|, which is 1 for every one-column block:
  // a pendulum of point coordinates then kept x dependent down to the bottom of its swing, where
  // x no longer follows from y (3e-5 of the range over 10 s at rtol 1e-8, against 1e-9 with an angle).
  static double Quality(const Eigen::MatrixXd& Jn, const std::vector<int>& dep) {
    if (dep.empty()) return 1.0;
    const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(Columns(Jn, dep));
    return qr.matrixR().diagonal().cwiseAbs().minCoeff();
  }
  // The pivot columns of a full-pivoting LU are dependent; returns that block's quality.
  double Pick(const Eigen::MatrixXd& Jn, std::vector<int>& dep, std::vector<int>& ind) const {
    Eigen::FullPivLU<Eigen::MatrixXd> lu(Jn);
    lu.setThreshold(kRankTolerance);
    const int r = static_cast<int>(lu.rank()), n = sys_.n();
    std::vector<bool> is_dep(n, false);
    for (int k = 0; k < r; ++k) is_dep[lu.permutationQ().indices()[k]] = true;
    dep.clear();
    ind.clear();
    for (int j = 0; j < n; ++j) (is_dep[j] ? dep : ind).push_back(j);
    return Quality(Jn, dep);
  }

  DynamicsSystem& sys_;
  std::vector<int> dep_, ind_;
  int choices_ = 0;
  double best_quality_ = 1.0;
};

std::string SingularStop(double quality) {
  return "Φ_q loses rank (best dependent block's pivot ratio " + Fmt(quality) +
         "): a singular position where the independent coordinates no longer determine the dependent ones, "
         "so coordinate partitioning cannot tell the branches apart and stops";
}

class CoordinatePartitioning final : public FreeDynamicsMethod {
 public:
  explicit CoordinatePartitioning(PartitioningOptions o)
      : FreeDynamicsMethod("dyn-coordinate-partitioning",
                           "forward dynamics: independent coordinates from the pivots of Φ_q, dependent ones by Newton"),
        o_(o) {}
  // DOPRI5 (the default) is swept by its tolerance, RK4 by its step.
  Control control() const override { return o_.rk4 ? Control::kStep : Control::kTolerance; }
  double default_control() const override { return o_.rk4 ? o_.h : o_.rtol; }

 protected:
  // Always dense (see PartitioningOptions): the partition is chosen by a full-pivoting LU.
  LinearAlgebra linear_algebra() const override { return LinearAlgebra::kDense; }
  std::string DenseSolverText() const override {
    return std::string(kIndex1Dense) +
           "; always dense: the partition is a full-pivoting LU of Φ_q (pivots for conditioning, not fill), "
           "and the method stops at the first singular position anyway";
  }
  std::string SparseSolverText() const override { return DenseSolverText(); }
  void Settings(const NaturalModel&, const ControlValue& c, std::map<std::string, std::string>& s) const override {
    s["formulation"] = "coordinate partitioning (Wehage–Haug): q̈ from [M Φ_qᵀ; Φ_q 0] on the exact manifold";
    s["partition"] = "full-pivoting LU of the row-normalized Φ_q; re-chosen when the dependent block's pivot ratio falls below " +
                     Fmt(o_.rechoose_ratio) + " × a fresh choice's";
    s["newton_tolerance"] = Fmt(o_.newton_tolerance) + " (scaled ‖Φ‖)";
    if (o_.rk4) {
      s["integrator"] = "classic RK4 on the independent coordinates, fixed step";
      s["h"] = ControlText(c, " s") + ", the largest (equal steps landing on every sample)";
    } else {
      s["integrator"] = "Dormand–Prince 5(4) on the independent coordinates";
      s["rtol"] = ControlText(c, "");
      s["atol"] = AtolText(c, o_.rtol, o_.atol) + " × coordinate scale";
      s["projection_error"] = "the Newton displacement of the step's end is added to the error estimate";
    }
  }

  void Integrate(RunState& run, const Eigen::VectorXd&) const override {
    DynamicsSystem& sys = run.sys;
    const Analysis& a = run.model.analysis;
    const int n = sys.n();
    Eigen::VectorXd y(2 * n);
    y << run.result.trajectory[0].q, run.result.trajectory[0].qd;
    Partition part(sys);
    part.Choose(y.head(n), y.tail(n));
    long newton = 0;
    const OdeProject project = [&](double, Eigen::VectorXd& yy, std::string& why) {
      return part.Project(yy, o_.newton_tolerance, why, newton);
    };
    const OdeRhs f = Index1Rhs(sys, 0.0, 0.0);
    std::string why;
    double t = a.t0;
    const auto finish = [&](long steps, long evals) {
      run.steps = steps;
      run.evaluations = evals;
      run.iterations = newton;
      run.result.settings["partitions_chosen"] = std::to_string(part.choices());
    };
    if (o_.rk4) {
      OdeStats stats;
      Rk4Scratch scratch;
      for (int k = 1; k < a.samples; ++k) {
        run.Integrating();
        const double t_next = a.TimeAt(k);
        const auto [sub, h] = StepsTo(t, t_next, run.control.value);
        for (long i = 0; i < sub; ++i) {
          CheckBudgetInStep(run.options, i, a.TimeAt(k - 1));
          const Eigen::VectorXd before = y;
          if (!Rk4Step(f, project, t, h, y, why, stats, &scratch)) {
            finish(stats.steps, stats.evaluations);
            return run.Fail(t, why);
          }
          // A fixed step cannot retry: a dependent coordinate that moved far more than the step's
          // own velocity allows means Newton–Raphson jumped to another assembly branch.
          const double jump = ((y.head(n) - before.head(n)) - h * before.tail(n)).cwiseAbs().cwiseQuotient(sys.model().q_scale).maxCoeff();
          if (jump > 0.1) {
            finish(stats.steps, stats.evaluations);
            return run.Fail(t, "coordinate partitioning jumped to another assembly branch (a singular position: Φ_q loses rank)");
          }
          t = i + 1 == sub ? t_next : t + h;
          part.MaybeRechoose(y.head(n), y.tail(n), o_.rechoose_ratio);
          if (part.best_quality() < kSingularTolerance) {
            finish(stats.steps, stats.evaluations);
            return run.Fail(t, SingularStop(part.best_quality()));
          }
        }
        Eigen::VectorXd qdd;
        if (!SampleAccelerations(run, t, y, 0, 0, qdd, why)) return run.Fail(t, why);
        run.Record(t, y.head(n), y.tail(n), qdd);
      }
      finish(stats.steps, stats.evaluations);
      return;
    }
    Dopri5Options opt;
    opt.rtol = run.control.value;
    opt.atol = StateAtol(sys.model(), EffectiveAtol(run.control, o_.rtol, o_.atol));
    // Every component counts in the error norm: the dependent ones carry the projection's
    // displacement, which rejects a step whose Newton–Raphson jumped to another branch.
    long accepted_steps = 0;
    opt.on_accept = [&](double, const Eigen::VectorXd& yy, Eigen::VectorXd&, std::string& stop) {
      CheckBudgetInStep(run.options, accepted_steps++, run.result.trajectory.back().t);
      part.MaybeRechoose(yy.head(n), yy.tail(n), o_.rechoose_ratio);
      if (part.best_quality() >= kSingularTolerance) return true;
      stop = SingularStop(part.best_quality());
      return false;
    };
    Dopri5 dopri(opt);
    for (int k = 1; k < a.samples; ++k) {
      run.Integrating();
      const bool ok = dopri.Advance(f, project, t, a.TimeAt(k), y, why);
      finish(dopri.stats().steps, dopri.stats().evaluations);
      if (!ok) return run.Fail(t, why);
      Eigen::VectorXd qdd;
      if (!SampleAccelerations(run, t, y, 0, 0, qdd, why)) return run.Fail(t, why);
      run.Record(t, y.head(n), y.tail(n), qdd);
    }
    run.result.settings["rejected_steps"] = std::to_string(dopri.stats().rejected);
  }

 private:
  PartitioningOptions o_;
};

}  // namespace

std::optional<std::string> DynamicsApplicability(const Model& model) {
  if (model.kind != ScenarioKind::kLinkage && model.kind != ScenarioKind::kSpatial)
    return "forward dynamics is implemented for planar and spatial linkages only";
  if (!model.IsFree()) return "a driven scene: its motion is prescribed (kinematics), not forward dynamics";
  if (!model.HasMass()) return "a free scene without masses: forward dynamics needs mass properties";
  if (model.q_layout.empty()) return "the scene has no coordinates";
  return std::nullopt;
}

std::unique_ptr<Method> MakeBaumgarteRk4Method(BaumgarteOptions o) { return std::make_unique<BaumgarteRk4>(o); }
std::unique_ptr<Method> MakeBaumgarteDopri5Method(BaumgarteOptions o) { return std::make_unique<BaumgarteDopri5>(o); }
std::unique_ptr<Method> MakeAli3pMethod(Ali3pOptions o) { return std::make_unique<Ali3p>(o); }
std::unique_ptr<Method> MakeCoordinatePartitioningMethod(PartitioningOptions o) {
  return std::make_unique<CoordinatePartitioning>(o);
}

}  // namespace mechbench::numeric
