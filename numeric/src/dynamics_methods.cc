#include "mechbench/format.h"
#include "mechbench/numeric/dynamics_methods.h"

#include "mechbench/errors.h"
#include "mechbench/numeric/constraints.h"
#include "mechbench/numeric/forward_dynamics.h"
#include "mechbench/numeric/natural_model.h"
#include "mechbench/run_control.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace mechbench::numeric {
namespace {

// The state of one run: samples, statistics at the samples, and how it ended.
struct RunState {
  const Model& model;
  DynamicsSystem& sys;
  Result& result;
  // The run's step or tolerance: the method's own, or the RunOptions override (never stored in
  // the method, which stays as constructed).
  ControlValue control;
  double E0 = 0;
  double energy_drift = 0, max_residual = 0, max_residual_rate = 0;
  long steps = 0, iterations = 0, evaluations = 0;

  void Record(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& qd, const Eigen::VectorXd& qdd) {
    const double res = sys.ScaledPhi(q);
    const double rate = sys.ScaledPhiDot(q, qd);
    const double E = sys.Energy(q, qd);
    energy_drift = std::max(energy_drift, std::fabs(E - E0));
    max_residual = std::max(max_residual, res);
    max_residual_rate = std::max(max_residual_rate, rate);
    result.trajectory.push_back(Sample{t, q, qd, qdd, sys.data().Phi.norm()});
  }
  void Fail(double t, const std::string& why) {
    result.status = Status::kDiverged;
    result.reason = "at t = " + Fmt(t) + " s: " + why;
  }
  // Number of equal steps of at most h from t to t_next.
  static int Substeps(double t, double t_next, double h) {
    return std::max(1, static_cast<int>(std::ceil((t_next - t) / h - 1e-9)));
  }
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

