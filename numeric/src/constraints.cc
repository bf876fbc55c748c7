#include "mechbench/numeric/constraints.h"

#include "mechbench/errors.h"
#include "planar.h"
#include "spatial_rows.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace mechbench::numeric {
namespace {

using V2 = Eigen::Vector2d;

using planar::Cross;
using planar::Perp;
V2 Rotate(double th, const V2& v) {
  const double c = std::cos(th), s = std::sin(th);
  return {c * v.x() - s * v.y(), s * v.x() + c * v.y()};
}
V2 RotateT(double th, const V2& v) { return Rotate(-th, v); }
// ∂cross(a, b)/∂a = (b_y, −b_x) = −Perp(b);  ∂cross(a, b)/∂b = (−a_y, a_x) = Perp(a).

// Partial derivatives of one row with respect to the points it uses and to its coordinate slots,
// each with its time derivative (the row of Φ̇_q). A point may appear twice (a dot-form angle
// between two bars that share a point): the scatter sums the entries.
struct Partials {
  int np = 0;
  std::array<int, 4> pt{};
  std::array<V2, 4> g, gd;
  int ns = 0;
  std::array<int, 3> slot{};
  std::array<double, 3> s{}, sd{};
  void Point(int p, const V2& grad, const V2& rate) {
    pt[np] = p, g[np] = grad, gd[np] = rate, ++np;
  }
  void Slot(int i, double grad, double rate) {
    if (i < 0) return;
    slot[ns] = i, s[ns] = grad, sd[ns] = rate, ++ns;
  }
};

// The value of `row` at data.r / data.q and, when `out` is given, its partials at data.rd / data.qd.
double EvalRow(const ConstraintRow& row, const NaturalData& d, Partials* out) {
  const auto& r = d.r;
  const auto& rd = d.rd;
  const auto th = [&] { return d.q[row.slots[0]]; };
  const auto thd = [&] { return d.qd[row.slots[0]]; };
  switch (row.kind) {
    case RowKind::kBodyDistance: {
      const int p0 = row.pts[0], p1 = row.pts[1];
      const V2 v = r[p1] - r[p0];
      if (out) {
        const V2 vd = rd[p1] - rd[p0];
        out->Point(p1, 2 * v, 2 * vd);
        out->Point(p0, -2 * v, -2 * vd);
      }
      return v.squaredNorm() - row.L * row.L;
    }
    case RowKind::kBodyLinearX:
    case RowKind::kBodyLinearY: {
      const int c = row.kind == RowKind::kBodyLinearX ? 0 : 1;
      const int p0 = row.pts[0], p1 = row.pts[1], pk = row.pts[2];
      const V2 v = r[p1] - r[p0];
      const V2 e = c == 0 ? V2(1, 0) : V2(0, 1);
      const V2 P_row = c == 0 ? V2(0, -1) : V2(1, 0);  // row c of P
      if (out) {
        out->Point(pk, e, V2::Zero());
        out->Point(p0, -(1 - row.a) * e + row.b * P_row, V2::Zero());
        out->Point(p1, -row.a * e - row.b * P_row, V2::Zero());
      }
      return (r[pk] - r[p0] - row.a * v - row.b * Perp(v))[c];
    }
    case RowKind::kPointOnLine: {
      const int p = row.pts[0], l0 = row.pts[1], l1 = row.pts[2];
      const V2 u = r[p] - r[l0], w = r[l1] - r[l0];
      if (out) {
        const V2 ud = rd[p] - rd[l0], wd = rd[l1] - rd[l0];
        out->Point(p, -Perp(w), -Perp(wd));
        out->Point(l1, Perp(u), Perp(ud));
        out->Point(l0, Perp(w) - Perp(u), Perp(wd) - Perp(ud));
      }
      return Cross(u, w);
    }
    case RowKind::kGear: {
      const double phi_c = row.slots[2] >= 0 ? d.q[row.slots[2]] : 0.0;
      if (out) {
        out->Slot(row.slots[0], row.z_a, 0.0);
        out->Slot(row.slots[1], row.z_b, 0.0);
        out->Slot(row.slots[2], -row.z_a - row.z_b, 0.0);
      }
      return row.z_a * (d.q[row.slots[0]] - phi_c) + row.z_b * (d.q[row.slots[1]] - phi_c) - row.c;
    }
    case RowKind::kCoupling: {
      if (out) {
        out->Slot(row.slots[0], -row.k, 0.0);
        out->Slot(row.slots[1], 1.0, 0.0);
      }
      return d.q[row.slots[1]] - row.k * d.q[row.slots[0]] - row.c;
    }
    case RowKind::kAngleCos: {
      const int a = row.pts[0], b = row.pts[1];
      if (out) {
        out->Point(b, V2(1, 0), V2::Zero());
        out->Point(a, V2(-1, 0), V2::Zero());
        out->Slot(row.slots[0], row.L * std::sin(th()), row.L * std::cos(th()) * thd());
      }
      return (r[b] - r[a]).x() - row.L * std::cos(th());
    }
    case RowKind::kAngleSin: {
      const int a = row.pts[0], b = row.pts[1];
      if (out) {
        out->Point(b, V2(0, 1), V2::Zero());
        out->Point(a, V2(0, -1), V2::Zero());
        out->Slot(row.slots[0], -row.L * std::cos(th()), row.L * std::sin(th()) * thd());
      }
      return (r[b] - r[a]).y() - row.L * std::sin(th());
    }
    case RowKind::kAngleDot: {
      const int a = row.pts[0], b = row.pts[1], c0 = row.ref[0], c1 = row.ref[1];
      const V2 rho = r[c1] - r[c0], v = r[b] - r[a];
      if (out) {
        const V2 rhod = rd[c1] - rd[c0], vd = rd[b] - rd[a];
        out->Point(c1, v, vd);
        out->Point(c0, -v, -vd);
        out->Point(b, rho, rhod);
        out->Point(a, -rho, -rhod);
        out->Slot(row.slots[0], row.L * std::sin(th()), row.L * std::cos(th()) * thd());
      }
      return rho.dot(v) - row.L * std::cos(th());
    }
    case RowKind::kAngleCross: {
      // Φ = cross(R(θ)ρ, v). With ρθ = R(θ)ρ: ∂/∂v = Perp(ρθ), ∂/∂ρ = −Rᵀ Perp(v),
      // ∂/∂θ = cross(P ρθ, v) = −ρθ·v. Rates use Ṙ = P R θ̇.
      const int a = row.pts[0], b = row.pts[1];
      const bool ground = row.ref[0] < 0;
      const V2 rho = ground ? V2(1, 0) : V2(r[row.ref[1]] - r[row.ref[0]]);
      const V2 v = r[b] - r[a];
      const double t = th();
      const V2 rho_t = Rotate(t, rho);
      if (out) {
        const V2 rhod = ground ? V2::Zero() : V2(rd[row.ref[1]] - rd[row.ref[0]]);
        const V2 vd = rd[b] - rd[a];
        const double td = thd();
        const V2 rho_td = Perp(rho_t) * td + Rotate(t, rhod);
        out->Point(b, Perp(rho_t), Perp(rho_td));
        out->Point(a, -Perp(rho_t), -Perp(rho_td));
        if (!ground) {
          const V2 g = -RotateT(t, Perp(v));
          const V2 gd = -RotateT(t, v) * td - RotateT(t, Perp(vd));
          out->Point(row.ref[1], g, gd);
          out->Point(row.ref[0], -g, -gd);
        }
        out->Slot(row.slots[0], -rho_t.dot(v), -(rho_td.dot(v) + rho_t.dot(vd)));
      }
      return Cross(rho_t, v);
    }
    case RowKind::kDistance: {
      const int a = row.pts[0], b = row.pts[1];
      const V2 v = r[b] - r[a];
      const double s = d.q[row.slots[0]];
      if (out) {
        const V2 vd = rd[b] - rd[a];
        out->Point(b, 2 * v, 2 * vd);
        out->Point(a, -2 * v, -2 * vd);
        out->Slot(row.slots[0], -2 * s, -2 * d.qd[row.slots[0]]);
      }
      return v.squaredNorm() - s * s;
    }
    case RowKind::kUnit3:
    case RowKind::kDistance3:
    case RowKind::kDot3:
    case RowKind::kLinear3:
    case RowKind::kPointOnLine3:
    case RowKind::kAngle3:
      break;  // spatial rows: spatial_rows.cc (a spatial model never reaches this function)
  }
  MB_ASSERT(false, "unknown row kind");
  return 0.0;
}

// Writes the partials of row i into `J` (rate = false) or their time derivatives (rate = true).
void Scatter(const NaturalModel& model, const Partials& p, int i, bool rate, Eigen::MatrixXd& J) {
  for (int k = 0; k < p.np; ++k) {
    const V2& g = rate ? p.gd[k] : p.g[k];
    for (int axis = 0; axis < 2; ++axis) {
      const int s = model.point_slot[p.pt[k]][axis];
      if (s >= 0) J(i, s) += g[axis];
    }
  }
  for (int k = 0; k < p.ns; ++k) J(i, p.slot[k]) += rate ? p.sd[k] : p.s[k];
}

void Differentiate(const NaturalModel& model, NaturalData& data, bool rate, Eigen::MatrixXd& J) {
  if (model.dim == 3) return spatial::Differentiate(model, data, rate, J);
  J.setZero(model.m(), model.n);
  for (int i = 0; i < model.m(); ++i) {
    Partials p;
    EvalRow(model.rows[i], data, &p);
    Scatter(model, p, i, rate, J);
  }
}

}  // namespace

