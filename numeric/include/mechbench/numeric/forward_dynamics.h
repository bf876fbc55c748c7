// Forward dynamics of free scenes in natural coordinates: the pieces every formulation shares.
//
// Equations of motion (M constant in natural coordinates; Q = gravity + constant point forces +
// the force elements' Q_e(q, q̇), dynamics.h):
//   M q̈ + Φ_qᵀ λ = Q̃(q, q̇),   Φ(q) = 0,   Q̃ = Q / meters_per_unit  (so M q̈ is in kg·length/s²)
// Index-1 form with Baumgarte stabilisation (α, β in 1/s):
//   [M Φ_qᵀ; Φ_q 0] [q̈; λ] = [Q̃; −Φ̇_q q̇ − 2α Φ̇ − β² Φ],   Φ̇ = Φ_q q̇ (no time-dependent rows)
// Energy E = ½ q̇ᵀ M q̇ u² − Q̃_cᵀ q u² + V_springs(q) [J] with u = meters_per_unit and Q̃_c the
// constant part (exact: it does not depend on q or q̇). Torques and dampers are not in E: their
// work goes into the energy balance along a motion (EnergyBalance).
#pragma once

#include "mechbench/method.h"
#include "mechbench/numeric/natural_data.h"
#include "mechbench/numeric/natural_model.h"
#include "mechbench/numeric/solver.h"

#include "mechbench/numeric/constraints.h"