  void DoRun(const Model& model, const RunOptions& options, Result& result) const final {
    const NaturalModel nm = Compile(model);
    const FreeStart start = AssembleFreeStart(nm);
    result.messages.insert(result.messages.end(), start.instant.messages.begin(), start.instant.messages.end());
    DynamicsSystem sys(nm);
    sys.ChooseRows(start.q);
    Eigen::VectorXd qdd0, lambda0;
    std::string why;
    // At t0 the state is assembled to round-off, so the Baumgarte terms are left out: q̈ and λ
    // are the exact index-1 values every formulation starts from.
    if (!sys.Accelerations(start.q, start.qd, 0, 0, qdd0, lambda0, &why))
      throw ScenarioError({model.source_file, 0}, "singular position at t0: " + why,
                          "start the free scene away from a position where Φ_q loses rank");
    // Without a motion no step is taken: the interval cap does not apply.
    const bool motion = options.motion && model.analysis.HasMotion();
    RunState run{model, sys, result,
                 EffectiveControl(control(), default_control(), options, motion ? LargestInterval(model.analysis) : kNaN)};
    Settings(nm, run.control, result.settings);
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
    run.E0 = sys.Energy(start.q, start.qd);
    out["energy"] = run.E0;
    run.Record(model.analysis.t0, start.q, start.qd, qdd0);
    if (motion) Integrate(run, lambda0);
    out["energy_drift"] = run.energy_drift;
    out["max_residual"] = run.max_residual;
    out["max_residual_rate"] = run.max_residual_rate;
    out["steps"] = static_cast<double>(run.steps);
    out["evaluations"] = static_cast<double>(run.evaluations);
    out["iterations"] = static_cast<double>(run.iterations);
    result.settings["steps"] = std::to_string(run.steps);
  }
};

// ---- index-1 with Baumgarte -------------------------------------------------------------------

OdeRhs Index1Rhs(DynamicsSystem& sys, double alpha, double beta) {
  return [&sys, alpha, beta](double, const Eigen::VectorXd& y, Eigen::VectorXd& dy, std::string& why) {
    const int n = sys.n();
    Eigen::VectorXd qdd, lambda;
    if (!sys.Accelerations(y.head(n), y.tail(n), alpha, beta, qdd, lambda, &why)) return false;
    dy.resize(2 * n);
    dy.head(n) = y.tail(n);
    dy.tail(n) = qdd;
    return true;
  };
}

void BaumgarteSettings(const BaumgarteOptions& o, std::map<std::string, std::string>& s) {
  s["formulation"] = "index-1 Lagrange multipliers [M Φ_qᵀ; Φ_q 0][q̈; λ] = [Q; −Φ̇_q q̇ − 2αΦ̇ − β²Φ]";
  s["alpha"] = Fmt(o.alpha) + " 1/s";
  s["beta"] = Fmt(o.beta) + " 1/s";
  s["linear_solver"] = "dense LU with partial pivoting (Eigen), singular when its residual exceeds 1e-8";
}

// Accelerations at a sample (for the output) with the method's own Baumgarte terms.
bool SampleAccelerations(RunState& run, const Eigen::VectorXd& y, double alpha, double beta, Eigen::VectorXd& qdd,
                         std::string& why) {
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
    const OdeRhs f = Index1Rhs(run.sys, o_.alpha, o_.beta);
    OdeStats stats;
    std::string why;
    double t = a.t0;
    for (int k = 1; k < a.samples; ++k) {
      const double t_next = a.TimeAt(k);
      const int sub = RunState::Substeps(t, t_next, h_max);
      const double h = (t_next - t) / sub;
      for (int i = 0; i < sub; ++i) {
        if (!Rk4Step(f, {}, t, h, y, why, stats)) {
          run.steps = stats.steps;
          run.evaluations = stats.evaluations;
          return run.Fail(t, why);
        }
        t = i + 1 == sub ? t_next : t + h;
      }
      Eigen::VectorXd qdd;
      if (!SampleAccelerations(run, y, o_.alpha, o_.beta, qdd, why)) return run.Fail(t, why);
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
    Dopri5 dopri(opt);
    const OdeRhs f = Index1Rhs(run.sys, o_.alpha, o_.beta);
    std::string why;
    double t = a.t0;
    for (int k = 1; k < a.samples; ++k) {
      const bool ok = dopri.Advance(f, {}, t, a.TimeAt(k), y, why);
      run.steps = dopri.stats().steps;
      run.evaluations = dopri.stats().evaluations;
      if (!ok) return run.Fail(t, why);
      Eigen::VectorXd qdd;
      if (!SampleAccelerations(run, y, o_.alpha, o_.beta, qdd, why)) return run.Fail(t, why);
      run.Record(t, y.head(n), y.tail(n), qdd);
    }
    run.result.settings["rejected_steps"] = std::to_string(dopri.stats().rejected);
    run.result.settings["h_range"] = Fmt(dopri.stats().h_min) + " … " + Fmt(dopri.stats().h_max) + " s";
  }

 private:
  BaumgarteOptions o_;
};

// ---- ALI3-P -----------------------------------------------------------------------------------

// W += c Σ_k w_k ∂²Φ_k/∂q² over the active distance rows |r1 − r0|² − L² (Hessian 2[I −I; −I I]
// in the two points' coordinates) and |r_b − r_a|² − s² (the same, and −2 on s).
void AddDistanceHessians(const NaturalModel& nm, const std::vector<int>& rows, const Eigen::VectorXd& w, double c,
                         Eigen::MatrixXd& W) {
  for (size_t k = 0; k < rows.size(); ++k) {
    const ConstraintRow& row = nm.rows[rows[k]];
    if (row.kind != RowKind::kBodyDistance && row.kind != RowKind::kDistance) continue;
    const double g = 2 * c * w[static_cast<Eigen::Index>(k)];
    for (int axis = 0; axis < 2; ++axis) {
      const int a = nm.point_slot[row.pts[0]][axis], b = nm.point_slot[row.pts[1]][axis];
      if (a >= 0) W(a, a) += g;
      if (b >= 0) W(b, b) += g;
      if (a >= 0 && b >= 0) W(a, b) -= g, W(b, a) -= g;
    }
    if (row.kind == RowKind::kDistance && row.slots[0] >= 0) W(row.slots[0], row.slots[0]) -= g;
  }
}

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
    s["integrator"] = "trapezoidal rule, fixed step, Newton on M + (h²/4)(α Φ_qᵀΦ_q + Σ(αΦ+λ)_i ∂²Φ_i/∂q² of distance rows)";
    s["projections"] = "mass-orthogonal: W q̇ = M q̇*, W q̈ = M q̈* − (h²/4) Φ_qᵀ α Φ̇_q q̇";
    s["h"] = ControlText(c, " s") + ", the largest (equal steps landing on every sample)";
    s["penalty"] = "α h²/4 = " + Fmt(o_.penalty) + " × max diag M at the largest h (α in 1/s² × kg, rows scaled to " +
                   "length units; the ratio, not α, is kept when h changes)";
    s["tolerance"] = Fmt(o_.tolerance) + " (max |Δq_j| / coordinate scale)";
    s["max_iterations"] = std::to_string(o_.max_iterations);
  }

  void Integrate(RunState& run, const Eigen::VectorXd& lambda0) const override {
    DynamicsSystem& sys = run.sys;
    const NaturalModel& nm = sys.model();
    const Analysis& a = run.model.analysis;
    const int m = sys.m();
    const Eigen::MatrixXd& M = sys.M();
    const Eigen::VectorXd& Q = sys.Q();
    // Rows in length units (distance rows are length², angle rows length·…), so one α fits all.
    Eigen::VectorXd S(m);
    for (int k = 0; k < m; ++k) S[k] = nm.length_scale / nm.rows[sys.active_rows()[k]].scale;
    // α from the largest step, so that α h²/4 = penalty × max diag M [kg].
    const double h_max = run.control.value;
    const double alpha = o_.penalty * std::max(M.diagonal().maxCoeff(), 1e-300) * 4 / (h_max * h_max);
    Eigen::VectorXd q = run.result.trajectory[0].q, qd = run.result.trajectory[0].qd;
    Eigen::VectorXd qdd = run.result.trajectory[0].qdd;
    Eigen::VectorXd lam = lambda0.cwiseQuotient(S);  // warm start from the exact multipliers at t0
    Eigen::LLT<Eigen::MatrixXd> llt;
    Eigen::LDLT<Eigen::MatrixXd> ldlt;
    Eigen::MatrixXd Js, W;
    double t = a.t0;
    for (int k = 1; k < a.samples; ++k) {
      const double t_next = a.TimeAt(k);
      const int sub = RunState::Substeps(t, t_next, h_max);
      const double h = (t_next - t) / sub, c = h * h / 4;
      for (int i = 0; i < sub; ++i) {
        const Eigen::VectorXd qd_hat = (2 / h) * q + qd;
        const Eigen::VectorXd qdd_hat = (4 / (h * h)) * q + (4 / h) * qd + qdd;
        Eigen::VectorXd qn = q + h * qd + 0.5 * h * h * qdd;
        bool converged = false;
        double prev = INFINITY;
        for (int it = 1; it <= o_.max_iterations; ++it) {
          sys.Evaluate(qn, qd, false);
          Js = S.asDiagonal() * sys.J();
          const Eigen::VectorXd phis = S.cwiseProduct(sys.phi());
          if (it > 1) lam += alpha * phis;
          // f(q) = (h²/4)(M q̈ + Φ_qᵀ(αΦ + λ) − Q) with q̈ = (4/h²) q − q̂̈.
          const Eigen::VectorXd force = alpha * phis + lam;
          const Eigen::VectorXd f = M * (qn - c * qdd_hat) + c * (Js.transpose() * force - Q);
          // Tangent: M + (h²/4)(α Φ_qᵀΦ_q + Σ_i (αΦ_i + λ_i) ∂²Φ_i/∂q²). The second term (the
          // constraint forces' geometric stiffness) is what keeps Newton converging where Φ_q
          // loses rank; it is exact for the quadratic distance rows and left out for the others.
          W = M + (c * alpha) * Js.transpose() * Js;
          AddDistanceHessians(nm, sys.active_rows(), S.cwiseProduct(force), c, W);
          ldlt.compute(W);
          if (ldlt.info() != Eigen::Success) return run.Fail(t, "the ALI3-P tangent matrix is singular");
          const Eigen::VectorXd dq = ldlt.solve(f);
          qn -= dq;
          ++run.iterations;
          const double step = dq.cwiseAbs().cwiseQuotient(nm.q_scale).maxCoeff();
          if (!std::isfinite(step)) return run.Fail(t, "the ALI3-P iteration produced NaN/Inf");
          // Converged at the tolerance, or at the round-off floor where the steps stop shrinking.
          if (step <= o_.tolerance || (step <= 1e-9 && step > 0.5 * prev)) {
            converged = true;
            break;
          }
          prev = step;
        }
        if (!converged)
          return run.Fail(t + h, "the ALI3-P Newton iteration did not converge in " + std::to_string(o_.max_iterations) +
                                     " iterations");
        sys.Evaluate(qn, qd, false);
        lam += alpha * S.cwiseProduct(sys.phi());
        Js = S.asDiagonal() * sys.J();
        W = M + (c * alpha) * Js.transpose() * Js;
        llt.compute(W);
        // Mass-orthogonal projections onto Φ_q q̇ = 0 and Φ_q q̈ + Φ̇_q q̇ = 0.
        const Eigen::VectorXd qd_star = (2 / h) * qn - qd_hat;
        const Eigen::VectorXd qdd_star = (4 / (h * h)) * qn - qdd_hat;
        qd = llt.solve(M * qd_star);
        sys.Evaluate(qn, qd, true);
        qdd = llt.solve(M * qdd_star - (c * alpha) * Js.transpose() * S.cwiseProduct(sys.jdot_qd()));
        q = qn;
        ++run.steps;
        t = i + 1 == sub ? t_next : t + h;
        if (!q.allFinite() || !qd.allFinite() || !qdd.allFinite()) return run.Fail(t, "the state became NaN/Inf");
      }
      run.Record(t, q, qd, qdd);
    }
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
  // Smallest over largest |R_kk| of the dependent block's pivoted QR: 0 = singular, 1 = ideal.
  static double Quality(const Eigen::MatrixXd& Jn, const std::vector<int>& dep) {
    if (dep.empty()) return 1.0;
    const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(Columns(Jn, dep));
    const Eigen::VectorXd d = qr.matrixR().diagonal().cwiseAbs();
    return d.maxCoeff() > 0 ? d.minCoeff() / d.maxCoeff() : 0.0;
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
      for (int k = 1; k < a.samples; ++k) {
        const double t_next = a.TimeAt(k);
        const int sub = RunState::Substeps(t, t_next, run.control.value);
        const double h = (t_next - t) / sub;
        for (int i = 0; i < sub; ++i) {
          const Eigen::VectorXd before = y;
          if (!Rk4Step(f, project, t, h, y, why, stats)) {
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
        if (!SampleAccelerations(run, y, 0, 0, qdd, why)) return run.Fail(t, why);
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
    opt.on_accept = [&](double, const Eigen::VectorXd& yy, Eigen::VectorXd&, std::string& stop) {
      part.MaybeRechoose(yy.head(n), yy.tail(n), o_.rechoose_ratio);
      if (part.best_quality() >= kSingularTolerance) return true;
      stop = SingularStop(part.best_quality());
      return false;
    };
    Dopri5 dopri(opt);
    for (int k = 1; k < a.samples; ++k) {
      const bool ok = dopri.Advance(f, project, t, a.TimeAt(k), y, why);
      finish(dopri.stats().steps, dopri.stats().evaluations);
      if (!ok) return run.Fail(t, why);
      Eigen::VectorXd qdd;
      if (!SampleAccelerations(run, y, 0, 0, qdd, why)) return run.Fail(t, why);
      run.Record(t, y.head(n), y.tail(n), qdd);
    }
    run.result.settings["rejected_steps"] = std::to_string(dopri.stats().rejected);
  }

 private:
  PartitioningOptions o_;
};

}  // namespace

std::optional<std::string> DynamicsApplicability(const Model& model) {
  if (model.kind != ScenarioKind::kLinkage) return "forward dynamics is implemented for planar linkages only";
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
