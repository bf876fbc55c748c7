// The index-1 matrix's sparse LU (KLU refactored with the pivots of its first factorization):
// answers as a dense LU does, and takes fresh pivots when the old ones no longer serve.
#include "mechbench/numeric/refactoring_lu.h"

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include <complex>
#include <vector>

namespace mechbench::numeric {
namespace numeric_refactoring_lu_test {  // this file's own names (the tests build in unity batches)
namespace {

// A 3 × 3 matrix with every entry in its pattern, from dense values.
template <typename Scalar>
Eigen::SparseMatrix<Scalar> Full(const Eigen::Matrix<Scalar, 3, 3>& d) {
  std::vector<Eigen::Triplet<Scalar>> t;
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) t.emplace_back(r, c, d(r, c));
  Eigen::SparseMatrix<Scalar> A(3, 3);
  A.setFromTriplets(t.begin(), t.end());
  A.makeCompressed();
  return A;
}

TEST(RefactoringLu, RefactorsWithItsPivotsAndTakesFreshOnesWhenTheyFail) {
  Eigen::Matrix3d d1, d2, d3;
  d1 << 4, 1, 0, 1, 3, 1, 0, 1, 2;        // diagonally dominant: the diagonal pivots serve
  d2 << 5, 1, 0.5, 1, 4, 1, 0.5, 1, 3;    // the same pivots still serve
  d3 << 0, 1, 2, 1, 0, 1, 2, 1, 0;        // a zero where the first pivot was: they cannot
  const Eigen::Vector3d b(1, 2, 3);
  RefactoringLu lu;
  ASSERT_TRUE(lu.Analyze(Full(d1)));
  Eigen::VectorXd x;
  for (const Eigen::Matrix3d* d : {&d1, &d2, &d3}) {
    ASSERT_TRUE(lu.Solve(Full(*d), b, x));
    const Eigen::Vector3d exact = d->partialPivLu().solve(b);
    EXPECT_LT((x - exact).norm(), 1e-14 * exact.norm());
  }
  EXPECT_EQ(lu.full_factorizations(), 2);  // the first, and d3's fresh pivots; d2 was refactored
}

TEST(RefactoringLu, ASingularMatrixIsNoAnswer) {
  Eigen::Matrix3d d;
  d << 1, 2, 3, 2, 4, 6, 1, 1, 1;  // rows 1 and 2 dependent
  RefactoringLu lu;
  ASSERT_TRUE(lu.Analyze(Full(d)));
  Eigen::VectorXd x;
  EXPECT_FALSE(lu.Solve(Full(d), Eigen::Vector3d(1, 2, 3), x));
}

// The complex one (KLU's klu_z_ functions; the complex-time reference's index-1 matrix) alike.
TEST(RefactoringLu, ComplexValuesRefactorAndTakeFreshPivotsAlike) {
  using C = std::complex<double>;
  Eigen::Matrix3cd d1, d2, d3;
  d1 << C(4, 1), 1, 0, 1, C(3, -0.5), C(1, 1), 0, C(1, -1), 2;
  d2 << C(5, 0.2), 1, C(0.5, 0.1), 1, 4, 1, C(0.5, -0.1), 1, C(3, 2);
  d3 << 0, 1, C(2, 1), 1, 0, 1, C(2, -1), 1, 0;  // a zero where the first pivot was
  const Eigen::Vector3cd b(C(1, 1), 2, C(0, 3));
  ComplexRefactoringLu lu;
  ASSERT_TRUE(lu.Analyze(Full(d1)));
  Eigen::VectorXcd x;
  for (const Eigen::Matrix3cd* d : {&d1, &d2, &d3}) {
    ASSERT_TRUE(lu.Solve(Full(*d), b, x));
    const Eigen::Vector3cd exact = d->partialPivLu().solve(b);
    EXPECT_LT((x - exact).norm(), 1e-14 * exact.norm());
  }
  EXPECT_EQ(lu.full_factorizations(), 2);
}

}  // namespace
}  // namespace numeric_refactoring_lu_test
}  // namespace mechbench::numeric
