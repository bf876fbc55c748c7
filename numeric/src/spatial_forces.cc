// Force elements of spatial scenes (spatial_forces.h): spring–dampers between two points, point
// forces with a law and torques on rigid bodies, in natural coordinates. Every point of a spatial
// scene has its own q slots (an attached point is tied to its body's basis by rows), so a force at
// a point is a generalized force on that point's three slots.
//
// A torque T [N·m] on a rigid body with basis e0 (a point), e1, e2, e3 and columns
// X = [X1 X2 X3], X_k = e_k − e0 (a point) or e_k (a unit vector). The body's rows keep the Gram
// matrix G = Xᵀ X constant (its value in the file), so X⁻¹ = G⁻¹ Xᵀ and its angular velocity,
// from Ẋ = [ω]× X, is ω = vee(Ẋ X⁻¹) = ½ vee(Ẋ G⁻¹ Xᵀ − X G⁻¹ Ẋᵀ). Its power is then
//   T·ω = ½ Σ_k (T × Y_k)·Ẋ_k,  Y = X G⁻¹  (Σ_ij [T]×_ij A_ij = T·vee(A − Aᵀ) for any A),
// so by virtual power the generalized force on column X_k is Q_Xk = ½ T × Y_k, which goes to e_k's
// slots and, for a point e_k, with a minus sign to e0's. Check: for δX_k = δθ × X_k,
// ½ Σ_k (T × Y_k)·(δθ × X_k) = ½ [(T·δθ) tr(Yᵀ X) − Tᵀ X Yᵀ δθ] = ½ (3 − 1) T·δθ, since Yᵀ X = I
// and X Yᵀ = X G⁻¹ Xᵀ = I. Q is linear in q for a constant T: ∂Q_Xk/∂X_j = ½ G⁻¹_jk [T]×.
// As everywhere in dynamics.h, Q δq u is the virtual work [J] (u = meters_per_unit).
#include "spatial_forces.h"

#include "mechbench/errors.h"
#include "mechbench/numeric/spatial.h"

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <cmath>

