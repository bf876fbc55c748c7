// A sparse LU for a square matrix whose pattern is fixed and whose values change at every solve
// (the index-1 matrix [M Φ_qᵀ; Φ_q 0] at each stage of a run): SuiteSparse's KLU, ordered once
// (AMD on the block-triangular form), factored in full once, then refactored with the same pivot
// sequence — no search for pivots or for the factors' pattern, which is most of a general sparse
// LU's cost on these small systems (Eigen's SparseLU redoes its supernodal search at every
// factorization). A refactored solve whose residual is not at round-off is done again with a full
// factorization (fresh pivots), so the answer is as good as a general LU's.
#pragma once

#include <Eigen/SparseCore>

#include <memory>

namespace mechbench::numeric {

class RefactoringLu {
 public:
  RefactoringLu();
  ~RefactoringLu();
  RefactoringLu(const RefactoringLu&) = delete;
  RefactoringLu& operator=(const RefactoringLu&) = delete;

  // The ordering, from A's pattern (compressed, column-major); forgets any factorization.
  bool Analyze(const Eigen::SparseMatrix<double>& A);
  // Solves A x = b (A with the analyzed pattern, new values). False when A is singular to KLU.
  bool Solve(const Eigen::SparseMatrix<double>& A, const Eigen::VectorXd& b, Eigen::VectorXd& x);
  // How many solves needed fresh pivots (the first one included).
  long full_factorizations() const { return full_; }

 private:
  bool FactorFully(const Eigen::SparseMatrix<double>& A);
  struct Klu;
  std::unique_ptr<Klu> klu_;
  long full_ = 0;
  Eigen::VectorXd res_;
};

}  // namespace mechbench::numeric
