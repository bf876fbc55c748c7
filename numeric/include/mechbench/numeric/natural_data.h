// Per-run state and scratch of the natural-coordinate solver (MuJoCo's mjData): everything an
// algorithm writes. Sizes are written beside each field; n = coordinates, m = constraint rows,
// f = driver rows, P = points.
#pragma once

#include "mechbench/numeric/natural_model.h"

#include <Eigen/Core>
#include <Eigen/OrderingMethods>
#include <Eigen/QR>
#include <Eigen/SparseCore>
#include <Eigen/SparseLU>
#include <Eigen/SparseQR>

#include <vector>

namespace mechbench::numeric {

// Dense or sparse storage and linear algebra. For the kinematic data below: kAuto is dense below
// kSparseKinematicsFromCoordinates (the textbook scenes, a few coordinates: their dense path with
// its small-LU fast path is kept as it is) and sparse from it (long chains, where m × n blocks do
// not fit: 3.2 GB each at N = 10,000 four-bars). The dynamics choose their own (forward_dynamics.h).
enum class LinearAlgebra { kAuto, kDense, kSparse };
const char* ToString(LinearAlgebra la);
inline constexpr int kSparseKinematicsFromCoordinates = 64;

struct NaturalData;

// Φ_q of a set of rows as a sparse matrix with a fixed pattern (every entry a row can touch, from
// its kind: at most 8 per row), and Φ̇_q on the same pattern on request. Built once per row set
// (the pattern does not depend on q); Evaluate writes Φ, Φ_q (and Φ̇_q q̇, Φ̇_q) of those rows in
// O(rows) and allocates nothing. Entries are summed in the same order as the dense EvalJacobian,
// so Φ_q is the same to the bit; Φ̇_q q̇ is summed per row instead of as a dense product (the same
// to round-off). Functions in constraints.cc.
class SparseJacobian {
 public:
  using Matrix = Eigen::SparseMatrix<double, Eigen::RowMajor>;
  SparseJacobian() = default;
  SparseJacobian(const NaturalModel& model, const std::vector<int>& rows);

  // At q (and q̇ when `qd` is given; then also Φ̇_q q̇ → *jdot_qd, and Φ̇_q → Jdot() when
  // `rate_matrix`): Φ of the rows → phi, Φ_q → J(). Sets data.q, the point positions and, with
  // qd, data.qd and the point velocities.
  void Evaluate(const NaturalModel& model, NaturalData& data, const Eigen::VectorXd& q, const Eigen::VectorXd* qd,
                Eigen::VectorXd& phi, Eigen::VectorXd* jdot_qd, bool rate_matrix = false);
  const Matrix& J() const { return J_; }
  const Matrix& Jdot() const { return Jdot_; }  // after an Evaluate with rate_matrix
  const std::vector<int>& rows() const { return rows_; }
  int rows_count() const { return static_cast<int>(rows_.size()); }
  bool empty() const { return start_.empty(); }  // default-constructed: no pattern yet

 private:
  // Evaluate for a spatial model (NaturalModel::dim = 3; spatial_rows.cc): three partials per
  // entity instead of two per point.
  void Evaluate3(const NaturalModel& model, NaturalData& data, const Eigen::VectorXd& q, const Eigen::VectorXd* qd,
                 Eigen::VectorXd& phi, Eigen::VectorXd* jdot_qd, bool rate_matrix);

  std::vector<int> rows_;
  Matrix J_, Jdot_;
  // Per row k, index_[start_[k] …] is the value index of each partial (two per point, x then y,
  // then one per slot) in J_, −1 for a constant coordinate.
  std::vector<int> start_, index_;
};

// Scratch of the kinematic solver (solver.cc), sized by NaturalData's constructor so that a
// position, velocity or acceleration solve allocates nothing on its fast path (a square,
// well-conditioned [Φ_q; B] factored by LU). Nothing here is a result; read data.q, qd, qdd, Phi…
struct KinematicScratch {
  // Largest n factored by LU (kinematic scenes have a few coordinates); NaturalData sizes the
  // scratch matrices up front for these, a larger scene at its first solve.
  static constexpr int kMaxLuSize = 64;

