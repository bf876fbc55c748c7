#include "mechbench/numeric/dynamics.h"
#include "mechbench/numeric/spatial.h"
#include "spatial_forces.h"

#include "mechbench/errors.h"
#include "planar.h"

#include <Eigen/SparseCore>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

namespace mechbench::numeric {
namespace {

using planar::Interpolation;

// The four q slots of a body's basic points (−1 for constant coordinates).
std::array<int, 4> BodySlots(const NaturalModel& model, const Body& body) {
  const auto& s0 = model.point_slot[body.points[0]];
  const auto& s1 = model.point_slot[body.points[1]];
  return {s0[0], s0[1], s1[0], s1[1]};
}

// A point body's element (model.h): over its point P and, on a guide along a moving body, that
// body's first two points r1, r2 (L apart), its centre of mass is r_G = C [r_P; r1; r2] and its
// rate of turning ω = |W [ṙ_P; ṙ1; ṙ2]|, with C = [I, −A, A], A = (c_x I + c_y P)/L and
// W = [0, −I, I]/L: the block's x axis is u = (r2 − r1)/L, so r_G = r_P + c_x u + c_y P u is linear
// in q and M_e = m CᵀC + I_G WᵀW is constant, as a two-point body's. On a fixed guide or none the
// block does not turn: C = [I], W = 0 (a constant com offset moves nothing).
struct PointBodyElement {
  std::array<int, 6> slot{-1, -1, -1, -1, -1, -1};
  Eigen::Matrix<double, 2, 6> C = Eigen::Matrix<double, 2, 6>::Zero(), W = Eigen::Matrix<double, 2, 6>::Zero();
};
PointBodyElement PointBodyElementOf(const NaturalModel& model, const Body& body) {
  PointBodyElement e;
  const auto& sp = model.point_slot[body.points[0]];
  e.slot[0] = sp[0], e.slot[1] = sp[1];
  e.C.leftCols<2>().setIdentity();
  if (body.guide < 0) return e;
  const Joint& j = model.model.joints[body.guide];
  if (j.type != JointType::kPointOnBody) return e;
  const Body& guide = model.model.bodies[j.body];
  const double L = guide.Length();
  MB_ASSERT(L > 0, "a guide body has a positive length");
  const auto& s1 = model.point_slot[guide.points[0]];
  const auto& s2 = model.point_slot[guide.points[1]];
  e.slot = {sp[0], sp[1], s1[0], s1[1], s2[0], s2[1]};
  Eigen::Matrix2d A;
  A << body.com_B.x(), -body.com_B.y(), body.com_B.y(), body.com_B.x();
  A /= L;
  e.C.middleCols<2>(2) = -A;
  e.C.rightCols<2>() = A;
  e.W.middleCols<2>(2) = -Eigen::Matrix2d::Identity() / L;
  e.W.rightCols<2>() = Eigen::Matrix2d::Identity() / L;
  return e;
}

}  // namespace

Eigen::Matrix<double, 6, 6> PointBodyMassMatrix(const NaturalModel& model, const Body& body, std::array<int, 6>& slot) {
  const PointBodyElement e = PointBodyElementOf(model, body);
  slot = e.slot;
  return body.mass * e.C.transpose() * e.C + body.inertia_com * e.W.transpose() * e.W;
}

Eigen::Matrix<double, 6, 1> PointBodyWeight(const NaturalModel& model, const Body& body, const Eigen::Vector2d& g_SI,
                                            std::array<int, 6>& slot) {
  const PointBodyElement e = PointBodyElementOf(model, body);
  slot = e.slot;
  return e.C.transpose() * (body.mass * g_SI);
}

Eigen::Matrix4d ElementMassMatrix(double mass, double L, const Eigen::Vector2d& com_B, double inertia_com) {
  MB_ASSERT(L > 0, "element mass matrix needs a positive length");
  const double I_i = inertia_com + mass * com_B.squaredNorm();  // polar inertia about point i
  const double a = I_i / (L * L), bx = mass * com_B.x() / L, by = mass * com_B.y() / L;
  Eigen::Matrix4d M;
  M << mass + a - 2 * bx, 0, bx - a, -by,
       0, mass + a - 2 * bx, by, bx - a,
       bx - a, by, a, 0,
       -by, bx - a, 0, a;
  return M;
}

void MassMatrix(const NaturalModel& model, NaturalData& data) {
  if (model.dim == 3) return SpatialMassMatrix(model, data);
  if (data.sparse) {
    // The same element entries, summed in the same (body) order by setFromTriplets; exact zeros
    // (terms that cancel) dropped, as a sparse view of the dense matrix drops them.
    std::vector<Eigen::Triplet<double>> t;
    t.reserve(16 * model.model.bodies.size());
    for (const Body& body : model.model.bodies) {
      if (!body.HasMass() || body.points.size() < 2) continue;
      const Eigen::Matrix4d Me = ElementMassMatrix(body.mass, body.Length(), body.com_B, body.inertia_com);
      const auto slot = BodySlots(model, body);
      for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i)
          if (slot[i] >= 0 && slot[j] >= 0) t.emplace_back(slot[i], slot[j], Me(i, j));
    }
    for (const Body& body : model.model.bodies) {
      if (!body.HasMass() || !body.IsPointBody()) continue;
      std::array<int, 6> slot;
      const Eigen::Matrix<double, 6, 6> Me = PointBodyMassMatrix(model, body, slot);
      for (int j = 0; j < 6; ++j)
        for (int i = 0; i < 6; ++i)
          if (slot[i] >= 0 && slot[j] >= 0) t.emplace_back(slot[i], slot[j], Me(i, j));
    }
    data.M_sparse.resize(model.n, model.n);
    data.M_sparse.setFromTriplets(t.begin(), t.end());
    data.M_sparse.prune([](Eigen::Index, Eigen::Index, double v) { return v != 0.0; });
    data.M_sparse.makeCompressed();
    return;
  }
  data.M.setZero(model.n, model.n);
  for (const Body& body : model.model.bodies) {
    if (!body.HasMass() || body.points.size() < 2) continue;
    const Eigen::Matrix4d Me = ElementMassMatrix(body.mass, body.Length(), body.com_B, body.inertia_com);
    const auto slot = BodySlots(model, body);
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j)
        if (slot[i] >= 0 && slot[j] >= 0) data.M(slot[i], slot[j]) += Me(i, j);
  }
  for (const Body& body : model.model.bodies) {
    if (!body.HasMass() || !body.IsPointBody()) continue;
    std::array<int, 6> slot;
    const Eigen::Matrix<double, 6, 6> Me = PointBodyMassMatrix(model, body, slot);
    for (int i = 0; i < 6; ++i)
      for (int j = 0; j < 6; ++j)
        if (slot[i] >= 0 && slot[j] >= 0) data.M(slot[i], slot[j]) += Me(i, j);
  }
}

