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
// ∂Φ/∂q → data.Phi_q [m × n] (sparse data: data.jac.J()). Also sets data.q and the point positions.
void EvalJacobian(const NaturalModel& model, NaturalData& data, const Eigen::VectorXd& q);
// Both in one pass over the rows: Φ(q, t) → data.Phi and ∂Φ/∂q → data.Phi_q, the same values as
// EvalPhi and EvalJacobian. Also sets data.q, data.t and the point positions.
void EvalPhiJacobian(const NaturalModel& model, NaturalData& data, const Eigen::VectorXd& q, double t);
// ∂Φ/∂t → data.Phi_t [m]: zero, since time enters only through the driver rows.
void EvalPhit(const NaturalModel& model, NaturalData& data, const Eigen::VectorXd& q, double t);
// dΦ_q/dt = Σ_k ∂Φ_q/∂q_k q̇_k → data.Phidot_q [m × n] (sparse data: data.jac.Jdot(), with Φ_q
// re-evaluated at q into data.jac.J() on the way). Sets data.q, data.qd.
void EvalPhidotQ(const NaturalModel& model, NaturalData& data, const Eigen::VectorXd& q,
                 const Eigen::VectorXd& qd);
// Φ̇_q q̇ → data.Phidot_q_qd [m] (and data.Phidot_q on the way).
void EvalPhidotQdot(const NaturalModel& model, NaturalData& data, const Eigen::VectorXd& q,
                    const Eigen::VectorXd& qd);
// Φ̇_q q̇ → data.Phidot_q_qd [m] alone, each row's term summed from its partials' rates (as the
// sparse path sums it; equal to the dense product to round-off) without forming data.Phidot_q,
// which it leaves as it was: the acceleration problem's one need. Sets data.q, data.qd.
void EvalPhidotQdotRows(const NaturalModel& model, NaturalData& data, const Eigen::VectorXd& q,
                        const Eigen::VectorXd& qd);

// Driver rows q_i − f_i(t): their residuals, and f_i's rate and acceleration at t [f].
Eigen::VectorXd DriverResiduals(const NaturalModel& model, const Eigen::VectorXd& q, double t);
Eigen::VectorXd DriverRates(const NaturalModel& model, double t);
Eigen::VectorXd DriverAccelerations(const NaturalModel& model, double t);

// SparseJacobian (Φ_q of a set of rows with a fixed pattern) is declared in natural_data.h.

// Residual divided by each row's typical size (ConstraintRow::scale), max norm: the number the
// position solver compares with its tolerance. Reads data.Phi.
double ScaledResidual(const NaturalModel& model, const NaturalData& data);

}  // namespace mechbench::numeric
