#include "mechbench/numeric/solver.h"

#include "mechbench/errors.h"
#include "mechbench/format.h"
#include "mechbench/numeric/constraints.h"
#include "mechbench/numeric/forward_dynamics.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <type_traits>
#include <utility>

namespace mechbench::numeric {
namespace {

std::string Num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

std::string Plural(int k, const char* one, const char* many) {
  return std::to_string(k) + " " + (k == 1 ? one : many);
}

// Typical size of each augmented row: the constraint rows' scales, then the driven slots' scales.
void AugmentedScales(const NaturalModel& model, bool with_drivers, Eigen::VectorXd& s) {
  s.resize(model.m() + (with_drivers ? model.f() : 0));
  for (int i = 0; i < model.m(); ++i) s[i] = model.rows[i].scale;
  if (with_drivers)
    for (int k = 0; k < model.f(); ++k) s[model.m() + k] = model.q_scale[model.drivers[k].slot];
}

// [Φ_q; B] with B the driver rows (a 1 in each driven slot's column).
void FillAugmented(const NaturalModel& model, const NaturalData& data, bool with_drivers, Eigen::MatrixXd& A) {
  const int m = model.m(), f = with_drivers ? model.f() : 0;
  A.setZero(m + f, model.n);
  A.topRows(m) = data.Phi_q;
  for (int k = 0; k < f; ++k) A(m + k, model.drivers[k].slot) = 1.0;
}

// The same rows weighted, w_i [Φ_q; B]_ij → As, in one pass.
void FillWeighted(const NaturalModel& model, const NaturalData& data, bool with_drivers, const Eigen::VectorXd& w,
                  Eigen::MatrixXd& As) {
  const int m = model.m(), f = with_drivers ? model.f() : 0, n = model.n, rows = m + f;
  if (As.rows() != rows || As.cols() != n) As.resize(rows, n);
  const double* J = data.Phi_q.data();
  const double* wm = w.data();
  double* out = As.data();
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < m; ++i) out[j * rows + i] = J[j * m + i] * wm[i];
  for (int k = 0; k < f; ++k) {
    const int slot = model.drivers[k].slot;
    for (int j = 0; j < n; ++j) out[j * rows + m + k] = j == slot ? wm[m + k] : 0.0;
  }
}

bool SameQ(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return a.size() == b.size() && (a.array() == b.array()).all();
}

// Whether data.Phi_q holds Φ_q at data.q (every evaluation of Φ_q records where it was made).
bool JacobianCurrent(const NaturalData& data) {
  return data.kin.jacobian_valid && SameQ(data.kin.jacobian_q, data.q);
}

// Bound on n·κ of a square weighted matrix for the LU path (κ in the 1- or ∞-norm). κ₂ ≤ n·κ₁ and
// κ₂ ≤ n·κ_∞, and every diagonal entry of a column-pivoted QR's R lies between σ_min and σ_max, so
// below this bound the rank-revealing decomposition finds full rank with a margin of 100 over the
// loosest relative threshold it is given (kSingularTolerance): LU then solves the same nonsingular
// system, equal to round-off. Anything worse conditioned takes the decomposition as before.
constexpr double kLuConditionBound = 1e4;
// Larger systems keep the rank-revealing decomposition.
constexpr int kLuMaxSize = KinematicScratch::kMaxLuSize;

// The dense kernels of the LU path on column-major n × n arrays. The size is a template argument
// when it is small (N > 0, loops the compiler unrolls: kinematic systems are a handful of
// coordinates) and read at run time otherwise (N = 0); the arithmetic is the same either way.

// In-place LU with partial pivoting (LAPACK's getf2): false when a pivot is zero. Every loop runs
// between its natural bounds (no test inside: loops over whole columns with `if (i > k)` are not
// unrolled at -O2, and with their mispredicted branches this factorization and its solves were
// 40 % of the §4.5 kinematic sample's profile), and asks to be unrolled, so that for a fixed N the kernel is straight-line code. The arithmetic and
// its order are those of the loops over whole columns, so the factors are the same to the bit.
#define MB_UNROLL _Pragma("GCC unroll 8")
template <int N>
bool LuKernel(double* a, int n_rt, int* piv) {
  const int n = N > 0 ? N : n_rt;
  MB_UNROLL for (int k = 0; k < n; ++k) {
    double* ck = a + k * n;
    int p = k;
    double big = std::fabs(ck[k]);
    MB_UNROLL for (int i = k + 1; i < n; ++i) {
      const double v = std::fabs(ck[i]);
      if (v > big) big = v, p = i;
    }
    piv[k] = p;
    if (!(big > 0)) return false;  // a zero (or NaN) column
    if (p != k)
      MB_UNROLL for (int j = 0; j < n; ++j) std::swap(a[j * n + k], a[j * n + p]);
    const double inv_pivot = 1.0 / ck[k];
    MB_UNROLL for (int i = k + 1; i < n; ++i) ck[i] *= inv_pivot;
    MB_UNROLL for (int j = k + 1; j < n; ++j) {
      double* cj = a + j * n;
      const double u = cj[k];
      MB_UNROLL for (int i = k + 1; i < n; ++i) cj[i] -= ck[i] * u;
    }
  }
  return true;
}

// x ← A⁻¹ x with the factors of LuKernel.
template <int N>
void LuSolveKernel(const double* a, int n_rt, const int* piv, double* x) {
  const int n = N > 0 ? N : n_rt;
  MB_UNROLL for (int k = 0; k < n; ++k)
    if (piv[k] != k) std::swap(x[k], x[piv[k]]);
  MB_UNROLL for (int k = 0; k < n; ++k) {
    const double* ck = a + k * n;
    const double xk = x[k];
    MB_UNROLL for (int i = k + 1; i < n; ++i) x[i] -= ck[i] * xk;
  }
  MB_UNROLL for (int k = n - 1; k >= 0; --k) {
    const double* ck = a + k * n;
    x[k] /= ck[k];
    const double xk = x[k];
    MB_UNROLL for (int i = 0; i < k; ++i) x[i] -= ck[i] * xk;
  }
}

// An upper bound on κ_∞(A) = ‖A‖_∞‖A⁻¹‖_∞ in O(n²), from A (`a`) and its factors (`lu`): A⁻¹ =
// U⁻¹L⁻¹P, and a triangular T has ‖T⁻¹‖_∞ ≤ ‖M(T)⁻¹e‖_∞ with M(T) its comparison matrix (|t_ii|
// on the diagonal, −|t_ij| off it), whose inverse is nonnegative (Higham, Accuracy and Stability
// of Numerical Algorithms, §8.2). y: scratch [n].
template <int N>
double ConditionBoundKernel(const double* a, const double* lu, int n_rt, double* y) {
  const int n = N > 0 ? N : n_rt;
  double norm_a = 0, l = 0, u = 0;
  MB_UNROLL for (int i = 0; i < n; ++i) {
    double r = 0;
    MB_UNROLL for (int j = 0; j < n; ++j) r += std::fabs(a[j * n + i]);
    norm_a = std::max(norm_a, r);
  }
  MB_UNROLL for (int i = 0; i < n; ++i) {  // M(L) y = e, L unit lower
    double yi = 1.0;
    MB_UNROLL for (int j = 0; j < i; ++j) yi += std::fabs(lu[j * n + i]) * y[j];
    y[i] = yi;
    l = std::max(l, yi);
  }
  MB_UNROLL for (int i = n - 1; i >= 0; --i) {  // M(U) y = e
    double yi = 1.0;
    MB_UNROLL for (int j = i + 1; j < n; ++j) yi += std::fabs(lu[j * n + i]) * y[j];
    y[i] = yi / std::fabs(lu[i * n + i]);
    u = std::max(u, y[i]);
  }
  return norm_a * l * u;
}

// κ₁(A) = ‖A‖₁‖A⁻¹‖₁ exactly, column by column of the inverse (O(n³)). y: scratch [n].
template <int N>
double ConditionExactKernel(const double* a, const double* lu, int n_rt, const int* piv, double* y) {
  const int n = N > 0 ? N : n_rt;
  double norm_a = 0, norm_inv = 0;
  for (int j = 0; j < n; ++j) {
    double c = 0, ci = 0;
    for (int i = 0; i < n; ++i) c += std::fabs(a[j * n + i]), y[i] = i == j ? 1.0 : 0.0;
    LuSolveKernel<N>(lu, n, piv, y);
    for (int i = 0; i < n; ++i) ci += std::fabs(y[i]);
    norm_a = std::max(norm_a, c);
    norm_inv = std::max(norm_inv, ci);
  }
  return norm_a * norm_inv;
}

// f(std::integral_constant<int, N>) with N = n for the small sizes, 0 (run-time size) otherwise.
template <class F>
decltype(auto) WithSize(int n, F&& f) {
  switch (n) {
    case 1: return f(std::integral_constant<int, 1>{});
    case 2: return f(std::integral_constant<int, 2>{});
    case 3: return f(std::integral_constant<int, 3>{});
    case 4: return f(std::integral_constant<int, 4>{});
    case 5: return f(std::integral_constant<int, 5>{});
    case 6: return f(std::integral_constant<int, 6>{});
    case 7: return f(std::integral_constant<int, 7>{});
    case 8: return f(std::integral_constant<int, 8>{});
    default: return f(std::integral_constant<int, 0>{});
  }
}

#undef MB_UNROLL

// Factors the row-weighted matrix s.As: LU with partial pivoting when it is square, small and
// well conditioned, otherwise the complete orthogonal decomposition with the relative threshold
// `threshold` (≤ 0: Eigen's default, as a least-squares solve). Returns the numerical rank.
// "Well conditioned" is n·κ ≤ kLuConditionBound, κ first bounded above in O(n²) (∞-norm) and,
// when that bound is too loose, computed exactly (1-norm).
int Factor(KinematicScratch& s, double threshold) {
  const int rows = static_cast<int>(s.As.rows()), n = static_cast<int>(s.As.cols());
  if (rows == n && n > 0 && n <= kLuMaxSize) {
    if (s.lu.rows() != n || s.lu.cols() != n) s.lu.resize(n, n);
    if (s.piv.size() != n) s.piv.resize(n);
    if (s.col.size() != n) s.col.resize(n);
    std::copy_n(s.As.data(), n * n, s.lu.data());
    const double limit = kLuConditionBound / n;
    const bool ok = WithSize(n, [&](auto size) {
      constexpr int N = decltype(size)::value;
      if (!LuKernel<N>(s.lu.data(), n, s.piv.data())) return false;
      if (ConditionBoundKernel<N>(s.As.data(), s.lu.data(), n, s.col.data()) <= limit) return true;
      return ConditionExactKernel<N>(s.As.data(), s.lu.data(), n, s.piv.data(), s.col.data()) <= limit;  // false for NaN
    });
    if (ok) {
      s.use_lu = true;
      return n;
    }
  }
  s.use_lu = false;
  if (threshold > 0)
    s.cod.setThreshold(threshold);
  else
    s.cod.setThreshold(Eigen::Default);
  s.cod.compute(s.As);
  return static_cast<int>(s.cod.rank());
}

// The factored system with the weighted right-hand side s.wb → s.step.
void SolveFactored(KinematicScratch& s) {
  if (s.use_lu) {
    s.step = s.wb;
    const int n = static_cast<int>(s.lu.rows());
    WithSize(n, [&](auto size) { LuSolveKernel<decltype(size)::value>(s.lu.data(), n, s.piv.data(), s.step.data()); });
  } else {
    s.step = s.cod.solve(s.wb);
  }
}

// ---- the sparse path (NaturalData::sparse) ------------------------------------------------------
//
// Every matrix is the weighted augmented matrix transposed, At = (W [Φ_q; B])ᵀ [n × (m + f)]: a QR
// of At without column ordering takes the rows in their order, so that a row whose distance from
// the span of the rows before it is below the threshold is the dependent one (greedy in row order,
// as the dense rank analysis), and the consistent system's minimum-norm solution is
// x = Q [R₁₁⁻ᵀ (Pᵀ b)₁; 0]. Square systems in Newton's iteration take a sparse LU (COLAMD) first.

// A zero-free diagonal for At's pattern [rows × cols]: perm[r] = the new position of row r, each
// column's matched row at the column's own index (greedy in column order, then augmenting paths
// for a column whose rows are all taken), unmatched rows after. Eigen's left-looking QR pivots
// column k on row k, so without it every column fills in from unrelated rows: O(N²) entries of R
// on the N-four-bar (4 s at N = 1000) against O(N) with it (0.12 s at N = 10,000).
std::vector<int> ZeroFreeDiagonal(const Eigen::SparseMatrix<double>& At) {
  const int rows = static_cast<int>(At.rows()), cols = static_cast<int>(At.cols());
  const int* outer = At.outerIndexPtr();
  const int* inner = At.innerIndexPtr();
  std::vector<int> row_of(rows, -1), match(cols, -1), seen(rows, -1);
  struct Frame {
    int col, pos, via;  // the column explored, its next entry, the row that led to it
  };
  std::vector<Frame> stack;
  for (int c = 0; c < cols; ++c) {
    for (int e = outer[c]; e < outer[c + 1] && match[c] < 0; ++e)
      if (row_of[inner[e]] < 0) row_of[inner[e]] = c, match[c] = inner[e];
    if (match[c] >= 0) continue;
    // Iterative depth-first search for an augmenting path (chains make it N long).
    stack.assign(1, {c, outer[c], -1});
    while (!stack.empty()) {
      Frame& f = stack.back();
      if (f.pos == outer[f.col + 1]) {
        stack.pop_back();
        continue;
      }
      const int r = inner[f.pos++];
      if (seen[r] == c) continue;
      seen[r] = c;
      if (row_of[r] >= 0) {
        stack.push_back({row_of[r], outer[row_of[r]], r});
        continue;
      }
      // Free row: flip the path, each column on the stack taking the row below it.
      int row = r;
      for (size_t k = stack.size(); k-- > 0;) {
        const int col = stack[k].col, next = stack[k].via;
        match[col] = row, row_of[row] = col;
        row = next;
      }
      break;
    }
  }
  std::vector<int> perm(rows, -1);
  int at = 0;
  for (int c = 0; c < cols; ++c)
    if (match[c] >= 0) perm[match[c]] = at++;
  for (int r = 0; r < rows; ++r)
    if (perm[r] < 0) perm[r] = at++;
  return perm;
}

// W [Φ_q; B] transposed, from data.jac.J() at data.q, into s.At: one column per row of the
// augmented matrix, in their order; its rows are the coordinates that some row touches (SparseQR
// needs no empty row), in ZeroFreeDiagonal's order (computed once per pattern); s.used[j] is the
// row of At of coordinate j, or −1.
void FillWeightedTransposed(const NaturalModel& model, const NaturalData& data, bool with_drivers,
                            const Eigen::VectorXd& w, KinematicScratch& s) {
  const SparseJacobian::Matrix& J = data.jac.J();
  const int m = model.m(), f = with_drivers ? model.f() : 0, n = model.n;
  const auto fill = [&](const std::vector<int>& row) {
    std::vector<Eigen::Triplet<double>> t;
    t.reserve(static_cast<size_t>(J.nonZeros() + f));
    for (int i = 0; i < m; ++i)
      for (SparseJacobian::Matrix::InnerIterator it(J, i); it; ++it) t.emplace_back(row[it.col()], i, it.value() * w[i]);
    for (int k = 0; k < f; ++k) t.emplace_back(row[model.drivers[k].slot], m + k, w[m + k]);
    s.At.setZero();
    s.At.setFromTriplets(t.begin(), t.end());
    s.At.makeCompressed();
  };
  if (s.used_cols != m + f || static_cast<int>(s.used.size()) != n) {
    std::vector<int> compact(n, -1);
    for (Eigen::Index e = 0; e < J.nonZeros(); ++e) compact[J.innerIndexPtr()[e]] = 0;
    for (int k = 0; k < f; ++k) compact[model.drivers[k].slot] = 0;
    int rows = 0;
    for (int j = 0; j < n; ++j)
      if (compact[j] >= 0) compact[j] = rows++;
    s.At.resize(rows, m + f);
    fill(compact);
    const std::vector<int> perm = ZeroFreeDiagonal(s.At);
    s.used.assign(n, -1);
    for (int j = 0; j < n; ++j)
      if (compact[j] >= 0) s.used[j] = perm[compact[j]];
    s.used_cols = m + f;
  }
  fill(s.used);
}

// The largest singular value of At, by power iteration (a few per cent is enough for a relative
// threshold; O(nnz) per iteration).
double LargestSingularValue(const Eigen::SparseMatrix<double>& At) {
  if (At.nonZeros() == 0) return 0.0;
  Eigen::VectorXd v = Eigen::VectorXd::Ones(At.cols()), u;
  double sigma = 0;
  for (int it = 0; it < 30; ++it) {
    v.normalize();
    u = At * v;
    v = At.transpose() * u;
    const double next = std::sqrt(v.norm());
    if (std::fabs(next - sigma) <= 1e-3 * next) return next;
    sigma = next;
  }
  return sigma;
}

// QR of s.At with the absolute threshold `threshold` on |R_kk| (≤ 0: Eigen's default, as a
// least-squares solve). Returns the numerical rank; s.Rt holds R₁₁ᵀ for the solves.
int FactorSparseQr(KinematicScratch& s, double threshold) {
  s.use_lu_sparse = false;
  if (s.At.cols() == 0) return 0;
  if (!(threshold > 0)) {
    // Eigen's (and SuiteSparseQR's) default: 20 (rows + cols) ε × the largest column norm.
    double largest = 0;
    for (Eigen::Index j = 0; j < s.At.cols(); ++j) largest = std::max(largest, s.At.col(j).norm());
    threshold = 20.0 * static_cast<double>(s.At.rows() + s.At.cols()) * (largest > 0 ? largest : 1.0) *
                std::numeric_limits<double>::epsilon();
  }
  s.qr.setPivotThreshold(threshold);
  s.qr.compute(s.At);
  MB_ASSERT(s.qr.info() == Eigen::Success, "sparse QR of the augmented matrix failed");
  const int r = static_cast<int>(s.qr.rank());
  // R₁₁ᵀ through triplets: SparseQR leaves R's columns unsorted, which a block copy rejects.
  std::vector<Eigen::Triplet<double>> t;
  const Eigen::SparseMatrix<double>& R = s.qr.matrixR();
  for (int j = 0; j < std::min<int>(r, static_cast<int>(R.outerSize())); ++j)
    for (Eigen::SparseMatrix<double>::InnerIterator it(R, j); it; ++it)
      if (it.row() < r) t.emplace_back(j, static_cast<int>(it.row()), it.value());
  s.Rt.resize(r, r);
  s.Rt.setFromTriplets(t.begin(), t.end());
  return r;
}

// The minimum-norm solution of the factored rows' consistent part with the right-hand side s.wb
// → s.step [n] (coordinates that no row touches: 0).
void SolveSparse(KinematicScratch& s, int n) {
  s.step.setZero(n);
  if (s.At.cols() == 0) return;
  Eigen::VectorXd x;  // in At's row order
  if (s.use_lu_sparse) {
    x = s.lu_sparse.solve(s.wb);
  } else {
    const int r = static_cast<int>(s.qr.rank());
    const Eigen::VectorXd pb = s.qr.colsPermutation().transpose() * s.wb;
    Eigen::VectorXd y = Eigen::VectorXd::Zero(s.At.rows());
    y.head(r) = s.Rt.triangularView<Eigen::Lower>().solve(pb.head(r));
    x = s.qr.matrixQ() * y;
  }
  for (int j = 0; j < n; ++j)
    if (s.used[j] >= 0) s.step[j] = x[s.used[j]];
}

// The row-normalized [Φ_q; B] at data.q (rows scaled to unit length, so that rows in different
// units weigh alike; zero rows stay zero) factored in data.kin, with threshold kSingularTolerance
// so that a singular position is seen rather than answered by least squares. The velocity and
// acceleration problems at one position share it. Returns the numerical rank.
int FactorNormalized(const NaturalModel& model, NaturalData& data) {
  KinematicScratch& s = data.kin;
  if (s.factored_valid && SameQ(s.factored_q, data.q) && JacobianCurrent(data)) return s.factored_rank;
  if (data.sparse) {
    if (!JacobianCurrent(data)) EvalJacobian(model, data, data.q);
    const SparseJacobian::Matrix& J = data.jac.J();
    s.w.resize(model.m() + model.f());
    for (int i = 0; i < model.m(); ++i) {
      const double nrm = J.row(i).norm();
      s.w[i] = nrm > 0 ? 1.0 / nrm : 1.0;
    }
    for (int k = 0; k < model.f(); ++k) s.w[model.m() + k] = 1.0;
    FillWeightedTransposed(model, data, true, s.w, s);
    s.factored_rank = FactorSparseQr(s, kSingularTolerance * LargestSingularValue(s.At));
    s.factored_q = data.q;
    s.factored_valid = true;
    return s.factored_rank;
  }
  AssembleAugmented(model, data);
  const Eigen::MatrixXd& A = data.A;
  s.w.resize(A.rows());
  for (Eigen::Index i = 0; i < A.rows(); ++i) {
    const double nrm = A.row(i).norm();
    s.w[i] = nrm > 0 ? 1.0 / nrm : 1.0;
  }
  FillWeighted(model, data, true, s.w, s.As);
  s.factored_rank = Factor(s, kSingularTolerance);
  s.factored_q = data.q;
  s.factored_valid = true;
  return s.factored_rank;
}

double ScaledStep(const NaturalModel& model, const Eigen::VectorXd& dq) {
  return dq.cwiseAbs().cwiseQuotient(model.q_scale).maxCoeff();
}

// Numerical rank of A after normalizing its rows (zero rows stay zero and add nothing).
int RowNormalizedRank(const Eigen::MatrixXd& A, double tolerance) {
  if (A.rows() == 0 || A.cols() == 0) return 0;
  Eigen::MatrixXd B = A;
  for (Eigen::Index i = 0; i < B.rows(); ++i) {
    const double nrm = B.row(i).norm();
    if (nrm > 0) B.row(i) /= nrm;
  }
  const Eigen::VectorXd sv = Eigen::JacobiSVD<Eigen::MatrixXd>(B).singularValues();
  if (sv.size() == 0 || sv[0] == 0.0) return 0;
  int rank = 0;
  for (Eigen::Index i = 0; i < sv.size(); ++i)
    if (sv[i] > tolerance * sv[0]) ++rank;
  return rank;
}

// Row indices sorted by scaled residual |Φ_i| / scale_i, largest first.
std::vector<int> WorstRows(const NaturalModel& model, const NaturalData& data) {
  std::vector<int> idx(model.m());
  std::iota(idx.begin(), idx.end(), 0);
  std::sort(idx.begin(), idx.end(), [&](int a, int b) {
    return std::fabs(data.Phi[a]) / model.rows[a].scale > std::fabs(data.Phi[b]) / model.rows[b].scale;
  });
  return idx;
}

// "row 1 body coupler (f.yaml:9) Φ = 3.284, …" for the first `count` rows of `rows`.
std::string DescribeRows(const NaturalModel& model, const NaturalData& data, const std::vector<int>& rows, size_t count) {
  std::string s;
  for (size_t k = 0; k < std::min(count, rows.size()); ++k) {
    const int i = rows[k];
    if (k) s += ", ";
    s += "row " + std::to_string(i) + " " + model.rows[i].Where() + " Φ = " + Num(data.Phi[i]);
  }
  return s;
}

std::string DriverList(const NaturalModel& model) {
  std::string s;
  for (int k = 0; k < model.f(); ++k) {
    if (k) s += ", ";
    s += model.drivers[k].law.coordinate + " (" + model.drivers[k].law.src.Str() + ")";
  }
  return s.empty() ? "none" : s;
}

SourceRef FirstDriverOrFile(const NaturalModel& model) {
  if (model.f() > 0) return model.drivers[0].law.src;
  return {model.model.source_file, 0};
}

// An angle row whose own derivative with respect to θ vanishes at this θ: the usual reason a
// cos/sin/dot form loses rank (cos at 0 or π, sin at ±π/2; a cos+sin pair never does). Sets
// `where` to its coordinate; empty when none.
std::string SingularAngleHint(const NaturalModel& model, const NaturalData& data, SourceRef& where) {
  const auto has = [&](RowKind kind, int slot) {
    return std::any_of(model.rows.begin(), model.rows.end(),
                       [&](const ConstraintRow& r) { return r.kind == kind && r.slots[0] == slot; });
  };
  for (const ConstraintRow& row : model.rows) {
    if (row.slots[0] < 0) continue;
    const double th = data.q[row.slots[0]];
    bool bad = false;
    if (row.kind == RowKind::kAngleDot) bad = std::fabs(std::sin(th)) < 1e-5;
    if (row.kind == RowKind::kAngleCos && !has(RowKind::kAngleSin, row.slots[0])) bad = std::fabs(std::sin(th)) < 1e-5;
    if (row.kind == RowKind::kAngleSin && !has(RowKind::kAngleCos, row.slots[0])) bad = std::fabs(std::cos(th)) < 1e-5;
    if (bad) {
      where = row.src;
      return row.Where() + " is at θ = " + Num(th) + " rad, where its form loses rank";
    }
  }
  return {};
}

// Two differently named points at the same place (to 1e-9 of the scene's size): a joint written
// with the wrong one leaves a body loose and shows only as extra degrees of freedom (newuser8 3a:
// a coupler ending at C2 beside the rocker's C). Empty when none.
std::string CoincidentPointsHint(const NaturalModel& model, const NaturalData& data) {
  std::vector<std::pair<std::string, Eigen::Vector3d>> points;
  const auto at = [&](int slot, double constant) { return slot >= 0 ? data.q[slot] : constant; };
  if (model.dim == 3) {
    for (const Entity3& e : model.entities)
      if (e.kind == EntityKind::kPoint)
        points.emplace_back(e.name, Eigen::Vector3d(at(e.slot[0], e.value.x()), at(e.slot[1], e.value.y()),
                                                    at(e.slot[2], e.value.z())));
  } else {
    for (size_t i = 0; i < model.point_slot.size() && i < model.model.points.size(); ++i)
      points.emplace_back(model.model.points[i].name,
                          Eigen::Vector3d(at(model.point_slot[i][0], model.point_const[i].x()),
                                          at(model.point_slot[i][1], model.point_const[i].y()), 0.0));
  }
  const double tol = 1e-9 * model.length_scale;
  for (size_t i = 0; i < points.size(); ++i)
    for (size_t j = i + 1; j < points.size(); ++j)
      if ((points[i].second - points[j].second).norm() <= tol)
        return "points " + points[i].first + " and " + points[j].first +
               " are at the same place but are two points (two bodies joined there share one point: list the same "
               "name in both)";
  return {};
}

[[noreturn]] void ThrowDofMismatch(const NaturalModel& model, const NaturalData& data, const RankReport& rk) {
  SourceRef where = FirstDriverOrFile(model);
  const std::string hint = SingularAngleHint(model, data, where);
  std::string problem = "n − rank Φ_q = " + std::to_string(rk.n) + " − " + std::to_string(rk.rank) + " = " +
                        Plural(rk.dof, "degree of freedom", "degrees of freedom") + " but " +
                        Plural(rk.f, "driver is", "drivers are") + " given (" + DriverList(model) + ")";
  std::string fix;
  if (!hint.empty()) {
    problem += "; " + hint;
    fix = "use form: cross (or cos+sin) for that angle, or start away from that position";
  } else if (const std::string same = rk.dof > rk.f ? CoincidentPointsHint(model, data) : std::string(); !same.empty()) {
    problem += "; " + same;
    fix = "if a joint meant one point, name it in both bodies (and remove the other point); else drive " +
          Plural(rk.dof, "coordinate", "coordinates");
  } else if (rk.dof > rk.f) {
    fix = "drive " + Plural(rk.dof, "coordinate", "coordinates") +
          ", or move the instant away from a singular (toggle/dead-centre) position where rank Φ_q drops";
  } else {
    fix = "remove " + Plural(rk.f - rk.dof, "driver", "drivers") + " (the mechanism has " +
          Plural(rk.dof, "degree of freedom", "degrees of freedom") + ")";
  }
  throw ScenarioError(where, problem, fix);
}

}  // namespace

