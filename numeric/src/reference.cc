#include "mechbench/format.h"
#include "mechbench/numeric/reference.h"

#include "mechbench/motion_error.h"

#include "mechbench/numeric/dynamics_methods.h"
#include "mechbench/numeric/forward_dynamics.h"
#include "mechbench/numeric/natural_model.h"
#include "mechbench/numeric/refactoring_lu.h"

#include <Eigen/SparseCore>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <ctime>
#include <exception>
#include <numbers>

namespace mechbench::numeric {
namespace {

std::string FmtN(double v) { return Fmt(v, 3); }


double CpuSeconds() { return static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }

// ---- the N-four-bar's full model in complex time ----------------------------------------------
//
// The motion is real-analytic in t (a pendulum), so the full model's equations also hold along
// its continuation to complex t. Just off the real axis Φ_q keeps its rank, so an index-1 run along
// t + iδ passes every singular position at a distance, and a leg back down to the real axis gives
// the motion there: the analytic continuation, which is the smooth passage (a branch switch is not
// analytic). The imaginary parts back on the real axis must vanish: a check of its own.

using Complex = std::complex<double>;

// DynamicsSystem::Accelerations (index-1 with Baumgarte) in complex arithmetic, for the distance
// rows |r1 − r0|² − L² of the N-four-bar's bars; no conjugates, so every function stays analytic.
// KLU (refactoring_lu.h: ordered and pivoted once, then refactored) on the fixed pattern [M Φ_qᵀ; Φ_q 0].
class ComplexIndex1 {
 public:
  ComplexIndex1(const DynamicsSystem& sys, double alpha, double beta) : sys_(sys), alpha_(alpha), beta_(beta) {
    const NaturalModel& nm = sys.model();
    n_ = nm.n, m_ = sys.m();
    if (nm.model.HasForceElements()) {
      // Its right-hand side is the constant Q: loads that depend on q and q̇ are not continued.
      problem = "complex time takes constant loads only, not spring–dampers, torques or varying point forces";
      return;
    }
    // M's nonzeros (sparse: O(n), no dense n × n pass at large N).
    const Eigen::SparseMatrix<double> M =
        sys.sparse() ? sys.M_sparse() : Eigen::SparseMatrix<double>(sys.M().sparseView(0.0, 0.0));
    std::vector<Eigen::Triplet<Complex>> t;
    for (int j = 0; j < M.outerSize(); ++j)
      for (Eigen::SparseMatrix<double>::InnerIterator it(M, j); it; ++it) t.emplace_back(it.row(), it.col(), 0.0);
    for (int k = 0; k < m_; ++k) {
      const ConstraintRow& row = nm.rows[sys.active_rows()[k]];
      if (row.kind != RowKind::kBodyDistance) {
        problem = "complex time takes distance rows only, not " + std::string(ToString(row.kind)) + " (" +
                  row.Where() + ")";
        return;
      }
      Row r;
      r.L2 = row.L * row.L;
      for (int p = 0; p < 2; ++p)
        for (int a = 0; a < 2; ++a) {
          r.slot[p][a] = nm.point_slot[row.pts[p]][a];
          r.fixed[p][a] = nm.point_const[row.pts[p]][a];
          if (r.slot[p][a] >= 0) t.emplace_back(n_ + k, r.slot[p][a], 0.0), t.emplace_back(r.slot[p][a], n_ + k, 0.0);
        }
      rows_.push_back(r);
    }
    kkt_.resize(n_ + m_, n_ + m_);
    kkt_.setFromTriplets(t.begin(), t.end());
    kkt_.makeCompressed();
    for (int j = 0; j < M.outerSize(); ++j)
      for (Eigen::SparseMatrix<double>::InnerIterator it(M, j); it; ++it)
        mass_.push_back({Index(static_cast<int>(it.row()), static_cast<int>(it.col())), it.value()});
    for (int k = 0; k < m_; ++k)
      for (int p = 0; p < 2; ++p)
        for (int a = 0; a < 2; ++a) {
          const int s = rows_[k].slot[p][a];
          rows_[k].at[p][a][0] = s >= 0 ? Index(n_ + k, s) : -1;
          rows_[k].at[p][a][1] = s >= 0 ? Index(s, n_ + k) : -1;
        }
    if (!lu_.Analyze(kkt_)) problem = "the complex index-1 matrix's pattern cannot be ordered";
    rhs_.resize(n_ + m_);
  }

