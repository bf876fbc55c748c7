#include "mechbench/numeric/solver.h"

#include "mechbench/errors.h"
#include "mechbench/numeric/constraints.h"
#include "mechbench/numeric/forward_dynamics.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>

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
Eigen::VectorXd AugmentedScales(const NaturalModel& model, bool with_drivers) {
  Eigen::VectorXd s(model.m() + (with_drivers ? model.f() : 0));
  for (int i = 0; i < model.m(); ++i) s[i] = model.rows[i].scale;
  if (with_drivers)
    for (int k = 0; k < model.f(); ++k) s[model.m() + k] = model.q_scale[model.drivers[k].slot];
  return s;
}

// [Φ_q; B] with B the driver rows (a 1 in each driven slot's column).
void FillAugmented(const NaturalModel& model, const NaturalData& data, bool with_drivers, Eigen::MatrixXd& A) {
  const int m = model.m(), f = with_drivers ? model.f() : 0;
  A.setZero(m + f, model.n);
  A.topRows(m) = data.Phi_q;
  for (int k = 0; k < f; ++k) A(m + k, model.drivers[k].slot) = 1.0;
}

// Least-squares solve of A x = b with rows weighted by 1/scale, so that rows in different units
// count alike when the system is inconsistent (off the constraint manifold); a consistent system
// has the same solution either way. Minimum-norm when rank deficient.
Eigen::VectorXd SolveScaled(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, const Eigen::VectorXd& scale) {
  const Eigen::VectorXd w = scale.cwiseInverse();
  const Eigen::MatrixXd As = w.asDiagonal() * A;
  return Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd>(As).solve(w.asDiagonal() * b);
}

// The same for the linear kinematic problems, with rows normalized to unit length, returning
// the numerical rank so that a singular position is seen rather than answered by least squares.
Eigen::VectorXd SolveNormalized(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, int& rank) {
  Eigen::VectorXd w(A.rows());
  for (Eigen::Index i = 0; i < A.rows(); ++i) {
    const double nrm = A.row(i).norm();
    w[i] = nrm > 0 ? 1.0 / nrm : 1.0;
  }
  Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod;
  cod.setThreshold(kSingularTolerance);
  cod.compute(w.asDiagonal() * A);
  rank = static_cast<int>(cod.rank());
  return cod.solve(w.asDiagonal() * b);
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
  EvalJacobian(model, data, data.q);
  FillAugmented(model, data, true, data.A);
}

NewtonReport SolvePosition(const NaturalModel& model, NaturalData& data, const Eigen::VectorXd& q_start,
                           double t, const NewtonOptions& options, bool with_drivers) {
  MB_ASSERT(q_start.size() == model.n, "start q has the wrong size");
  NewtonReport rep;
  const int m = model.m(), f = with_drivers ? model.f() : 0;
  const Eigen::VectorXd scale = AugmentedScales(model, with_drivers);
  Eigen::VectorXd q = q_start, b(m + f);
  Eigen::MatrixXd A;
  const auto residual = [&](const Eigen::VectorXd& qq) {
    EvalPhi(model, data, qq, t);
    b.head(m) = -data.Phi;
    if (f) b.tail(f) = -DriverResiduals(model, qq, t);
    return (m + f) ? b.cwiseAbs().cwiseQuotient(scale).maxCoeff() : 0.0;
  };
  double res = residual(q), prev = res;
  for (int k = 1; k <= options.max_iterations; ++k) {
    EvalJacobian(model, data, q);
    FillAugmented(model, data, with_drivers, A);
    const Eigen::VectorXd dq = SolveScaled(A, b, scale);
    q += dq;
    res = residual(q);
    rep.iterations = k;
    if (options.record_iterates) rep.iterates.push_back(q);
    if (!q.allFinite() || !std::isfinite(res)) break;
    // Converged when Φ is at its tolerance and the step is negligible, or when Φ is at its
    // tolerance and no longer shrinks (round-off floor, slow steps near a singular position).
    if (res <= options.phi_tolerance && (ScaledStep(model, dq) <= options.step_tolerance || res > 0.5 * prev)) {
      rep.converged = true;
      break;
    }
    prev = res;
  }
  rep.scaled_residual = res;
  rep.residual = data.Phi.norm();
  EvalJacobian(model, data, q);
  return rep;
}

int SolveVelocity(const NaturalModel& model, NaturalData& data, double t) {
  AssembleAugmented(model, data);
  EvalPhit(model, data, data.q, t);
  data.rhs.resize(model.m() + model.f());
  data.rhs.head(model.m()) = -data.Phi_t;
  data.rhs.tail(model.f()) = DriverRates(model, t);
  int rank = 0;
  const Eigen::VectorXd qd = SolveNormalized(data.A, data.rhs, rank);
  UpdatePointVelocities(model, data, qd);
  return rank;
}

int SolveAcceleration(const NaturalModel& model, NaturalData& data, double t) {
  AssembleAugmented(model, data);
  EvalPhidotQdot(model, data, data.q, data.qd);
  data.rhs.resize(model.m() + model.f());
  // Φ̇_t = 0: time enters only through the driver rows, whose f̈ is on the right.
  data.rhs.head(model.m()) = -data.Phidot_q_qd;
  data.rhs.tail(model.f()) = DriverAccelerations(model, t);
  int rank = 0;
  const Eigen::VectorXd qdd = SolveNormalized(data.A, data.rhs, rank);
  UpdatePointAccelerations(model, data, qdd);
  return rank;
}

RankReport AnalyzeRank(const NaturalModel& model, NaturalData& data, double tolerance) {
  RankReport rk;
  rk.n = model.n;
  rk.m = model.m();
  rk.f = model.f();
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
  NaturalData dd(driven);
  InstantReport rep;
  std::string what;
  for (const Driver& d : model.model.initial) what += (what.empty() ? "" : ", ") + d.coordinate;
  rep.newton = SolvePosition(driven, dd, q_start, t, options, true);
  const RankReport probe = AnalyzeRank(driven, dd);
  if (!rep.newton.converged || probe.dof <= driven.f()) {
    try {
      rep = SolveInstant(driven, dd, t, q_start, options);
    } catch (const ScenarioError& e) {
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
    NaturalData probe(model);
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
