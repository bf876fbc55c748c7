// One step of ALI3-P (index-3 augmented Lagrangian with mass-orthogonal projections, trapezoidal
// rule; García de Jalón & Bayo, Cuadrado et al.) on a DynamicsSystem, dense or sparse as the
// system is. dyn-ali3p (dynamics_methods.cc) drives it over the samples; the benchmark times it.
//
// Per step, Newton on f(q) = (h²/4)(M q̈ + Φ_qᵀ(αΦ + λ) − Q(q, q̇)), q̈ = (4/h²) q − q̂̈,
// q̇ = (2/h) q − q̂̇, with the tangent
//   W = M + (h²/4)(α Φ_qᵀΦ_q + Σ_i (αΦ_i + λ_i) ∂²Φ_i/∂q² of the distance rows)
//         − sym((h²/4) ∂Q/∂q + (h/2) ∂Q/∂q̇)   (the force elements; sym: the symmetric part)
// (λ ← λ + αΦ after every iteration but the first), then the projections
//   W̄ q̇ = M q̇*,  W̄ q̈ = M q̈* − (h²/4) α Φ_qᵀ Φ̇_q q̇,  W̄ = M + (h²/4) α Φ_qᵀΦ_q at the new q.
// Rows are scaled to length units (S = length_scale / row scale) so that one α fits all, and
// α h²/4 = penalty × max diag M at the run's largest step.
//
// Numerically (needed for second order on the 40-bay N-four-bar, coordinates up to 41 m, where
// length_scale = 40 makes the penalty's part of W 1600 times that of one bay, cond W̄ = 4.9e6):
//  - Newton iterates on the increment Δ = q_{n+1} − q_n, and q̇*, q̈* come from Δ, not from
//    (2/h) q_{n+1} − ((2/h) q_n + q̇_n), whose rounding (ε |q| 2/h) would stay in q̇;
//  - a Newton step within the tolerance is followed by one more pass, with the same factorization,
//    on the residual at the new iterate (λ updated there), W⁻¹ f in length units; the step is
//    accepted when that is within the tolerance too (with the penalty's weight in W, a small step
//    can leave a much larger quadratic remainder in the tangent directions);
//  - the projections are solved for the corrections q̇ − q̇*, q̈ − q̈* (same equations), so that
//    W̄'s conditioning costs ε cond(W̄) of the correction, not of the whole q̇ and q̈.
#pragma once

#include "mechbench/numeric/dynamics.h"
#include "mechbench/numeric/dynamics_methods.h"
#include "mechbench/numeric/forward_dynamics.h"

#include <Eigen/Core>
#include <Eigen/Cholesky>
#include <Eigen/SparseCholesky>

#include <memory>
#include <string>
#include <vector>

namespace mechbench::numeric {

class Ali3pStepper {
 public:
  // `h_max`: the run's largest step; `lambda0`: the index-1 multipliers of the active rows at the
  // start (the warm start). `sys` must outlive the stepper and keep its rows.
  Ali3pStepper(DynamicsSystem& sys, const Ali3pOptions& options, double h_max, const Eigen::VectorXd& lambda0);
  ~Ali3pStepper();

  // One step of h from (q, q̇, q̈), in place. Returns false (state unspecified, `why` set) when
  // the tangent matrix is singular, Newton does not converge, or NaN/Inf appear. `alpha_factor`
  // scales the penalty (sub-steps keep α h²/4).
  bool Step(double h, Eigen::VectorXd& q, Eigen::VectorXd& qd, Eigen::VectorXd& qdd, std::string& why,
            double alpha_factor = 1.0);
  // Step, and where it fails (Newton near a singular position), the same interval again in 4
  // sub-steps, each of those likewise, up to Ali3pOptions::retry_levels deep. False when even the
  // smallest sub-step fails.
  bool Advance(double h, Eigen::VectorXd& q, Eigen::VectorXd& qd, Eigen::VectorXd& qdd, std::string& why);

  long iterations() const { return iterations_; }   // Newton iterations so far
  int last_iterations() const { return last_iterations_; }
  long slow_steps() const { return slow_steps_; }   // accepted by Ali3pOptions::singular_tolerance
  long retries() const { return retries_; }         // intervals redone in sub-steps by Advance
  double alpha() const { return alpha_; }           // penalty [kg/(s²)·…], see the header comment
  // Multipliers of the active rows in the file's row units (λ / S), after the last step.
  Eigen::VectorXd Multipliers() const { return lam_.cwiseProduct(S_); }

 private:
  class SparseTangent;
  bool Factorize(bool with_hessian, const Eigen::VectorXd& force, double c);
  void Solve(const Eigen::VectorXd& rhs, Eigen::VectorXd& x, bool projection);

  DynamicsSystem& sys_;
  Ali3pOptions o_;
  double alpha_ = 0;
  Eigen::VectorXd S_, lam_;
  Eigen::VectorXd step_scale_;  // per slot: what a Newton step is measured against (see the constructor)
  bool Retry(double h, int level, Eigen::VectorXd& q, Eigen::VectorXd& qd, Eigen::VectorXd& qdd, std::string& why);
  long iterations_ = 0, slow_steps_ = 0, retries_ = 0;
  Eigen::VectorXd q0_, qd0_, qdd0_, lam0_;  // Advance: the state at the interval's start
  double t0_ = 0;                            // and its time (DynamicsSystem::time)
  int last_iterations_ = 0;
  // Scratch (sized once).
  Eigen::VectorXd dx_, b_, qn_, qdn_, phis_, force_, f_, dq_, rhs_, qd_star_, qdd_star_, tmp_;
  std::vector<ElementDerivative> derivatives_;  // force elements at the iterate (dynamics.h)
  // Dense mode.
  Eigen::MatrixXd Js_, W_;
  Eigen::LDLT<Eigen::MatrixXd> ldlt_;
  Eigen::LLT<Eigen::MatrixXd> llt_;
  // Sparse mode.
  std::unique_ptr<SparseTangent> sparse_;
};

}  // namespace mechbench::numeric