void AssembleAugmented(const NaturalModel& model, NaturalData& data) {
  if (!JacobianCurrent(data)) EvalJacobian(model, data, data.q);  // else Φ_q (and r) are at data.q
  FillAugmented(model, data, true, data.A);
}

// Each Newton step is a least-squares solve of [Φ_q; B] Δq = −[Φ; q_B − f(t)] with rows weighted
// by 1/scale, so that rows in different units count alike when the system is inconsistent (off
// the constraint manifold); a consistent system has the same solution either way. Minimum-norm
// when rank deficient. Every vector and matrix is data.kin's scratch.
NewtonReport SolvePosition(const NaturalModel& model, NaturalData& data, const Eigen::VectorXd& q_start,
                           double t, const NewtonOptions& options, bool with_drivers) {
  MB_ASSERT(q_start.size() == model.n, "start q has the wrong size");
  NewtonReport rep;
  KinematicScratch& s = data.kin;
  s.factored_valid = false;  // s.As, s.w and the factorizations are overwritten below
  const int m = model.m(), f = with_drivers ? model.f() : 0;
  const double t0 = model.model.analysis.t0;
  AugmentedScales(model, with_drivers, s.scale);
  s.w = s.scale.cwiseInverse();
  s.b.resize(m + f);
  s.q = q_start;
  // Φ and Φ_q at s.q (Φ_q serves the next step, or the caller at the last iterate); returns the
  // scaled residual of the augmented rows and leaves −[Φ; q_B − f(t)] in s.b.
  // Simplified Newton (dense systems, options.simplified): the iteration matrix factored at one
  // iterate serves the next ones while each step shrinks the residual at least 4× (it converges
  // linearly at about the relative change of Φ_q between the iterates, a small fraction from a
  // good prediction); only Φ is evaluated for those steps. Otherwise Φ_q is evaluated and
  // factored again, a full Newton step.
  const bool simplified = options.simplified && !data.sparse;
  bool factored = false;  // s holds a factorization of the weighted [Φ_q; B] at some iterate
  const auto residual = [&](bool jacobian = true) {
    if (jacobian)
      EvalPhiJacobian(model, data, s.q, t);
    else
      EvalPhi(model, data, s.q, t);
    s.b.head(m) = -data.Phi;
    for (int k = 0; k < f; ++k) {
      const DriverRow& d = model.drivers[k];
      s.b[m + k] = -(s.q[d.slot] - d.law.At(t, t0));
    }
    return (m + f) ? s.b.cwiseAbs().cwiseQuotient(s.scale).maxCoeff() : 0.0;
  };
  double res = residual(), prev = res;
  bool lu_pattern = false;  // sparse: the LU's ordering, computed at the first step (the pattern is fixed)
  for (int k = 1; k <= options.max_iterations; ++k) {
    s.wb = s.w.cwiseProduct(s.b);
    if (data.sparse) {
      FillWeightedTransposed(model, data, with_drivers, s.w, s);
      // Square: the sparse LU, unless it finds the matrix singular; otherwise (or then) the QR.
      s.use_lu_sparse = false;
      if (m + f == model.n && s.At.rows() == model.n) {
        s.As_sparse = s.At.transpose();
        if (!lu_pattern) s.lu_sparse.analyzePattern(s.As_sparse), lu_pattern = true;
        s.lu_sparse.factorize(s.As_sparse);
        s.use_lu_sparse = s.lu_sparse.info() == Eigen::Success;
      }
      if (!s.use_lu_sparse) FactorSparseQr(s, /*threshold=*/0.0);
      SolveSparse(s, model.n);
    } else {
      if (!simplified || !factored) {
        FillWeighted(model, data, with_drivers, s.w, s.As);
        Factor(s, /*threshold=*/0.0);
        factored = true;
      }
      SolveFactored(s);
    }
    s.q += s.step;
    // Simplified: Φ_q too when the residual was already at its tolerance before this step, which
    // is then most likely the last one (the check that the step is negligible): the Jacobian the
    // caller needs at the last iterate comes with that pass instead of a pass of its own.
    res = residual(/*jacobian=*/!simplified || prev <= options.phi_tolerance);
    rep.iterations = k;
    if (options.record_iterates) rep.iterates.push_back(s.q);
    if (!s.q.allFinite() || !std::isfinite(res)) break;
    // Converged when Φ is at its tolerance and the step is negligible, or when Φ is at its
    // tolerance and no longer shrinks (round-off floor, slow steps near a singular position).
    if (res <= options.phi_tolerance && (ScaledStep(model, s.step) <= options.step_tolerance || res > 0.5 * prev)) {
      rep.converged = true;
      break;
    }
    // A simplified step that did not shrink the residual 4×: the next is a full Newton step.
    if (simplified && !(res <= 0.25 * prev)) {
      if (!JacobianCurrent(data)) residual(/*jacobian=*/true);
      factored = false;
    }
    prev = res;
  }
  // The contract: Φ_q at the last iterate too.
  if (simplified && !JacobianCurrent(data)) EvalJacobian(model, data, data.q);
  rep.scaled_residual = res;
  rep.residual = data.Phi.norm();
  return rep;
}