SparseJacobian::SparseJacobian(const NaturalModel& model, const std::vector<int>& rows) : rows_(rows) {
  // The partials' structure depends on the row kind and on which coordinates are constant, not on
  // q: evaluate each row once anywhere (the model's constant points, zeros) to read it. The probe
  // is sparse data (O(n), no dense block).
  NaturalData probe(model, LinearAlgebra::kSparse);
  std::vector<Eigen::Triplet<double>> entries;
  std::vector<std::vector<int>> cols(rows.size());
  for (size_t k = 0; k < rows.size(); ++k) {
    if (model.dim == 3) {
      spatial::Columns(model, model.rows[rows[k]], cols[k]);
      for (int c : cols[k])
        if (c >= 0) entries.emplace_back(static_cast<int>(k), c, 0.0);
      continue;
    }
    Partials p;
    EvalRow(model.rows[rows[k]], probe, &p);
    for (int j = 0; j < p.np; ++j)
      for (int axis = 0; axis < 2; ++axis) cols[k].push_back(model.point_slot[p.pt[j]][axis]);
    for (int j = 0; j < p.ns; ++j) cols[k].push_back(p.slot[j]);
    for (int c : cols[k])
      if (c >= 0) entries.emplace_back(static_cast<int>(k), c, 0.0);
  }
  J_.resize(static_cast<Eigen::Index>(rows.size()), model.n);
  J_.setFromTriplets(entries.begin(), entries.end());  // duplicates merge: one entry per (row, column)
  J_.makeCompressed();
  Jdot_ = J_;
  start_.assign(rows.size() + 1, 0);
  for (size_t k = 0; k < rows.size(); ++k) {
    start_[k] = static_cast<int>(index_.size());
    const int* inner = J_.innerIndexPtr();
    const int begin = J_.outerIndexPtr()[k], end = J_.outerIndexPtr()[k + 1];
    for (int c : cols[k]) {
      if (c < 0) {
        index_.push_back(-1);
        continue;
      }
      const int* at = std::lower_bound(inner + begin, inner + end, c);
      MB_ASSERT(at != inner + end && *at == c, "sparse Jacobian pattern lookup");
      index_.push_back(static_cast<int>(at - inner));
    }
  }
  start_[rows.size()] = static_cast<int>(index_.size());
}

