// A sparse LU for a square matrix whose pattern is fixed and whose values change at every solve
// (the index-1 matrix [M Φ_qᵀ; Φ_q 0] at each stage of a run): SuiteSparse's KLU, ordered once
// (AMD on the block-triangular form), factored in full once, then refactored with the same pivot
// sequence — no search for pivots or for the factors' pattern, which is most of a general sparse
// LU's cost on these small systems (Eigen's SparseLU redoes its supernodal search at every
// factorization). A refactored solve whose residual is not at round-off is done again with a full
// factorization (fresh pivots), so the answer is as good as a general LU's.
#pragma once

#include <Eigen/SparseCore>

#include <complex>
#include <memory>

namespace mechbench::numeric {

// Real (double) or complex (std::complex<double>: KLU's klu_z_ functions, e.g. the complex-time
// reference's index-1 matrix) values; instantiated for those two.
template <typename Scalar>
class RefactoringLuOf {
 public:
  using Matrix = Eigen::SparseMatrix<Scalar>;
  using Vector = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>;
  RefactoringLuOf();
  ~RefactoringLuOf();
  RefactoringLuOf(const RefactoringLuOf&) = delete;
  RefactoringLuOf& operator=(const RefactoringLuOf&) = delete;

  // The ordering, from A's pattern (compressed, column-major); forgets any factorization.
  bool Analyze(const Matrix& A);
  // Solves A x = b (A with the analyzed pattern, new values). False when A is singular to KLU.
  bool Solve(const Matrix& A, const Vector& b, Vector& x);
  // How many solves needed fresh pivots (the first one included).
  long full_factorizations() const { return full_; }

 private:
  bool FactorFully(const Matrix& A);
  struct Klu;
  std::unique_ptr<Klu> klu_;
  long full_ = 0;
  Vector res_;
};

using RefactoringLu = RefactoringLuOf<double>;
using ComplexRefactoringLu = RefactoringLuOf<std::complex<double>>;

}  // namespace mechbench::numeric
