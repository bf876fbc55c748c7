#include "mechbench/numeric/refactoring_lu.h"

#include <klu.h>

#include <cmath>

namespace mechbench::numeric {
namespace {

// KLU's real (klu_) and complex (klu_z_) functions by value type; KLU takes non-const pointers to
// the pattern and values it only reads, complex values as interleaved (re, im) pairs, which is
// std::complex<double>'s layout.
template <typename Scalar>
struct KluOps;
template <>
struct KluOps<double> {
  static double* Values(const Eigen::SparseMatrix<double>& A) { return const_cast<double*>(A.valuePtr()); }
  static double* Data(Eigen::VectorXd& x) { return x.data(); }
  static klu_numeric* Factor(int* p, int* i, double* x, klu_symbolic* s, klu_common* c) { return klu_factor(p, i, x, s, c); }
  static int Refactor(int* p, int* i, double* x, klu_symbolic* s, klu_numeric* n, klu_common* c) {
    return klu_refactor(p, i, x, s, n, c);
  }
  static int Solve(klu_symbolic* s, klu_numeric* n, int dim, double* b, klu_common* c) { return klu_solve(s, n, dim, 1, b, c); }
  static void Free(klu_numeric** n, klu_common* c) { klu_free_numeric(n, c); }
};
template <>
struct KluOps<std::complex<double>> {
  using C = std::complex<double>;
  static double* Values(const Eigen::SparseMatrix<C>& A) { return reinterpret_cast<double*>(const_cast<C*>(A.valuePtr())); }
  static double* Data(Eigen::VectorXcd& x) { return reinterpret_cast<double*>(x.data()); }
  static klu_numeric* Factor(int* p, int* i, double* x, klu_symbolic* s, klu_common* c) { return klu_z_factor(p, i, x, s, c); }
  static int Refactor(int* p, int* i, double* x, klu_symbolic* s, klu_numeric* n, klu_common* c) {
    return klu_z_refactor(p, i, x, s, n, c);
  }
  static int Solve(klu_symbolic* s, klu_numeric* n, int dim, double* b, klu_common* c) { return klu_z_solve(s, n, dim, 1, b, c); }
  static void Free(klu_numeric** n, klu_common* c) { klu_z_free_numeric(n, c); }
};

template <typename Scalar>
int* Outer(const Eigen::SparseMatrix<Scalar>& A) { return const_cast<int*>(A.outerIndexPtr()); }
template <typename Scalar>
int* Inner(const Eigen::SparseMatrix<Scalar>& A) { return const_cast<int*>(A.innerIndexPtr()); }

}  // namespace

template <typename Scalar>
struct RefactoringLuOf<Scalar>::Klu {
  klu_common common;
  klu_symbolic* symbolic = nullptr;
  klu_numeric* numeric = nullptr;
  Klu() { klu_defaults(&common); }
  ~Klu() {
    if (numeric) KluOps<Scalar>::Free(&numeric, &common);
    if (symbolic) klu_free_symbolic(&symbolic, &common);
  }
};

template <typename Scalar>
RefactoringLuOf<Scalar>::RefactoringLuOf() : klu_(std::make_unique<Klu>()) {}
template <typename Scalar>
RefactoringLuOf<Scalar>::~RefactoringLuOf() = default;

template <typename Scalar>
bool RefactoringLuOf<Scalar>::Analyze(const Matrix& A) {
  Klu& k = *klu_;
  if (k.numeric) KluOps<Scalar>::Free(&k.numeric, &k.common);
  if (k.symbolic) klu_free_symbolic(&k.symbolic, &k.common);
  if (!A.isCompressed() || A.rows() != A.cols()) return false;
  k.symbolic = klu_analyze(static_cast<int>(A.rows()), Outer(A), Inner(A), &k.common);
  return k.symbolic != nullptr;
}

template <typename Scalar>
bool RefactoringLuOf<Scalar>::FactorFully(const Matrix& A) {
  Klu& k = *klu_;
  if (k.numeric) KluOps<Scalar>::Free(&k.numeric, &k.common);
  ++full_;
  k.numeric = KluOps<Scalar>::Factor(Outer(A), Inner(A), KluOps<Scalar>::Values(A), k.symbolic, &k.common);
  return k.numeric != nullptr && k.common.status == KLU_OK;
}

template <typename Scalar>
bool RefactoringLuOf<Scalar>::Solve(const Matrix& A, const Vector& b, Vector& x) {
  Klu& k = *klu_;
  if (!k.symbolic) return false;
  const int n = static_cast<int>(A.rows());
  const auto solve = [&] {
    x = b;
    return KluOps<Scalar>::Solve(k.symbolic, k.numeric, n, KluOps<Scalar>::Data(x), &k.common) == 1 && x.allFinite();
  };
  bool fresh = false;
  if (!k.numeric ||
      KluOps<Scalar>::Refactor(Outer(A), Inner(A), KluOps<Scalar>::Values(A), k.symbolic, k.numeric, &k.common) != 1 ||
      k.common.status != KLU_OK) {
    if (!FactorFully(A)) return false;
    fresh = true;
  }
  if (!solve() && fresh) return false;
  if (fresh) return true;
  // The old pivots on new values: accepted when the residual is at round-off, else fresh pivots.
  res_.noalias() = A * x;
  res_ -= b;
  const double big = Eigen::Map<const Vector>(A.valuePtr(), A.nonZeros()).cwiseAbs().maxCoeff();
  if (x.allFinite() && res_.norm() <= 1e-13 * (big * x.norm() + b.norm())) return true;
  return FactorFully(A) && solve();
}

template class RefactoringLuOf<double>;
template class RefactoringLuOf<std::complex<double>>;

}  // namespace mechbench::numeric