int SolveVelocity(const NaturalModel& model, NaturalData& data, double t) {
  KinematicScratch& s = data.kin;
  const int rank = FactorNormalized(model, data);
  EvalPhit(model, data, data.q, t);
  const int m = model.m(), f = model.f();
  const double t0 = model.model.analysis.t0;
  data.rhs.resize(m + f);
  data.rhs.head(m) = -data.Phi_t;
  for (int k = 0; k < f; ++k) data.rhs[m + k] = model.drivers[k].law.RateAt(t, t0);
  s.wb = s.w.cwiseProduct(data.rhs);
  if (data.sparse)
    SolveSparse(s, model.n);
  else
    SolveFactored(s);
  UpdatePointVelocities(model, data, s.step);
  return rank;
}

int SolveAcceleration(const NaturalModel& model, NaturalData& data, double t) {
  KinematicScratch& s = data.kin;
  const int rank = FactorNormalized(model, data);
  EvalPhidotQdotRows(model, data, data.q, data.qd);
  const int m = model.m(), f = model.f();
  data.rhs.resize(m + f);
  // Φ̇_t = 0: time enters only through the driver rows, whose f̈(t) is on the right.
  data.rhs.head(m) = -data.Phidot_q_qd;
  const double t0 = model.model.analysis.t0;
  for (int k = 0; k < f; ++k) data.rhs[m + k] = model.drivers[k].law.AccelerationAt(t, t0);
  s.wb = s.w.cwiseProduct(data.rhs);
  if (data.sparse)
    SolveSparse(s, model.n);
  else
    SolveFactored(s);
  UpdatePointAccelerations(model, data, s.step);
  return rank;
}

