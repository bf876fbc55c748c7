#include "mechbench/numeric/solver.h"

#include "mechbench/errors.h"
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

// In-place LU with partial pivoting (LAPACK's getf2): false when a pivot is zero. The inner loops
// run over whole columns with the bounds as conditions, so that for a fixed N every loop has a
// constant trip count and is unrolled.
template <int N>
bool LuKernel(double* a, int n_rt, int* piv) {
  const int n = N > 0 ? N : n_rt;
  for (int k = 0; k < n; ++k) {
    double* ck = a + k * n;
    int p = k;
    double big = std::fabs(ck[k]);
    for (int i = 0; i < n; ++i)
      if (i > k && std::fabs(ck[i]) > big) big = std::fabs(ck[i]), p = i;
    piv[k] = p;
    if (!(big > 0)) return false;  // a zero (or NaN) column
    if (p != k)
      for (int j = 0; j < n; ++j) std::swap(a[j * n + k], a[j * n + p]);
    const double inv_pivot = 1.0 / ck[k];
    for (int i = 0; i < n; ++i)
      if (i > k) ck[i] *= inv_pivot;
    for (int j = 0; j < n; ++j) {
      if (j <= k) continue;
      double* cj = a + j * n;
      const double u = cj[k];
      for (int i = 0; i < n; ++i)
        if (i > k) cj[i] -= ck[i] * u;
    }
  }
  return true;
}

// x ← A⁻¹ x with the factors of LuKernel.
template <int N>
void LuSolveKernel(const double* a, int n_rt, const int* piv, double* x) {
  const int n = N > 0 ? N : n_rt;
  for (int k = 0; k < n; ++k)
    if (piv[k] != k) std::swap(x[k], x[piv[k]]);
  for (int k = 0; k < n; ++k) {
    const double* ck = a + k * n;
    const double xk = x[k];
    for (int i = 0; i < n; ++i)
      if (i > k) x[i] -= ck[i] * xk;
  }
  for (int k = n - 1; k >= 0; --k) {
    const double* ck = a + k * n;
    x[k] /= ck[k];
    const double xk = x[k];
    for (int i = 0; i < n; ++i)
      if (i < k) x[i] -= ck[i] * xk;
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
  for (int i = 0; i < n; ++i) {
    double r = 0;
    for (int j = 0; j < n; ++j) r += std::fabs(a[j * n + i]);
    norm_a = std::max(norm_a, r);
  }
  for (int i = 0; i < n; ++i) {  // M(L) y = e, L unit lower
    double yi = 1.0;
    for (int j = 0; j < i; ++j) yi += std::fabs(lu[j * n + i]) * y[j];
    y[i] = yi;
    l = std::max(l, yi);
  }
  for (int i = n - 1; i >= 0; --i) {  // M(U) y = e
    double yi = 1.0;
    for (int j = i + 1; j < n; ++j) yi += std::fabs(lu[j * n + i]) * y[j];
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
    res = residual(/*jacobian=*/!simplified);
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
      residual(/*jacobian=*/true);
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
  EvalPhidotQdot(model, data, data.q, data.qd);
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
    const Eigen::VectorXi& order = s.qr.colsPermutation().indices();
    for (int k = rk.augmented_rank; k < order.size(); ++k)
      if (order[k] < rk.m) rk.redundant_rows.push_back(order[k]);
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

// A free scene placed by its initial conditions: they act as drivers at t0 only (value and
// velocity), so the position and velocity problems are the kinematic ones; q̈ is left to
// forward dynamics (reported as 0 here and dropped by the numeric method).
InstantReport FreeInstantFromInitial(const NaturalModel& model, NaturalData& data, double t,
                                     const Eigen::VectorXd& q_start, const NewtonOptions& options) {
  const NaturalModel driven = Compile(model.model.InitialAsDrivers());
  NaturalData dd(driven, data.sparse ? LinearAlgebra::kSparse : LinearAlgebra::kDense);  // the caller's path
  InstantReport rep;
  std::string what;
  for (const Driver& d : model.model.initial) what += (what.empty() ? "" : ", ") + d.coordinate;
  rep.newton = SolvePosition(driven, dd, q_start, t, options, true);
  const RankReport probe = AnalyzeRank(driven, dd);
  if (!rep.newton.converged || probe.dof <= driven.f()) {
    try {
      rep = SolveInstant(driven, dd, t, q_start, options);
    } catch (const ScenarioError& e) {
      // A singular position here is the initial conditions' doing, not a driver's: a coordinate
      // that is stationary at this position as the mechanism moves (xP of a rod through the
      // horizontal) does not fix the motion. Name it, and the coordinate that would.
      if (e.problem().find("singular position") != std::string::npos) {
        std::string other;
        for (const Driver& d : model.model.initial) {
          const std::string& c = d.coordinate;
          const bool point = c.size() > 1 && (c[0] == 'x' || c[0] == 'y') &&
                             model.model.PointIndex(c.substr(1)) >= 0;
          if (point) other += (other.empty() ? "" : " or ") + std::string(c[0] == 'x' ? "y" : "x") + c.substr(1);
        }
        const bool one = model.model.initial.size() == 1;
        std::string rank = e.problem();  // "… rank [Φ_q; B] = 1 < n = 2 (…)": the rank alone
        if (const size_t at = rank.find("rank ["); at != std::string::npos) {
          rank = rank.substr(at);
          rank = rank.substr(0, std::min(rank.find(" ("), rank.find("; ", rank.find("] ="))));
        } else {
          rank = "near-singular";
        }
        throw ScenarioError(e.where(),
                            std::string(one ? "the initial condition on " : "the initial conditions on ") + what +
                                (one ? " does" : " do") + " not fix the motion at this position: " +
                                (one ? "that coordinate is" : "they are") +
                                " stationary here as the mechanism moves (" + rank + ")",
                            std::string(one ? "give it" : "give them") + " on " + (other.empty() ? "another coordinate" : other) +
                                " or on an angle");
      }
      throw ScenarioError(e.where(), "initial conditions (" + what + "): " + e.problem(), e.fix());
    }
    rep.messages.push_back("free scene: placed at t0 by its initial conditions (" + what +
                           "), then released; its motion needs forward dynamics");
  } else {
    // Fewer initial conditions than degrees of freedom: the rest is assembled next to the guess
    // and given the minimum-norm velocity.
    rep.rank = probe;
    SolveVelocity(driven, dd, t);
    rep.messages.push_back("free scene: initial conditions (" + what + ") fix " + Plural(driven.f(), "coordinate", "coordinates") +
                           " of " + Plural(probe.dof, "degree of freedom", "degrees of freedom") +
                           "; the rest assembled next to the guess with the minimum-norm velocity");
  }
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
    throw ScenarioError(FirstDriverOrFile(model),
                        "cannot reach the driven values (" + DriverList(model) +
                            "): the mechanism assembles without its drivers, but with them ‖Φ‖ = " +
                            Num(rep.newton.residual) + " after " + std::to_string(rep.newton.iterations) +
                            " iterations (largest residuals: " + DescribeRows(model, data, WorstRows(model, data), 2) + ")",
                        "check the drivers' values (a crank driven beyond its range?) and the initial guess");
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
