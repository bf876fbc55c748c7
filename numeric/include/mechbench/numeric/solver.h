// The kinematic problems of the book's chapter 4 on the augmented system [Φ; B]:
//   position      Newton–Raphson  [Φ_q; B] Δq = −[Φ; q_B − f(t)]          (eq. 4.59)
//   velocity      [Φ_q; B] q̇ = [−Φ_t; ḟ(t)]                               (eq. 4.7, 4.9)
//   acceleration  [Φ_q; B] q̈ = [−Φ̇_q q̇ − Φ̇_t; f̈(t)]                     (eq. 4.15, 4.17)
// Every linear solve is a row-weighted least-squares solve: LU with partial pivoting when [Φ_q; B]
// is square and well conditioned (there the least-squares solution is the unique one, so the
// answer is the same to round-off), otherwise a rank-revealing complete orthogonal decomposition,
// so redundant but consistent rows (the cos+sin pair of §4.4) and singular positions are handled
// as before. Scratch lives in NaturalData::kin: a sample allocates nothing on the LU path, and the
// velocity and acceleration problems at one position share Φ_q and its factorization.
#pragma once

#include "mechbench/numeric/natural_data.h"
#include "mechbench/numeric/natural_model.h"

#include <Eigen/Core>

#include <string>
#include <vector>

namespace mechbench::numeric {

struct NewtonOptions {
  double phi_tolerance = 1e-12;   // on max_i |Φ_i| / scale_i (ScaledResidual)
  double step_tolerance = 1e-12;  // on max_j |Δq_j| / q_scale_j
  int max_iterations = 50;
  bool record_iterates = true;
  // Simplified Newton on dense systems: keep the iteration matrix factored at one iterate while
  // each step shrinks the residual at least 4×, evaluating Φ alone for those steps (a full step
  // otherwise). For a sequence of positions from a good prediction (a motion's samples); the
  // instant and the book's printed iterates take full Newton steps.
  bool simplified = false;
};

struct NewtonReport {
  bool converged = false;
  int iterations = 0;            // steps taken (at least one)
  double residual = 0.0;         // ‖Φ‖₂ of the constraint rows at the last iterate (unscaled)
  double scaled_residual = 0.0;  // ScaledResidual over constraint and driver rows
  std::vector<Eigen::VectorXd> iterates;  // q after step 1, 2, … (when recorded)
};

// Newton–Raphson from `q_start` on the constraint rows and, when `with_drivers`, the driver rows
// at time t. Leaves the last iterate in data.q and data.Phi/Phi_q evaluated there.
NewtonReport SolvePosition(const NaturalModel& model, NaturalData& data,
                           const Eigen::VectorXd& q_start, double t,
                           const NewtonOptions& options = {}, bool with_drivers = true);

// Relative singular-value thresholds on row-normalized matrices. Rank and degrees of freedom use
// kRankTolerance. The linear problems use the looser kSingularTolerance: Newton–Raphson converges
// only linearly at a singular position and stops with coordinates ~1e-6 off it, where the smallest
// singular value is of that order, so a condition number above ~1e6 is read as singular.
inline constexpr double kRankTolerance = 1e-8;
inline constexpr double kSingularTolerance = 1e-6;

// Velocity and acceleration problems at data.q (already assembled), time t → data.qd, data.qdd.
// Both return the numerical rank of [Φ_q; B] (kSingularTolerance): below n the position is
// singular for these drivers and the minimum-norm answer is not the motion.
int SolveVelocity(const NaturalModel& model, NaturalData& data, double t);
int SolveAcceleration(const NaturalModel& model, NaturalData& data, double t);

// Augmented matrix [Φ_q; B] at data.q → data.A (evaluates Φ_q).
void AssembleAugmented(const NaturalModel& model, NaturalData& data);

struct RankReport {
  int n = 0, m = 0, f = 0;
  int rank = 0;            // rank of Φ_q
  int dof = 0;             // n − rank
  int augmented_rank = 0;  // rank of [Φ_q; B]; n when the drivers fix the motion
  std::vector<int> redundant_rows;  // rows that add nothing to the rank of the rows before them
};
// Rank of Φ_q and [Φ_q; B] at data.q by SVD of the row-normalized matrices (relative threshold
// `tolerance`), so that rows in different units (length, length², teeth·rad) weigh the same.
RankReport AnalyzeRank(const NaturalModel& model, NaturalData& data, double tolerance = kRankTolerance);

struct InstantReport {
  NewtonReport newton;
  RankReport rank;
  std::vector<std::string> messages;  // notes that do not make the scene invalid (redundancy)
};
// Position, velocity and acceleration at time t from q_start, with the checks of an instant:
// throws ScenarioError naming the culprit's file and line when the scene cannot assemble, when
// the drivers do not match the degrees of freedom, or when the augmented matrix is singular.
InstantReport SolveInstant(const NaturalModel& model, NaturalData& data, double t,
                           const Eigen::VectorXd& q_start, const NewtonOptions& options = {});

// Why the drivers' values at t cannot be reached from the assembled position `from` (its drivers at
// their values there): they are stepped from there toward t (a continuation), and with one driver
// the other way too, which gives its reachable range. `direct` is the Newton report that failed;
// `from_where` names the position in the text (kFromDrawing at t0, "the position at t = … s" along
// a motion). `reachable`: the continuation gets there, so the failure is the starting guess's.
struct ReachReport {
  bool reachable = false;
  std::string what, fix;
};
inline const std::string kFromDrawing = "the position drawn in the file";
ReachReport DescribeUnreachableDrivers(const NaturalModel& model, const NaturalData& from, double t,
                                       const NewtonOptions& options, const NewtonReport& direct,
                                       const std::string& from_where);

}  // namespace mechbench::numeric