RankReport AnalyzeRank(const NaturalModel& model, NaturalData& data, double tolerance) {
  RankReport rk;
  rk.n = model.n;
  rk.m = model.m();
  rk.f = model.f();
  if (data.sparse) {
    // One QR of the row-normalized [Φ_q; B] transposed, rows in order: the rank of Φ_q is the
    // number of its rows independent of the rows before them (the driver rows come after), the
    // redundant rows are the others, and the augmented rank is the whole QR's.
    KinematicScratch& s = data.kin;
    s.factored_valid = false;  // s.At and s.qr are overwritten
    if (!JacobianCurrent(data)) EvalJacobian(model, data, data.q);
    const SparseJacobian::Matrix& J = data.jac.J();
    s.w.resize(rk.m + rk.f);
    for (int i = 0; i < rk.m; ++i) {
      const double nrm = J.row(i).norm();
      s.w[i] = nrm > 0 ? 1.0 / nrm : 1.0;
    }
    for (int k = 0; k < rk.f; ++k) s.w[rk.m + k] = 1.0;
    FillWeightedTransposed(model, data, true, s.w, s);
    rk.augmented_rank = FactorSparseQr(s, tolerance * LargestSingularValue(s.At));
    if (s.At.cols() > 0) {  // no rows at all (a scene of free point masses): nothing factored, none redundant
      const Eigen::VectorXi& order = s.qr.colsPermutation().indices();
      for (int k = rk.augmented_rank; k < order.size(); ++k)
        if (order[k] < rk.m) rk.redundant_rows.push_back(order[k]);
    }
    std::sort(rk.redundant_rows.begin(), rk.redundant_rows.end());
    rk.rank = rk.m - static_cast<int>(rk.redundant_rows.size());
    rk.dof = rk.n - rk.rank;
    return rk;
  }
  AssembleAugmented(model, data);
  rk.rank = RowNormalizedRank(data.Phi_q, tolerance);
  rk.dof = rk.n - rk.rank;
  rk.augmented_rank = RowNormalizedRank(data.A, tolerance);
  if (rk.rank < rk.m) {
    // Greedy in row order, so the later of two dependent rows is the redundant one (the book's
    // §4.4 calls the cos/sin pair redundant with the earlier distance row).
    int have = 0;
    for (int i = 0; i < rk.m; ++i) {
      const int now = RowNormalizedRank(data.Phi_q.topRows(i + 1), tolerance);
      if (now == have) rk.redundant_rows.push_back(i);
      have = now;
    }
  }
  return rk;
}