void SparseJacobian::Evaluate(const NaturalModel& model, NaturalData& data, const Eigen::VectorXd& q,
                              const Eigen::VectorXd* qd, Eigen::VectorXd& phi, Eigen::VectorXd* jdot_qd, bool rate_matrix) {
  if (model.dim == 3) return Evaluate3(model, data, q, qd, phi, jdot_qd, rate_matrix);
  UpdatePoints(model, data, q);
  if (qd) UpdatePointVelocities(model, data, *qd);
  const int m = rows_count();
  phi.resize(m);
  if (jdot_qd) jdot_qd->resize(m);
  double* values = J_.valuePtr();
  std::fill(values, values + J_.nonZeros(), 0.0);
  double* rates = rate_matrix && qd ? Jdot_.valuePtr() : nullptr;
  if (rates) std::fill(rates, rates + Jdot_.nonZeros(), 0.0);
  for (int k = 0; k < m; ++k) {
    Partials p;
    phi[k] = EvalRow(model.rows[rows_[k]], data, &p);
    const int* idx = index_.data() + start_[k];
    double rate = 0;
    for (int j = 0; j < p.np; ++j, idx += 2) {
      for (int axis = 0; axis < 2; ++axis)
        if (idx[axis] >= 0) {
          values[idx[axis]] += p.g[j][axis];
          if (rates) rates[idx[axis]] += p.gd[j][axis];
        }
      if (qd) rate += p.gd[j].dot(data.rd[p.pt[j]]);
    }
    for (int j = 0; j < p.ns; ++j, ++idx) {
      values[*idx] += p.s[j];
      if (rates) rates[*idx] += p.sd[j];
      if (qd) rate += p.sd[j] * (*qd)[p.slot[j]];
    }
    if (jdot_qd) (*jdot_qd)[k] = rate;
  }
}

