// Per-run state and scratch of the natural-coordinate solver (MuJoCo's mjData): everything an
// algorithm writes. Sizes are written beside each field; n = coordinates, m = constraint rows,
// f = driver rows, P = points.
#pragma once

#include "mechbench/numeric/natural_model.h"

#include <Eigen/Core>
#include <Eigen/QR>

#include <vector>

namespace mechbench::numeric {

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
};

struct NaturalData {
  explicit NaturalData(const NaturalModel& model);

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

  KinematicScratch kin;  // the kinematic solver's scratch (not results)
};

}  // namespace mechbench::numeric