namespace {

[[noreturn]] void ThrowCannotAssemble(const NaturalModel& model, const NaturalData& data, const NewtonReport& nr) {
  const std::vector<int> worst = WorstRows(model, data);
  const ConstraintRow& culprit = model.rows[worst.front()];
  throw ScenarioError(culprit.src,
                      "cannot assemble: " + culprit.Where() + " cannot close the loop; ‖Φ‖ = " + Num(nr.residual) +
                          " after " + std::to_string(nr.iterations) +
                          " iterations (largest residuals: " + DescribeRows(model, data, worst, 3) + ")",
                      "check lengths and the initial guess");
}

// Slots that, with `given`, fix every one of the `dof` degrees of freedom at data.q: the null
// space of Φ_q (row-normalized) holds the motions the constraints allow; each step takes the slot
// that moves most in the part of it the slots chosen so far leave free (a coordinate stationary
// there would not fix the motion). Empty above a size where a dense decomposition is too slow
// for an error message.
std::vector<int> CompletingSlots(const NaturalModel& model, NaturalData& data, const std::vector<int>& given, int dof) {
  if (dof <= 0 || model.n > 1500) return {};
  Eigen::MatrixXd N;
  if (model.m() == 0) {
    N = Eigen::MatrixXd::Identity(model.n, model.n);
  } else {
    EvalJacobian(model, data, data.q);
    Eigen::MatrixXd J = data.sparse ? Eigen::MatrixXd(data.jac.J()) : data.Phi_q;
    for (Eigen::Index i = 0; i < J.rows(); ++i)
      if (const double nrm = J.row(i).norm(); nrm > 0) J.row(i) /= nrm;
    const Eigen::BDCSVD<Eigen::MatrixXd> svd(J, Eigen::ComputeFullV);
    N = svd.matrixV().rightCols(std::min<Eigen::Index>(dof, model.n));
  }
  std::vector<Eigen::VectorXd> basis;  // orthonormal, in the null space's coordinates
  const auto rest = [&](int slot) {
    Eigen::VectorXd r = N.row(slot).transpose();
    for (const Eigen::VectorXd& u : basis) r -= u.dot(r) * u;
    return r;
  };
  constexpr double kMoves = 1e-6;  // a slot moving less than this per unit motion is stationary
  for (int slot : given)
    if (const Eigen::VectorXd r = rest(slot); r.norm() > kMoves) basis.push_back(r.normalized());
  std::vector<int> out;
  while (static_cast<int>(basis.size()) < N.cols()) {
    int best = -1;
    double best_norm = kMoves;
    for (int slot = 0; slot < model.n; ++slot) {
      if (std::find(given.begin(), given.end(), slot) != given.end() || std::find(out.begin(), out.end(), slot) != out.end())
        continue;
      if (const double r = rest(slot).norm(); r > best_norm * (1 + 1e-9)) {
        best = slot;
        best_norm = r;
      }
    }
    if (best < 0) break;
    basis.push_back(rest(best).normalized());
    out.push_back(best);
  }
  return out;
}

// An angle's slot (a planar angle or rotation, a spatial angle about an axis) [rad].
bool SlotIsAngle(const Model& m, int slot) {
  const Model::Slot& s = m.q_layout[slot];
  if (s.coordinate >= 0)
    return m.coordinates[s.coordinate].type == CoordinateType::kAngle ||
           m.coordinates[s.coordinate].type == CoordinateType::kRotation;
  return s.spatial_coordinate >= 0 && m.spatial.coordinates[s.spatial_coordinate].IsAngle();
}

// "2.0944 (120 deg)" for an angle's value, "1.866" for a length.
std::string SlotValue(const Model& m, int slot, double v, int digits = 6) {
  // A solved 0 is a round-off away from it (8.35e-18): shown as the 0 it is.
  if (std::fabs(v) < 1e-12 * (SlotIsAngle(m, slot) ? 1.0 : m.LengthScale())) v = 0.0;
  return SlotIsAngle(m, slot) ? Fmt(v, digits) + " (" + Fmt(v * 180 / M_PI, digits) + " deg)" : Fmt(v, digits);
}

std::string InitialLine(const Driver& d) { return d.coordinate + " (line " + std::to_string(d.src.line) + ")"; }

// A free scene whose initial conditions cannot all be met: the first one the mechanism cannot
// reach on its own, or the set when each alone can be.
[[noreturn]] void ThrowUnreachableInitial(const NaturalModel& model, const Eigen::VectorXd& q_start, double t,
                                          const NewtonOptions& options, const NewtonReport& together, bool sparse) {
  const LinearAlgebra la = sparse ? LinearAlgebra::kSparse : LinearAlgebra::kDense;
  NaturalData free(model, la);
  const NewtonReport undriven = SolvePosition(model, free, q_start, t, options, false);
  if (!undriven.converged) ThrowCannotAssemble(model, free, undriven);
  const Model& m = model.model;
  for (const Driver& d : m.initial) {
    Model one = m;
    one.drivers = {d};
    one.drivers.front().acceleration = 0.0;
    one.initial.clear();
    const NaturalModel alone = Compile(one);
    NaturalData ad(alone, la);
    const NewtonReport r = SolvePosition(alone, ad, q_start, t, options, true);
    if (r.converged) continue;
    const int slot = m.SlotIndex(d.coordinate);
    throw ScenarioError(d.src,
                        "the initial condition " + d.coordinate + " = " + SlotValue(m, slot, d.value) +
                            " cannot be reached: the mechanism assembles without it, but not with " + d.coordinate +
                            " at that value (‖Φ‖ = " + Num(r.residual) + " after " + std::to_string(r.iterations) +
                            " Newton iterations)",
                        "give " + d.coordinate + " a value the mechanism can reach, e.g. its value in the position " +
                            "drawn in the file, " + SlotValue(m, slot, free.q[slot]));
  }
  std::string list, drawn;
  for (const Driver& d : m.initial) {
    const int slot = m.SlotIndex(d.coordinate);
    list += (list.empty() ? "" : ", ") + InitialLine(d);
    drawn += (drawn.empty() ? "" : ", ") + d.coordinate + " = " + SlotValue(m, slot, free.q[slot]);
  }
  throw ScenarioError(m.initial.front().src,
                      "the initial conditions " + list + " cannot be reached together: each alone can, but with all of them "
                      "‖Φ‖ = " + Num(together.residual) + " after " + std::to_string(together.iterations) +
                          " Newton iterations",
                      "give values the mechanism reaches together, e.g. those of the position drawn in the file: " + drawn);
}

// ---- Drivers whose values at t the position problem cannot reach ------------------------------
// Newton–Raphson from the file's drawing says only that it did not converge. To tell a value out
// of the mechanism's reach from a guess that is too far, the drivers are stepped from their values
// in the drawn position toward their values at t (a continuation: each step's Newton starts at the
// last position reached, the step halved when it fails and grown when it succeeds), which finds
// how far along that way the mechanism follows. Cold path only (an error message).

// The position reached along the way, and the nearest the position problem came just beyond it.
struct Followed {
  double s = 0.0;                   // fraction of the way reached, in [0, 1]
  Eigen::VectorXd q;                // the assembled position there
  double beyond_residual = -1.0;    // just past s: the smallest ‖Φ‖ of a failed solve's iterates (−1: none)
  std::vector<int> beyond_worst;    // and its rows, largest scaled residual first
  Eigen::VectorXd beyond_phi;       // Φ at that iterate
};

// `still` is the scene with every driver a constant (no law); its driver k goes from `from[k]` to
// `to[k]` as s goes from 0 to 1, starting at q0, assembled with the drivers at `from`.
Followed FollowDrivers(NaturalModel& still, LinearAlgebra la, const Eigen::VectorXd& q0, const Eigen::VectorXd& from,
                       const Eigen::VectorXd& to, double t, const NewtonOptions& options) {
  Followed out;
  out.q = q0;
  NaturalData d(still, la);
  NewtonOptions o = options;
  o.record_iterates = true;
  o.simplified = false;
  const auto set = [&](double s) {
    for (int k = 0; k < still.f(); ++k) still.drivers[k].law.value = from[k] + s * (to[k] - from[k]);
  };
  // 16 steps to the end at most, or a bisection to a limit 1e-7 of the way (~2 solves a halving).
  constexpr double kFirst = 1.0 / 16, kSmallest = 1e-7;
  constexpr int kMaxSolves = 120;
  double h = kFirst;
  bool failed = false;  // after a failure, a bisection toward the limit: no growing the step again
  for (int solves = 0; out.s < 1.0 && h >= kSmallest && solves < kMaxSolves; ++solves) {
    const double s_try = std::min(1.0, out.s + h);
    set(s_try);
    const NewtonReport r = SolvePosition(still, d, out.q, t, o, true);
    if (r.converged) {
      out.s = s_try;
      out.q = d.q;
      out.beyond_residual = -1.0;
      if (!failed) h = std::min(2 * h, kFirst);
      continue;
    }
    // The iterate nearest to a solution (a diverging Newton's last one says nothing).
    double best = std::numeric_limits<double>::infinity();
    Eigen::VectorXd q_best = out.q;
    for (const Eigen::VectorXd& q : r.iterates) {
      if (!q.allFinite()) break;
      EvalPhi(still, d, q, t);
      if (const double nrm = d.Phi.norm(); nrm < best) best = nrm, q_best = q;
    }
    EvalPhi(still, d, q_best, t);
    out.beyond_residual = std::isfinite(best) ? best : d.Phi.norm();
    out.beyond_worst = WorstRows(still, d);
    out.beyond_phi = d.Phi;
    failed = true;
    h /= 2;
  }
  set(1.0);
  return out;
}

}  // namespace