  std::string problem;  // why it cannot run this model (empty: it can)

  bool Accelerations(const Eigen::VectorXcd& q, const Eigen::VectorXcd& qd, Eigen::VectorXcd& qdd, std::string& why) {
    Complex* v = kkt_.valuePtr();
    std::fill(v, v + kkt_.nonZeros(), Complex(0));
    for (const auto& [at, value] : mass_) v[at] = value;
    rhs_.head(n_) = sys_.Q().cast<Complex>();
    for (int k = 0; k < m_; ++k) {
      const Row& r = rows_[k];
      Complex d[2], w[2];  // r1 − r0, v1 − v0
      for (int a = 0; a < 2; ++a) {
        const auto at = [&](int p, const Eigen::VectorXcd& x, double fixed) {
          return r.slot[p][a] >= 0 ? x[r.slot[p][a]] : Complex(fixed);
        };
        d[a] = at(1, q, r.fixed[1][a]) - at(0, q, r.fixed[0][a]);
        w[a] = at(1, qd, 0.0) - at(0, qd, 0.0);
      }
      for (int p = 0; p < 2; ++p)
        for (int a = 0; a < 2; ++a)
          if (r.at[p][a][0] >= 0) v[r.at[p][a][0]] = v[r.at[p][a][1]] = (p == 1 ? 2.0 : -2.0) * d[a];
      const Complex phi = d[0] * d[0] + d[1] * d[1] - r.L2;
      const Complex phi_dot = 2.0 * (d[0] * w[0] + d[1] * w[1]);  // Φ_q q̇
      const Complex jdot_qd = 2.0 * (w[0] * w[0] + w[1] * w[1]);  // Φ̇_q q̇
      rhs_[n_ + k] = -jdot_qd - 2.0 * alpha_ * phi_dot - beta_ * beta_ * phi;
    }
    if (!lu_.Solve(kkt_, rhs_, x_)) {
      why = "the complex index-1 matrix is singular";
      return false;
    }
    qdd = x_.head(n_);
    return true;
  }