namespace {

// Sparse data: Φ_q of every row (the pattern built at the first call) at q, and Φ → phi, Φ̇_q q̇ →
// *jdot_qd and Φ̇_q when qd is given. Records that data.jac holds Φ_q at q.
void EvaluateSparse(const NaturalModel& model, NaturalData& data, const Eigen::VectorXd& q, const Eigen::VectorXd* qd,
                    Eigen::VectorXd& phi, Eigen::VectorXd* jdot_qd) {
  if (data.jac.empty()) {
    std::vector<int> all(model.m());
    for (int i = 0; i < model.m(); ++i) all[i] = i;
    data.jac = SparseJacobian(model, all);
  }
  data.jac.Evaluate(model, data, q, qd, phi, jdot_qd, /*rate_matrix=*/qd != nullptr);
  data.kin.jacobian_q = data.q;
  data.kin.jacobian_valid = true;
}

}  // namespace

void UpdatePoints(const NaturalModel& model, NaturalData& data, const Eigen::VectorXd& q) {
  MB_ASSERT(q.size() == model.n, "q has the wrong size");
  data.q = q;
  for (size_t p = 0; p < model.point_slot.size(); ++p)
    for (int axis = 0; axis < 2; ++axis) {
      const int s = model.point_slot[p][axis];
      data.r[p][axis] = s >= 0 ? q[s] : model.point_const[p][axis];
    }
}

void UpdatePointVelocities(const NaturalModel& model, NaturalData& data, const Eigen::VectorXd& qd) {
  MB_ASSERT(qd.size() == model.n, "q̇ has the wrong size");
  data.qd = qd;
  for (size_t p = 0; p < model.point_slot.size(); ++p)
    for (int axis = 0; axis < 2; ++axis) {
      const int s = model.point_slot[p][axis];
      data.rd[p][axis] = s >= 0 ? qd[s] : 0.0;
    }
}

void UpdatePointAccelerations(const NaturalModel& model, NaturalData& data, const Eigen::VectorXd& qdd) {
  MB_ASSERT(qdd.size() == model.n, "q̈ has the wrong size");
  data.qdd = qdd;
  for (size_t p = 0; p < model.point_slot.size(); ++p)
    for (int axis = 0; axis < 2; ++axis) {
      const int s = model.point_slot[p][axis];
      data.rdd[p][axis] = s >= 0 ? qdd[s] : 0.0;
    }
}

void EvalPhi(const NaturalModel& model, NaturalData& data, const Eigen::VectorXd& q, double t) {
  UpdatePoints(model, data, q);
  data.t = t;
  if (model.dim == 3) return spatial::EvalPhi(model, data);
  data.Phi.resize(model.m());
  for (int i = 0; i < model.m(); ++i) data.Phi[i] = EvalRow(model.rows[i], data, nullptr);
}

void EvalJacobian(const NaturalModel& model, NaturalData& data, const Eigen::VectorXd& q) {
  if (data.sparse) return EvaluateSparse(model, data, q, nullptr, data.kin.phi, nullptr);
  UpdatePoints(model, data, q);
  Differentiate(model, data, /*rate=*/false, data.Phi_q);
  data.kin.jacobian_q = data.q;
  data.kin.jacobian_valid = true;
}