ReachReport DescribeUnreachableDrivers(const NaturalModel& model, const NaturalData& drawn, double t,
                                       const NewtonOptions& options, const NewtonReport& direct,
                                       const std::string& from_where) {
  const Model& m = model.model;
  const double t0 = m.analysis.t0;
  const int f = model.f();
  const LinearAlgebra la = drawn.sparse ? LinearAlgebra::kSparse : LinearAlgebra::kDense;
  const std::string at_t = "t = " + Fmt(t, 6) + " s";
  Model still_model = m;
  Eigen::VectorXd from(f), to(f);
  for (int k = 0; k < f; ++k) {
    Driver& d = still_model.drivers[k];
    to[k] = model.drivers[k].law.At(t, t0);
    from[k] = drawn.q[model.drivers[k].slot];
    d.law = nullptr;
    d.value = from[k];
    d.velocity = d.acceleration = 0.0;
  }
  NaturalModel still = Compile(still_model);
  MB_ASSERT(still.f() == f && still.n == model.n, "the scene with constant drivers compiles to another layout");
  const Followed ahead = FollowDrivers(still, la, drawn.q, from, to, t, options);
  const auto named = [&](int k, double v) { return model.drivers[k].law.coordinate + " = " + SlotValue(m, model.drivers[k].slot, v, 4); };
  std::string targets, drawn_values, reached;
  for (int k = 0; k < f; ++k) {
    targets += (k ? ", " : "") + named(k, to[k]);
    drawn_values += (k ? ", " : "") + named(k, from[k]);
    reached += (k ? ", " : "") + named(k, from[k] + ahead.s * (to[k] - from[k]));
  }
  const std::string head = "cannot reach the driven values (" + DriverList(model) + ") at " + at_t + ": ";
  const std::string direct_text = "Newton–Raphson from " + std::string(from_where == kFromDrawing ? "the file's drawing" : "the prediction") + " gives ‖Φ‖ = " + Num(direct.residual) + " after " +
                                  std::to_string(direct.iterations) + " iterations";
  if (ahead.s >= 1.0) {
    // Reachable: the drawing is too far from the position for Newton–Raphson alone.
    std::string there;
    for (int slot = 0; slot < model.n && there.size() < 200; ++slot)
      if (std::fabs(ahead.q[slot] - drawn.q[slot]) > 1e-6 * model.q_scale[slot])
        there += (there.empty() ? "" : ", ") + m.q_layout[slot].name + " = " + Fmt(ahead.q[slot], 6);
    return ReachReport{true,
                        head + direct_text + ", but the mechanism does reach " + targets +
                            " when its drivers are stepped there from " + from_where + " (" + drawn_values +
                            "): the " + std::string(from_where == kFromDrawing ? "drawing" : "prediction") +
                            " is too far from that position for Newton–Raphson",
                        "draw the mechanism nearer its position at " + at_t + " (there: " + there + ")"};
  }
  const auto beyond = [&](const Followed& fl) {
    if (fl.beyond_residual < 0) return std::string();
    std::string rows;
    for (size_t i = 0; i < std::min<size_t>(2, fl.beyond_worst.size()); ++i) {
      const int r = fl.beyond_worst[i];
      rows += (i ? ", " : "") + ("row " + std::to_string(r) + " " + still.rows[r].Where() + " Φ = " + Num(fl.beyond_phi[r]));
    }
    // Just past a fold the least-squares residual is tiny and its largest rows are round-off, not
    // the cause (newuser8): named only when they are far from closing.
    return "; just beyond, the nearest the position problem comes is ‖Φ‖ = " + Num(fl.beyond_residual) +
           (fl.beyond_residual > 1e-6 * m.LengthScale() ? " (largest residuals: " + rows + ")" : std::string());
  };
  if (f == 1) {
    // One driver: its range from the drawn position, followed the other way too (as far as four
    // times the scene's size, or a full turn for an angle).
    const int slot = model.drivers[0].slot;
    const bool angle = SlotIsAngle(m, slot);
    const double toward = to[0] - from[0];
    const double span = std::max(std::fabs(toward), angle ? 2 * M_PI : 4 * m.LengthScale());
    Eigen::VectorXd away(1);
    away[0] = from[0] - (toward > 0 ? span : -span);
    const Followed back = FollowDrivers(still, la, drawn.q, from, away, t, options);
    const double lim_toward = from[0] + ahead.s * toward, lim_away = from[0] + back.s * (away[0] - from[0]);
    const double lo = std::min(lim_toward, lim_away), hi = std::max(lim_toward, lim_away);
    const bool lo_limited = toward > 0 ? back.s < 1 : true, hi_limited = toward > 0 ? true : back.s < 1;
    const std::string coord = model.drivers[0].law.coordinate;
    const auto v = [&](double x) { return SlotValue(m, slot, x, 4); };
    const std::string range = (lo_limited ? v(lo) : v(lo) + " (no limit found this far)") + " … " +
                              (hi_limited ? v(hi) : v(hi) + " (no limit found this far)");
    const std::string within = lo_limited && hi_limited ? "within " + v(lo) + " … " + v(hi)
                               : lo_limited             ? "from " + v(lo) + " up"
                                                        : "up to " + v(hi);
    if (angle) {
      // The same position a whole number of turns away inside the range: reached the other way round.
      const double turns = std::round((0.5 * (lo + hi) - to[0]) / (2 * M_PI));
      if (const double same = to[0] + turns * 2 * M_PI; turns != 0 && same >= lo && same <= hi)
        return ReachReport{false,
                            head + named(0, to[0]) + " is the position " + named(0, same) + " " +
                                (turns > 0 ? "plus" : "minus") + " whole turns, which the mechanism reaches from " +
                                from_where + " (" + drawn_values + ") only the other way round: it moves "
                                "through " + coord + " = " + range + " (" + direct_text + ")",
                            "draw the mechanism nearer its position at " + at_t + ", or drive " + coord + " from " + v(same)};
    }
    return ReachReport{false,
                        head + named(0, to[0]) + " is out of the mechanism's reach: from " + from_where + " (" +
                            drawn_values + ") it moves through " + coord + " = " + range +
                            " (the driver stepped each way until the position problem has no solution)" + beyond(ahead) +
                            " (" + direct_text + ")",
                        "give " + coord + " values " + within + " (a crank driven beyond its range?), or draw the "
                        "mechanism in another assembly (branch) that reaches " + v(to[0])};
  }
  return ReachReport{false,
                      head + "together they are out of the mechanism's reach: stepping the drivers from their values in " +
                      from_where + " (" + drawn_values + ") toward " + targets + ", the position problem has "
                      "a solution up to " + Fmt(100 * ahead.s, 3) + " % of the way (" + reached + ")" + beyond(ahead) + " (" +
                          direct_text + ")",
                      "give the drivers values the mechanism reaches together (a crank driven beyond its range?), or "
                      "draw the mechanism in another assembly (branch) that reaches them"};
}

