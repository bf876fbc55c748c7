#include "mechbench/numeric/forward_dynamics.h"

#include "mechbench/numeric/refactoring_lu.h"

#include "mechbench/errors.h"
#include "mechbench/numeric/constraints.h"
#include "mechbench/numeric/dynamics.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

namespace mechbench::numeric {

const char* ToString(LinearAlgebra la) {
  switch (la) {
    case LinearAlgebra::kAuto: return "auto";
    case LinearAlgebra::kDense: return "dense";
    case LinearAlgebra::kSparse: return "sparse";
  }
  return "?";
}

int PatternIndex(const Eigen::SparseMatrix<double>& m, int r, int c, const char* what) {
  const int* inner = m.innerIndexPtr();
  const int* begin = inner + m.outerIndexPtr()[c];
  const int* end = inner + m.outerIndexPtr()[c + 1];
  const int* at = std::lower_bound(begin, end, r);
  MB_ASSERT(at != end && *at == r, what);
  return static_cast<int>(at - inner);
}

bool UseSparse(LinearAlgebra la, int n, int sparse_from) {
  return la == LinearAlgebra::kSparse || (la == LinearAlgebra::kAuto && n >= sparse_from);
}

DynamicsSystem::DynamicsSystem(const NaturalModel& model, LinearAlgebra la, int sparse_from)
    // Dense dynamics read the dense Φ_q: their data stays dense at any size. Sparse dynamics of a
    // large scene keep no dense block at all (sparse data, kSparseKinematicsFromCoordinates).
    : model_(&model),
      data_(model, UseSparse(la, model.n, sparse_from) ? LinearAlgebra::kAuto : LinearAlgebra::kDense),
      sparse_(UseSparse(la, model.n, sparse_from)),
      requested_(la),
      sparse_from_(sparse_from) {
  MassMatrix(model, data_);
  GeneralizedForces(model, data_);
  time_ = model.model.analysis.t0;
  Q_ = data_.Q / model.meters_per_unit;
  loads_ = Q_;
  if (data_.sparse) {
    M_sparse_ = data_.M_sparse;
    M_diagonal_ = M_sparse_.diagonal();
  } else {
    M_ = data_.M;
    M_diagonal_ = M_.diagonal();
  }
  active_.resize(model.m());
  for (int i = 0; i < model.m(); ++i) active_[i] = i;
  if (sparse_) {
    if (!data_.sparse) {
      M_sparse_ = M_.sparseView(0.0, 0.0);  // exact zeros dropped, every other entry kept
      M_sparse_.makeCompressed();
    }
    std::vector<int> all(model.m());
    for (int i = 0; i < model.m(); ++i) all[i] = i;
    jac_all_ = SparseJacobian(model, all);
    BuildSparse();
  }
}

const Eigen::MatrixXd& DynamicsSystem::M() const {
  MB_ASSERT(!data_.sparse, "DynamicsSystem::M() is the dense mass matrix: use M_sparse() for sparse data");
  return M_;
}

std::string DynamicsSystem::LinearAlgebraText(const std::string& what_dense, const std::string& what_sparse) const {
  std::string why;
  if (requested_ == LinearAlgebra::kAuto && sparse_from_ <= 0)
    why = " (chosen automatically: sparse is faster at every size)";
  else if (requested_ == LinearAlgebra::kAuto)
    why = sparse_ ? " (chosen automatically: n = " + std::to_string(n()) + " ≥ " + std::to_string(sparse_from_) + ")"
                  : " (chosen automatically: n = " + std::to_string(n()) + " < " + std::to_string(sparse_from_) +
                        ", where dense is faster)";
  else
    why = " (not automatic: set by the method)";
  return (sparse_ ? what_sparse : what_dense) + why;
}

void DynamicsSystem::ChooseRows(const Eigen::VectorXd& q) {
  UpdatePoints(*model_, data_, q);
  const RankReport rk = AnalyzeRank(*model_, data_);
  dropped_ = rk.redundant_rows;
  active_.clear();
  for (int i = 0; i < model_->m(); ++i)
    if (std::find(dropped_.begin(), dropped_.end(), i) == dropped_.end()) active_.push_back(i);
  if (sparse_) BuildSparse();
}

void DynamicsSystem::BuildSparse() {
  const int nn = n();
  jac_ = SparseJacobian(*model_, active_);
  const SparseRowMatrix& J = jac_.J();
  const int ma = m();
  // Pattern of [M Φ_qᵀ; Φ_q 0]: triplets carry their source so that values can be mapped back.
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(static_cast<size_t>(M_sparse_.nonZeros() + 2 * J.nonZeros()));
  for (int c = 0; c < M_sparse_.outerSize(); ++c)
    for (SparseColMatrix::InnerIterator it(M_sparse_, c); it; ++it) t.emplace_back(it.row(), it.col(), 0.0);
  for (int k = 0; k < ma; ++k)
    for (SparseRowMatrix::InnerIterator it(J, k); it; ++it) {
      t.emplace_back(nn + k, it.col(), 0.0);
      t.emplace_back(it.col(), nn + k, 0.0);
    }
  kkt_sparse_.resize(nn + ma, nn + ma);
  kkt_sparse_.setFromTriplets(t.begin(), t.end());
  kkt_sparse_.makeCompressed();
  const auto index = [&](int r, int c) { return PatternIndex(kkt_sparse_, r, c, "index-1 matrix pattern lookup"); };
  kkt_base_.assign(static_cast<size_t>(kkt_sparse_.nonZeros()), 0.0);
  for (int c = 0; c < M_sparse_.outerSize(); ++c)
    for (SparseColMatrix::InnerIterator it(M_sparse_, c); it; ++it) kkt_base_[index(it.row(), it.col())] = it.value();
  kkt_from_j_.assign(2 * static_cast<size_t>(J.nonZeros()), 0);
  for (int k = 0; k < ma; ++k)
    for (SparseRowMatrix::InnerIterator it(J, k); it; ++it) {
      const Eigen::Index e = &it.value() - J.valuePtr();
      kkt_from_j_[2 * e] = index(nn + k, it.col());
      kkt_from_j_[2 * e + 1] = index(it.col(), nn + k);
    }
  // Ordered once: the pattern does not change along the run.
  sparse_lu_ = std::make_shared<RefactoringLu>();
  MB_ASSERT(sparse_lu_->Analyze(kkt_sparse_), "KLU could not order the index-1 matrix");
  kkt_rhs_.resize(nn + ma);
  kkt_x_.resize(nn + ma);
  kkt_res_.resize(nn + ma);
}

const Eigen::MatrixXd& DynamicsSystem::J() const {
  MB_ASSERT(!sparse_, "DynamicsSystem::J() is the dense Φ_q: use J_sparse() in sparse mode");
  return J_;
}

void DynamicsSystem::Evaluate(const Eigen::VectorXd& q, const Eigen::VectorXd& qd, bool with_rates) {
  if (sparse_) {
    jac_.Evaluate(*model_, data_, q, with_rates ? &qd : nullptr, phi_, with_rates ? &jdot_qd_ : nullptr);
    return;
  }
  EvalPhi(*model_, data_, q, data_.t);
  EvalJacobian(*model_, data_, q);
  const int ma = m();
  phi_.resize(ma);
  J_.resize(ma, n());
  for (int k = 0; k < ma; ++k) {
    phi_[k] = data_.Phi[active_[k]];
    J_.row(k) = data_.Phi_q.row(active_[k]);
  }
  if (!with_rates) return;
  EvalPhidotQdot(*model_, data_, q, qd);
  jdot_qd_.resize(ma);
  for (int k = 0; k < ma; ++k) jdot_qd_[k] = data_.Phidot_q_qd[active_[k]];
}

namespace {
void SingularWhy(std::string* why, double relative) {
  if (!why) return;
  char buf[160];
  std::snprintf(buf, sizeof buf, "the index-1 matrix [M Φ_qᵀ; Φ_q 0] is singular (relative solve residual %.2g): Φ_q lost rank",
                relative);
  *why = buf;
}

// The first entry of `v` that is not finite, or -1.
Eigen::Index FirstNonFinite(const Eigen::VectorXd& v) {
  for (Eigen::Index i = 0; i < v.size(); ++i)
    if (!std::isfinite(v[i])) return i;
  return -1;
}

std::string Range(double lo, double hi) {
  char buf[80];
  std::snprintf(buf, sizeof buf, "%.2g … %.2g", lo, hi);
  return buf;
}
}  // namespace

// A failed solve is a singular matrix only when what went into it was finite: a mass matrix or
// loads beyond double range (a mass of 1e308 times gravity), or a state that grew without bound in
// the step before (a gravity of 1e300), make every solve fail alike and must be named as such.
std::string DynamicsSystem::Overflow(const Eigen::VectorXd& q, const Eigen::VectorXd& qd, const Eigen::VectorXd& x) const {
  const auto slot = [&](Eigen::Index i) { return model_->model.q_layout[static_cast<size_t>(i)].name; };
  const auto value = [](double v) {
    if (std::isnan(v)) return std::string("NaN");
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3g", v);
    return std::string(buf);
  };
  for (Eigen::Index j = 0; j < M_.cols(); ++j)
    if (const Eigen::Index i = FirstNonFinite(M_.col(j)); i >= 0)
      return "the mass matrix overflows: M[" + slot(i) + ", " + slot(j) + "] = " + value(M_(i, j)) +
             " (the mass properties are beyond double range)";
  if (const Eigen::Index i = FirstNonFinite(Q_); i >= 0)
    return "the loads overflow: Q[" + slot(i) + "] = " + value(Q_[i]) +
           " (gravity × mass or a point force beyond double range)";
  if (const Eigen::Index i = FirstNonFinite(loads_); i >= 0 && FirstNonFinite(q) < 0 && FirstNonFinite(qd) < 0)
    return "the loads overflow: Q[" + slot(i) + "] = " + value(loads_[i]) +
           " (a spring–damper or torque beyond double range at this state: its own values, or the positions and "
           "velocities it is evaluated at)";
  if (const Eigen::Index i = FirstNonFinite(q); i >= 0)
    return "the state overflowed: q." + slot(i) + " = " + value(q[i]) + " (the step before it grew without bound)";
  if (const Eigen::Index i = FirstNonFinite(qd); i >= 0)
    return "the state overflowed: qd." + slot(i) + " = " + value(qd[i]) + " (the step before it grew without bound)";
  if (FirstNonFinite(phi_) >= 0 || FirstNonFinite(jdot_qd_) >= 0)
    return "the constraint terms overflow: Φ̇_q q̇, quadratic in q̇, is not finite with q̇ up to " +
           value(qd.cwiseAbs().maxCoeff()) + " (the step before grew the velocities past what double precision can square)";
  if (FirstNonFinite(x) >= 0) {
    // Every input finite, the solution not: the entries span more than double's range.
    const double big = std::max(M_.cwiseAbs().maxCoeff(), Q_.cwiseAbs().maxCoeff());
    double small = INFINITY;
    for (Eigen::Index i = 0; i < M_.size(); ++i)
      if (M_.data()[i] != 0) small = std::min(small, std::fabs(M_.data()[i]));
    return "the solve overflows: [q̈; λ] is not finite although M, Q and Φ_q are (|M| and |Q| span " +
           Range(small, big) + ", beyond what double precision can combine)";
  }
  return {};
}

// Neither LU reports a near-singular KKT matrix by itself (partial pivoting never does): a solve
// is accepted when it is finite and its own residual is small against the system's size. On
// success, x = [q̈; λ] is split into its parts; on failure, an overflow is named before a
// singular matrix is blamed.
bool DynamicsSystem::AcceptSolve(const Eigen::VectorXd& q, const Eigen::VectorXd& qd, const Eigen::VectorXd& x,
                                 double res, double size, Eigen::VectorXd& qdd, Eigen::VectorXd& lambda, std::string* why) {
  overflowed_ = false;
  if (x.allFinite() && res <= 1e-8 * size) {
    qdd = x.head(n());
    lambda = x.tail(x.size() - n());
    return true;
  }
  const std::string overflow = Overflow(q, qd, x);
  overflowed_ = !overflow.empty();
  if (overflowed_) {
    if (why) *why = overflow;
  } else {
    SingularWhy(why, size > 0 ? res / size : res);
  }
  return false;
}

bool DynamicsSystem::Accelerations(const Eigen::VectorXd& q, const Eigen::VectorXd& qd, double alpha, double beta,
                                   Eigen::VectorXd& qdd, Eigen::VectorXd& lambda, std::string* why) {
  Evaluate(q, qd, true);
  const int nn = n(), ma = m();
  if (sparse_) {
    const SparseRowMatrix& J = jac_.J();
    double* v = kkt_sparse_.valuePtr();
    std::copy(kkt_base_.begin(), kkt_base_.end(), v);
    const double* jv = J.valuePtr();
    for (Eigen::Index e = 0; e < J.nonZeros(); ++e) v[kkt_from_j_[2 * e]] = v[kkt_from_j_[2 * e + 1]] = jv[e];
    kkt_rhs_.head(nn) = Loads(q, qd);
    kkt_rhs_.tail(ma).noalias() = -jdot_qd_ - beta * beta * phi_;
    kkt_rhs_.tail(ma).noalias() -= (2.0 * alpha) * (J * qd);
    if (!sparse_lu_->Solve(kkt_sparse_, kkt_rhs_, kkt_x_)) {
      kkt_x_.setZero();  // no solution: blamed on an overflow when there is one, else the matrix
      return AcceptSolve(q, qd, kkt_x_, INFINITY, 0, qdd, lambda, why);
    }
    kkt_res_.noalias() = kkt_sparse_ * kkt_x_;
    kkt_res_ -= kkt_rhs_;
    const double big = Eigen::Map<const Eigen::VectorXd>(v, kkt_sparse_.nonZeros()).cwiseAbs().maxCoeff();
    return AcceptSolve(q, qd, kkt_x_, kkt_res_.norm(), big * kkt_x_.norm() + kkt_rhs_.norm(), qdd, lambda, why);
  }
  kkt_.setZero(nn + ma, nn + ma);
  kkt_.topLeftCorner(nn, nn) = M_;
  kkt_.topRightCorner(nn, ma) = J_.transpose();
  kkt_.bottomLeftCorner(ma, nn) = J_;
  kkt_rhs_.resize(nn + ma);
  kkt_rhs_.head(nn) = Loads(q, qd);
  // Φ_t = 0 for a free scene, so Φ̇ = Φ_q q̇.
  kkt_rhs_.tail(ma) = -jdot_qd_ - 2.0 * alpha * (J_ * qd) - beta * beta * phi_;
  lu_.compute(kkt_);
  kkt_x_ = lu_.solve(kkt_rhs_);
  return AcceptSolve(q, qd, kkt_x_, (kkt_ * kkt_x_ - kkt_rhs_).norm(),
                     kkt_.cwiseAbs().maxCoeff() * kkt_x_.norm() + kkt_rhs_.norm(), qdd, lambda, why);
}

const Eigen::VectorXd& DynamicsSystem::Loads(const Eigen::VectorXd& q, const Eigen::VectorXd& qd) {
  if (!has_elements()) return Q_;
  loads_.setZero(n());
  AddElementForces(*model_, q, qd, time_, loads_);
  loads_ /= model_->meters_per_unit;
  loads_ += Q_;
  return loads_;
}

double DynamicsSystem::Energy(const Eigen::VectorXd& q, const Eigen::VectorXd& qd) const {
  const double u = model_->meters_per_unit;
  const double V = has_elements() ? SpringPotential(*model_, q) : 0.0;
  if (sparse_) return (0.5 * qd.dot(M_sparse_ * qd) - Q_.dot(q)) * u * u + V;
  return (0.5 * qd.dot(M_ * qd) - Q_.dot(q)) * u * u + V;
}

double EnergyBalance::Next(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& qd, const Eigen::VectorXd& qdd) {
  const NaturalModel& nm = sys_->model();
  const bool has_qdd = qdd.size() == q.size() && qdd.allFinite();
  double rate = 0;
  const double power = DamperPower(nm, q, qd, has_qdd ? &qdd : nullptr, &rate);
  const std::vector<double> angle = TorqueBodyAngles(nm, q);
  if (started_) {
    const double h = t - t_;
    dissipated_ += 0.5 * h * (power_ + power);
    if (have_rate_ && has_qdd) dissipated_ += h * h / 12 * (rate_ - rate);
    for (size_t k = 0; k < angle.size(); ++k)
      if (!nm.model.torques[k].law)
        torque_work_ += nm.model.torques[k].torque * std::remainder(angle[k] - angle_[k], 2 * std::numbers::pi);
  }
  double law_rate = 0, force_rate = 0;
  double law_power = LawTorquePower(nm, q, qd, t, has_qdd ? &qdd : nullptr, &law_rate);
  if (nm.model.HasVaryingPointForces()) {  // their work, as the laws' torques'
    law_power += VaryingPointForcePower(nm, q, qd, t, has_qdd ? &qdd : nullptr, &force_rate);
    law_rate += force_rate;
  }
  if (nm.model.HasSpringLaws()) {  // springs with a law have no potential: their tension's work
    double spring_rate = 0;
    law_power += LawSpringPower(nm, q, qd, t, has_qdd ? &qdd : nullptr, &spring_rate);
    law_rate += spring_rate;
  }
  if (started_) {
    const double h = t - t_;
    torque_work_ += 0.5 * h * (law_power_ + law_power);
    if (have_rate_ && has_qdd) torque_work_ += h * h / 12 * (law_rate_ - law_rate);
  }
  law_power_ = law_power, law_rate_ = law_rate;
  started_ = true;
  t_ = t, power_ = power, rate_ = rate, have_rate_ = has_qdd, angle_ = angle;
  return sys_->Energy(q, qd) - torque_work_ + dissipated_;
}

double DynamicsSystem::ScaledPhi(const Eigen::VectorXd& q) {
  EvalPhi(*model_, data_, q, data_.t);
  return ScaledResidual(*model_, data_);
}

double DynamicsSystem::ScaledPhiDot(const Eigen::VectorXd& q, const Eigen::VectorXd& qd) {
  if (sparse_) {
    jac_all_.Evaluate(*model_, data_, q, nullptr, phi_all_, nullptr);
    rate_all_.noalias() = jac_all_.J() * qd;
  } else {
    EvalJacobian(*model_, data_, q);
    rate_all_ = data_.Phi_q * qd;
  }
  double worst = 0;
  for (int i = 0; i < model_->m(); ++i) worst = std::max(worst, std::fabs(rate_all_[i]) / model_->rows[i].scale);
  return worst;
}

Eigen::VectorXd DynamicsSystem::FullLambda(const Eigen::VectorXd& lambda_active) const {
  Eigen::VectorXd full = Eigen::VectorXd::Zero(model_->m());
  for (int k = 0; k < m(); ++k) full[active_[k]] = lambda_active[k];
  return full;
}

FreeStart AssembleFreeStart(const NaturalModel& model, const NewtonOptions& options) {
  NaturalData data(model);
  FreeStart s;
  s.instant = SolveInstant(model, data, model.model.analysis.t0, model.model.GuessQ(), options);
  s.q = data.q;
  s.qd = data.qd;
  return s;
}

// ---- integrators ------------------------------------------------------------------------------

bool Rk4Step(const OdeRhs& f, const OdeProject& project, double t, double h, Eigen::VectorXd& y, std::string& why,
             OdeStats& stats, Rk4Scratch* scratch) {
  Rk4Scratch local;
  Rk4Scratch& sc = scratch ? *scratch : local;
  Eigen::VectorXd &k1 = sc.k1, &k2 = sc.k2, &k3 = sc.k3, &k4 = sc.k4, &ys = sc.ys;
  const auto stage = [&](double ts, Eigen::VectorXd& yy, Eigen::VectorXd& k) {
    if (project && !project(ts, yy, why)) return false;
    ++stats.evaluations;
    return f(ts, yy, k, why);
  };
  ys = y;
  if (!stage(t, ys, k1)) return false;
  ys = y + 0.5 * h * k1;
  if (!stage(t + 0.5 * h, ys, k2)) return false;
  ys = y + 0.5 * h * k2;
  if (!stage(t + 0.5 * h, ys, k3)) return false;
  ys = y + h * k3;
  if (!stage(t + h, ys, k4)) return false;
  y += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);  // one expression: no temporary
  if (project && !project(t + h, y, why)) return false;
  ++stats.steps;
  stats.h_min = stats.steps == 1 ? h : std::min(stats.h_min, h);
  stats.h_max = std::max(stats.h_max, h);
  if (!y.allFinite()) {
    why = "the state became NaN/Inf";
    return false;
  }
  return true;
}

