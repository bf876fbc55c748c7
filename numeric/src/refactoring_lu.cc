#include "mechbench/numeric/refactoring_lu.h"

#include <klu.h>

#include <cmath>

namespace mechbench::numeric {

struct RefactoringLu::Klu {
  klu_common common;
  klu_symbolic* symbolic = nullptr;
  klu_numeric* numeric = nullptr;
  Klu() { klu_defaults(&common); }
  ~Klu() {
    if (numeric) klu_free_numeric(&numeric, &common);
    if (symbolic) klu_free_symbolic(&symbolic, &common);
  }
};

RefactoringLu::RefactoringLu() : klu_(std::make_unique<Klu>()) {}
RefactoringLu::~RefactoringLu() = default;

namespace {
// KLU takes non-const pointers to the pattern and values it only reads.
int* Outer(const Eigen::SparseMatrix<double>& A) { return const_cast<int*>(A.outerIndexPtr()); }
int* Inner(const Eigen::SparseMatrix<double>& A) { return const_cast<int*>(A.innerIndexPtr()); }
double* Values(const Eigen::SparseMatrix<double>& A) { return const_cast<double*>(A.valuePtr()); }
}  // namespace

bool RefactoringLu::Analyze(const Eigen::SparseMatrix<double>& A) {
  Klu& k = *klu_;
  if (k.numeric) klu_free_numeric(&k.numeric, &k.common);
  if (k.symbolic) klu_free_symbolic(&k.symbolic, &k.common);
  if (!A.isCompressed() || A.rows() != A.cols()) return false;
  k.symbolic = klu_analyze(static_cast<int>(A.rows()), Outer(A), Inner(A), &k.common);
  return k.symbolic != nullptr;
}

bool RefactoringLu::FactorFully(const Eigen::SparseMatrix<double>& A) {
  Klu& k = *klu_;
  if (k.numeric) klu_free_numeric(&k.numeric, &k.common);
  ++full_;
  k.numeric = klu_factor(Outer(A), Inner(A), Values(A), k.symbolic, &k.common);
  return k.numeric != nullptr && k.common.status == KLU_OK;
}

bool RefactoringLu::Solve(const Eigen::SparseMatrix<double>& A, const Eigen::VectorXd& b, Eigen::VectorXd& x) {
  Klu& k = *klu_;
  if (!k.symbolic) return false;
  const int n = static_cast<int>(A.rows());
  const auto solve = [&] {
    x = b;
    return klu_solve(k.symbolic, k.numeric, n, 1, x.data(), &k.common) == 1 && x.allFinite();
  };
  bool fresh = false;
  if (!k.numeric || klu_refactor(Outer(A), Inner(A), Values(A), k.symbolic, k.numeric, &k.common) != 1 ||
      k.common.status != KLU_OK) {
    if (!FactorFully(A)) return false;
    fresh = true;
  }
  if (!solve() && fresh) return false;
  if (fresh) return true;
  // The old pivots on new values: accepted when the residual is at round-off, else fresh pivots.
  res_.noalias() = A * x;
  res_ -= b;
  const double big = Eigen::Map<const Eigen::VectorXd>(A.valuePtr(), A.nonZeros()).cwiseAbs().maxCoeff();
  if (x.allFinite() && res_.norm() <= 1e-13 * (big * x.norm() + b.norm())) return true;
  return FactorFully(A) && solve();
}

}  // namespace mechbench::numeric