namespace {

[[noreturn]] void ThrowUnreachableDrivers(const NaturalModel& model, const NaturalData& drawn, double t,
                                          const NewtonOptions& options, const NewtonReport& direct) {
  const ReachReport r = DescribeUnreachableDrivers(model, drawn, t, options, direct, kFromDrawing);
  throw ScenarioError(FirstDriverOrFile(model), r.what, r.fix);
}

// A free scene placed by its initial conditions: they act as drivers at t0 only (value and
// velocity), so the position and velocity problems are the kinematic ones; q̈ is left to
// forward dynamics (reported as 0 here and dropped by the numeric method). There must be one
// per degree of freedom: fewer would leave the state to be invented, more over-determine it.
InstantReport FreeInstantFromInitial(const NaturalModel& model, NaturalData& data, double t,
                                     const Eigen::VectorXd& q_start, const NewtonOptions& options) {
  const Model& m = model.model;
  const NaturalModel driven = Compile(m.InitialAsDrivers());
  NaturalData dd(driven, data.sparse ? LinearAlgebra::kSparse : LinearAlgebra::kDense);  // the caller's path
  InstantReport rep;
  std::string what;
  for (const Driver& d : m.initial) what += (what.empty() ? "" : ", ") + d.coordinate;
  const bool spatial = model.dim == 3;
  rep.newton = SolvePosition(driven, dd, q_start, t, options, true);
  const LinearAlgebra la = data.sparse ? LinearAlgebra::kSparse : LinearAlgebra::kDense;
  // The degrees of freedom where the conditions place it, or (when they cannot) where the file
  // draws it, so that a failed iterate's rank never decides the count.
  RankReport probe;
  if (rep.newton.converged) {
    probe = AnalyzeRank(driven, dd);
  } else {
    NaturalData drawn(model, la);
    const NewtonReport undriven = SolvePosition(model, drawn, q_start, t, options, false);
    if (!undriven.converged) ThrowCannotAssemble(model, drawn, undriven);
    probe = AnalyzeRank(model, drawn);
  }
  const int given = driven.f();
  if (probe.dof != given) {
    const SourceRef where = m.initial_src.line > 0 ? m.initial_src : m.initial.front().src;
    const std::string counts = Plural(probe.dof, "degree of freedom", "degrees of freedom") + " but " +
                               Plural(given, "initial condition", "initial conditions") + " (" + what + ")";
    if (probe.dof < given)
      throw ScenarioError(where,
                          "the mechanism has " + counts + ": a free scene is released from a state that needs one "
                          "initial condition per degree of freedom",
                          "keep " + std::to_string(probe.dof) + " of them and remove the others");
    // More degrees of freedom here than where the file draws it: a singular (dead-centre)
    // position, where rank Φ_q drops, rather than too few conditions.
    NaturalData drawn(model, la);
    if (rep.newton.converged && SolvePosition(model, drawn, q_start, t, options, false).converged) {
      if (const RankReport rd = AnalyzeRank(model, drawn); rd.dof == given)
        throw ScenarioError(where,
                            "the initial conditions (" + what + ") place the mechanism at a singular position: it has " +
                                Plural(rd.dof, "degree of freedom", "degrees of freedom") + " where the file draws it but " +
                                std::to_string(probe.dof) + " there (rank Φ_q drops)",
                            "give initial values away from that (dead-centre or toggle) position");
    }
    // Fewer: the rest of the state would have to be invented. Name coordinates that complete it,
    // with their values where the given ones place the mechanism (when they do).
    if (rep.newton.converged) data.q = dd.q;
    else SolvePosition(model, data, q_start, t, options, false);  // converges: assembled above
    std::vector<int> slots_given;
    for (const Driver& d : m.initial) slots_given.push_back(m.SlotIndex(d.coordinate));
    const std::vector<int> more = CompletingSlots(model, data, slots_given, probe.dof);
    std::string fix;
    if (static_cast<int>(more.size()) == probe.dof - given) {
      fix = "add " + Plural(probe.dof - given, "initial condition", "initial conditions") + " under initial:";
      for (int slot : more) {
        fix += " - {coordinate: " + m.q_layout[slot].name;
        // `value` is required (the loader's rule): where the given conditions place it, or else
        // where the file draws it.
        fix += ", value: " + Fmt(data.q[slot], 6) + ", velocity: 0}";
      }
      fix += rep.newton.converged ? " (the values where the given conditions place it; any velocities)"
                                  : " (the values where the file draws it: change them to ones the mechanism reaches "
                                    "together with the given ones; any velocities)";
    } else {
      fix = "add " + Plural(probe.dof - given, "initial condition", "initial conditions") +
            " on coordinates that move independently of " + what;
    }
    throw ScenarioError(where,
                        "the mechanism has " + counts + ": the rest of the state it is released from is not given",
                        fix);
  }
  if (!rep.newton.converged) ThrowUnreachableInitial(model, q_start, t, options, rep.newton, data.sparse);
  try {
    rep = SolveInstant(driven, dd, t, q_start, options);
  } catch (const ScenarioError& e) {
    // A singular position here is the initial conditions' doing, not a driver's: a coordinate
    // that is stationary at this position as the mechanism moves (xP of a rod through the
    // horizontal) does not fix the motion. Name it, and the coordinate that would.
    if (e.problem().find("singular position") != std::string::npos) {
      // The coordinates that do fix it here: those that move most in the motions the given ones
      // leave free (Φ_q's null space at this position).
      data.q = dd.q;
      std::vector<int> slots_given;
      for (const Driver& d : m.initial) slots_given.push_back(m.SlotIndex(d.coordinate));
      std::string other;
      for (int slot : CompletingSlots(model, data, slots_given, probe.dof))
        other += (other.empty() ? "" : " or ") + m.q_layout[slot].name;
      const bool one = m.initial.size() == 1;
      std::string rank = e.problem();  // "… rank [Φ_q; B] = 1 < n = 2 (…)": the rank alone
      if (const size_t at = rank.find("rank ["); at != std::string::npos) {
        rank = rank.substr(at);
        rank = rank.substr(0, std::min(rank.find(" ("), rank.find("; ", rank.find("] ="))));
      } else {
        rank = "near-singular";
      }
      // Spatial scenes have no angle coordinates (yet): only a point's or vector's component.
      const std::string alternatives = (other.empty() ? std::string("another coordinate") : other) +
                                       (spatial ? "" : " or on an angle");
      throw ScenarioError(e.where(),
                          std::string(one ? "the initial condition on " : "the initial conditions on ") + what +
                              (one ? " does" : " do") + " not fix the motion at this position: " +
                              (one ? "that coordinate is" : "they are") +
                              " stationary here as the mechanism moves (" + rank + ")",
                          std::string(one ? "give it" : "give them") + " on " + alternatives);
    }
    throw ScenarioError(e.where(), "initial conditions (" + what + "): " + e.problem(), e.fix());
  }
  rep.messages.push_back("free scene: placed at t0 by its initial conditions (" + what +
                         "), then released; its motion needs forward dynamics");
  UpdatePoints(model, data, dd.q);
  UpdatePointVelocities(model, data, dd.qd);
  UpdatePointAccelerations(model, data, Eigen::VectorXd::Zero(model.n));
  // The rank of Φ_q alone (the caller reads dof from it), not of the driven augmented matrix.
  rep.rank = AnalyzeRank(model, data);
  EvalPhi(model, data, data.q, t);
  EvalJacobian(model, data, data.q);
  return rep;
}

}  // namespace