 private:
  struct Row {
    int slot[2][2];      // q slot of each point's x, y (−1: fixed)
    double fixed[2][2];  // the fixed values [length]
    int at[2][2][2];     // value indices of the Φ_q entry and of its transpose
    double L2 = 0;       // [length²]
  };
  int Index(int r, int c) const {
    const int* inner = kkt_.innerIndexPtr();
    const int* begin = inner + kkt_.outerIndexPtr()[c];
    const int* end = inner + kkt_.outerIndexPtr()[c + 1];
    return static_cast<int>(std::lower_bound(begin, end, r) - inner);
  }
  const DynamicsSystem& sys_;
  double alpha_, beta_;
  int n_ = 0, m_ = 0;
  std::vector<Row> rows_;
  std::vector<std::pair<int, double>> mass_;
  Eigen::SparseMatrix<Complex> kkt_;
  ComplexRefactoringLu lu_;
  Eigen::VectorXcd rhs_, x_;
};

// One run over the whole motion from `start` (at t0): up to t0 + i·detour, along t + i·detour,
// and down to the real axis at every sample (each leg from the path's state there, which the path
// then continues from). DOPRI5 at rtol on (q, q̇) ∈ ℂ²ⁿ stored as real and imaginary parts (atol
// rtol/100 × coordinate scale on each); on a straight piece t = z0 + d·s (s real), dy/ds = d·f(y).
// `cpu_budget` [s] (NaN: none) stops it between samples, over-budget with the samples so far.
Result RunInComplexTime(const Model& model, const DynamicsSystem& sys, const Sample& start, double alpha, double beta,
                        double detour, double rtol, double cpu_budget) {
  Result r;
  r.method = "whole run (index-1 DOPRI5 rtol " + FmtN(rtol) + " along t + " + FmtN(detour) + "i s)";
  r.settings["path"] = "t0 → t0 + " + FmtN(detour) + "i s, along t + " + FmtN(detour) +
                       "i s, down to the real axis at every sample (analytic continuation)";
  r.settings["formulation"] = "index-1 with Baumgarte, the full natural-coordinate model in complex arithmetic";
  const double cpu = CpuSeconds();
  const NaturalModel& nm = sys.model();
  const Analysis& a = model.analysis;
  const int n = nm.n;
  ComplexIndex1 dyn(sys, alpha, beta);
  if (!dyn.problem.empty()) {
    r.status = Status::kNotApplicable;
    r.reason = dyn.problem;
    return r;
  }
  Eigen::VectorXcd q(n), qd(n), qdd(n), dy(2 * n);
  const auto split = [&](const Eigen::VectorXd& y) {
    q = y.head(n).cast<Complex>() + Complex(0, 1) * y.segment(2 * n, n).cast<Complex>();
    qd = y.segment(n, n).cast<Complex>() + Complex(0, 1) * y.tail(n).cast<Complex>();
  };
  const auto along = [&](Complex d) {
    return OdeRhs([&, d](double, const Eigen::VectorXd& y, Eigen::VectorXd& dydt, std::string& why) {
      split(y);
      if (!dyn.Accelerations(q, qd, qdd, why)) return false;
      dy << d * qd, d * qdd;
      dydt.resize(4 * n);
      dydt << dy.real(), dy.imag();
      return true;
    });
  };
  Dopri5Options dop;
  dop.rtol = rtol;
  dop.atol = (rtol * 1e-2 * nm.q_scale).replicate(4, 1);
  long steps = 0, evaluations = 0;
  const auto leg = [&](Complex d, Eigen::VectorXd& y, std::string& why) {
    Dopri5 dopri(dop);
    double s = 0;
    const bool ok = dopri.Advance(along(d), {}, s, detour, y, why);
    steps += dopri.stats().steps, evaluations += dopri.stats().evaluations;
    return ok;
  };
  Eigen::VectorXd y = Eigen::VectorXd::Zero(4 * n);
  y << start.q, start.qd, Eigen::VectorXd::Zero(2 * n);
  r.trajectory.push_back(start);
  double imaginary = 0;  // largest |Im q_j| / q_scale_j at the samples
  std::string why;
  Dopri5 path(dop);
  double t = a.t0;
  if (!leg(Complex(0, 1), y, why)) {
    r.status = Status::kDiverged;
    r.reason = "on the way up from t0: " + why;
  }
  for (int k = 1; k < a.samples && r.ok(); ++k) {
    const double tk = a.TimeAt(k);
    if (cpu_budget > 0 && CpuSeconds() - cpu > cpu_budget) {
      r.status = Status::kOverBudget;
      r.reason = "stopped at t = " + Fmt(t, 4) + " s of " + Fmt(a.t1, 4) + " s: its CPU budget of " + Fmt(cpu_budget, 3) +
                 " s ran out";
      break;
    }
    if (!path.Advance(along(1.0), {}, t, tk, y, why)) {
      r.status = Status::kDiverged;
      r.reason = "at t = " + Fmt(t) + " + " + FmtN(detour) + "i s: " + why;
      break;
    }
    Eigen::VectorXd down = y;
    if (!leg(Complex(0, -1), down, why)) {
      r.status = Status::kDiverged;
      r.reason = "on the way down to t = " + Fmt(tk) + " s: " + why;
      break;
    }
    split(down);
    if (!dyn.Accelerations(q, qd, qdd, why)) qdd.setConstant(n, kNaN);
    imaginary = std::max(imaginary, q.imag().cwiseQuotient(nm.q_scale).cwiseAbs().maxCoeff());
    r.trajectory.push_back(Sample{tk, q.real(), qd.real(), qdd.real(), 0.0});
  }
  steps += path.stats().steps, evaluations += path.stats().evaluations;
  r.quantities["steps"] = static_cast<double>(steps);
  r.quantities["evaluations"] = static_cast<double>(evaluations);
  r.quantities["imaginary"] = imaginary;
  r.cpu_seconds = CpuSeconds() - cpu;
  return r;
}

}  // namespace

Reference ReferenceFromExact(const Model& model, const ExactMotion& exact_motion, const ReferenceOptions& o) {
  Reference ref;
  const Analysis& a = model.analysis;
  // Pass 1 finds the singular positions; pass 2 also gives the states where the segments start.
  // Both within the primary's budget: a motion of 1e9 s has 1e12 stops.
  double cpu = CpuSeconds();
  RunOptions budget;
  if (o.cpu_budget > 0) budget.cpu_deadline = cpu + o.cpu_budget;
  std::vector<double> crossings;
  ExactSolution exact;
  struct Segment {
    double t0, t1;
  };
  std::vector<Segment> segments;
  try {
    exact = exact_motion.solve({}, budget);
    crossings = exact.singular;
    std::vector<double> starts;
    double begin = a.t0;
    const double until = std::min(a.t1, exact_motion.confirm_until);
    for (size_t k = 0; k <= crossings.size(); ++k) {
      const double end = std::min(until, k < crossings.size() ? crossings[k] - o.segment_margin : a.t1);
      if (end > begin) {
        segments.push_back({begin, end});
        if (begin > a.t0) starts.push_back(begin);
      }
      if (k < crossings.size()) begin = std::min(a.t1, crossings[k] + o.segment_margin);
    }
    if (!starts.empty()) exact = exact_motion.solve(starts, budget);
  } catch (const BudgetExceeded& b) {
    Result& p = ref.primary;
    p.method = exact_motion.method;
    p.status = Status::kOverBudget;
    p.reason = "stopped at t = " + Fmt(b.t, 4) + " s of " + Fmt(a.t1, 4) + " s: its CPU budget of " +
               Fmt(o.cpu_budget, 3) + " s ran out" + exact_motion.budget_note;
    p.cpu_seconds = CpuSeconds() - cpu;
    ref.description = "no reference: " + p.reason;
    return ref;
  }
  Result& p = ref.primary;
  p.method = exact_motion.method;
  p.trajectory = exact.trajectory;
  p.quantities = exact.quantities;
  p.settings["formulation"] = exact_motion.formulation;
  p.cpu_seconds = CpuSeconds() - cpu;
  ref.singular_positions = static_cast<int>(crossings.size());

  // Confirmation: index-1 DOPRI5 on the full model, one segment at a time from the reference state.
  cpu = CpuSeconds();
  Result& c = ref.confirmation;
  const bool piecewise = !crossings.empty() || exact_motion.whole_run;
  c.method = "confirmation (dyn-baumgarte-dopri5 rtol " + FmtN(o.segment_rtol) +
             (piecewise ? " between the singular positions)" : " over t = " + FmtN(a.t0) + " … " +
                                                                   FmtN(segments.empty() ? a.t0 : segments.back().t1) + " s)");
  const NaturalModel nm = Compile(model);
  DynamicsSystem sys(nm);
  const int nq = nm.n;
  BaumgarteOptions bg;
  Eigen::VectorXd qdd, lambda, y(2 * nq);
  const OdeRhs f = [&](double tt, const Eigen::VectorXd& yy, Eigen::VectorXd& dy, std::string& why) {
    sys.SetTime(tt);
    if (!sys.Accelerations(yy.head(nq), yy.tail(nq), bg.alpha, bg.beta, qdd, lambda, &why)) return false;
    dy.resize(2 * nq);
    dy << yy.tail(nq), qdd;
    return true;
  };
  std::vector<Sample> ref_subset;
  size_t next_start = 0;
  for (const Segment& seg : segments) {
    const Sample& s0 = seg.t0 == a.t0 ? exact.trajectory[0] : exact.extra[next_start++];
    if (seg.t0 == a.t0) sys.ChooseRows(s0.q);
    y << s0.q, s0.qd;
    Dopri5Options dop;
    dop.rtol = o.segment_rtol;
    dop.atol = Eigen::VectorXd(2 * nq);
    dop.atol << o.segment_rtol * 1e-2 * nm.q_scale, o.segment_rtol * 1e-2 * nm.q_scale;
    Dopri5 dopri(dop);
    double t = seg.t0;
    std::string why;
    for (int k = 0; k < a.samples; ++k) {
      const double tk = a.TimeAt(k);
      if (tk < seg.t0 || tk > seg.t1) continue;
      if (o.cpu_budget > 0 && CpuSeconds() - cpu > o.cpu_budget) {
        c.status = Status::kOverBudget;
        c.reason = "stopped at t = " + Fmt(t, 4) + " s of " + Fmt(a.t1, 4) + " s: its CPU budget of " +
                   Fmt(o.cpu_budget, 3) + " s ran out";
        break;
      }
      if (tk > t && !dopri.Advance(f, {}, t, tk, y, why)) {
        c.status = Status::kDiverged;
        c.reason = "at t = " + Fmt(t) + " s (segment " + Fmt(seg.t0) + " … " + Fmt(seg.t1) + " s): " + why;
        break;
      }
      sys.SetTime(tk);
      if (!sys.Accelerations(y.head(nq), y.tail(nq), bg.alpha, bg.beta, qdd, lambda, &why)) qdd.setConstant(nq, kNaN);
      c.trajectory.push_back(Sample{tk, y.head(nq), y.tail(nq), qdd, 0.0});
      ref_subset.push_back(exact.trajectory[k]);
    }
    if (!c.ok()) break;
  }
  c.cpu_seconds = CpuSeconds() - cpu;
  ref.compared_samples = static_cast<int>(c.trajectory.size());
  const MotionError e = CompareMotion(model, ScaleOfMotion(model, exact.trajectory), ref_subset, c.trajectory);
  ref.segment_agreement = e.q.max;
  const bool segments_ok = c.ok() && e.problem.empty() && e.q.max <= o.agreement && ref.compared_samples > 0;

  // Across them: one run of the same equations over the whole motion, from the model's own
  // initial state (as every dynamics method assembles it), in complex time.
  Result& w = ref.whole_run;
  if (exact_motion.whole_run) try {
    const FreeStart fs = AssembleFreeStart(nm);
    Sample start{a.t0, fs.q, fs.qd, Eigen::VectorXd(), 0.0};
    sys.SetTime(a.t0);
    if (!sys.Accelerations(start.q, start.qd, bg.alpha, bg.beta, qdd, lambda)) qdd.setConstant(nq, kNaN);
    start.qdd = qdd;
    w = RunInComplexTime(model, sys, start, bg.alpha, bg.beta, o.detour, o.whole_run_rtol, o.cpu_budget);
  } catch (const std::exception& ex) {
    w.status = Status::kFailed;
    w.reason = std::string("the initial state: ") + ex.what();
  }
  if (!exact_motion.whole_run) {
    ref.confirmed = segments_ok;
    ref.agreement = c.ok() ? e.q.max : INFINITY;
    ref.tolerance = o.agreement;
    ref.description = exact_motion.describe(exact);
    std::string seg = "index-1 DOPRI5 (rtol " + FmtN(o.segment_rtol) + ") on the full " + std::to_string(nq) +
                      "-coordinate model over t = " + FmtN(a.t0) + " … " +
                      FmtN(segments.empty() ? a.t0 : segments.back().t1) + " s (" + std::to_string(ref.compared_samples) +
                      " of " + std::to_string(a.samples) + " samples)";
    if (!c.ok())
      seg += " " + std::string(ToString(c.status)) + " " + c.reason;
    else if (segments_ok)
      seg += " to " + FmtN(e.q.max) + " (stated " + FmtN(o.agreement) + ")";
    else
      seg += " differs by " + FmtN(e.q.max) + " at " + e.q.slot + ", t = " + FmtN(e.q.t) + " s (stated " +
             FmtN(o.agreement) + ")";
    ref.description += (ref.confirmed ? ", confirmed by " : ", UNCONFIRMED: ") + seg;
    return ref;
  }
  c.cpu_seconds += w.cpu_seconds;  // what the harness reports as the confirmation's cost
  const MotionError we = CompareMotion(model, exact.trajectory, w.trajectory);
  ref.whole_run_tolerance = o.whole_run_agreement;
  if (w.ok()) {
    ref.whole_run_agreement = we.q.max;
    if (exact_motion.branch_spread) ref.whole_run_spread = exact_motion.branch_spread(w.trajectory);
  }
  const bool whole_ok = w.ok() && we.problem.empty() && we.q.max <= o.whole_run_agreement;

  ref.confirmed = segments_ok && whole_ok;
  // For the harness (the formulations' distance): the worse of the two, against the wider statement.
  ref.agreement = w.ok() ? std::max(e.q.max, we.q.max) : INFINITY;
  ref.tolerance = std::max(o.agreement, o.whole_run_agreement);
  ref.description = exact_motion.describe(exact);
  std::string seg = "index-1 DOPRI5 (rtol " + FmtN(o.segment_rtol) + ") on the full " + std::to_string(nq) +
                    "-coordinate model between the singular positions (restarted " + FmtN(o.segment_margin) +
                    " s after each, " + std::to_string(ref.compared_samples) + " of " + std::to_string(a.samples) +
                    " samples)";
  if (!c.ok())
    seg += " " + std::string(ToString(c.status)) + " " + c.reason;
  else if (segments_ok)
    seg += " to " + FmtN(e.q.max) + " (stated " + FmtN(o.agreement) + ")";
  else
    seg += " differs by " + FmtN(e.q.max) + " at " + e.q.slot + ", t = " + FmtN(e.q.t) + " s (stated " + FmtN(o.agreement) +
           ")";
  std::string whole = "across them by one run of the same equations from t0 along t + " + FmtN(o.detour) +
                      "i s in complex time (DOPRI5 rtol " + FmtN(o.whole_run_rtol) + ", not extrapolated)";
  if (!w.ok())
    whole += " " + std::string(ToString(w.status)) + ": " + w.reason;
  else if (whole_ok)
    whole += " to " + FmtN(we.q.max) + " over all " + std::to_string(we.samples) + " samples (stated " +
             FmtN(o.whole_run_agreement) + ")";
  else
    whole += " differs by " + FmtN(we.q.max) + " at " + we.q.slot + ", t = " + FmtN(we.q.t) + " s (stated " +
             FmtN(o.whole_run_agreement) + (we.problem.empty() ? ")" : "; " + we.problem + ")");
  ref.description += (ref.confirmed ? ", confirmed by " : ", UNCONFIRMED: ") + seg + "; " + whole;
  return ref;
}


Reference ReferenceTrajectory(const Model& model, const ReferenceOptions& o) {
  Reference ref;
  const double duration = model.analysis.t1 - model.analysis.t0;
  const double stated = o.agreement * std::max(1.0, duration / o.agreement_horizon);
  ref.tolerance = stated;
  BaumgarteOptions bg;
  bg.rtol = o.rtol;
  bg.atol = o.atol;
  const RunOptions budget{.cpu_budget = o.cpu_budget};
  ref.primary = MakeBaumgarteDopri5Method(bg)->Run(model, budget);
  ref.primary.method = "reference (dyn-baumgarte-dopri5, rtol " + FmtN(o.rtol) + ")";
  if (!ref.primary.ok()) {
    ref.description = "no reference: " + ref.primary.reason;
    return ref;
  }
  ref.description = "index-1 + Baumgarte, DOPRI5 (rtol " + FmtN(o.rtol) + ")";
  PartitioningOptions cp;
  cp.rtol = o.rtol;
  cp.atol = o.atol;
  ref.confirmation = MakeCoordinatePartitioningMethod(cp)->Run(model, budget);
  std::string by = "coordinate partitioning + DOPRI5";
  if (!ref.confirmation.ok() && ref.confirmation.status != Status::kOverBudget) {
    // At rtol its step can fall below round-off where its dependent coordinates, solved by Newton
    // to ~1e-13, are noise to the error estimate (Andrews' mechanism, 0.011 s into its 0.03 s);
    // 100 × rtol is still 100 × finer than the stated agreement.
    const std::string reason = ref.confirmation.reason;
    cp.rtol = 100 * o.rtol;
    cp.atol = 100 * o.atol;
    ref.confirmation = MakeCoordinatePartitioningMethod(cp)->Run(model, budget);
    if (ref.confirmation.ok()) {
      ref.description += "; coordinate partitioning at rtol " + FmtN(o.rtol) + " stopped (" + reason + ")";
      by = "coordinate partitioning + DOPRI5 at rtol " + FmtN(cp.rtol);
    } else {
      ref.confirmation.reason = reason;
    }
  }
  if (!ref.confirmation.ok()) {
    ref.description += "; coordinate partitioning stopped (" + ref.confirmation.reason + ")";
    Ali3pOptions al;
    al.h = o.ali3p_h;
    ref.confirmation = MakeAli3pMethod(al)->Run(model, budget);
    by = "ALI3-P (h = " + FmtN(o.ali3p_h) + " s)";
  }
  ref.confirmation.method = "confirmation (" + by + ")";
  const MotionError e = CompareMotion(model, ref.primary.trajectory, ref.confirmation.trajectory);
  ref.agreement = e.q.max;
  ref.agreement_qd = e.qd.max;
  ref.agreement_qdd = e.qdd.max;
  ref.confirmed = ref.confirmation.ok() && e.problem.empty() && e.q.max <= stated;
  const std::string statement = "stated " + FmtN(stated) +
                                (stated > o.agreement ? " = " + FmtN(o.agreement) + " per " + FmtN(o.agreement_horizon) +
                                                            " s of motion × " + FmtN(duration) + " s"
                                                      : "");
  // Without constraint rows coordinate partitioning has no dependent coordinates: it integrates
  // the same ODE M q̈ = Q with the same DOPRI5, so its agreement repeats the run, it checks nothing.
  const bool same_ode = Compile(model).m() == 0 && by.rfind("coordinate partitioning", 0) == 0;
  if (ref.confirmed && same_ode)
    ref.description += "; the scene has no constraints, so " + by + " integrates the same ODE (M q̈ = Q) and agrees to " +
                       FmtN(e.q.max) + ": the same computation, not an independent confirmation";
  else if (ref.confirmed)
    ref.description += ", confirmed by " + by + " to " + FmtN(e.q.max) + " (" + statement + ")";
  else if (!ref.confirmation.ok())
    ref.description += ", UNCONFIRMED: " + by + " " + ToString(ref.confirmation.status) + " " + ref.confirmation.reason;
  else
    ref.description += ", UNCONFIRMED: " + by + " differs by " + FmtN(e.q.max) + " at " + e.q.slot + ", t = " + FmtN(e.q.t) +
                       " s (" + statement + ")";
  return ref;
}

}  // namespace mechbench::numeric
