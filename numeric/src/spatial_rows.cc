// The spatial rows (RowKind k*3): value, partials and their time derivatives, dense and sparse
// assembly, and the Hessians (spatial.h).
#include "spatial_rows.h"

#include "mechbench/errors.h"
#include "mechbench/numeric/constraints.h"
#include "mechbench/numeric/spatial.h"

#include <algorithm>
#include <cmath>

namespace mechbench::numeric {
namespace {

using V3 = Eigen::Vector3d;

// Partials of one spatial row with respect to its entities (a gradient per entity, an entity may
// appear twice: the scatter sums) and its coordinate slot, each with its time derivative.
struct Partials3 {
  int ne = 0;
  std::array<int, 5> ent{};
  std::array<V3, 5> g, gd;
  int ns = 0;
  int slot = -1;
  double s = 0, sd = 0;
  void Ent(int e, const V3& grad, const V3& rate) {
    if (e < 0) return;
    ent[ne] = e, g[ne] = grad, gd[ne] = rate, ++ne;
  }
  void Slot(int i, double grad, double rate) {
    if (i < 0) return;
    slot = i, s = grad, sd = rate, ns = 1;
  }
};

bool IsDotRow(RowKind k) { return k == RowKind::kUnit3 || k == RowKind::kDistance3 || k == RowKind::kDot3; }

// The row's value at q and, with `out`, its partials (rates at qd).
double EvalRow3(const NaturalModel& nm, const ConstraintRow& row, const Eigen::VectorXd& q,
                const Eigen::VectorXd& qd, Partials3* out) {
  const auto& e = row.ent;
  const auto pos = [&](int k) { return EntityValue(nm, q, e[k]); };
  const auto vel = [&](int k) { return EntityRate(nm, qd, e[k]); };
  if (IsDotRow(row.kind)) {
    const V3 A = pos(0) - pos(1), B = pos(2) - pos(3);
    if (out) {
      const V3 Ad = vel(0) - vel(1), Bd = vel(2) - vel(3);
      out->Ent(e[0], B, Bd);
      out->Ent(e[1], -B, -Bd);
      out->Ent(e[2], A, Ad);
      out->Ent(e[3], -A, -Ad);
    }
    return A.dot(B) - row.c;
  }
  if (row.kind == RowKind::kLinear3) {
    const V3 unit = V3::Unit(row.axis);
    double v = 0;
    for (int k = 0; k < 5; ++k) {
      if (e[k] < 0) continue;
      v += row.coef[k] * pos(k)[row.axis];
      if (out) out->Ent(e[k], row.coef[k] * unit, V3::Zero());
    }
    return v;
  }
  if (row.kind == RowKind::kAngle3) {
    // Φ = cos θ T − sin θ D, T = (u × w)·a, D = u·w: sin(φ − θ) for unit u, w ⊥ a.
    const V3 u = pos(0), w = pos(1), a = pos(2);
    const double th = q[row.slots[0]], c = std::cos(th), s = std::sin(th);
    const double T = u.cross(w).dot(a), D = u.dot(w);
    if (out) {
      const V3 ud = vel(0), wd = vel(1), ad = vel(2);
      const double thd = qd[row.slots[0]];
      const double Td = ud.cross(w).dot(a) + u.cross(wd).dot(a) + u.cross(w).dot(ad), Dd = ud.dot(w) + u.dot(wd);
      out->Ent(e[0], c * w.cross(a) - s * w, -s * thd * w.cross(a) + c * (wd.cross(a) + w.cross(ad)) - c * thd * w - s * wd);
      out->Ent(e[1], c * a.cross(u) - s * u, -s * thd * a.cross(u) + c * (ad.cross(u) + a.cross(ud)) - c * thd * u - s * ud);
      out->Ent(e[2], c * u.cross(w), -s * thd * u.cross(w) + c * (ud.cross(w) + u.cross(wd)));
      out->Slot(row.slots[0], -s * T - c * D, -c * thd * T - s * Td + s * thd * D - c * Dd);
    }
    return c * T - s * D;
  }
  MB_ASSERT(row.kind == RowKind::kPointOnLine3, "a planar row in a spatial model");
  const int a = row.axis;
  const V3 unit = V3::Unit(a);
  const double s = q[row.slots[0]];
  const V3 w = pos(2) - pos(3);
  if (out) {
    const double sd = qd[row.slots[0]];
    out->Ent(e[0], unit, V3::Zero());
    out->Ent(e[1], -unit, V3::Zero());
    out->Ent(e[2], -s * unit, -sd * unit);
    out->Ent(e[3], s * unit, sd * unit);
    out->Slot(row.slots[0], -w[a], -(vel(2) - vel(3))[a]);
  }
  return (pos(0) - pos(1) - s * w)[a];
}

}  // namespace

Eigen::Vector3d EntityValue(const NaturalModel& model, const Eigen::VectorXd& q, int e) {
  if (e < 0) return V3::Zero();
  const Entity3& E = model.entities[e];
  V3 r;
  for (int c = 0; c < 3; ++c) r[c] = E.slot[c] >= 0 ? q[E.slot[c]] : E.value[c];
  return r;
}

Eigen::Vector3d EntityRate(const NaturalModel& model, const Eigen::VectorXd& qd, int e) {
  if (e < 0) return V3::Zero();
  const Entity3& E = model.entities[e];
  V3 v;
  for (int c = 0; c < 3; ++c) v[c] = E.slot[c] >= 0 ? qd[E.slot[c]] : 0.0;
  return v;
}

void SpatialRowHessian(const NaturalModel& model, const ConstraintRow& row, const Eigen::VectorXd& q,
                       std::vector<Eigen::Triplet<double>>& out) {
  const auto& e = row.ent;
  const auto add = [&](int a, int b, double v) {
    if (a < 0 || b < 0) return;
    out.emplace_back(a, b, v);
    out.emplace_back(b, a, v);
  };
  const auto slot = [&](int ent, int c) { return ent < 0 ? -1 : model.entities[ent].slot[c]; };
  if (IsDotRow(row.kind)) {
    // Φ = (e0 − e1)·(e2 − e3) − c: ∂²Φ/∂e_p∂e_r = s_p s_r I for p ∈ {0, 1}, r ∈ {2, 3}.
    const int sign[4] = {1, -1, 1, -1};
    for (int p = 0; p < 2; ++p)
      for (int r = 2; r < 4; ++r)
        for (int c = 0; c < 3; ++c) add(slot(e[p], c), slot(e[r], c), sign[p] * sign[r]);
  } else if (row.kind == RowKind::kPointOnLine3) {
    add(row.slots[0], slot(e[2], row.axis), -1.0);
    add(row.slots[0], slot(e[3], row.axis), 1.0);
  } else if (row.kind == RowKind::kAngle3) {
    // Φ = cos θ (u × w)·a − sin θ u·w: bilinear in each pair of u, w, a; θ's terms trigonometric.
    const V3 u = EntityValue(model, q, e[0]), w = EntityValue(model, q, e[1]), a = EntityValue(model, q, e[2]);
    const int th = row.slots[0];
    const double c = std::cos(q[th]), s = std::sin(q[th]);
    const auto block = [&](int p, int r, const Eigen::Matrix3d& B) {  // ∂²Φ/∂e_p∂e_r = B (row: e_p's axis)
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          if (B(i, j) != 0.0) add(slot(e[p], i), slot(e[r], j), B(i, j));
    };
    const auto skew = [](const V3& v) {
      Eigen::Matrix3d S;
      S << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
      return S;
    };
    block(0, 1, -c * skew(a) - s * Eigen::Matrix3d::Identity());  // ∂/∂w of c (w × a) − s w
    block(0, 2, c * skew(w));                                      // ∂/∂a of c (w × a)
    block(1, 2, -c * skew(u));                                     // ∂/∂a of c (a × u)
    const V3 gu = -s * w.cross(a) - c * w, gw = -s * a.cross(u) - c * u, ga = -s * u.cross(w);
    for (int i = 0; i < 3; ++i) {
      add(th, slot(e[0], i), gu[i]);
      add(th, slot(e[1], i), gw[i]);
      add(th, slot(e[2], i), ga[i]);
    }
    out.emplace_back(th, th, -c * u.cross(w).dot(a) + s * u.dot(w));  // the diagonal once
  }
}

namespace spatial {

void EvalPhi(const NaturalModel& model, NaturalData& data) {
  data.Phi.resize(model.m());
  for (int i = 0; i < model.m(); ++i) data.Phi[i] = EvalRow3(model, model.rows[i], data.q, data.qd, nullptr);
}

void Differentiate(const NaturalModel& model, const NaturalData& data, bool rate, Eigen::MatrixXd& J) {
  J.setZero(model.m(), model.n);
  for (int i = 0; i < model.m(); ++i) {
    Partials3 p;
    EvalRow3(model, model.rows[i], data.q, data.qd, &p);
    for (int k = 0; k < p.ne; ++k) {
      const V3& g = rate ? p.gd[k] : p.g[k];
      for (int c = 0; c < 3; ++c)
        if (const int s = model.entities[p.ent[k]].slot[c]; s >= 0) J(i, s) += g[c];
    }
    if (p.ns) J(i, p.slot) += rate ? p.sd : p.s;
  }
}

void Columns(const NaturalModel& model, const ConstraintRow& row, std::vector<int>& cols) {
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(model.n);
  Partials3 p;
  EvalRow3(model, row, zero, zero, &p);
  for (int k = 0; k < p.ne; ++k)
    for (int c = 0; c < 3; ++c) cols.push_back(model.entities[p.ent[k]].slot[c]);
  if (p.ns) cols.push_back(p.slot);
}

}  // namespace spatial

void SparseJacobian::Evaluate3(const NaturalModel& model, NaturalData& data, const Eigen::VectorXd& q,
                               const Eigen::VectorXd* qd, Eigen::VectorXd& phi, Eigen::VectorXd* jdot_qd,
                               bool rate_matrix) {
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
    Partials3 p;
    phi[k] = EvalRow3(model, model.rows[rows_[k]], data.q, data.qd, &p);
    const int* idx = index_.data() + start_[k];
    double rate = 0;
    for (int j = 0; j < p.ne; ++j, idx += 3) {
      for (int c = 0; c < 3; ++c)
        if (idx[c] >= 0) {
          values[idx[c]] += p.g[j][c];
          if (rates) rates[idx[c]] += p.gd[j][c];
        }
      if (qd) rate += p.gd[j].dot(EntityRate(model, *qd, p.ent[j]));
    }
    if (p.ns) {
      values[*idx] += p.s;
      if (rates) rates[*idx] += p.sd;
      if (qd) rate += p.sd * (*qd)[p.slot];
    }
    if (jdot_qd) (*jdot_qd)[k] = rate;
  }
}

}  // namespace mechbench::numeric