#include <Eigen/Core>
#include <Eigen/LU>
#include <Eigen/SparseCore>
#include <Eigen/SparseLU>

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace mechbench::numeric {

template <typename Scalar>
class RefactoringLuOf;  // refactoring_lu.h: KLU, refactored with fixed pivots
using RefactoringLu = RefactoringLuOf<double>;

// Dense or sparse linear algebra for the dynamics (DynamicsSystem, ALI3-P's tangent matrix).
// Dense: Eigen's dense LU / LDLᵀ, O(n³) per factorization. Sparse: Φ_q with a fixed pattern
// (SparseJacobian), KLU (SuiteSparse; ordered and pivoted once, then refactored) on the index-1
// matrix and SimplicialLDLT
// (AMD ordering) on ALI3-P's symmetric tangent matrix, the orderings computed once per run, so
// that a step of the N-four-bar costs O(N). kAuto: sparse from a number of coordinates on, per
// formulation (below). (LinearAlgebra is declared in natural_data.h.)
// Where sparse starts to pay, measured (RelWithDebInfo, 2026-11-23, one step of the N-four-bar
// with each forced; bench step/…):
//  - the index-1 matrix (RK4 step, 4 solves): dense 3.4 / 21 / 60 / 242 µs at N = 1 / 4 / 8 / 16
//    (n = 4 / 10 / 18 / 34), sparse 7.8 / 31 / 45 / 79 µs: even near n = 14. A whole fourbar_free
//    run (n = 5) is 4.0 ms dense, 9.1 ms sparse. Sparse from n = 16.
//  - ALI3-P's step: sparse is faster at every size (1.25 against 1.77 µs at n = 4; fourbar_free
//    1.6 against 2.2 ms, §5.1 1.3 against 1.4 ms), so always sparse.
inline constexpr int kSparseIndex1FromCoordinates = 16;
inline constexpr int kSparseAli3pFromCoordinates = 0;
// The choice for a scene with n coordinates.
bool UseSparse(LinearAlgebra la, int n, int sparse_from);

// Where entry (r, c) of a compressed column-major matrix sits in its value array, so that a
// matrix with a fixed pattern is refilled in place; (r, c) must be in the pattern (`what` names
// the matrix in the assertion).
int PatternIndex(const Eigen::SparseMatrix<double>& m, int r, int c, const char* what);

// Everything a dynamics formulation needs that does not change along the run, plus scratch.
class DynamicsSystem {
 public:
  using SparseRowMatrix = Eigen::SparseMatrix<double, Eigen::RowMajor>;
  using SparseColMatrix = Eigen::SparseMatrix<double>;

  // `sparse_from`: kAuto's threshold (kSparseIndex1FromCoordinates, kSparseAli3pFromCoordinates).
  explicit DynamicsSystem(const NaturalModel& model, LinearAlgebra la = LinearAlgebra::kAuto,
                          int sparse_from = kSparseIndex1FromCoordinates);

  const NaturalModel& model() const { return *model_; }
  int n() const { return model_->n; }
  int m() const { return static_cast<int>(active_.size()); }  // independent constraint rows
  const Eigen::MatrixXd& M() const;                          // [n × n] kg; dense data only
  const SparseColMatrix& M_sparse() const { return M_sparse_; }  // the same, sparse (sparse mode)
  const Eigen::VectorXd& M_diagonal() const { return M_diagonal_; }  // [n] kg, either mode
  // [n] the constant part of Q̃ = Q / meters_per_unit (gravity and point forces).
  const Eigen::VectorXd& Q() const { return Q_; }
  // [n] Q̃(q, q̇, t): Q() plus the force elements' part (dynamics.h) at time(), in scratch kept by
  // the system.
  const Eigen::VectorXd& Loads(const Eigen::VectorXd& q, const Eigen::VectorXd& qd);
  // The time at which Loads (and Accelerations) evaluate loads given as laws of t [s]; formulations
  // set it before each evaluation (t0 until then).
  void SetTime(double t) { time_ = t; }
  double time() const { return time_; }
  bool has_elements() const { return model_->model.HasForceElements(); }
  const std::vector<int>& active_rows() const { return active_; }
  const std::vector<int>& dropped_rows() const { return dropped_; }
  bool sparse() const { return sparse_; }
  // "dense … (chosen automatically: n = 5 < 16, …)" / "sparse … (requested)": for the settings.
  std::string LinearAlgebraText(const std::string& what_dense, const std::string& what_sparse) const;

  // Drops rows that are redundant at q (rank of Φ_q, kRankTolerance): the cos+sin pair of §4.4
  // keeps its redundancy along the motion, and a KKT matrix with dependent rows is singular.
  void ChooseRows(const Eigen::VectorXd& q);

  // Φ, Φ_q, Φ̇_q q̇ restricted to the active rows → phi_, J_ (dense) or J_sparse() (sparse),
  // jdot_qd_ (and `data`).
  void Evaluate(const Eigen::VectorXd& q, const Eigen::VectorXd& qd, bool with_rates = true);
  const Eigen::VectorXd& phi() const { return phi_; }
  const Eigen::MatrixXd& J() const;  // dense mode only
  const SparseRowMatrix& J_sparse() const { return jac_.J(); }  // sparse mode only
  const Eigen::VectorXd& jdot_qd() const { return jdot_qd_; }

  // Index-1 accelerations and multipliers at (q, q̇) with Baumgarte α, β [1/s]. Returns false
  // (and sets `why`) when the KKT matrix is singular to working precision: a singular position;
  // or when a number that goes into it is beyond double range (overflowed() is then true and
  // `why` names it: the mass matrix, the loads, the state or the constraint terms).
  bool Accelerations(const Eigen::VectorXd& q, const Eigen::VectorXd& qd, double alpha, double beta,
                     Eigen::VectorXd& qdd, Eigen::VectorXd& lambda, std::string* why = nullptr);
  bool overflowed() const { return overflowed_; }  // the last Accelerations failed on an overflow

  double Energy(const Eigen::VectorXd& q, const Eigen::VectorXd& qd) const;  // [J]
  // ‖Φ‖ scaled row by row (ScaledResidual, all rows), and ‖Φ_q q̇‖ scaled likewise per second.
  double ScaledPhi(const Eigen::VectorXd& q);
  double ScaledPhiDot(const Eigen::VectorXd& q, const Eigen::VectorXd& qd);
  // Multipliers of the active rows spread back to all m rows (0 on dropped rows).
  Eigen::VectorXd FullLambda(const Eigen::VectorXd& lambda_active) const;

  NaturalData& data() { return data_; }

 private:
  void BuildSparse();  // patterns, value maps and orderings for the active rows
  // What overflowed when a solve failed ("" when every input and the solution are finite).
  std::string Overflow(const Eigen::VectorXd& q, const Eigen::VectorXd& qd, const Eigen::VectorXd& x) const;
  bool AcceptSolve(const Eigen::VectorXd& q, const Eigen::VectorXd& qd, const Eigen::VectorXd& x, double res,
                   double size, Eigen::VectorXd& qdd, Eigen::VectorXd& lambda, std::string* why);

  const NaturalModel* model_;
  NaturalData data_;
  bool sparse_ = false;
  bool overflowed_ = false;
  LinearAlgebra requested_ = LinearAlgebra::kAuto;
  int sparse_from_ = kSparseIndex1FromCoordinates;
  Eigen::MatrixXd M_;  // empty for sparse data (large scenes)
  SparseColMatrix M_sparse_;
  Eigen::VectorXd M_diagonal_;
  Eigen::VectorXd Q_, loads_;
  std::vector<int> active_, dropped_;
  Eigen::VectorXd phi_, jdot_qd_;
  Eigen::MatrixXd J_;
  Eigen::MatrixXd kkt_;
  Eigen::VectorXd kkt_rhs_, kkt_x_, kkt_res_;
  Eigen::PartialPivLU<Eigen::MatrixXd> lu_;
  // Sparse mode: Φ_q of the active rows and of all rows (ScaledPhiDot); the index-1 matrix with
  // a fixed pattern: its values are kkt_base_ (M) plus Φ_q scattered through kkt_from_j_ (two
  // value indices per entry of J_sparse(): (n + k, j) and (j, n + k)).
  SparseJacobian jac_, jac_all_;
  Eigen::VectorXd phi_all_, rate_all_;
  SparseColMatrix kkt_sparse_;
  std::vector<double> kkt_base_;
  std::vector<int> kkt_from_j_;
  double time_ = 0;
  std::shared_ptr<RefactoringLu> sparse_lu_;  // the index-1 matrix's LU (sparse mode)
};

// The energy balance along a motion [J]: E(q, q̇) (DynamicsSystem::Energy) − the work of the
// torques (T times each body's turn, unwrapped from sample to sample: it must turn less than π
// between two) + what the dampers dissipated since the first sample, integrated over the samples
// by the cubic Hermite rule on c L̇² and its rate (from q̈; fourth order in the sample interval),
// or by the trapezoidal rule where a sample has no q̈. A torque given as a law T(t, q, q̇) does the
// work ∫ T ω dt, integrated by the same rule on T ω and its rate; so does a varying point force
// (a law, or a follower force in a body's frame), ∫ f·v dt, and a spring–damper with a law (its
// whole tension, ∫ −F L̇ dt: it has no potential). Constant along an exact motion of a free
// scene; its largest change is the run's energy drift.
class EnergyBalance {
 public:
  explicit EnergyBalance(const DynamicsSystem& sys) : sys_(&sys) {}
  // The balance at the next sample of the motion (samples in time order; the first sets the origin).
  double Next(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& qd, const Eigen::VectorXd& qdd);

 private:
  const DynamicsSystem* sys_;
  bool started_ = false;
  double t_ = 0, power_ = 0, rate_ = 0, dissipated_ = 0, torque_work_ = 0;
  double law_power_ = 0, law_rate_ = 0;  // torques given as laws: T ω and its rate at the last sample
  bool have_rate_ = false;
  std::vector<double> angle_;
};

// The state at t0 of a free scene, assembled from Model::initial (SolveInstant does this).
struct FreeStart {
  Eigen::VectorXd q, qd;
  InstantReport instant;
};
FreeStart AssembleFreeStart(const NaturalModel& model, const NewtonOptions& options = {});

// Explicit integrators on y' = f(t, y). `f` returns false when it cannot evaluate (singular);
// `project`, when given, replaces a stage's y by a consistent one (coordinate partitioning) and
// returns false when it cannot. Both set `why`.
using OdeRhs = std::function<bool(double t, const Eigen::VectorXd& y, Eigen::VectorXd& dy, std::string& why)>;
using OdeProject = std::function<bool(double t, Eigen::VectorXd& y, std::string& why)>;

struct OdeStats {
  long steps = 0, rejected = 0, evaluations = 0;
  double h_min = 0, h_max = 0;
};

// Classic RK4 from t to t + h. `scratch`, when given, holds the stages from step to step (no
// allocation once sized).
struct Rk4Scratch {
  Eigen::VectorXd k1, k2, k3, k4, ys;
};
bool Rk4Step(const OdeRhs& f, const OdeProject& project, double t, double h, Eigen::VectorXd& y, std::string& why,
             OdeStats& stats, Rk4Scratch* scratch = nullptr);

// Dormand–Prince 5(4) with the usual step-size controller (Hairer, Nørsett & Wanner II.4), FSAL,
// ending exactly at t_end. The error norm is an RMS of err_i / (atol_i + rtol max(|y_i|, |y_new_i|))
// over the components where `error_mask` is non-zero (all when empty).
struct Dopri5Options {
  double rtol = 1e-8;
  Eigen::VectorXd atol;   // per component, absolute
  double h_initial = 0;   // 0 = estimated
  double h_max = 0;       // 0 = no limit
  long max_steps = 2000000;
  Eigen::VectorXd error_mask;
  // Called after every accepted step (e.g. to re-choose a partition; may change error_mask).
  // Returning false stops the integration with `why`.
  std::function<bool(double t, const Eigen::VectorXd& y, Eigen::VectorXd& error_mask, std::string& why)> on_accept;
};
class Dopri5 {
 public:
  explicit Dopri5(Dopri5Options options) : opt_(std::move(options)) {}
  // Advances y from t to t_end. On failure (step below round-off, f or project failing) returns
  // false and leaves t, y at the last accepted step.
  bool Advance(const OdeRhs& f, const OdeProject& project, double& t, double t_end, Eigen::VectorXd& y,
               std::string& why);
  const OdeStats& stats() const { return stats_; }
  // Forget the FSAL derivative (after y was changed from outside, e.g. a new partition).
  void Reset() { have_k1_ = false; }
  // y' at the last accepted step's end (the FSAL stage; valid inside on_accept and after Advance).
  const Eigen::VectorXd& derivative() const { return k1_; }

 private:
  Dopri5Options opt_;
  OdeStats stats_;
  double h_ = 0;
  bool have_k1_ = false;
  Eigen::VectorXd k1_;
};

}  // namespace mechbench::numeric