void EvalPhiJacobian(const NaturalModel& model, NaturalData& data, const Eigen::VectorXd& q, double t) {
  data.t = t;
  if (data.sparse) return EvaluateSparse(model, data, q, nullptr, data.Phi, nullptr);
  UpdatePoints(model, data, q);
  if (model.dim == 3) {
    spatial::EvalPhi(model, data);
    spatial::Differentiate(model, data, /*rate=*/false, data.Phi_q);
    data.kin.jacobian_q = data.q;
    data.kin.jacobian_valid = true;
    return;
  }
  data.Phi.resize(model.m());
  data.Phi_q.setZero(model.m(), model.n);
  for (int i = 0; i < model.m(); ++i) {
    Partials p;
    data.Phi[i] = EvalRow(model.rows[i], data, &p);
    Scatter(model, p, i, /*rate=*/false, data.Phi_q);
  }
  data.kin.jacobian_q = data.q;
  data.kin.jacobian_valid = true;
}

void EvalPhit(const NaturalModel& model, NaturalData& data, const Eigen::VectorXd& q, double t) {
  UpdatePoints(model, data, q);
  data.t = t;
  data.Phi_t.setZero(model.m());
}

void EvalPhidotQ(const NaturalModel& model, NaturalData& data, const Eigen::VectorXd& q,
                 const Eigen::VectorXd& qd) {
  if (data.sparse) return EvaluateSparse(model, data, q, &qd, data.kin.phi, &data.Phidot_q_qd);
  UpdatePoints(model, data, q);
  UpdatePointVelocities(model, data, qd);
  Differentiate(model, data, /*rate=*/true, data.Phidot_q);
}

void EvalPhidotQdot(const NaturalModel& model, NaturalData& data, const Eigen::VectorXd& q,
                    const Eigen::VectorXd& qd) {
  // Sparse: Φ̇_q q̇ summed per row on the way (EvaluateSparse).
  if (data.sparse) return EvaluateSparse(model, data, q, &qd, data.kin.phi, &data.Phidot_q_qd);
  EvalPhidotQ(model, data, q, qd);
  data.Phidot_q_qd.noalias() = data.Phidot_q * qd;
}

void EvalPhidotQdotRows(const NaturalModel& model, NaturalData& data, const Eigen::VectorXd& q,
                        const Eigen::VectorXd& qd) {
  if (data.sparse || model.dim == 3) return EvalPhidotQdot(model, data, q, qd);
  UpdatePoints(model, data, q);
  UpdatePointVelocities(model, data, qd);
  data.Phidot_q_qd.resize(model.m());
  for (int i = 0; i < model.m(); ++i) {
    Partials p;
    EvalRow(model.rows[i], data, &p);
    double rate = 0;
    for (int k = 0; k < p.np; ++k) rate += p.gd[k].dot(data.rd[p.pt[k]]);  // a constant point's rd is 0
    for (int k = 0; k < p.ns; ++k) rate += p.sd[k] * qd[p.slot[k]];
    data.Phidot_q_qd[i] = rate;
  }
}

Eigen::VectorXd DriverResiduals(const NaturalModel& model, const Eigen::VectorXd& q, double t) {
  const double t0 = model.model.analysis.t0;
  Eigen::VectorXd r(model.f());
  for (int k = 0; k < model.f(); ++k) r[k] = q[model.drivers[k].slot] - model.drivers[k].law.At(t, t0);
  return r;
}

Eigen::VectorXd DriverRates(const NaturalModel& model, double t) {
  const double t0 = model.model.analysis.t0;
  Eigen::VectorXd r(model.f());
  for (int k = 0; k < model.f(); ++k) r[k] = model.drivers[k].law.RateAt(t, t0);
  return r;
}

Eigen::VectorXd DriverAccelerations(const NaturalModel& model, double t) {
  const double t0 = model.model.analysis.t0;
  Eigen::VectorXd r(model.f());
  for (int k = 0; k < model.f(); ++k) r[k] = model.drivers[k].law.AccelerationAt(t, t0);
  return r;
}

double ScaledResidual(const NaturalModel& model, const NaturalData& data) {
  double worst = 0.0;
  for (int i = 0; i < model.m(); ++i) worst = std::max(worst, std::fabs(data.Phi[i]) / model.rows[i].scale);
  return worst;
}

}  // namespace mechbench::numeric
