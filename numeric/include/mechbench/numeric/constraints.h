// Constraint evaluation in natural coordinates: Φ, Φ_q, Φ_t, Φ̇_q and Φ̇_q q̇, all analytic.
// Each algorithm writes into `data` and reads nothing else from it unless said so.
#pragma once

#include "mechbench/numeric/natural_data.h"
#include "mechbench/numeric/natural_model.h"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <vector>

namespace mechbench::numeric {

// Every point's position, velocity, acceleration from q, q̇, q̈ → data.r / rd / rdd (and data.q /
// qd / qdd); constant coordinates keep their value and have zero rates.
void UpdatePoints(const NaturalModel& model, NaturalData& data, const Eigen::VectorXd& q);
void UpdatePointVelocities(const NaturalModel& model, NaturalData& data, const Eigen::VectorXd& qd);
void UpdatePointAccelerations(const NaturalModel& model, NaturalData& data, const Eigen::VectorXd& qdd);

// Φ(q, t) → data.Phi [m]. Also sets data.q, data.t and the point positions.
void EvalPhi(const NaturalModel& model, NaturalData& data, const Eigen::VectorXd& q, double t);
// ∂Φ/∂q → data.Phi_q [m × n]. Also sets data.q and the point positions.
void EvalJacobian(const NaturalModel& model, NaturalData& data, const Eigen::VectorXd& q);
// Both in one pass over the rows: Φ(q, t) → data.Phi and ∂Φ/∂q → data.Phi_q, the same values as
// EvalPhi and EvalJacobian. Also sets data.q, data.t and the point positions.
void EvalPhiJacobian(const NaturalModel& model, NaturalData& data, const Eigen::VectorXd& q, double t);
// ∂Φ/∂t → data.Phi_t [m]: zero, since time enters only through the driver rows.
void EvalPhit(const NaturalModel& model, NaturalData& data, const Eigen::VectorXd& q, double t);
// dΦ_q/dt = Σ_k ∂Φ_q/∂q_k q̇_k → data.Phidot_q [m × n]. Sets data.q, data.qd.
void EvalPhidotQ(const NaturalModel& model, NaturalData& data, const Eigen::VectorXd& q,
                 const Eigen::VectorXd& qd);
// Φ̇_q q̇ → data.Phidot_q_qd [m] (and data.Phidot_q on the way).
void EvalPhidotQdot(const NaturalModel& model, NaturalData& data, const Eigen::VectorXd& q,
                    const Eigen::VectorXd& qd);

// Driver rows q_i − f_i(t): their residuals, and f_i's rate and acceleration at t [f].
Eigen::VectorXd DriverResiduals(const NaturalModel& model, const Eigen::VectorXd& q, double t);
Eigen::VectorXd DriverRates(const NaturalModel& model, double t);
Eigen::VectorXd DriverAccelerations(const NaturalModel& model, double t);

// Φ_q of a set of rows as a sparse matrix with a fixed pattern (every entry a row can touch, from
// its kind: at most 8 per row), for the dynamics of large scenes where the dense data.Phi_q costs
// O(m n) per evaluation. Built once per row set (the pattern does not depend on q); Evaluate
// writes Φ, Φ_q and Φ̇_q q̇ of those rows in O(rows) and allocates nothing. Entries are summed in
// the same order as the dense EvalJacobian, so Φ_q is the same to the bit; Φ̇_q q̇ is summed per
// row instead of as a dense product (the same to round-off).
class SparseJacobian {
 public:
  using Matrix = Eigen::SparseMatrix<double, Eigen::RowMajor>;
  SparseJacobian() = default;
  SparseJacobian(const NaturalModel& model, const std::vector<int>& rows);

  // At q (and q̇ when `qd` is given; then also Φ̇_q q̇ → *jdot_qd): Φ of the rows → phi, Φ_q → J().
  // Sets data.q, the point positions and, with qd, data.qd and the point velocities.
  void Evaluate(const NaturalModel& model, NaturalData& data, const Eigen::VectorXd& q, const Eigen::VectorXd* qd,
                Eigen::VectorXd& phi, Eigen::VectorXd* jdot_qd);
  const Matrix& J() const { return J_; }
  const std::vector<int>& rows() const { return rows_; }
  int rows_count() const { return static_cast<int>(rows_.size()); }

 private:
  std::vector<int> rows_;
  Matrix J_;
  // Per row k, index_[start_[k] …] is the value index of each partial (two per point, x then y,
  // then one per slot) in J_, −1 for a constant coordinate.
  std::vector<int> start_, index_;
};

// Residual divided by each row's typical size (ConstraintRow::scale), max norm: the number the
// position solver compares with its tolerance. Reads data.Phi.
double ScaledResidual(const NaturalModel& model, const NaturalData& data);

}  // namespace mechbench::numeric