  Eigen::VectorXd q;      // [n] Newton iterate
  Eigen::VectorXd step;   // [n] Newton step / solution of the last linear solve
  Eigen::VectorXd scale;  // [m + f] typical size of each augmented row (Newton's row weights are 1/scale)
  Eigen::VectorXd b;      // [m + f] right-hand side
  Eigen::VectorXd w;      // [m + f] row weights of the factored matrix
  Eigen::VectorXd wb;     // [m + f] weighted right-hand side
  Eigen::MatrixXd As;     // [(m + f) × n] row-weighted augmented matrix
  // Square and well conditioned: LU with partial pivoting (L unit lower, below the diagonal; U
  // on and above), row interchanges in piv; otherwise the rank-revealing cod.
  Eigen::MatrixXd lu;     // [n × n]
  Eigen::VectorXi piv;    // [n]
  Eigen::VectorXd col;    // [n] scratch of the condition-number check
  Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod;
  bool use_lu = false;    // which of the two holds the last factorization

  // Φ_q (data.Phi_q) was last evaluated at jacobian_q (set by EvalJacobian / EvalPhiJacobian;
  // code that writes data.Phi_q any other way must clear jacobian_valid).
  bool jacobian_valid = false;
  Eigen::VectorXd jacobian_q;  // [n]
  // The row-normalized [Φ_q; B] at factored_q is factored (lu or cod) with numerical rank
  // factored_rank: shared by the velocity and acceleration problems at one position.
  bool factored_valid = false;
  int factored_rank = 0;
  Eigen::VectorXd factored_q;  // [n]

  // Sparse data (NaturalData::sparse) instead of As, lu, cod: the weighted augmented matrix
  // transposed, [n × (m + f)] (its columns are the rows, so that a QR without column ordering
  // takes them in row order), its rank-revealing QR, and the sparse LU of the square [Φ_q; B]
  // that Newton uses when it can.
  Eigen::SparseMatrix<double> At;
  std::vector<int> used;  // [n] At's row of each coordinate, −1 for one that no row touches
  int used_cols = -1;     // the number of columns (m or m + f) `used` was ordered for
  Eigen::SparseQR<Eigen::SparseMatrix<double>, Eigen::NaturalOrdering<int>> qr;
  Eigen::SparseMatrix<double> Rt;  // [r × r] transpose of the QR's leading triangle (solves)
  Eigen::SparseMatrix<double> As_sparse;  // [(m + f) × n] weighted, for the LU
  Eigen::SparseLU<Eigen::SparseMatrix<double>, Eigen::COLAMDOrdering<int>> lu_sparse;
  bool use_lu_sparse = false;
  Eigen::VectorXd phi;  // [m] Φ that a sparse Jacobian evaluation writes on the way (not a result)
};

struct NaturalData {
  // kAuto: sparse from kSparseKinematicsFromCoordinates coordinates.
  explicit NaturalData(const NaturalModel& model, LinearAlgebra la = LinearAlgebra::kAuto);

  // Sparse: Φ_q, Φ̇_q and M live in jac and M_sparse, and the dense Phi_q, Phidot_q, A, M below
  // stay empty (0 × 0), so nothing here is O(m n) or O(n²); every algorithm on NaturalData takes
  // the sparse path (same results to round-off, see solver.h for the rank).
  bool sparse = false;

  double t = 0.0;            // [s]
  Eigen::VectorXd q;         // [n] coordinates
  Eigen::VectorXd qd;        // [n] velocities
  Eigen::VectorXd qdd;       // [n] accelerations

  // Every point's in-plane position, velocity and acceleration, constants included [P].
  std::vector<Eigen::Vector2d> r, rd, rdd;

  Eigen::VectorXd Phi;          // [m] Φ(q, t)
  Eigen::MatrixXd Phi_q;        // [m × n] ∂Φ/∂q (dense; row i is ConstraintRow i, column j is slot j)
  Eigen::VectorXd Phi_t;        // [m] ∂Φ/∂t (0: time enters only through the driver rows)
  Eigen::MatrixXd Phidot_q;     // [m × n] dΦ_q/dt
  Eigen::VectorXd Phidot_q_qd;  // [m] Φ̇_q q̇, the acceleration problem's velocity term

  Eigen::MatrixXd A;    // [(m + f) × n] augmented matrix [Φ_q; B]
  Eigen::VectorXd rhs;  // [m + f] right-hand side of the last augmented solve

  Eigen::VectorXd lambda;  // [m] Lagrange multipliers (dynamics; placeholder for now)
  Eigen::MatrixXd M;       // [n × n] mass matrix [kg] (constant in natural coordinates)
  Eigen::VectorXd Q;       // [n] generalized forces [N]

  // Sparse data only: Φ_q of every row (jac.J(), [m × n]; Φ̇_q in jac.Jdot() after EvalPhidotQ),
  // its pattern built at the first evaluation, and M [n × n, kg] (MassMatrix).
  SparseJacobian jac;
  Eigen::SparseMatrix<double> M_sparse;

  KinematicScratch kin;  // the kinematic solver's scratch (not results)
};

}  // namespace mechbench::numeric