void GeneralizedForces(const NaturalModel& model, NaturalData& data) {
  if (model.dim == 3) return SpatialGeneralizedForces(model, data);
  data.Q.setZero(model.n);
  // Gravity is in length/s²; newtons need m/s².
  const Eigen::Vector2d g_SI = model.model.gravity * model.meters_per_unit;
  for (const Body& body : model.model.bodies) {
    if (!body.HasMass() || body.points.size() < 2) continue;
    const Eigen::Vector4d Qe = Interpolation(body.Length(), body.com_B).transpose() * (body.mass * g_SI);
    const auto slot = BodySlots(model, body);
    for (int i = 0; i < 4; ++i)
      if (slot[i] >= 0) data.Q[slot[i]] += Qe[i];
  }
  for (const Body& body : model.model.bodies) {
    if (!body.HasMass() || !body.IsPointBody()) continue;
    std::array<int, 6> slot;
    const Eigen::Matrix<double, 6, 1> Qe = PointBodyWeight(model, body, g_SI, slot);
    for (int i = 0; i < 6; ++i)
      if (slot[i] >= 0) data.Q[slot[i]] += Qe[i];
  }
  for (const PointForce& f : model.model.forces) {
    if (!f.IsConstantWorld()) continue;  // a force element (AddElementForces)
    for (int axis = 0; axis < 2; ++axis) {
      const int s = model.point_slot[f.point][axis];
      if (s >= 0) data.Q[s] += f.f_W[axis];
    }
  }
}

}  // namespace mechbench::numeric

// ---- force elements ---------------------------------------------------------------------------

