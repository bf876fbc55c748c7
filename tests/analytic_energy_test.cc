// The energy route to M and Q (energy.h): its sparse polarisation (pairs of coordinates that share
// a body only) against the dense one on A02's 41 four-bars, and the choice by size.
#include "mechbench/analytic/energy.h"
#include "mechbench/loader.h"

#include <gtest/gtest.h>

#include <climits>
#include <string>

namespace mechbench::analytic {
namespace analytic_energy_test {  // this file's own names (the tests build in unity batches)
namespace {

Model A02() { return LoadScenario(std::string(MECHBENCH_TEST_DATA) + "/../../scenarios/benchmarks/a02_nfourbar_40.yaml"); }

// Every entry the dense polarisation finds, the sparse one finds too; the entries it leaves out are
// the dense one's round-off (two energies that differ only in summation order), and Q is the same.
TEST(AnalyticEnergy, SparsePolarisationIsTheDenseOne) {
  const Model model = A02();
  const int n = static_cast<int>(model.q_layout.size());
  ASSERT_GE(n, kSparseMassFromCoordinates);
  const MassAndForces dense = MassAndForcesByEnergy(model, INT_MAX), sparse = MassAndForcesByEnergy(model, 0);
  ASSERT_FALSE(dense.sparse);
  ASSERT_TRUE(sparse.sparse);
  EXPECT_EQ(sparse.M.size(), 0);
  EXPECT_EQ(dense.Q, sparse.Q);
  const Eigen::MatrixXd M = Eigen::MatrixXd(sparse.M_sparse);
  const double largest = dense.M.cwiseAbs().maxCoeff();
  ASSERT_GT(largest, 0);
  EXPECT_LE((M - dense.M).cwiseAbs().maxCoeff(), 1e-14 * largest);
  for (int i = 0; i < n; ++i) EXPECT_EQ(M(i, i), dense.M(i, i)) << i;
  // A few entries per row: each bar couples the four coordinates of its two points.
  EXPECT_LE(sparse.M_sparse.nonZeros(), 16 * static_cast<Eigen::Index>(model.bodies.size()));
  EXPECT_EQ(M, M.transpose());
}

TEST(AnalyticEnergy, SmallScenesStayDense) {
  const Model model = LoadScenario(ResolveScenario("fourbar_free"));
  const MassAndForces mf = MassAndForcesByEnergy(model);
  EXPECT_FALSE(mf.sparse);
  EXPECT_EQ(mf.M.rows(), static_cast<Eigen::Index>(model.q_layout.size()));
}

}  // namespace
}  // namespace analytic_energy_test
}  // namespace mechbench::analytic