bool Dopri5::Advance(const OdeRhs& f, const OdeProject& project, double& t, double t_end, Eigen::VectorXd& y,
                     std::string& why) {
  // Dormand–Prince 5(4) coefficients.
  static constexpr double c2 = 1.0 / 5, c3 = 3.0 / 10, c4 = 4.0 / 5, c5 = 8.0 / 9;
  static constexpr double a21 = 1.0 / 5;
  static constexpr double a31 = 3.0 / 40, a32 = 9.0 / 40;
  static constexpr double a41 = 44.0 / 45, a42 = -56.0 / 15, a43 = 32.0 / 9;
  static constexpr double a51 = 19372.0 / 6561, a52 = -25360.0 / 2187, a53 = 64448.0 / 6561, a54 = -212.0 / 729;
  static constexpr double a61 = 9017.0 / 3168, a62 = -355.0 / 33, a63 = 46732.0 / 5247, a64 = 49.0 / 176,
                          a65 = -5103.0 / 18656;
  static constexpr double a71 = 35.0 / 384, a73 = 500.0 / 1113, a74 = 125.0 / 192, a75 = -2187.0 / 6784,
                          a76 = 11.0 / 84;
  // Error coefficients: b (5th order) − b̂ (4th order).
  static constexpr double e1 = 71.0 / 57600, e3 = -71.0 / 16695, e4 = 71.0 / 1920, e5 = -17253.0 / 339200,
                          e6 = 22.0 / 525, e7 = -1.0 / 40;
  const Eigen::Index dim = y.size();
  if (opt_.atol.size() != dim) opt_.atol = Eigen::VectorXd::Constant(dim, 1e-12);
  if (opt_.error_mask.size() != dim) opt_.error_mask = Eigen::VectorXd::Ones(dim);
  const auto eval = [&](double ts, Eigen::VectorXd& yy, Eigen::VectorXd& k) {
    if (project && !project(ts, yy, why)) return false;
    ++stats_.evaluations;
    if (!f(ts, yy, k, why)) return false;
    if (!k.allFinite()) {
      why = "the derivative became NaN/Inf";
      return false;
    }
    return true;
  };
  if (!have_k1_) {
    Eigen::VectorXd y0 = y;
    if (!eval(t, y0, k1_)) return false;
    y = y0;
    have_k1_ = true;
  }
  const auto err_norm = [&](const Eigen::VectorXd& err, const Eigen::VectorXd& y_old, const Eigen::VectorXd& y_new) {
    double sum = 0;
    int count = 0;
    for (Eigen::Index i = 0; i < dim; ++i) {
      if (opt_.error_mask[i] == 0) continue;
      const double sc = opt_.atol[i] + opt_.rtol * std::max(std::fabs(y_old[i]), std::fabs(y_new[i]));
      sum += (err[i] / sc) * (err[i] / sc);
      ++count;
    }
    return count ? std::sqrt(sum / count) : 0.0;
  };
  if (h_ <= 0) {
    // Initial step (Hairer's starting-step heuristic, simplified): h = 0.01 ‖y‖ / ‖y'‖.
    const double d0 = err_norm(y, y, y), d1 = err_norm(k1_, y, y);
    h_ = (d0 < 1e-5 || d1 < 1e-5) ? 1e-6 : 0.01 * d0 / d1;
    if (opt_.h_initial > 0) h_ = opt_.h_initial;
  }
  Eigen::VectorXd k2, k3, k4, k5, k6, k7, ys, y_new, y_raw, err;
  const double span = std::max(std::fabs(t_end), 1.0);
  while (t < t_end - 1e-14 * span) {
    if (stats_.steps + stats_.rejected >= opt_.max_steps) {
      why = "DOPRI5 exceeded its step budget";
      return false;
    }
    double h = std::min(h_, t_end - t);
    if (opt_.h_max > 0) h = std::min(h, opt_.h_max);
    const bool last = h >= t_end - t;
    if (h < 1e-14 * span) {
      why = "DOPRI5 step size fell below round-off";
      return false;
    }
    ys = y + h * a21 * k1_;
    bool ok = eval(t + c2 * h, ys, k2);
    if (ok) ys = y + h * (a31 * k1_ + a32 * k2), ok = eval(t + c3 * h, ys, k3);
    if (ok) ys = y + h * (a41 * k1_ + a42 * k2 + a43 * k3), ok = eval(t + c4 * h, ys, k4);
    if (ok) ys = y + h * (a51 * k1_ + a52 * k2 + a53 * k3 + a54 * k4), ok = eval(t + c5 * h, ys, k5);
    if (ok) ys = y + h * (a61 * k1_ + a62 * k2 + a63 * k3 + a64 * k4 + a65 * k5), ok = eval(t + h, ys, k6);
    if (ok) {
      y_new = y + h * (a71 * k1_ + a73 * k3 + a74 * k4 + a75 * k5 + a76 * k6);
      y_raw = y_new;
      ok = eval(t + h, y_new, k7);  // projects y_new too (coordinate partitioning)
    }
    if (!ok) {
      // A failed stage (e.g. a singular matrix met by a long trial step): retry smaller first.
      if (h > 1e-10 * span) {
        h_ = 0.25 * h;
        ++stats_.rejected;
        continue;
      }
      return false;
    }
    err = h * (e1 * k1_ + e3 * k3 + e4 * k4 + e5 * k5 + e6 * k6 + e7 * k7);
    // A projection that moves the step's end (dependent coordinates re-solved) counts as error:
    // near a singular position Newton–Raphson can land on another branch, and this rejects it.
    if (project) err = err.cwiseAbs() + (y_new - y_raw).cwiseAbs();
    const double e = err_norm(err, y, y_new);
    if (!std::isfinite(e)) {
      h_ = 0.25 * h;
      ++stats_.rejected;
      continue;
    }
    // Step-size controller: safety 0.9, factor in [0.2, 10], exponent 1/5.
    const double factor = e == 0 ? 10.0 : std::clamp(0.9 * std::pow(e, -0.2), 0.2, 10.0);
    if (e <= 1.0) {
      t = last ? t_end : t + h;
      y = y_new;
      k1_ = k7;
      ++stats_.steps;
      stats_.h_min = stats_.steps == 1 ? h : std::min(stats_.h_min, h);
      stats_.h_max = std::max(stats_.h_max, h);
      if (opt_.on_accept && !opt_.on_accept(t, y, opt_.error_mask, why)) return false;
      // Do not let a short final step (landing on t_end) shrink the next one.
      h_ = last ? std::max(h_, h * factor) : h * factor;
    } else {
      ++stats_.rejected;
      h_ = h * std::min(1.0, factor);
    }
  }
  return true;
}

}  // namespace mechbench::numeric
