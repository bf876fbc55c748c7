// Per-run state and scratch of the natural-coordinate solver (MuJoCo's mjData): everything an
// algorithm writes. Sizes are written beside each field; n = coordinates, m = constraint rows,
// f = driver rows, P = points.
#pragma once

#include "mechbench/numeric/natural_model.h"

#include <Eigen/Core>

#include <vector>

namespace mechbench::numeric {

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
};

}  // namespace mechbench::numeric