namespace mechbench::numeric::detail {
namespace {

using V3 = Eigen::Vector3d;
using M3 = Eigen::Matrix3d;
using Vec12 = Eigen::Matrix<double, 12, 1>;

M3 Skew(const V3& a) {
  M3 S;
  S << 0, -a.z(), a.y(), a.z(), 0, -a.x(), -a.y(), a.x(), 0;
  return S;
}

const Eigen::VectorXd* Rates(const Eigen::VectorXd& q, const Eigen::VectorXd& qd) {
  return qd.size() == q.size() ? &qd : nullptr;
}

// The rate of a law p(t, q, q̇) along the motion: ∂p/∂t + ∇_q p·q̇ + ∇_q̇ p·q̈ (grad over its variables).
double LawRate(const CompiledExpr& law, const std::vector<double>& grad, const Eigen::VectorXd& qd,
               const Eigen::VectorXd& qdd) {
  const int n = static_cast<int>(qd.size());
  double r = 0;
  const std::vector<int>& vars = law.variables();
  for (size_t k = 0; k < vars.size(); ++k) {
    if (vars[k] == kLoadVarTime) r += grad[k];
    else if (vars[k] <= n) r += grad[k] * qd[vars[k] - 1];
    else r += grad[k] * qdd[vars[k] - 1 - n];
  }
  return r;
}

// A buffer of CompiledExpr::kMaxVariables per component, for the laws' gradients.
using Grads = std::array<std::vector<double>, 3>;
Grads NewGrads() {
  Grads g;
  for (auto& v : g) v.assign(CompiledExpr::kMaxVariables, 0.0);
  return g;
}

// A load's world value at the load variables x; with grad (three buffers of
// CompiledExpr::kMaxVariables), each law's gradient over its variables.
V3 LoadValue(const SpatialLoad& l, const std::vector<double>& x, std::vector<double>* grad = nullptr) {
  V3 v = l.value;
  for (int c = 0; c < 3; ++c)
    if (l.law[c]) v[c] = grad ? l.law[c]->EvalGradient(x.data(), grad[c].data()) : l.law[c]->Eval(x.data());
  return v;
}

// ---- spring–dampers ----
// A spring's state; p = k, c, L0, F0 (SpringDamper::Param), a law's value at the load variables.
struct Spring3 {
  V3 d, e, v;
  double L = 0, Ldot = 0, F = 0;
  std::array<double, 4> p{};
};
// With x (the load variables), each law's value (and with grad, four buffers of
// CompiledExpr::kMaxVariables, its gradient); without, the constants (a spring with a law needs x).
Spring3 SpringAt(const NaturalModel& model, const SpringDamper& s, const Eigen::VectorXd& q, const Eigen::VectorXd* qd,
                 const std::vector<double>* x = nullptr, std::vector<double>* grad = nullptr) {
  const double u = model.meters_per_unit;
  Spring3 st;
  st.d = EntityValue(model, q, s.points[1]) - EntityValue(model, q, s.points[0]);
  st.v = qd ? V3(EntityRate(model, *qd, s.points[1]) - EntityRate(model, *qd, s.points[0])) : V3::Zero();
  st.L = st.d.norm();
  st.e = st.L > 0 ? V3(st.d / st.L) : V3::Zero();
  st.Ldot = st.e.dot(st.v);
  st.p = {s.stiffness, s.damping, s.free_length, s.preload};
  if (x)
    for (int k = 0; k < 4; ++k)
      if (s.law[k]) st.p[k] = grad ? s.law[k]->EvalGradient(x->data(), grad[k].data()) : s.law[k]->Eval(x->data());
  st.F = st.p[0] * (st.L - st.p[2]) * u + st.p[1] * st.Ldot * u + st.p[3];
  return st;
}
bool AnySpringLaw(const SpatialModel& s) {
  for (const SpringDamper& sp : s.springs)
    if (sp.HasLaw()) return true;
  return false;
}
// The load variables are needed (a law, a follower force or a torque).
bool NeedsLoadVariables(const SpatialModel& s) { return s.HasVaryingForces() || !s.torques.empty() || AnySpringLaw(s); }

// [[X, −X], [−X, X]] into a 6 × 6 block.
Eigen::Matrix<double, 6, 6> Pattern(const M3& X) {
  Eigen::Matrix<double, 6, 6> B;
  B << X, -X, -X, X;
  return B;
}

std::vector<int> EntitySlots(const NaturalModel& model, std::initializer_list<int> entities) {
  std::vector<int> slot;
  for (int e : entities)
    for (int c = 0; c < 3; ++c) slot.push_back(model.entities[e].slot[c]);
  return slot;
}

// ---- torques and follower forces ----
// A torque's (or a follower force's) rigid body: its basis entities, G⁻¹ = (X̄ᵀ X̄)⁻¹ and
// X̄⁻¹ = G⁻¹ X̄ᵀ from the file's pose.
struct TorqueBody {
  std::array<int, 4> e{};
  std::array<bool, 4> point{};
  M3 Ginv, X0inv;
};
TorqueBody BasisOf(const NaturalModel& model, int body) {
  const SpatialModel& s = model.model.spatial;
  const SpatialBody& b = s.bodies[body];
  MB_ASSERT(b.entities.size() >= 4, "a spatial torque or body frame is a rigid body's (the loader checks)");
  TorqueBody t;
  M3 X;
  for (int k = 0; k < 4; ++k) t.e[k] = b.entities[k], t.point[k] = !s.entities[t.e[k]].vector;
  for (int k = 1; k < 4; ++k) X.col(k - 1) = s.entities[t.e[k]].r_W - (t.point[k] ? s.entities[t.e[0]].r_W : V3::Zero());
  t.Ginv = (X.transpose() * X).inverse();
  t.X0inv = t.Ginv * X.transpose();
  return t;
}
TorqueBody TorqueBodyOf(const NaturalModel& model, const SpatialLoad& l) { return BasisOf(model, l.body); }
// X (or Ẋ, Ẍ) at the entities' values v (EntityValue or EntityRate).
template <class F>
M3 Columns(const TorqueBody& t, const F& v) {
  M3 X;
  for (int k = 1; k < 4; ++k) X.col(k - 1) = v(t.e[k]) - (t.point[k] ? v(t.e[0]) : V3::Zero());
  return X;
}
// Q_e [e0; e1; e2; e3] from the column forces QX.col(k − 1) = Q_Xk.
Vec12 Scatter(const TorqueBody& t, const M3& QX) {
  Vec12 Q = Vec12::Zero();
  for (int k = 1; k < 4; ++k) {
    Q.segment<3>(3 * k) += QX.col(k - 1);
    if (t.point[k]) Q.segment<3>(0) -= QX.col(k - 1);
  }
  return Q;
}
// Q_Xk = ½ T × Y_k / u for each k.
M3 ColumnForces(const V3& T, const M3& Y, double u) {
  M3 QX;
  for (int k = 0; k < 3; ++k) QX.col(k) = 0.5 * T.cross(Y.col(k)) / u;
  return QX;
}

// A point force's world value f_W = R F and R = X(q) X̄⁻¹ (I for world components): F its
// components at the load variables x (with grad, each law's gradient).
struct Force3 {
  V3 F, f_W;
  M3 R = M3::Identity();
};
Force3 ForceAt(const NaturalModel& model, const SpatialLoad& f, const Eigen::VectorXd& q, const std::vector<double>& x,
               std::vector<double>* grad = nullptr) {
  Force3 r;
  r.F = LoadValue(f, x, grad);
  if (f.frame >= 0) {
    const TorqueBody tb = BasisOf(model, f.frame);
    r.R = Columns(tb, [&](int e) { return EntityValue(model, q, e); }) * tb.X0inv;
  }
  r.f_W = r.R * r.F;
  return r;
}

void AddAt(Eigen::VectorXd& Q, const std::vector<int>& slot, const Eigen::VectorXd& Qe) {
  for (size_t i = 0; i < slot.size(); ++i)
    if (slot[i] >= 0) Q[slot[i]] += Qe[static_cast<Eigen::Index>(i)];
}

}  // namespace

void AddSpatialElementForces(const NaturalModel& model, const Eigen::VectorXd& q, const Eigen::VectorXd& qd, double t,
                             Eigen::VectorXd& Q) {
  if (model.dim != 3) return;
  const SpatialModel& s = model.model.spatial;
  const double u = model.meters_per_unit;
  std::vector<double> x;
  if (NeedsLoadVariables(s)) LoadVariables(model, q, qd, t, x);
  for (const SpringDamper& sp : s.springs) {
    const Spring3 st = SpringAt(model, sp, q, Rates(q, qd), sp.HasLaw() ? &x : nullptr);
    Eigen::Matrix<double, 6, 1> Qe;
    Qe << st.F * st.e, -st.F * st.e;
    AddAt(Q, EntitySlots(model, {sp.points[0], sp.points[1]}), Qe);
  }
  for (const SpatialLoad& f : s.forces)
    if (f.IsVarying()) AddAt(Q, EntitySlots(model, {f.point}), ForceAt(model, f, q, x).f_W);
  for (const SpatialLoad& l : s.torques) {
    const TorqueBody tb = TorqueBodyOf(model, l);
    const M3 Y = Columns(tb, [&](int e) { return EntityValue(model, q, e); }) * tb.Ginv;
    AddAt(Q, EntitySlots(model, {tb.e[0], tb.e[1], tb.e[2], tb.e[3]}), Scatter(tb, ColumnForces(LoadValue(l, x), Y, u)));
  }
}

void AppendSpatialElementSlots(const NaturalModel& model, std::vector<std::vector<int>>& out) {
  if (model.dim != 3) return;
  const SpatialModel& s = model.model.spatial;
  const auto add_laws = [&](const auto& laws, std::vector<int>& slot) {
    for (const auto& law : laws)
      if (law)
        for (int var : law->variables())
          if (var != kLoadVarTime) AddSlot(slot, (var - 1) % model.n);
  };
  for (const SpringDamper& sp : s.springs) {
    std::vector<int> slot = EntitySlots(model, {sp.points[0], sp.points[1]});
    add_laws(sp.law, slot);
    out.push_back(slot);
  }
  for (const SpatialLoad& f : s.forces) {
    if (!f.IsVarying()) continue;
    std::vector<int> slot = EntitySlots(model, {f.point});
    if (f.frame >= 0) {
      const SpatialBody& b = s.bodies[f.frame];
      for (int k = 0; k < 4; ++k)
        for (int c = 0; c < 3; ++c) AddSlot(slot, model.entities[b.entities[k]].slot[c]);
    }
    add_laws(f.law, slot);
    out.push_back(slot);
  }
  for (const SpatialLoad& l : s.torques) {
    const SpatialBody& b = s.bodies[l.body];
    std::vector<int> slot = EntitySlots(model, {b.entities[0], b.entities[1], b.entities[2], b.entities[3]});
    add_laws(l.law, slot);
    out.push_back(slot);
  }
}

void SpatialElementDerivatives(const NaturalModel& model, const Eigen::VectorXd& q, const Eigen::VectorXd& qd, double t,
                               std::vector<ElementDerivative>& out, size_t k) {
  if (model.dim != 3) return;
  const SpatialModel& s = model.model.spatial;
  const double u = model.meters_per_unit;
  const int n = model.n;
  std::vector<double> x;
  Grads grad = NewGrads();
  std::array<std::vector<double>, 4> pgrad;
  for (auto& g : pgrad) g.assign(CompiledExpr::kMaxVariables, 0.0);
  if (NeedsLoadVariables(s)) LoadVariables(model, q, qd, t, x);
  for (const SpringDamper& sp : s.springs) {
    ElementDerivative& D = out[k++];
    const Spring3 st = SpringAt(model, sp, q, Rates(q, qd), sp.HasLaw() ? &x : nullptr, pgrad.data());
    const double ks = st.p[SpringDamper::kStiffness], cs = st.p[SpringDamper::kDamping];
    if (!(st.L > 0)) {  // coincident ends: only a zero-length spring is smooth there, f_b = −k u d
      D.K.topLeftCorner<6, 6>() = Pattern(-ks * u * M3::Identity());
      continue;
    }
    // f_b = −F e: ∂f_b/∂d = −e (∂F/∂d)ᵀ − F (I − e eᵀ)/L, ∂F/∂d = k u e + c u (I − e eᵀ) v / L.
    const M3 across = M3::Identity() - st.e * st.e.transpose();
    const V3 dF = ks * u * st.e + cs * u * (across * st.v) / st.L;
    D.K.topLeftCorner<6, 6>() = Pattern(-st.e * dF.transpose() - st.F * across / st.L);
    D.C.topLeftCorner<6, 6>() = Pattern(-cs * u * st.e * st.e.transpose());
    // A law p adds ∂Q/∂p ∂p/∂q_s (or ∂q̇_s): Q = F [e; −e], ∂F/∂(k, c, L0, F0) = ((L − L0) u, L̇ u, −k u, 1).
    const double dF_dp[4] = {(st.L - st.p[SpringDamper::kFreeLength]) * u, st.Ldot * u, -ks * u, 1.0};
    Eigen::Matrix<double, 6, 1> dQ;
    dQ << st.e, -st.e;
    for (int p = 0; p < 4; ++p) {
      if (!sp.law[p]) continue;
      const std::vector<int>& vars = sp.law[p]->variables();
      for (size_t v = 0; v < vars.size(); ++v) {
        if (vars[v] == kLoadVarTime) continue;
        const int col = Column(D.slot, (vars[v] - 1) % n);
        if (col >= 0) (vars[v] > n ? D.C : D.K).col(col).head<6>() += dQ * (dF_dp[p] * pgrad[p][v]);
      }
    }
  }
  // A law adds ∂Q/∂p_c ∂p_c/∂q_s (or ∂q̇_s) in column s, for each component c.
  const auto add_law_columns = [&](const SpatialLoad& l, ElementDerivative& D, const std::array<Eigen::VectorXd, 3>& dQ) {
    for (int c = 0; c < 3; ++c) {
      if (!l.law[c]) continue;
      const std::vector<int>& vars = l.law[c]->variables();
      for (size_t v = 0; v < vars.size(); ++v) {
        if (vars[v] == kLoadVarTime) continue;
        const int col = Column(D.slot, (vars[v] - 1) % n);
        if (col >= 0) (vars[v] > n ? D.C : D.K).col(col).head(dQ[c].size()) += dQ[c] * grad[c][v];
      }
    }
  };
  for (const SpatialLoad& f : s.forces) {
    if (!f.IsVarying()) continue;
    ElementDerivative& D = out[k++];
    const Force3 fa = ForceAt(model, f, q, x, grad.data());
    std::array<Eigen::VectorXd, 3> dQ;  // ∂Q/∂F_c on the point's slots: R's column c
    for (int c = 0; c < 3; ++c) dQ[c] = fa.R.col(c);
    add_law_columns(f, D, dQ);
    if (f.frame < 0) continue;
    // f_W = X w, w = X̄⁻¹ F: ∂f_W/∂e_k = w_k I, and −w_k I on e0 for a point e_k.
    const TorqueBody tb = BasisOf(model, f.frame);
    const V3 w = tb.X0inv * fa.F;
    for (int a = 0; a < 3; ++a) {
      const int row = Column(D.slot, model.entities[f.point].slot[a]);
      if (row < 0) continue;
      for (int kk = 1; kk < 4; ++kk) {
        if (const int c = Column(D.slot, model.entities[tb.e[kk]].slot[a]); c >= 0) D.K(row, c) += w[kk - 1];
        if (tb.point[kk])
          if (const int c0 = Column(D.slot, model.entities[tb.e[0]].slot[a]); c0 >= 0) D.K(row, c0) -= w[kk - 1];
      }
    }
  }
  for (const SpatialLoad& l : s.torques) {
    ElementDerivative& D = out[k++];
    const TorqueBody tb = TorqueBodyOf(model, l);
    const V3 T = LoadValue(l, x, grad.data());
    const M3 Y = Columns(tb, [&](int e) { return EntityValue(model, q, e); }) * tb.Ginv;
    // K_e = Σ_k Σ_j D_kᵀ (½ G⁻¹_jk [T]× / u) D_j, X_k = D_k q_e (+I on e_k, −I on e0 for a point).
    const M3 TX = 0.5 * Skew(T) / u;
    Eigen::Matrix<double, 12, 12> K = Eigen::Matrix<double, 12, 12>::Zero();
    for (int a = 1; a < 4; ++a)
      for (int b = 1; b < 4; ++b) {
        const M3 B = tb.Ginv(b - 1, a - 1) * TX;  // ∂Q_Xa/∂X_b
        K.block<3, 3>(3 * a, 3 * b) += B;
        if (tb.point[b]) K.block<3, 3>(3 * a, 0) -= B;
        if (tb.point[a]) K.block<3, 3>(0, 3 * b) -= B;
        if (tb.point[a] && tb.point[b]) K.block<3, 3>(0, 0) += B;
      }
    D.K.topLeftCorner<12, 12>() = K;
    std::array<Eigen::VectorXd, 3> dQ;  // ∂Q_e/∂T_c: Q_Xk = ½ e_c × Y_k / u
    for (int c = 0; c < 3; ++c) dQ[c] = Scatter(tb, ColumnForces(V3::Unit(c), Y, u));
    add_law_columns(l, D, dQ);
  }
}

double SpatialSpringPotential(const NaturalModel& model, const Eigen::VectorXd& q) {
  if (model.dim != 3) return 0;
  const double u = model.meters_per_unit;
  double V = 0;
  for (const SpringDamper& sp : model.model.spatial.springs) {
    if (sp.HasLaw()) continue;  // no potential: its work is in SpatialLawSpringPower
    const double x = (SpringAt(model, sp, q, nullptr).L - sp.free_length) * u;
    V += 0.5 * sp.stiffness * x * x + sp.preload * x;
  }
  return V;
}

double SpatialDamperPower(const NaturalModel& model, const Eigen::VectorXd& q, const Eigen::VectorXd& qd,
                          const Eigen::VectorXd* qdd, double& rate) {
  if (model.dim != 3) return 0;
  const double u = model.meters_per_unit;
  double P = 0;
  for (const SpringDamper& sp : model.model.spatial.springs) {
    if (sp.damping == 0 || sp.HasLaw()) continue;  // a spring with a law: SpatialLawSpringPower
    const Spring3 st = SpringAt(model, sp, q, &qd);
    P += sp.damping * st.Ldot * st.Ldot * u * u;
    if (qdd && st.L > 0) {  // L̈ = e·(r̈_b − r̈_a) + (|v|² − L̇²)/L
      const V3 a = EntityRate(model, *qdd, sp.points[1]) - EntityRate(model, *qdd, sp.points[0]);
      rate += 2 * sp.damping * st.Ldot * (st.e.dot(a) + (st.v.squaredNorm() - st.Ldot * st.Ldot) / st.L) * u * u;
    }
  }
  return P;
}

double SpatialTorquePower(const NaturalModel& model, const Eigen::VectorXd& q, const Eigen::VectorXd& qd, double t,
                          const Eigen::VectorXd* qdd, double& rate) {
  if (model.dim != 3 || model.model.spatial.torques.empty()) return 0;
  std::vector<double> x;
  Grads grad = NewGrads();
  LoadVariables(model, q, qd, t, x);
  double P = 0;
  for (const SpatialLoad& l : model.model.spatial.torques) {
    const TorqueBody tb = TorqueBodyOf(model, l);
    const V3 T = LoadValue(l, x, grad.data());
    const M3 Y = Columns(tb, [&](int e) { return EntityValue(model, q, e); }) * tb.Ginv;
    const M3 Xd = Columns(tb, [&](int e) { return EntityRate(model, qd, e); });
    // P = ½ Σ_k (T × Y_k)·Ẋ_k; Ṗ = ½ Σ_k [(Ṫ × Y_k + T × Ẏ_k)·Ẋ_k + (T × Y_k)·Ẍ_k], Ẏ = Ẋ G⁻¹.
    for (int k = 0; k < 3; ++k) P += 0.5 * T.cross(Y.col(k)).dot(Xd.col(k));
    if (!qdd) continue;
    V3 Tdot = V3::Zero();
    for (int c = 0; c < 3; ++c)
      if (l.law[c]) Tdot[c] = LawRate(*l.law[c], grad[c], qd, *qdd);
    const M3 Yd = Xd * tb.Ginv;
    const M3 Xdd = Columns(tb, [&](int e) { return EntityRate(model, *qdd, e); });
    for (int k = 0; k < 3; ++k)
      rate += 0.5 * ((Tdot.cross(Y.col(k)) + T.cross(Yd.col(k))).dot(Xd.col(k)) + T.cross(Y.col(k)).dot(Xdd.col(k)));
  }
  return P;
}

double SpatialForcePower(const NaturalModel& model, const Eigen::VectorXd& q, const Eigen::VectorXd& qd, double t,
                         const Eigen::VectorXd* qdd, double& rate) {
  if (model.dim != 3 || !model.model.spatial.HasVaryingForces()) return 0;
  const double u = model.meters_per_unit;
  std::vector<double> x;
  Grads grad = NewGrads();
  LoadVariables(model, q, qd, t, x);
  double P = 0;
  for (const SpatialLoad& f : model.model.spatial.forces) {
    if (!f.IsVarying()) continue;
    const Force3 fa = ForceAt(model, f, q, x, grad.data());
    const V3 v = EntityRate(model, qd, f.point);
    P += fa.f_W.dot(v) * u;
    if (!qdd) continue;
    // d(f_W·v)/dt = (Ṙ F + R Ḟ)·v + f_W·a, Ṙ = Ẋ X̄⁻¹.
    V3 Fdot = V3::Zero();
    for (int c = 0; c < 3; ++c)
      if (f.law[c]) Fdot[c] = LawRate(*f.law[c], grad[c], qd, *qdd);
    V3 fdot = fa.R * Fdot;
    if (f.frame >= 0) {
      const TorqueBody tb = BasisOf(model, f.frame);
      fdot += Columns(tb, [&](int e) { return EntityRate(model, qd, e); }) * (tb.X0inv * fa.F);
    }
    rate += (fdot.dot(v) + fa.f_W.dot(EntityRate(model, *qdd, f.point))) * u;
  }
  return P;
}

double SpatialLawSpringPower(const NaturalModel& model, const Eigen::VectorXd& q, const Eigen::VectorXd& qd, double t,
                             const Eigen::VectorXd* qdd, double& rate) {
  if (model.dim != 3 || !AnySpringLaw(model.model.spatial)) return 0;
  const double u = model.meters_per_unit;
  std::vector<double> x;
  std::array<std::vector<double>, 4> grad;
  for (auto& g : grad) g.assign(CompiledExpr::kMaxVariables, 0.0);
  LoadVariables(model, q, qd, t, x);
  double P = 0;
  for (const SpringDamper& sp : model.model.spatial.springs) {
    if (!sp.HasLaw()) continue;
    const Spring3 st = SpringAt(model, sp, q, &qd, &x, grad.data());
    P -= st.F * st.Ldot * u;
    if (!qdd || !(st.L > 0)) continue;
    // As the planar LawSpringPower: d(−F L̇ u)/dt = −(Ḟ L̇ + F L̈) u, Ḟ = k̇ (L − L0) u + k (L̇ − L̇0) u
    // + ċ L̇ u + c L̈ u + Ḟ0; L̈ = e·(r̈_b − r̈_a) + (|v|² − L̇²)/L.
    const V3 a = EntityRate(model, *qdd, sp.points[1]) - EntityRate(model, *qdd, sp.points[0]);
    const double Lddot = st.e.dot(a) + (st.v.squaredNorm() - st.Ldot * st.Ldot) / st.L;
    double pdot[4] = {0, 0, 0, 0};
    for (int p = 0; p < 4; ++p)
      if (sp.law[p]) pdot[p] = LawRate(*sp.law[p], grad[p], qd, *qdd);
    const double ks = st.p[SpringDamper::kStiffness], cs = st.p[SpringDamper::kDamping];
    const double Fdot = pdot[0] * (st.L - st.p[SpringDamper::kFreeLength]) * u + ks * (st.Ldot - pdot[2]) * u +
                        pdot[1] * st.Ldot * u + cs * Lddot * u + pdot[3];
    rate -= (Fdot * st.Ldot + st.F * Lddot) * u;
  }
  return P;
}

}  // namespace mechbench::numeric::detail
