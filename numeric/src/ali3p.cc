#include "mechbench/numeric/ali3p.h"

#include "mechbench/errors.h"
#include "mechbench/numeric/dynamics.h"
#include "mechbench/numeric/natural_model.h"
#include "mechbench/numeric/spatial.h"

#include <Eigen/SparseCore>

#include <algorithm>
#include <cmath>

namespace mechbench::numeric {
namespace {

bool IsDistanceRow(const ConstraintRow& row) {
  return row.kind == RowKind::kBodyDistance || row.kind == RowKind::kDistance;
}

// W += c Σ_k w_k ∂²Φ_k/∂q² over the active distance rows |r1 − r0|² − L² (Hessian 2[I −I; −I I]
// in the two points' coordinates) and |r_b − r_a|² − s² (the same, and −2 on s); in a spatial
// model over every row quadratic in q (SpatialRowHessian, constant). An angle row's Hessian
// depends on q and is left out, as the planar angle rows' are (Newton still converges, linearly
// in that term).
bool ConstantSpatialHessian(const ConstraintRow& row) { return row.kind != RowKind::kAngle3; }

void AddDistanceHessians(const NaturalModel& nm, const std::vector<int>& rows, const Eigen::VectorXd& w, double c,
                         Eigen::MatrixXd& W) {
  if (nm.dim == 3) {  // every spatial row's Hessian (constant; spatial.h)
    std::vector<Eigen::Triplet<double>> t;
    for (size_t k = 0; k < rows.size(); ++k) {
      if (!ConstantSpatialHessian(nm.rows[rows[k]])) continue;
      t.clear();
      SpatialRowHessian(nm, nm.rows[rows[k]], Eigen::VectorXd(), t);
      for (const auto& e : t) W(e.row(), e.col()) += c * w[static_cast<Eigen::Index>(k)] * e.value();
    }
    return;
  }
  for (size_t k = 0; k < rows.size(); ++k) {
    const ConstraintRow& row = nm.rows[rows[k]];
    if (!IsDistanceRow(row)) continue;
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

}  // namespace

// The tangent matrix with a fixed pattern, lower triangle only (what SimplicialLDLT reads):
// M's entries, every pair of columns one row of Φ_q touches, and the distance rows' Hessians.
// Values are assembled through precomputed value indices, so an iteration allocates nothing
// and the AMD ordering is computed once per run.
class Ali3pStepper::SparseTangent {
 public:
  using ColMatrix = Eigen::SparseMatrix<double>;
  using RowMatrix = DynamicsSystem::SparseRowMatrix;

  explicit SparseTangent(const DynamicsSystem& sys) {
    const NaturalModel& nm = sys.model();
    const RowMatrix& J = sys.J_sparse();
    const ColMatrix& M = sys.M_sparse();
    const int n = sys.n(), m = sys.m();
    std::vector<Eigen::Triplet<double>> t;
    const auto add = [&](int i, int j) {
      if (i >= 0 && j >= 0) t.emplace_back(std::max(i, j), std::min(i, j), 0.0);
    };
    for (int c = 0; c < M.outerSize(); ++c)
      for (ColMatrix::InnerIterator it(M, c); it; ++it) add(static_cast<int>(it.row()), static_cast<int>(it.col()));
    for (int k = 0; k < m; ++k)
      for (RowMatrix::InnerIterator a(J, k); a; ++a)
        for (RowMatrix::InnerIterator b(J, k); b; ++b) add(static_cast<int>(a.col()), static_cast<int>(b.col()));
    // Spatial rows: their constant Hessians (lower triangle), kept as (row, entry) pairs.
    std::vector<std::pair<int, Eigen::Triplet<double>>> spatial;
    if (nm.dim == 3) {
      std::vector<Eigen::Triplet<double>> h;
      for (int k = 0; k < m; ++k) {
        if (!ConstantSpatialHessian(nm.rows[sys.active_rows()[k]])) continue;
        h.clear();
        SpatialRowHessian(nm, nm.rows[sys.active_rows()[k]], Eigen::VectorXd(), h);
        for (const auto& e : h)
          if (e.row() >= e.col()) add(e.row(), e.col()), spatial.emplace_back(k, e);
      }
    }
    for (int k = 0; k < m; ++k) {
      const ConstraintRow& row = nm.rows[sys.active_rows()[k]];
      if (!IsDistanceRow(row)) continue;
      for (int axis = 0; axis < 2; ++axis) {
        const int a = nm.point_slot[row.pts[0]][axis], b = nm.point_slot[row.pts[1]][axis];
        add(a, a), add(b, b), add(a, b);
      }
      if (row.kind == RowKind::kDistance) add(row.slots[0], row.slots[0]);
    }
    const std::vector<std::vector<int>> elements = ElementSlots(nm);
    for (const auto& slot : elements)
      for (int a : slot)
        for (int b : slot) add(a, b);
    W.resize(n, n);
    W.setFromTriplets(t.begin(), t.end());
    W.makeCompressed();
    base.assign(static_cast<size_t>(W.nonZeros()), 0.0);
    for (int c = 0; c < M.outerSize(); ++c)
      for (ColMatrix::InnerIterator it(M, c); it; ++it)
        if (it.row() >= it.col()) base[Index(static_cast<int>(it.row()), static_cast<int>(it.col()))] = it.value();
    // Per row, the pairs (a, b) of its entries with col_a ≥ col_b, as (value index a, value index b, W index).
    pair_start.assign(static_cast<size_t>(m) + 1, 0);
    for (int k = 0; k < m; ++k) {
      pair_start[k] = static_cast<int>(pairs.size());
      for (RowMatrix::InnerIterator a(J, k); a; ++a)
        for (RowMatrix::InnerIterator b(J, k); b; ++b)
          if (a.col() >= b.col())
            pairs.push_back({static_cast<int>(&a.value() - J.valuePtr()), static_cast<int>(&b.value() - J.valuePtr()),
                             Index(static_cast<int>(a.col()), static_cast<int>(b.col()))});
    }
    pair_start[m] = static_cast<int>(pairs.size());
    for (const auto& [k, e] : spatial) spatial_hessians.push_back({k, Index(e.row(), e.col()), e.value()});
    for (int k = 0; k < m; ++k) {
      const ConstraintRow& row = nm.rows[sys.active_rows()[k]];
      if (!IsDistanceRow(row)) continue;
      Hessian h;
      h.k = k;
      for (int axis = 0; axis < 2; ++axis) {
        const int a = nm.point_slot[row.pts[0]][axis], b = nm.point_slot[row.pts[1]][axis];
        h.aa[axis] = a >= 0 ? Index(a, a) : -1;
        h.bb[axis] = b >= 0 ? Index(b, b) : -1;
        h.ab[axis] = a >= 0 && b >= 0 ? Index(std::max(a, b), std::min(a, b)) : -1;
      }
      h.ss = row.kind == RowKind::kDistance && row.slots[0] >= 0 ? Index(row.slots[0], row.slots[0]) : -1;
      hessians.push_back(h);
    }
    // Per force element, the W index of each (i, j) of its w × w block in the lower triangle (−1: not stored).
    for (const auto& slot : elements) {
      const size_t w = slot.size();
      std::vector<int> at(w * w);
      for (size_t i = 0; i < w; ++i)
        for (size_t j = 0; j < w; ++j)
          at[w * i + j] = slot[i] >= 0 && slot[j] >= 0 && slot[i] >= slot[j] ? Index(slot[i], slot[j]) : -1;
      element_at.push_back(at);
    }
    newton.analyzePattern(W);
    projection.analyzePattern(W);
  }

  // W += the symmetric part of −(h²/4) K − (h/2) C of each force element (ElementDerivatives).
  void AddElements(const std::vector<ElementDerivative>& d, double c, double h) {
    double* v = W.valuePtr();
    for (size_t e = 0; e < d.size(); ++e) {
      const Eigen::MatrixXd T = -c * d[e].K - 0.5 * h * d[e].C;
      const int w = static_cast<int>(T.rows());
      for (int i = 0; i < w; ++i)
        for (int j = 0; j < w; ++j)
          if (const int at = element_at[e][w * i + j]; at >= 0) v[at] += 0.5 * (T(i, j) + T(j, i));
    }
  }

  // W = M + cα Σ_k S_k² J_kᵀ J_k (+ the distance Hessians weighted by w = S∘force when given).
  void Assemble(const RowMatrix& J, const Eigen::VectorXd& S, double c_alpha, const Eigen::VectorXd* w, double c) {
    double* v = W.valuePtr();
    std::copy(base.begin(), base.end(), v);
    const double* jv = J.valuePtr();
    const int m = static_cast<int>(J.rows());
    for (int k = 0; k < m; ++k) {
      const double s2 = c_alpha * S[k] * S[k];
      for (int p = pair_start[k]; p < pair_start[k + 1]; ++p) v[pairs[p].w] += s2 * jv[pairs[p].a] * jv[pairs[p].b];
    }
    if (!w) return;
    for (const Hessian& h : hessians) {
      const double g = 2 * c * (*w)[h.k];
      for (int axis = 0; axis < 2; ++axis) {
        if (h.aa[axis] >= 0) v[h.aa[axis]] += g;
        if (h.bb[axis] >= 0) v[h.bb[axis]] += g;
        if (h.ab[axis] >= 0) v[h.ab[axis]] -= g;
      }
      if (h.ss >= 0) v[h.ss] -= g;
    }
    for (const SpatialEntry& h : spatial_hessians) v[h.at] += c * (*w)[h.k] * h.value;
  }

  ColMatrix W;
  Eigen::SimplicialLDLT<ColMatrix, Eigen::Lower, Eigen::AMDOrdering<int>> newton, projection;

 private:
  int Index(int r, int c) const { return PatternIndex(W, r, c, "ALI3-P tangent pattern lookup"); }
  struct Pair {
    int a, b, w;
  };
  struct Hessian {
    int k = 0;
    int aa[2] = {-1, -1}, bb[2] = {-1, -1}, ab[2] = {-1, -1};
    int ss = -1;
  };
  std::vector<double> base;
  std::vector<int> pair_start;
  std::vector<Pair> pairs;
  std::vector<Hessian> hessians;
  struct SpatialEntry {  // a spatial row's constant Hessian entry: c w_k value goes to W's value `at`
    int k = 0, at = 0;
    double value = 0;
  };
  std::vector<SpatialEntry> spatial_hessians;
  std::vector<std::vector<int>> element_at;
};

namespace {
// The median length of the model's constant distances (planar body rows, spatial distance rows)
// [length]: the size of its links. The scene's extent when it has none.
double LinkScale(const NaturalModel& nm) {
  std::vector<double> L;
  for (const ConstraintRow& row : nm.rows) {
    if (row.kind == RowKind::kBodyDistance && row.L > 0) L.push_back(row.L);
    if (row.kind == RowKind::kDistance3 && row.c > 0) L.push_back(std::sqrt(row.c));
  }
  if (L.empty()) return nm.length_scale;
  std::nth_element(L.begin(), L.begin() + L.size() / 2, L.end());
  return L[L.size() / 2];
}
}  // namespace

Ali3pStepper::Ali3pStepper(DynamicsSystem& sys, const Ali3pOptions& options, double h_max, const Eigen::VectorXd& lambda0)
    : sys_(sys), o_(options) {
  const NaturalModel& nm = sys.model();
  const int m = sys.m();
  // Rows in length units (distance rows are length², angle rows length·…), so one α fits all.
  S_.resize(m);
  for (int k = 0; k < m; ++k) S_[k] = nm.length_scale / nm.rows[sys.active_rows()[k]].scale;
  // α from the largest step, so that α h²/4 = penalty × max diag M [kg].
  alpha_ = o_.penalty * std::max(sys.M_diagonal().maxCoeff(), 1e-300) * 4 / (h_max * h_max);
  lam_ = lambda0.cwiseQuotient(S_);  // warm start from the exact multipliers at t0
  if (sys.sparse()) sparse_ = std::make_unique<SparseTangent>(sys);  // from J_sparse()'s pattern
  // Newton's steps are measured against the size of the links, not of the coordinates: a length
  // coordinate's q_scale is the scene's extent (the largest |p|), which grows with a chain's length,
  // while an error δ left in a step costs (4/h²) δ in q̈ whatever the extent. Scaled by the extent,
  // the tolerance let N-four-bars of 1 m links keep 1e-10 × N m per step (error 1.6e-5 of the range
  // at N = 3000 over 0.1 s, against 2.9e-8 with the links' scale).
  step_scale_ = nm.q_scale;
  const double link = LinkScale(nm);
  for (int j = 0; j < step_scale_.size(); ++j)
    if (step_scale_[j] == nm.length_scale) step_scale_[j] = std::min(nm.length_scale, link);
}

Ali3pStepper::~Ali3pStepper() = default;

bool Ali3pStepper::Step(double h, Eigen::VectorXd& q, Eigen::VectorXd& qd, Eigen::VectorXd& qdd, std::string& why,
                        double alpha_factor) {
  const double alpha = alpha_ * alpha_factor;
  DynamicsSystem& sys = sys_;
  const NaturalModel& nm = sys.model();
  const double c = h * h / 4;
  const bool sparse = sys.sparse();
  const bool elements = sys.has_elements();
  sys.SetTime(sys.time() + h);  // the loads at the step's end (trapezoidal rule); Retry restores it
  // The unknown is the increment Δ = q_{n+1} − q_n (dx_): with b = h q̇ + (h²/4) q̈ (b_),
  //   q̈_{n+1} = (4/h²)(Δ − b),   q̇_{n+1} = (2/h) Δ − q̇,
  // the trapezoidal rule without the terms (4/h²) q and (2/h) q, whose rounding (ε |q| 2/h: 1.4e-10
  // m/s per step with coordinates of 40 m at h = 0.125 ms) would stay in q̇ and q̈ along the motion.
  b_ = h * qd + c * qdd;
  dx_ = h * qd + 0.5 * h * h * qdd;  // predictor
  qn_ = q + dx_;
  bool converged = false;
  // `check`: the last full iteration passed the tolerance; this pass evaluates the residual of the
  // dynamic equation at that iterate (with λ updated there) and takes the step it asks for with the
  // last factorization (see below). `checked`: it passed too, and the system holds Φ, Φ_q at the
  // iterate before that step, λ updated there.
  bool check = false, checked = false;
  double prev = INFINITY;
  last_iterations_ = 0;
  for (int it = 1; it <= o_.max_iterations; ++it) {
    sys.Evaluate(qn_, qd, false);
    phis_ = S_.cwiseProduct(sys.phi());
    if (it > 1) lam_ += alpha * phis_;
    // f(q) = (h²/4)(M q̈ + Φ_qᵀ(αΦ + λ) − Q) with (h²/4) q̈ = Δ − b.
    force_ = alpha * phis_ + lam_;
    tmp_ = dx_ - b_;
    // The loads at the iterate: q_{n+1} = q + Δ, q̇_{n+1} = (2/h) Δ − q̇ (constant without force elements).
    if (elements) qdn_ = (2 / h) * dx_ - qd;
    const Eigen::VectorXd& Q = elements ? sys.Loads(qn_, qdn_) : sys.Q();
    if (elements && !check) ElementDerivatives(nm, qn_, qdn_, sys.time(), derivatives_);
    if (sparse) {
      const DynamicsSystem::SparseRowMatrix& J = sys.J_sparse();
      rhs_ = S_.cwiseProduct(force_);
      f_.noalias() = J.transpose() * rhs_;
      f_ -= Q;
      f_ *= c;
      f_.noalias() += sys.M_sparse() * tmp_;
      if (!check) {
        // Tangent: M + (h²/4)(α Φ_qᵀΦ_q + Σ_i (αΦ_i + λ_i) ∂²Φ_i/∂q²), see the dense branch.
        sparse_->Assemble(J, S_, c * alpha, &rhs_, c);
        if (elements) sparse_->AddElements(derivatives_, c, h);
        sparse_->newton.factorize(sparse_->W);
        if (sparse_->newton.info() != Eigen::Success) {
          why = "the ALI3-P tangent matrix is singular";
          return false;
        }
      }
      dq_ = sparse_->newton.solve(f_);
    } else {
      const Eigen::MatrixXd& M = sys.M();
      Js_ = S_.asDiagonal() * sys.J();
      f_ = M * tmp_ + c * (Js_.transpose() * force_ - Q);
      if (!check) {
        // Tangent: M + (h²/4)(α Φ_qᵀΦ_q + Σ_i (αΦ_i + λ_i) ∂²Φ_i/∂q²). The second term (the
        // constraint forces' geometric stiffness) is what keeps Newton converging where Φ_q
        // loses rank; it is exact for the quadratic distance rows and left out for the others.
        W_ = M + (c * alpha) * Js_.transpose() * Js_;
        AddDistanceHessians(nm, sys.active_rows(), S_.cwiseProduct(force_), c, W_);
        // The force elements' ∂f/∂Δ = −(h²/4)(∂Q/∂q + (2/h) ∂Q/∂q̇): its symmetric part (the torque's
        // ∂Q/∂q is skew and drops out; LDLᵀ needs a symmetric W, and Newton then contracts
        // linearly in what is left out, at a rate of about (h²/4)|T|/(L² M)).
        if (elements)
          for (const ElementDerivative& d : derivatives_) {
            const Eigen::MatrixXd T = -c * d.K - 0.5 * h * d.C;
            const int w = static_cast<int>(T.rows());
            for (int i = 0; i < w; ++i)
              for (int j = 0; j < w; ++j)
                if (d.slot[i] >= 0 && d.slot[j] >= 0) W_(d.slot[i], d.slot[j]) += 0.5 * (T(i, j) + T(j, i));
          }
        ldlt_.compute(W_);
        if (ldlt_.info() != Eigen::Success) {
          why = "the ALI3-P tangent matrix is singular";
          return false;
        }
      }
      dq_ = ldlt_.solve(f_);
    }
    dx_ -= dq_;
    qn_ = q + dx_;
    ++iterations_;
    ++last_iterations_;
    const double step = dq_.cwiseAbs().cwiseQuotient(step_scale_).maxCoeff();
    if (!std::isfinite(step)) {
      why = "the ALI3-P iteration produced NaN/Inf";
      return false;
    }
    // A small Newton step does not mean a small error here: with the penalty's weight in W, the
    // quadratic term the step leaves (and the multipliers' update still to come) can be far above
    // it in the tangent directions, where only M resists, and q̈ = (4/h²)(q − …) magnifies what is
    // left by 4/h². So a step within the tolerance is followed by one pass that evaluates the
    // residual of the dynamic equation at the new iterate (λ updated there) in length units,
    // W⁻¹ f, with the factorization at hand, and takes that correction; the step is converged
    // when it is within the tolerance too.
    if (check) {
      if (step <= o_.tolerance) {
        converged = checked = true;
        break;
      }
      check = false;  // not yet: full iterations again
    } else if (step <= o_.tolerance) {
      check = true;
      prev = step;
      continue;
    }
    // Converged at the round-off floor where the steps stop shrinking.
    if (step <= 1e-9 && step > 0.5 * prev) {
      converged = true;
      break;
    }
    // Near a singular position the multiplier update λ ← λ + αΦ contracts only linearly (rate
    // ρ → 1 as Φ_q loses rank): accept a slowly contracting iteration (0.5 ≤ ρ < 1; a regular
    // step contracts quadratically and never gets here) whose remaining error, estimated as
    // step ρ/(1 − ρ), is within singular_tolerance.
    const double rho = step / prev;
    if (rho >= 0.5 && rho < 1 && step * rho / (1 - rho) <= o_.singular_tolerance) {
      converged = true;
      ++slow_steps_;
      break;
    }
    prev = step;
  }
  if (!converged) {
    why = "the ALI3-P Newton iteration did not converge in " + std::to_string(o_.max_iterations) + " iterations";
    return false;
  }
  if (!checked) {
    sys.Evaluate(qn_, qd, false);
    lam_ += alpha * S_.cwiseProduct(sys.phi());
  }
  // (Otherwise the system holds Φ_q at the iterate before the last correction, which moved q by
  // less than the tolerance, and λ was updated there: the correction is the one that update asked for.)
  //
  // Mass-orthogonal projections onto Φ_q q̇ = 0 and Φ_q q̈ + Φ̇_q q̇ = 0, W̄ q̇ = M q̇* and
  // W̄ q̈ = M q̈* − (h²/4) α Φ_qᵀ Φ̇_q q̇, solved for the corrections
  //   W̄ (q̇ − q̇*) = −(h²/4) α Φ_qᵀ Φ_q q̇*,   W̄ (q̈ − q̈*) = −(h²/4) α Φ_qᵀ (Φ_q q̈* + Φ̇_q q̇),
  // the same equations: W̄'s condition grows with the penalty (4.9e6 at N = 40 of the N-four-bar),
  // and a solve for the whole q̇ leaves an error of about ε cond(W̄) |q̇| in the tangent directions,
  // which nothing removes afterwards (~1e-9 of q̇ per step there, a drift that grew as h shrank), while a
  // solve for the correction leaves that much of the correction only.
  qd_star_ = (2 / h) * dx_ - qd;
  qdd_star_ = (dx_ - b_) / c;
  if (sparse) {
    const DynamicsSystem::SparseRowMatrix& J = sys.J_sparse();
    sparse_->Assemble(J, S_, c * alpha, nullptr, c);
    sparse_->projection.factorize(sparse_->W);
    if (sparse_->projection.info() != Eigen::Success) {
      why = "the ALI3-P projection matrix is singular";
      return false;
    }
    phis_.noalias() = J * qd_star_;
    tmp_ = (c * alpha) * S_.cwiseProduct(S_.cwiseProduct(phis_));
    rhs_.noalias() = J.transpose() * tmp_;
    qd = qd_star_ - sparse_->projection.solve(rhs_);
    sys.Evaluate(qn_, qd, true);
    phis_.noalias() = J * qdd_star_;
    phis_ += sys.jdot_qd();
    tmp_ = (c * alpha) * S_.cwiseProduct(S_.cwiseProduct(phis_));
    rhs_.noalias() = J.transpose() * tmp_;
    qdd = qdd_star_ - sparse_->projection.solve(rhs_);
  } else {
    const Eigen::MatrixXd& M = sys.M();
    Js_ = S_.asDiagonal() * sys.J();
    W_ = M + (c * alpha) * Js_.transpose() * Js_;
    llt_.compute(W_);
    qd = qd_star_ - llt_.solve((c * alpha) * Js_.transpose() * (Js_ * qd_star_));
    sys.Evaluate(qn_, qd, true);
    qdd = qdd_star_ - llt_.solve((c * alpha) * Js_.transpose() * (Js_ * qdd_star_ + S_.cwiseProduct(sys.jdot_qd())));
  }
  q = qn_;
  if (!q.allFinite() || !qd.allFinite() || !qdd.allFinite()) {
    why = "the state became NaN/Inf";
    return false;
  }
  return true;
}

bool Ali3pStepper::Advance(double h, Eigen::VectorXd& q, Eigen::VectorXd& qd, Eigen::VectorXd& qdd, std::string& why) {
  q0_ = q, qd0_ = qd, qdd0_ = qdd, lam0_ = lam_, t0_ = sys_.time();
  if (Step(h, q, qd, qdd, why)) return true;
  return o_.retry_levels > 0 && Retry(h, 1, q, qd, qdd, why);
}

bool Ali3pStepper::Retry(double h, int level, Eigen::VectorXd& q, Eigen::VectorXd& qd, Eigen::VectorXd& qdd,
                         std::string& why) {
  // From the step's start again, in 4 sub-steps of h/4 with α (h/4)²/4 = α h²/4 (the same penalty
  // against the mass), each retried in turn if it fails.
  q = q0_, qd = qd0_, qdd = qdd0_, lam_ = lam0_;
  sys_.SetTime(t0_);
  ++retries_;
  const double hs = h / 4, factor = static_cast<double>(1 << (4 * level));  // (4^level)²
  for (int k = 0; k < 4; ++k) {
    const Eigen::VectorXd q_start = q, qd_start = qd, qdd_start = qdd, lam_start = lam_;
    const double t_start = sys_.time();
    std::string sub_why;
    if (Step(hs, q, qd, qdd, sub_why, factor)) continue;
    if (level == o_.retry_levels) {
      why = sub_why + " (also in sub-steps of h/" + std::to_string(1 << (2 * level)) + ")";
      return false;
    }
    q0_ = q_start, qd0_ = qd_start, qdd0_ = qdd_start, lam0_ = lam_start, t0_ = t_start;
    if (!Retry(hs, level + 1, q, qd, qdd, why)) return false;
  }
  return true;
}

}  // namespace mechbench::numeric