InstantReport SolveInstant(const NaturalModel& model, NaturalData& data, double t, const Eigen::VectorXd& q_start,
                           const NewtonOptions& options) {
  InstantReport rep;
  if (model.f() == 0 && !model.model.initial.empty()) return FreeInstantFromInitial(model, data, t, q_start, options);
  if (model.f() == 0) {
    // A free scene without initial conditions: its loads decide the motion (forward dynamics).
    // Assemble it next to the guess (minimum-norm Newton steps) and report it at rest.
    rep.newton = SolvePosition(model, data, q_start, t, options, false);
    if (!rep.newton.converged) ThrowCannotAssemble(model, data, rep.newton);
    rep.rank = AnalyzeRank(model, data);
    rep.messages.push_back("no drivers: a free scene with " +
                           Plural(rep.rank.dof, "degree of freedom", "degrees of freedom") +
                           "; assembled next to the guess and reported at rest (q̇ = 0); its accelerations need forward dynamics");
    UpdatePointVelocities(model, data, Eigen::VectorXd::Zero(model.n));
    UpdatePointAccelerations(model, data, Eigen::VectorXd::Zero(model.n));
    EvalPhi(model, data, data.q, t);
    EvalJacobian(model, data, data.q);
    return rep;
  }
  rep.newton = SolvePosition(model, data, q_start, t, options, true);
  if (!rep.newton.converged) {
    // Tell "cannot assemble at all" from "cannot reach the driven values": solve without drivers.
    NaturalData probe(model, data.sparse ? LinearAlgebra::kSparse : LinearAlgebra::kDense);
    const NewtonReport undriven = SolvePosition(model, probe, q_start, t, options, false);
    if (!undriven.converged) ThrowCannotAssemble(model, probe, undriven);
    const RankReport rk = AnalyzeRank(model, probe);
    if (rk.dof != model.f()) ThrowDofMismatch(model, probe, rk);
    ThrowUnreachableDrivers(model, probe, t, options, rep.newton);
  }

  rep.rank = AnalyzeRank(model, data);
  const RankReport& rk = rep.rank;
  if (rk.dof != model.f()) ThrowDofMismatch(model, data, rk);
  if (rk.augmented_rank < model.n) {
    SourceRef where = FirstDriverOrFile(model);
    std::string hint = SingularAngleHint(model, data, where);
    throw ScenarioError(where,
                        "singular position: the drivers (" + DriverList(model) + ") do not fix the motion here, rank [Φ_q; B] = " +
                            std::to_string(rk.augmented_rank) + " < n = " + std::to_string(model.n) +
                            (hint.empty() ? std::string(" (a toggle or dead-centre position for this driver)") : "; " + hint),
                        "drive another coordinate, or move the instant away from this position");
  }
  if (!rk.redundant_rows.empty()) {
    std::string rows;
    for (int i : rk.redundant_rows) rows += (rows.empty() ? "" : ", ") + std::to_string(i) + " " + model.rows[i].Where();
    const int k = static_cast<int>(rk.redundant_rows.size());
    rep.messages.push_back(Plural(k, "redundant constraint", "redundant constraints") + ": row" + (k == 1 ? " " : "s ") +
                           rows + " (m = " + std::to_string(rk.m) + ", rank Φ_q = " + std::to_string(rk.rank) +
                           "); consistent, so solved by least squares, as the book's §4.4 notes");
  }
  if (SolveVelocity(model, data, t) < model.n) {
    SourceRef where = FirstDriverOrFile(model);
    const std::string hint = SingularAngleHint(model, data, where);
    throw ScenarioError(where,
                        "near-singular position: [Φ_q; B] has a condition number above " + Num(1 / kSingularTolerance) +
                            " with the drivers (" + DriverList(model) + ")" + (hint.empty() ? std::string() : "; " + hint),
                        "drive another coordinate, or move the instant away from this position");
  }
  SolveAcceleration(model, data, t);
  // Leave Φ, Φ_q, Φ̇_q at the solved instant for the caller.
  EvalPhi(model, data, data.q, t);
  EvalJacobian(model, data, data.q);
  return rep;
}

}  // namespace mechbench::numeric
