// Forward dynamics of free scenes in natural coordinates: the pieces every formulation shares.
//
// Equations of motion (M constant in natural coordinates, Q = gravity + constant point forces):
//   M q̈ + Φ_qᵀ λ = Q̃,   Φ(q) = 0,   Q̃ = Q / meters_per_unit  (so M q̈ is in kg·length/s²)
// Index-1 form with Baumgarte stabilisation (α, β in 1/s):
//   [M Φ_qᵀ; Φ_q 0] [q̈; λ] = [Q̃; −Φ̇_q q̇ − 2α Φ̇ − β² Φ],   Φ̇ = Φ_q q̇ (no time-dependent rows)
// Energy E = ½ q̇ᵀ M q̇ u² − Q̃ᵀ q u² [J] with u = meters_per_unit; the potential term is exact
// because Q is constant (it does not depend on q or q̇).
#pragma once

#include "mechbench/method.h"
#include "mechbench/numeric/natural_data.h"
#include "mechbench/numeric/natural_model.h"
#include "mechbench/numeric/solver.h"

#include <Eigen/Core>
#include <Eigen/LU>

#include <functional>
#include <string>
#include <vector>

namespace mechbench::numeric {

// Everything a dynamics formulation needs that does not change along the run, plus scratch.
class DynamicsSystem {
 public:
  explicit DynamicsSystem(const NaturalModel& model);

  const NaturalModel& model() const { return *model_; }
  int n() const { return model_->n; }
  int m() const { return static_cast<int>(active_.size()); }  // independent constraint rows
  const Eigen::MatrixXd& M() const { return M_; }            // [n × n] kg
  const Eigen::VectorXd& Q() const { return Q_; }            // [n] Q̃ = Q / meters_per_unit
  const std::vector<int>& active_rows() const { return active_; }
  const std::vector<int>& dropped_rows() const { return dropped_; }

  // Drops rows that are redundant at q (rank of Φ_q, kRankTolerance): the cos+sin pair of §4.4
  // keeps its redundancy along the motion, and a KKT matrix with dependent rows is singular.
  void ChooseRows(const Eigen::VectorXd& q);

  // Φ, Φ_q, Φ̇_q q̇ restricted to the active rows → phi_, J_, jdot_qd_ (and `data`).
  void Evaluate(const Eigen::VectorXd& q, const Eigen::VectorXd& qd, bool with_rates = true);
  const Eigen::VectorXd& phi() const { return phi_; }
  const Eigen::MatrixXd& J() const { return J_; }
  const Eigen::VectorXd& jdot_qd() const { return jdot_qd_; }

  // Index-1 accelerations and multipliers at (q, q̇) with Baumgarte α, β [1/s]. Returns false
  // (and sets `why`) when the KKT matrix is singular to working precision: a singular position.
  bool Accelerations(const Eigen::VectorXd& q, const Eigen::VectorXd& qd, double alpha, double beta,
                     Eigen::VectorXd& qdd, Eigen::VectorXd& lambda, std::string* why = nullptr);

  double Energy(const Eigen::VectorXd& q, const Eigen::VectorXd& qd) const;  // [J]
  // ‖Φ‖ scaled row by row (ScaledResidual, all rows), and ‖Φ_q q̇‖ scaled likewise per second.
  double ScaledPhi(const Eigen::VectorXd& q);
  double ScaledPhiDot(const Eigen::VectorXd& q, const Eigen::VectorXd& qd);
  // Multipliers of the active rows spread back to all m rows (0 on dropped rows).
  Eigen::VectorXd FullLambda(const Eigen::VectorXd& lambda_active) const;

  NaturalData& data() { return data_; }

 private:
  const NaturalModel* model_;
  NaturalData data_;
  Eigen::MatrixXd M_;
  Eigen::VectorXd Q_;
  std::vector<int> active_, dropped_;
  Eigen::VectorXd phi_, jdot_qd_;
  Eigen::MatrixXd J_;
  Eigen::MatrixXd kkt_;
  Eigen::VectorXd kkt_rhs_, kkt_x_;
  Eigen::PartialPivLU<Eigen::MatrixXd> lu_;
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

// Classic RK4 from t to t + h.
bool Rk4Step(const OdeRhs& f, const OdeProject& project, double t, double h, Eigen::VectorXd& y, std::string& why,
             OdeStats& stats);

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

 private:
  Dopri5Options opt_;
  OdeStats stats_;
  double h_ = 0;
  bool have_k1_ = false;
  Eigen::VectorXd k1_;
};

}  // namespace mechbench::numeric