namespace mechbench::numeric {
namespace {

Eigen::Vector2d Position(const NaturalModel& model, const Eigen::VectorXd& q, int p) {
  Eigen::Vector2d r;
  for (int axis = 0; axis < 2; ++axis) {
    const int s = model.point_slot[p][axis];
    r[axis] = s >= 0 ? q[s] : model.point_const[p][axis];
  }
  return r;
}

Eigen::Vector2d Rate(const NaturalModel& model, const Eigen::VectorXd& qd, int p) {
  Eigen::Vector2d v;
  for (int axis = 0; axis < 2; ++axis) {
    const int s = model.point_slot[p][axis];
    v[axis] = s >= 0 ? qd[s] : 0.0;
  }
  return v;
}

std::array<int, 4> PairSlots(const NaturalModel& model, int a, int b) {
  return {model.point_slot[a][0], model.point_slot[a][1], model.point_slot[b][0], model.point_slot[b][1]};
}

// A spring–damper's state: d = r_b − r_a, L, e = d/L (0 when L = 0), L̇, its parameters k, c, L0,
// F0 (the constants, or the laws at the load variables x), tension F [N].
struct SpringState {
  Eigen::Vector2d d, e, v;
  double L = 0, Ldot = 0, F = 0;
  std::array<double, 4> p{};  // SpringDamper::Param order
};
// x: the load variables [t, q, q̇] when the spring has a law (LoadVariables), else unused. With
// grad (four buffers of CompiledExpr::kMaxVariables), each law's gradient over its variables.
SpringState Spring(const NaturalModel& model, const SpringDamper& s, const Eigen::VectorXd& q, const Eigen::VectorXd* qd,
                   const std::vector<double>* x = nullptr, std::vector<double>* grad = nullptr) {
  const double u = model.meters_per_unit;
  SpringState st;
  st.d = Position(model, q, s.points[1]) - Position(model, q, s.points[0]);
  st.v = qd ? Eigen::Vector2d(Rate(model, *qd, s.points[1]) - Rate(model, *qd, s.points[0])) : Eigen::Vector2d::Zero();
  st.L = st.d.norm();
  st.e = st.L > 0 ? Eigen::Vector2d(st.d / st.L) : Eigen::Vector2d::Zero();
  st.Ldot = st.e.dot(st.v);
  st.p = {s.stiffness, s.damping, s.free_length, s.preload};
  if (x)
    for (int k = 0; k < 4; ++k)
      if (s.law[k]) st.p[k] = grad ? s.law[k]->EvalGradient(x->data(), grad[k].data()) : s.law[k]->Eval(x->data());
  st.F = st.p[0] * (st.L - st.p[2]) * u + st.p[1] * st.Ldot * u + st.p[3];
  return st;
}

const Eigen::Matrix2d kPerp = (Eigen::Matrix2d() << 0, -1, 1, 0).finished();

// [[X, −X], [−X, X]] into a 4 × 4 block.
Eigen::Matrix4d Pattern(const Eigen::Matrix2d& X) {
  Eigen::Matrix4d B;
  B << X, -X, -X, X;
  return B;
}

// A varying point force's frame → world rotation: I, or [d, P d]/L for a body frame (d = r_j − r_i,
// L the body's constant length, so that it is linear in q as the torque's pair is).
Eigen::Matrix2d ForceFrame(const NaturalModel& model, const Eigen::VectorXd& q, const PointForce& f) {
  if (f.frame < 0) return Eigen::Matrix2d::Identity();
  const Body& b = model.model.bodies[f.frame];
  const Eigen::Vector2d d = (Position(model, q, b.points[1]) - Position(model, q, b.points[0])) / b.Length();
  Eigen::Matrix2d R;
  R << d, kPerp * d;
  return R;
}

// Its components in its frame at the load variables x [N]; with grad (two buffers of
// CompiledExpr::kMaxVariables), each law's gradient over its variables.
Eigen::Vector2d ForceComponents(const PointForce& f, const std::vector<double>& x, std::vector<double>* grad = nullptr) {
  Eigen::Vector2d F = f.components;
  for (int k = 0; k < 2; ++k)
    if (f.law[k]) F[k] = grad ? f.law[k]->EvalGradient(x.data(), grad[k].data()) : f.law[k]->Eval(x.data());
  return F;
}

}  // namespace

namespace detail {

// The load variables [t, q, q̇] (model.h: LoadVarQ) for a law.
void LoadVariables(const NaturalModel& model, const Eigen::VectorXd& q, const Eigen::VectorXd& qd, double t,
                   std::vector<double>& x) {
  const int n = model.n;
  x.resize(static_cast<size_t>(1 + 2 * n));
  x[kLoadVarTime] = t;
  for (int i = 0; i < n; ++i) x[LoadVarQ(i)] = q[i], x[LoadVarQd(i, n)] = qd.size() == n ? qd[i] : 0.0;
}
void AddSlot(std::vector<int>& slot, int s) {
  if (s >= 0 && std::find(slot.begin(), slot.end(), s) == slot.end()) slot.push_back(s);
}
int Column(const std::vector<int>& slot, int s) {
  const auto it = std::find(slot.begin(), slot.end(), s);
  return s >= 0 && it != slot.end() ? static_cast<int>(it - slot.begin()) : -1;
}

}  // namespace detail

using detail::AddSlot;
using detail::Column;
using detail::LoadVariables;

std::vector<double> TorqueValues(const NaturalModel& model, const Eigen::VectorXd& q, const Eigen::VectorXd& qd, double t) {
  std::vector<double> out, x;
  for (const BodyTorque& bt : model.model.torques) {
    if (!bt.law) {
      out.push_back(bt.torque);
      continue;
    }
    if (x.empty()) LoadVariables(model, q, qd, t, x);
    out.push_back(bt.law->Eval(x.data()));
  }
  return out;
}

std::vector<ElementPointForce> ElementPointForces(const NaturalModel& model, const Eigen::VectorXd& q,
                                                  const Eigen::VectorXd& qd, double t) {
  std::vector<ElementPointForce> out;
  std::vector<double> x;
  for (const SpringDamper& s : model.model.springs) {
    if (s.HasLaw() && x.empty()) LoadVariables(model, q, qd, t, x);
    const SpringState st = Spring(model, s, q, &qd, s.HasLaw() ? &x : nullptr);
    out.push_back({s.points[0], -1, st.F * st.e});
    out.push_back({s.points[1], -1, -st.F * st.e});
  }
  const std::vector<double> torque = TorqueValues(model, q, qd, t);
  for (size_t k = 0; k < torque.size(); ++k) {
    const BodyTorque& bt = model.model.torques[k];
    const Body& b = model.model.bodies[bt.body];
    const double L = b.Length();
    const Eigen::Vector2d f_j = torque[k] / (model.meters_per_unit * L * L) * kPerp *
                                (Position(model, q, b.points[1]) - Position(model, q, b.points[0]));
    out.push_back({b.points[0], bt.body, -f_j});
    out.push_back({b.points[1], bt.body, f_j});
  }
  for (const PointForce& f : model.model.forces) {
    if (f.IsConstantWorld()) continue;
    if (x.empty()) LoadVariables(model, q, qd, t, x);
    out.push_back({f.point, f.frame, ForceFrame(model, q, f) * ForceComponents(f, x)});
  }
  return out;
}

void AddElementForces(const NaturalModel& model, const Eigen::VectorXd& q, const Eigen::VectorXd& qd, double t,
                      Eigen::VectorXd& Q) {
  for (const ElementPointForce& f : ElementPointForces(model, q, qd, t))
    for (int axis = 0; axis < 2; ++axis)
      if (const int s = model.point_slot[f.point][axis]; s >= 0) Q[s] += f.f_W[axis];
  const double u = model.meters_per_unit;
  for (const TorsionSpring& ts : model.model.torsions) {
    const double th = q[ts.slot], thd = qd.size() == q.size() ? qd[ts.slot] : 0.0;
    Q[ts.slot] += (-ts.stiffness * (th - ts.free_angle) - ts.damping * thd + ts.preload) / u;
  }
  detail::AddSpatialElementForces(model, q, qd, t, Q);
}

std::vector<std::vector<int>> ElementSlots(const NaturalModel& model) {
  std::vector<std::vector<int>> out;
  auto pair = [&](int a, int b) {
    const std::array<int, 4> s = PairSlots(model, a, b);
    return std::vector<int>(s.begin(), s.end());
  };
  const int n = model.n;
  for (const SpringDamper& s : model.model.springs) {
    std::vector<int> slot = pair(s.points[0], s.points[1]);
    for (const auto& law : s.law)  // a law adds the slots it reads
      if (law)
        for (int var : law->variables())
          if (var != kLoadVarTime) AddSlot(slot, (var - 1) % n);
    out.push_back(slot);
  }
  for (const BodyTorque& t : model.model.torques) {
    const Body& b = model.model.bodies[t.body];
    std::vector<int> slot = pair(b.points[0], b.points[1]);
    if (t.law)
      for (int var : t.law->variables()) {
        const int s = var == kLoadVarTime ? -1 : (var - 1) % n;  // q.<slot> or qd.<slot>
        if (s >= 0 && std::find(slot.begin(), slot.end(), s) == slot.end()) slot.push_back(s);
      }
    out.push_back(slot);
  }
  for (const TorsionSpring& ts : model.model.torsions) out.push_back({ts.slot});
  for (const PointForce& f : model.model.forces) {
    if (f.IsConstantWorld()) continue;
    std::vector<int> slot;
    for (int axis = 0; axis < 2; ++axis) AddSlot(slot, model.point_slot[f.point][axis]);
    if (f.frame >= 0)
      for (int p : {0, 1})
        for (int axis = 0; axis < 2; ++axis) AddSlot(slot, model.point_slot[model.model.bodies[f.frame].points[p]][axis]);
    for (const auto& law : f.law)
      if (law)
        for (int var : law->variables())
          if (var != kLoadVarTime) AddSlot(slot, (var - 1) % n);
    out.push_back(slot);
  }
  detail::AppendSpatialElementSlots(model, out);
  return out;
}

void ElementDerivatives(const NaturalModel& model, const Eigen::VectorXd& q, const Eigen::VectorXd& qd, double t,
                        std::vector<ElementDerivative>& out) {
  const double u = model.meters_per_unit;
  const std::vector<std::vector<int>> slots = ElementSlots(model);
  out.resize(slots.size());
  for (size_t e = 0; e < slots.size(); ++e) {
    const int w = static_cast<int>(slots[e].size());
    out[e].slot = slots[e];
    out[e].K.setZero(w, w);
    out[e].C.setZero(w, w);
  }
  size_t k = 0;
  const int n = model.n;
  std::vector<double> x, grad(CompiledExpr::kMaxVariables);
  std::vector<double> grad4[4];
  for (const SpringDamper& s : model.model.springs) {
    ElementDerivative& D = out[k++];
    if (s.HasLaw() && x.empty()) LoadVariables(model, q, qd, t, x);
    if (s.HasLaw() && grad4[0].empty())
      for (auto& g : grad4) g.assign(CompiledExpr::kMaxVariables, 0.0);
    const SpringState st = Spring(model, s, q, &qd, s.HasLaw() ? &x : nullptr, s.HasLaw() ? grad4 : nullptr);
    const double k_s = st.p[SpringDamper::kStiffness], c_s = st.p[SpringDamper::kDamping];
    if (!(st.L > 0)) {
      // Coincident ends: only a zero-length spring (L0 = 0) is smooth there, f_b = −k u d.
      D.K.topLeftCorner<4, 4>() = Pattern(-k_s * u * Eigen::Matrix2d::Identity());
      continue;
    }
    // f_b = −F e: ∂f_b/∂d = −e (∂F/∂d)ᵀ − F (I − e eᵀ)/L, ∂F/∂d = k u e + c u (I − e eᵀ) v / L.
    const Eigen::Matrix2d across = Eigen::Matrix2d::Identity() - st.e * st.e.transpose();
    const Eigen::Vector2d dF = k_s * u * st.e + c_s * u * (across * st.v) / st.L;
    D.K.topLeftCorner<4, 4>() = Pattern(-st.e * dF.transpose() - st.F * across / st.L);
    D.C.topLeftCorner<4, 4>() = Pattern(-c_s * u * st.e * st.e.transpose());
    if (!s.HasLaw()) continue;
    // A law p adds ∂Q/∂F ∂F/∂p ∂p/∂q_s (or ∂q̇_s) in column s, ∂Q/∂F = [e; −e] on [x_a, y_a, x_b, y_b]
    // and ∂F/∂p = (L − L0) u, L̇ u, −k u, 1 for k, c, L0, F0.
    Eigen::Vector4d dQ_dF;
    dQ_dF << st.e, -st.e;
    const double dF_dp[4] = {(st.L - st.p[SpringDamper::kFreeLength]) * u, st.Ldot * u, -k_s * u, 1.0};
    for (int p = 0; p < 4; ++p) {
      if (!s.law[p]) continue;
      const std::vector<int>& vars = s.law[p]->variables();
      for (size_t v = 0; v < vars.size(); ++v) {
        if (vars[v] == kLoadVarTime) continue;
        const int col = Column(D.slot, (vars[v] - 1) % n);
        if (col >= 0) (vars[v] > n ? D.C : D.K).block<4, 1>(0, col) += dQ_dF * (dF_dp[p] * grad4[p][v]);
      }
    }
  }
  for (const BodyTorque& bt : model.model.torques) {
    ElementDerivative& D = out[k++];
    const Body& b = model.model.bodies[bt.body];
    const double L = b.Length(), per_T = 1 / (u * L * L);  // τ = T per_T
    double T = bt.torque;
    if (bt.law) {
      if (x.empty()) LoadVariables(model, q, qd, t, x);
      T = bt.law->EvalGradient(x.data(), grad.data());
    }
    D.K.topLeftCorner<4, 4>() = Pattern(T * per_T * kPerp);
    if (!bt.law) continue;
    // ∂Q/∂T = per_T [−P d; P d] on [x_i, y_i, x_j, y_j], times ∂T/∂q_s or ∂T/∂q̇_s in column s.
    const Eigen::Vector2d Pd = per_T * kPerp * (Position(model, q, b.points[1]) - Position(model, q, b.points[0]));
    Eigen::Vector4d dQ_dT;
    dQ_dT << -Pd, Pd;
    const std::vector<int>& vars = bt.law->variables();
    for (size_t v = 0; v < vars.size(); ++v) {
      if (vars[v] == kLoadVarTime) continue;
      const bool rate = vars[v] > n;
      const int s = (vars[v] - 1) % n;
      const int col = static_cast<int>(std::find(D.slot.begin(), D.slot.end(), s) - D.slot.begin());
      (rate ? D.C : D.K).block<4, 1>(0, col) += dQ_dT * grad[v];
    }
  }
  for (const TorsionSpring& ts : model.model.torsions) {
    ElementDerivative& D = out[k++];
    D.K(0, 0) = -ts.stiffness / u;
    D.C(0, 0) = -ts.damping / u;
  }
  // A varying point force f_W = R F(t, q, q̇) at point P: a body frame adds ∂f_W/∂r_j = (F_x I +
  // F_y P)/L = −∂f_W/∂r_i; a law adds R_k ∂F_k/∂q_s (or ∂q̇_s) in column s.
  std::vector<double> grad2[2] = {std::vector<double>(CompiledExpr::kMaxVariables),
                                  std::vector<double>(CompiledExpr::kMaxVariables)};
  for (const PointForce& f : model.model.forces) {
    if (f.IsConstantWorld()) continue;
    ElementDerivative& D = out[k++];
    if (x.empty()) LoadVariables(model, q, qd, t, x);
    const Eigen::Vector2d F = ForceComponents(f, x, grad2);
    const Eigen::Matrix2d R = ForceFrame(model, q, f);
    const int row[2] = {Column(D.slot, model.point_slot[f.point][0]), Column(D.slot, model.point_slot[f.point][1])};
    if (f.frame >= 0) {
      const Body& b = model.model.bodies[f.frame];
      const Eigen::Matrix2d A = (F.x() * Eigen::Matrix2d::Identity() + F.y() * kPerp) / b.Length();
      for (int a = 0; a < 2; ++a) {
        if (row[a] < 0) continue;
        for (int c = 0; c < 2; ++c) {
          if (const int cj = Column(D.slot, model.point_slot[b.points[1]][c]); cj >= 0) D.K(row[a], cj) += A(a, c);
          if (const int ci = Column(D.slot, model.point_slot[b.points[0]][c]); ci >= 0) D.K(row[a], ci) -= A(a, c);
        }
      }
    }
    for (int comp = 0; comp < 2; ++comp) {
      if (!f.law[comp]) continue;
      const std::vector<int>& vars = f.law[comp]->variables();
      for (size_t v = 0; v < vars.size(); ++v) {
        if (vars[v] == kLoadVarTime) continue;
        const bool rate = vars[v] > n;
        const int col = Column(D.slot, (vars[v] - 1) % n);
        for (int a = 0; a < 2; ++a)
          if (row[a] >= 0 && col >= 0) (rate ? D.C : D.K)(row[a], col) += R(a, comp) * grad2[comp][v];
      }
    }
  }
  detail::SpatialElementDerivatives(model, q, qd, t, out, k);
}

double SpringPotential(const NaturalModel& model, const Eigen::VectorXd& q) {
  const double u = model.meters_per_unit;
  double V = 0;
  for (const SpringDamper& s : model.model.springs) {
    if (s.HasLaw()) continue;  // no potential: its work is in LawSpringPower
    const double x = (Spring(model, s, q, nullptr).L - s.free_length) * u;
    V += 0.5 * s.stiffness * x * x + s.preload * x;
  }
  for (const TorsionSpring& ts : model.model.torsions) {
    const double x = q[ts.slot] - ts.free_angle;
    V += 0.5 * ts.stiffness * x * x - ts.preload * x;
  }
  return V + detail::SpatialSpringPotential(model, q);
}

double DamperPower(const NaturalModel& model, const Eigen::VectorXd& q, const Eigen::VectorXd& qd,
                   const Eigen::VectorXd* qdd, double* rate) {
  const double u = model.meters_per_unit;
  double P = 0, dP = 0;
  for (const SpringDamper& s : model.model.springs) {
    if (s.damping == 0 || s.HasLaw()) continue;  // a spring with a law: LawSpringPower
    const SpringState st = Spring(model, s, q, &qd);
    P += s.damping * st.Ldot * st.Ldot * u * u;
    if (qdd && rate && st.L > 0) {
      const Eigen::Vector2d a = Rate(model, *qdd, s.points[1]) - Rate(model, *qdd, s.points[0]);
      const double Lddot = st.e.dot(a) + (st.v.squaredNorm() - st.Ldot * st.Ldot) / st.L;
      dP += 2 * s.damping * st.Ldot * Lddot * u * u;
    }
  }
  for (const TorsionSpring& ts : model.model.torsions) {
    const double w = qd[ts.slot];
    P += ts.damping * w * w;
    if (qdd && rate) dP += 2 * ts.damping * w * (*qdd)[ts.slot];
  }
  P += detail::SpatialDamperPower(model, q, qd, qdd && rate ? qdd : nullptr, dP);
  if (rate) *rate = dP;
  return P;
}

double LawTorquePower(const NaturalModel& model, const Eigen::VectorXd& q, const Eigen::VectorXd& qd, double t,
                      const Eigen::VectorXd* qdd, double* rate) {
  const int n = model.n;
  std::vector<double> x, grad(CompiledExpr::kMaxVariables);
  double P = 0, dP = 0;
  bool all_rates = qdd != nullptr;
  for (const BodyTorque& bt : model.model.torques) {
    if (!bt.law) continue;
    if (x.empty()) LoadVariables(model, q, qd, t, x);
    const double T = bt.law->EvalGradient(x.data(), grad.data());
    const Body& b = model.model.bodies[bt.body];
    const Eigen::Vector2d d = Position(model, q, b.points[1]) - Position(model, q, b.points[0]);
    const Eigen::Vector2d v = Rate(model, qd, b.points[1]) - Rate(model, qd, b.points[0]);
    const double L2 = d.squaredNorm(), omega = (d.x() * v.y() - d.y() * v.x()) / L2;
    P += T * omega;
    if (!qdd) continue;
    // Ṫ = ∂T/∂t + ∇_q T·q̇ + ∇_q̇ T·q̈; α = (d × d̈)/L² (|d| constant in a rigid body).
    double Tdot = 0;
    const std::vector<int>& vars = bt.law->variables();
    for (size_t k = 0; k < vars.size(); ++k) {
      if (vars[k] == kLoadVarTime) Tdot += grad[k];
      else if (vars[k] <= n) Tdot += grad[k] * qd[vars[k] - 1];
      else Tdot += grad[k] * (*qdd)[vars[k] - 1 - n];
    }
    const Eigen::Vector2d a = Rate(model, *qdd, b.points[1]) - Rate(model, *qdd, b.points[0]);
    const double alpha = (d.x() * a.y() - d.y() * a.x()) / L2;
    dP += Tdot * omega + T * alpha;
  }
  P += detail::SpatialTorquePower(model, q, qd, t, qdd, dP);  // every 3-D torque: T·ω
  if (rate) *rate = all_rates ? dP : 0.0;
  return P;
}

double VaryingPointForcePower(const NaturalModel& model, const Eigen::VectorXd& q, const Eigen::VectorXd& qd, double t,
                              const Eigen::VectorXd* qdd, double* rate) {
  const int n = model.n;
  const double u = model.meters_per_unit;
  std::vector<double> x, grad2[2] = {std::vector<double>(CompiledExpr::kMaxVariables),
                                     std::vector<double>(CompiledExpr::kMaxVariables)};
  double P = 0, dP = 0;
  for (const PointForce& f : model.model.forces) {
    if (f.IsConstantWorld()) continue;
    if (x.empty()) LoadVariables(model, q, qd, t, x);
    const Eigen::Vector2d F = ForceComponents(f, x, grad2);
    const Eigen::Matrix2d R = ForceFrame(model, q, f);
    const Eigen::Vector2d v = Rate(model, qd, f.point);
    P += (R * F).dot(v) * u;
    if (!qdd) continue;
    // d(f_W·v)/dt = (Ṙ F + R Ḟ)·v + f_W·a, Ḟ_k = ∂F_k/∂t + ∇_q F_k·q̇ + ∇_q̇ F_k·q̈.
    Eigen::Vector2d Fdot = Eigen::Vector2d::Zero();
    for (int comp = 0; comp < 2; ++comp) {
      if (!f.law[comp]) continue;
      const std::vector<int>& vars = f.law[comp]->variables();
      for (size_t k = 0; k < vars.size(); ++k) {
        if (vars[k] == kLoadVarTime) Fdot[comp] += grad2[comp][k];
        else if (vars[k] <= n) Fdot[comp] += grad2[comp][k] * qd[vars[k] - 1];
        else Fdot[comp] += grad2[comp][k] * (*qdd)[vars[k] - 1 - n];
      }
    }
    Eigen::Matrix2d Rdot = Eigen::Matrix2d::Zero();
    if (f.frame >= 0) {
      const Body& b = model.model.bodies[f.frame];
      const Eigen::Vector2d dd = (Rate(model, qd, b.points[1]) - Rate(model, qd, b.points[0])) / b.Length();
      Rdot << dd, kPerp * dd;
    }
    dP += ((Rdot * F + R * Fdot).dot(v) + (R * F).dot(Rate(model, *qdd, f.point))) * u;
  }
  P += detail::SpatialForcePower(model, q, qd, t, qdd, dP);
  if (rate) *rate = qdd ? dP : 0.0;
  return P;
}

double LawSpringPower(const NaturalModel& model, const Eigen::VectorXd& q, const Eigen::VectorXd& qd, double t,
                      const Eigen::VectorXd* qdd, double* rate) {
  const int n = model.n;
  const double u = model.meters_per_unit;
  std::vector<double> x, grad[4];
  double P = 0, dP = 0;
  for (const SpringDamper& s : model.model.springs) {
    if (!s.HasLaw()) continue;
    if (x.empty()) {
      LoadVariables(model, q, qd, t, x);
      for (auto& g : grad) g.assign(CompiledExpr::kMaxVariables, 0.0);
    }
    const SpringState st = Spring(model, s, q, &qd, &x, grad);
    P -= st.F * st.Ldot * u;
    if (!qdd || !(st.L > 0)) continue;
    // d(−F L̇ u)/dt = −(Ḟ L̇ + F L̈) u, Ḟ = k̇ (L − L0) u + k (L̇ − L̇0) u + ċ L̇ u + c L̈ u + Ḟ0, each
    // ṗ = ∂p/∂t + ∇_q p·q̇ + ∇_q̇ p·q̈; L̈ = e·(r̈_b − r̈_a) + (|v|² − L̇²)/L.
    const Eigen::Vector2d a = Rate(model, *qdd, s.points[1]) - Rate(model, *qdd, s.points[0]);
    const double Lddot = st.e.dot(a) + (st.v.squaredNorm() - st.Ldot * st.Ldot) / st.L;
    double pdot[4] = {0, 0, 0, 0};
    for (int p = 0; p < 4; ++p) {
      if (!s.law[p]) continue;
      const std::vector<int>& vars = s.law[p]->variables();
      for (size_t k = 0; k < vars.size(); ++k) {
        if (vars[k] == kLoadVarTime) pdot[p] += grad[p][k];
        else if (vars[k] <= n) pdot[p] += grad[p][k] * qd[vars[k] - 1];
        else pdot[p] += grad[p][k] * (*qdd)[vars[k] - 1 - n];
      }
    }
    const double k_s = st.p[SpringDamper::kStiffness], c_s = st.p[SpringDamper::kDamping];
    const double Fdot = pdot[0] * (st.L - st.p[SpringDamper::kFreeLength]) * u + k_s * (st.Ldot - pdot[2]) * u +
                        pdot[1] * st.Ldot * u + c_s * Lddot * u + pdot[3];
    dP -= (Fdot * st.Ldot + st.F * Lddot) * u;
  }
  P += detail::SpatialLawSpringPower(model, q, qd, t, qdd, dP);
  if (rate) *rate = qdd ? dP : 0.0;
  return P;
}

std::vector<double> TorqueBodyAngles(const NaturalModel& model, const Eigen::VectorXd& q) {
  std::vector<double> out;
  for (const BodyTorque& t : model.model.torques) {
    const Body& b = model.model.bodies[t.body];
    const Eigen::Vector2d d = Position(model, q, b.points[1]) - Position(model, q, b.points[0]);
    out.push_back(std::atan2(d.y(), d.x()));
  }
  return out;
}

}  // namespace mechbench::numeric
