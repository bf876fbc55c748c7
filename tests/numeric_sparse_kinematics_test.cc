// The sparse kinematic path (NaturalData::sparse: sparse Φ_q, Newton by sparse LU or QR, the ranks
// and redundant rows by a sparse QR in row order) against the dense one: every built-in scene and
// the bad-input fixtures forced through it, a medium N-four-bar (kAuto picks sparse there) and its
// singular position; and that a large model's data holds no dense m × n or n × n block.
#include "mechbench/errors.h"
#include "mechbench/loader.h"
#include "mechbench/numeric/constraints.h"
#include "mechbench/numeric/dynamics.h"
#include "mechbench/numeric/forward_dynamics.h"
#include "mechbench/numeric/natural_data.h"
#include "mechbench/numeric/natural_model.h"
#include "mechbench/references/nfourbar.h"
#include "mechbench/numeric/numeric_method.h"
#include "mechbench/numeric/solver.h"

#include <gtest/gtest.h>

#include <regex>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace mechbench::numeric {
namespace numeric_sparse_kinematics_test {  // this file's own names (the tests build in unity batches)
namespace {

using namespace ::mechbench::references;  // the N-four-bar's generator and exact motion

// One instant solved on either path: the data, the report, or the message it threw.
struct Instant {
  std::unique_ptr<NaturalData> data;  // NaturalData holds solvers that neither copy nor move
  InstantReport report;
  std::string error;  // ScenarioError::what(), empty when it solved
};

Instant Solve(const NaturalModel& nm, LinearAlgebra la) {
  Instant out;
  out.data = std::make_unique<NaturalData>(nm, la);
  try {
    out.report = SolveInstant(nm, *out.data, nm.model.analysis.t0, nm.model.GuessQ());
  } catch (const ScenarioError& e) {
    out.error = e.what();
  }
  return out;
}

// max_j |a_j − b_j| / (max |a| + 1): the scale of a whole vector, so that a zero component is not
// judged on round-off.
double Gap(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  if (a.size() != b.size()) return INFINITY;
  if (a.size() == 0) return 0.0;
  return (a - b).cwiseAbs().maxCoeff() / (a.cwiseAbs().maxCoeff() + 1.0);
}

// The two paths give the same instant: the same ranks and redundant rows, the same messages (or
// the same error), q, q̇, q̈ to round-off (Newton converges to 1e-12 of the coordinate scale on
// either; the linear problems are solved by LU/COD against QR/LU), and the same Φ_q entries.
void ExpectSameInstant(const NaturalModel& nm, const Instant& dense, const Instant& sparse) {
  ASSERT_FALSE(dense.data->sparse);
  ASSERT_TRUE(sparse.data->sparse);
  // A scene that cannot assemble (or cannot reach its drivers' values) leaves Newton wandering on
  // an inconsistent system, where the two paths' steps differ (least squares against the
  // minimum-norm solution) and so do the residuals it ends on after its iterations: the message
  // must be the same up to those values. Every other message is the same to the character.
  const auto masked = [](const std::string& s) { return std::regex_replace(s, std::regex("= -?[0-9.]+(e[-+]?[0-9]+)?"), "= #"); };
  EXPECT_EQ(masked(dense.error), masked(sparse.error));
  // (An unreachable driver's range and the rows just past it are the same on both paths; the
  // residuals of Newton from the drawing and just past the limit are those values.)
  const bool wandering = dense.error.find(" iterations (largest residuals:") != std::string::npos ||
                         dense.error.find("Newton–Raphson from the file's drawing gives") != std::string::npos;
  if (!wandering) {
    EXPECT_EQ(dense.error, sparse.error);
  }
  if (!dense.error.empty() || !sparse.error.empty()) return;
  const RankReport &a = dense.report.rank, &b = sparse.report.rank;
  EXPECT_EQ(a.rank, b.rank);
  EXPECT_EQ(a.dof, b.dof);
  EXPECT_EQ(a.augmented_rank, b.augmented_rank);
  EXPECT_EQ(a.redundant_rows, b.redundant_rows);
  EXPECT_EQ(dense.report.messages, sparse.report.messages);
  EXPECT_EQ(dense.report.newton.converged, sparse.report.newton.converged);
  EXPECT_LE(Gap(dense.data->q, sparse.data->q), 1e-10);
  EXPECT_LE(Gap(dense.data->qd, sparse.data->qd), 1e-9);
  EXPECT_LE(Gap(dense.data->qdd, sparse.data->qdd), 1e-8);
  EXPECT_LE(Gap(dense.data->Phi, sparse.data->Phi), 1e-10);
  // Φ_q evaluated by both at their own q: the sparse pattern holds every nonzero of the dense one.
  const Eigen::MatrixXd J = Eigen::MatrixXd(sparse.data->jac.J());
  ASSERT_EQ(J.rows(), dense.data->Phi_q.rows());
  ASSERT_EQ(J.cols(), dense.data->Phi_q.cols());
  EXPECT_LE((J - dense.data->Phi_q).cwiseAbs().maxCoeff(), 1e-8 * (dense.data->Phi_q.cwiseAbs().maxCoeff() + 1)) << nm.model.name;
}

// Every built-in scene the numeric method solves (textbook linkages and gear trains, the §4.4
// redundant cos+sin rows, free scenes placed by their initial conditions), forced through the
// sparse path.
TEST(NumericSparseKinematics, BuiltinScenesAgreeWithTheDensePath) {
  int solved = 0, redundant = 0;
  for (const std::string& f : BuiltinScenarioFiles()) {
    const Model model = LoadScenario(f);
    if (MakeNumericMethod()->Applicability(model)) continue;
    SCOPED_TRACE(model.name);
    const NaturalModel nm = Compile(model);
    const Instant dense = Solve(nm, LinearAlgebra::kDense), sparse = Solve(nm, LinearAlgebra::kSparse);
    ExpectSameInstant(nm, dense, sparse);
    solved += dense.error.empty();
    redundant += !dense.report.rank.redundant_rows.empty();
  }
  EXPECT_GE(solved, 20);
  EXPECT_GT(redundant, 0);  // the §4.4 scenes with a redundant cos+sin pair are among them
}

// The bad-input fixtures that reach the solver (a DOF mismatch, a singular instant, a point off its
// guide, …) give the same message on either path; those the loader or Compile reject do not get there.
TEST(NumericSparseKinematics, BadInputsGiveTheSameMessages) {
  int reached = 0;
  for (const auto& entry : std::filesystem::directory_iterator(std::string(MECHBENCH_TEST_DATA) + "/bad")) {
    std::optional<NaturalModel> nm;
    try {
      nm = Compile(LoadScenario(entry.path().string()));
    } catch (const ScenarioError&) {
      continue;
    }
    if (nm->n == 0) continue;
    SCOPED_TRACE(entry.path().filename().string());
    const Instant dense = Solve(*nm, LinearAlgebra::kDense), sparse = Solve(*nm, LinearAlgebra::kSparse);
    ExpectSameInstant(*nm, dense, sparse);
    reached += !dense.error.empty();
  }
  EXPECT_GE(reached, 2);  // 08_dof_mismatch, 09_singular_instant at least
}

// A medium N-four-bar, where kAuto picks the sparse path: the same start as the dense path.
TEST(NumericSparseKinematics, MediumNFourBarAgreesWithTheDensePath) {
  const NaturalModel nm = Compile(NFourBar({.n = 40, .t1 = 1, .samples = 2}));
  ASSERT_GE(nm.n, kSparseKinematicsFromCoordinates);
  const Instant dense = Solve(nm, LinearAlgebra::kDense), sparse = Solve(nm, LinearAlgebra::kAuto);
  ExpectSameInstant(nm, dense, sparse);
  EXPECT_EQ(sparse.report.rank.dof, 1);
}

// At the horizontal position every bar is collinear and Φ_q loses N ranks: both paths find the same
// rank and call the same rows redundant (greedy in row order: the later of dependent rows), and the
// velocity problem with a driven xP0 is singular on both.
TEST(NumericSparseKinematics, SingularPositionHasTheSameRankAndRedundantRows) {
  for (int n_bars : {1, 3, 12}) {
    SCOPED_TRACE(n_bars);
    const Model model = NFourBar({.n = n_bars, .t1 = 1, .samples = 2});
    const NaturalModel driven = Compile(model.InitialAsDrivers());
    const NFourBarSlots slots = NFourBarSlotsOf(model, n_bars);
    Eigen::VectorXd q = Eigen::VectorXd::Zero(driven.n);
    for (int i = 0; i <= n_bars; ++i) q[slots.x[i]] = i + 1.0, q[slots.y[i]] = 0.0;  // every crank at θ = 0
    RankReport rk[2];
    int velocity_rank[2];
    for (int s = 0; s < 2; ++s) {
      NaturalData data(driven, s ? LinearAlgebra::kSparse : LinearAlgebra::kDense);
      UpdatePoints(driven, data, q);
      rk[s] = AnalyzeRank(driven, data);
      velocity_rank[s] = SolveVelocity(driven, data, 0.0);
    }
    EXPECT_EQ(rk[0].rank, driven.m() - n_bars);
    EXPECT_EQ(rk[0].rank, rk[1].rank);
    EXPECT_EQ(rk[0].augmented_rank, rk[1].augmented_rank);
    EXPECT_EQ(rk[0].redundant_rows, rk[1].redundant_rows);
    EXPECT_EQ(static_cast<int>(rk[1].redundant_rows.size()), n_bars);
    EXPECT_LT(velocity_rank[0], driven.n);
    EXPECT_EQ(velocity_rank[0], velocity_rank[1]);
  }
}

// Newton from a start off the manifold converges to the same assembly on both paths (a driven
// scene: the solution is isolated, so any convergent iteration lands on it).
TEST(NumericSparseKinematics, NewtonFromADisturbedStartLandsOnTheSameAssembly) {
  const Model model = LoadScenario(ResolveScenario("fourbar_crank_rocker"));
  const NaturalModel nm = Compile(model);
  const Eigen::VectorXd start = model.GuessQ() + 0.05 * Eigen::VectorXd::Ones(nm.n).cwiseProduct(nm.q_scale);
  Eigen::VectorXd q[2];
  for (int s = 0; s < 2; ++s) {
    NaturalData data(nm, s ? LinearAlgebra::kSparse : LinearAlgebra::kDense);
    const NewtonReport nr = SolvePosition(nm, data, start, model.analysis.t0);
    ASSERT_TRUE(nr.converged);
    q[s] = data.q;
  }
  EXPECT_LE(Gap(q[0], q[1]), 1e-10);
}

// At N = 2000 (n = 4002, m = 4001) nothing dense is m × n or n × n: the data, the kinematic
// scratch and the dynamics system after the whole start (SolveInstant with its rank checks, the
// mass matrix, the index-1 accelerations) hold vectors and sparse matrices only.
TEST(NumericSparseKinematics, LargeModelAllocatesNoDenseBlock) {
  const Model model = NFourBar({.n = 2000, .t1 = 0.01, .samples = 2});
  const NaturalModel nm = Compile(model);
  const FreeStart start = AssembleFreeStart(nm);
  EXPECT_EQ(start.instant.rank.dof, 1);
  DynamicsSystem sys(nm, LinearAlgebra::kAuto, kSparseAli3pFromCoordinates);
  sys.ChooseRows(start.q);
  Eigen::VectorXd qdd, lambda;
  std::string why;
  ASSERT_TRUE(sys.Accelerations(start.q, start.qd, 0, 0, qdd, lambda, &why)) << why;
  EXPECT_TRUE(sys.dropped_rows().empty());
  const NaturalData& data = sys.data();
  EXPECT_TRUE(data.sparse);
  for (const Eigen::MatrixXd* dense : {&data.Phi_q, &data.Phidot_q, &data.A, &data.M, &data.kin.As, &data.kin.lu})
    EXPECT_EQ(dense->size(), 0);
  // What it holds instead grows with N: a few entries per row.
  EXPECT_LE(data.jac.J().nonZeros(), 8 * nm.m());
  EXPECT_LE(sys.M_sparse().nonZeros(), 16 * static_cast<Eigen::Index>(model.bodies.size()));
  EXPECT_EQ(sys.M_diagonal().size(), nm.n);
  // The start is the exact one (every crank vertical, P0 moving at 1 m/s along +x).
  const NFourBarSlots slots = NFourBarSlotsOf(model, 2000);
  for (int i : {0, 1000, 2000}) {
    EXPECT_NEAR(start.q[slots.x[i]], i, 1e-12);
    EXPECT_NEAR(start.q[slots.y[i]], 1, 1e-12);
    EXPECT_NEAR(start.qd[slots.x[i]], 1, 1e-12);
  }
}

}  // namespace
}  // namespace numeric_sparse_kinematics_test
}  // namespace mechbench::numeric
