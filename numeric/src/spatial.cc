// Spatial models built in code, and the 3-D mass matrix and weights of natural coordinates
// (spatial.h). The rows' evaluation is in spatial_rows.cc.
#include "mechbench/numeric/spatial.h"

#include "mechbench/errors.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>

namespace mechbench::numeric {
namespace {
using V3 = Eigen::Vector3d;
}  // namespace

int SpatialBuilder::Entity(const std::string& name, EntityKind kind, const Eigen::Vector3d& v, bool fixed) {
  nm_.dim = 3;
  Entity3 e;
  e.name = name;
  e.kind = kind;
  e.value = v;
  if (!fixed)
    for (int c = 0; c < 3; ++c) {
      e.slot[c] = static_cast<int>(q0_.size());
      q0_.push_back(v[c]);
      length_slot_.push_back(kind == EntityKind::kPoint);
      nm_.model.q_layout.push_back({name + "xyz"[c], -1, -1, -1});
    }
  nm_.entities.push_back(e);
  return static_cast<int>(nm_.entities.size()) - 1;
}

int SpatialBuilder::Point(const std::string& name, const Eigen::Vector3d& r, bool fixed) {
  return Entity(name, EntityKind::kPoint, r, fixed);
}

int SpatialBuilder::Vector(const std::string& name, const Eigen::Vector3d& u, bool fixed) {
  MB_ASSERT(std::fabs(u.norm() - 1) < 1e-12, "a basic vector of natural coordinates has unit length");
  return Entity(name, EntityKind::kVector, u, fixed);
}

int SpatialBuilder::Coordinate(const std::string& name, double value, bool is_length) {
  nm_.dim = 3;
  q0_.push_back(value);
  length_slot_.push_back(is_length);
  nm_.model.q_layout.push_back({name, -1, -1, -1});
  return static_cast<int>(q0_.size()) - 1;
}

void SpatialBuilder::Dot(int a0, int a1, int b0, int b1) {
  if (!Moves(a0) && !Moves(a1) && !Moves(b0) && !Moves(b1)) return;  // constant: no row
  ConstraintRow row;
  const V3 A = At(a0) - At(a1), B = At(b0) - At(b1);
  const bool same = a0 == b0 && a1 == b1;
  row.kind = !same ? RowKind::kDot3 : a1 < 0 ? RowKind::kUnit3 : RowKind::kDistance3;
  row.ent = {a0, a1, b0, b1, -1};
  row.c = A.dot(B);
  row.L = same ? A.norm() : 0.0;
  row.scale = std::max(A.norm() * B.norm(), 1e-300);
  row.element = std::string(ToString(row.kind)) + " " + nm_.entities[a0].name +
                (a1 >= 0 ? "-" + nm_.entities[a1].name : "") + " · " + nm_.entities[b0].name +
                (b1 >= 0 ? "-" + nm_.entities[b1].name : "");
  nm_.rows.push_back(row);
}

void SpatialBuilder::Distance(int a, int b) { Dot(b, a, b, a); }

int SpatialBuilder::Body(const std::string& name, const std::array<int, 4>& basis, double mass,
                         const Eigen::Vector3d& com_W, const Eigen::Matrix3d& inertia_com_W) {
  MB_ASSERT(nm_.entities[basis[0]].kind == EntityKind::kPoint, "a spatial body's first basis entity is a point");
  RigidBody3 b;
  b.name = name;
  b.basis = basis;
  // The body frame is the world frame at the build pose: X̄ is X there.
  for (int k = 1; k < 4; ++k) {
    const bool point = nm_.entities[basis[k]].kind == EntityKind::kPoint;
    b.X_B.col(k - 1) = At(basis[k]) - (point ? At(basis[0]) : V3::Zero());
  }
  MB_ASSERT(std::fabs(b.X_B.determinant()) > 1e-12 * b.X_B.colwise().norm().prod(),
            "a spatial body's basis must not be coplanar");
  b.mass = mass;
  b.com_B = com_W - At(basis[0]);
  b.inertia_com = inertia_com_W;
  bool moves = false;
  for (int e : basis) moves = moves || Moves(e);
  if (moves) {
    const auto column = [&](int k) {  // X_k as the pair (e_k, e0) or (e_k, none)
      const bool point = nm_.entities[basis[k]].kind == EntityKind::kPoint;
      return std::array<int, 2>{basis[k], point ? basis[0] : -1};
    };
    for (int a = 1; a < 4; ++a)
      for (int c = a; c < 4; ++c) {
        const auto A = column(a), B = column(c);
        const size_t before = nm_.rows.size();
        Dot(A[0], A[1], B[0], B[1]);  // no row between fixed entities (a point mass's world axes)
        if (nm_.rows.size() > before) nm_.rows.back().element = "body " + name + " " + nm_.rows.back().element;
      }
  }
  nm_.bodies3.push_back(b);
  return static_cast<int>(nm_.bodies3.size()) - 1;
}

void SpatialBuilder::Bar(const std::string& name, int a, int b, double mass) {
  Distance(a, b);
  if (mass > 0 && (Moves(a) || Moves(b))) nm_.bars3.push_back({name, {a, b}, mass});
}

void SpatialBuilder::Attach(int body, int entity) {
  const RigidBody3& b = nm_.bodies3[body];
  const bool point = nm_.entities[entity].kind == EntityKind::kPoint;
  // e = (point ? e0 : 0) + X c, c = X̄⁻¹ (ē − (point ? ē0 : 0)).
  const V3 c = b.X_B.lu().solve(At(entity) - (point ? At(b.basis[0]) : V3::Zero()));
  ConstraintRow row;
  row.kind = RowKind::kLinear3;
  row.ent = {entity, b.basis[0], b.basis[1], b.basis[2], b.basis[3]};
  row.coef = {1.0, point ? -1.0 : 0.0, -c[0], -c[1], -c[2]};
  for (int k = 1; k < 4; ++k)
    if (nm_.entities[b.basis[k]].kind == EntityKind::kPoint) row.coef[1] += c[k - 1];
  row.element = "body " + b.name + " " + (point ? "point " : "vector ") + nm_.entities[entity].name;
  row.scale = point ? std::max(b.X_B.colwise().norm().maxCoeff(), 1e-300) : 1.0;
  for (int axis = 0; axis < 3; ++axis) {
    row.axis = axis;
    nm_.rows.push_back(row);
  }
}

void SpatialBuilder::PointOnLine(int p, int a, int w0, int w1, int slot) {
  ConstraintRow row;
  row.kind = RowKind::kPointOnLine3;
  row.ent = {p, a, w0, w1, -1};
  row.slots = {slot, -1, -1};
  row.element = "point " + nm_.entities[p].name + " on line " + nm_.entities[a].name;
  row.scale = std::max((At(p) - At(a)).norm(), (At(w0) - At(w1)).norm());
  for (int axis = 0; axis < 3; ++axis) {
    row.axis = axis;
    nm_.rows.push_back(row);
  }
}

void SpatialBuilder::Angle(int u, int w, int a, int slot) {
  ConstraintRow row;
  row.kind = RowKind::kAngle3;
  row.ent = {u, w, a, -1, -1};
  row.slots = {slot, -1, -1};
  row.element = "angle " + nm_.model.q_layout[slot].name + " from " + nm_.entities[u].name + " to " + nm_.entities[w].name +
                " about " + nm_.entities[a].name;
  row.scale = 1.0;  // a sine: dimensionless
  nm_.rows.push_back(row);
}

void SpatialBuilder::Drive(int slot, const Driver& law) { nm_.drivers.push_back({slot, law}); }

NaturalModel SpatialBuilder::Build() const {
  NaturalModel nm = nm_;
  nm.dim = 3;
  nm.n = n();
  // Typical length: the largest distance between two points of the build pose (1 without points).
  double L = 0;
  for (const Entity3& a : nm.entities)
    for (const Entity3& b : nm.entities)
      if (a.kind == EntityKind::kPoint && b.kind == EntityKind::kPoint) L = std::max(L, (a.value - b.value).norm());
  nm.length_scale = L > 0 ? L : 1.0;
  nm.q_scale = Eigen::VectorXd::Ones(nm.n);
  for (int s = 0; s < nm.n; ++s)
    if (length_slot_[s]) nm.q_scale[s] = nm.length_scale;
  for (ConstraintRow& row : nm.rows)
    if (row.kind == RowKind::kPointOnLine3 || row.kind == RowKind::kDot3) row.scale = std::max(row.scale, 1e-12 * nm.length_scale);
  return nm;
}

// ---- mass and weight ----------------------------------------------------------------------------

namespace {

// w = T [1; c]: the weights of e0 … e3 for body-frame coefficients c (T takes the point basis
// entities' coefficients off e0's).
Eigen::Matrix4d WeightMap(const NaturalModel& model, const RigidBody3& body) {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  for (int k = 1; k < 4; ++k)
    if (model.entities[body.basis[k]].kind == EntityKind::kPoint) T(0, k) = -1.0;
  return T;
}

}  // namespace

std::array<int, 12> SpatialBodySlots(const NaturalModel& model, const RigidBody3& body) {
  std::array<int, 12> s;
  for (int k = 0; k < 4; ++k)
    for (int c = 0; c < 3; ++c) s[3 * k + c] = model.entities[body.basis[k]].slot[c];
  return s;
}

Eigen::Matrix<double, 12, 12> SpatialElementMassMatrix(const NaturalModel& model, const RigidBody3& body) {
  const double m = body.mass;
  const Eigen::Matrix3d Xinv = body.X_B.inverse();
  const V3 cG = Xinv * body.com_B;
  // Second moment about e0 from the inertia tensor: J_G = ½ tr(I_G) 1 − I_G.
  const Eigen::Matrix3d J_G = 0.5 * body.inertia_com.trace() * Eigen::Matrix3d::Identity() - body.inertia_com;
  const Eigen::Matrix3d J_O = m * body.com_B * body.com_B.transpose() + J_G;
  Eigen::Matrix4d S;
  S(0, 0) = m;
  S.block<1, 3>(0, 1) = m * cG.transpose();
  S.block<3, 1>(1, 0) = m * cG;
  S.block<3, 3>(1, 1) = Xinv * J_O * Xinv.transpose();
  const Eigen::Matrix4d T = WeightMap(model, body);
  const Eigen::Matrix4d W = T * S * T.transpose();
  Eigen::Matrix<double, 12, 12> Me;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) Me.block<3, 3>(3 * i, 3 * j) = W(i, j) * Eigen::Matrix3d::Identity();
  return Me;
}

Eigen::Matrix<double, 12, 1> SpatialBodyWeight(const NaturalModel& model, const RigidBody3& body,
                                               const Eigen::Vector3d& g_SI) {
  Eigen::Vector4d one_c;
  one_c << 1.0, body.X_B.inverse() * body.com_B;
  const Eigen::Vector4d w = WeightMap(model, body) * one_c;
  Eigen::Matrix<double, 12, 1> Q;
  for (int k = 0; k < 4; ++k) Q.segment<3>(3 * k) = w[k] * body.mass * g_SI;
  return Q;
}

void SpatialMassMatrix(const NaturalModel& model, NaturalData& data) {
  std::vector<Eigen::Triplet<double>> t;
  for (const RigidBody3& body : model.bodies3) {
    if (!(body.mass > 0)) continue;
    const Eigen::Matrix<double, 12, 12> Me = SpatialElementMassMatrix(model, body);
    const auto slot = SpatialBodySlots(model, body);
    for (int j = 0; j < 12; ++j)
      for (int i = 0; i < 12; ++i)
        if (slot[i] >= 0 && slot[j] >= 0 && Me(i, j) != 0.0) t.emplace_back(slot[i], slot[j], Me(i, j));
  }
  for (const Bar3& bar : model.bars3) {
    const double w[2][2] = {{bar.mass / 3, bar.mass / 6}, {bar.mass / 6, bar.mass / 3}};
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j)
        for (int c = 0; c < 3; ++c) {
          const int si = model.entities[bar.ends[i]].slot[c], sj = model.entities[bar.ends[j]].slot[c];
          if (si >= 0 && sj >= 0) t.emplace_back(si, sj, w[i][j]);
        }
  }
  if (data.sparse) {
    data.M_sparse.resize(model.n, model.n);
    data.M_sparse.setFromTriplets(t.begin(), t.end());
    data.M_sparse.makeCompressed();
    return;
  }
  data.M.setZero(model.n, model.n);
  for (const auto& e : t) data.M(e.row(), e.col()) += e.value();
}

void SpatialGeneralizedForces(const NaturalModel& model, NaturalData& data) {
  data.Q.setZero(model.n);
  const V3 g_SI = model.gravity3 * model.meters_per_unit;
  for (const RigidBody3& body : model.bodies3) {
    if (!(body.mass > 0)) continue;
    const Eigen::Matrix<double, 12, 1> Qe = SpatialBodyWeight(model, body, g_SI);
    const auto slot = SpatialBodySlots(model, body);
    for (int i = 0; i < 12; ++i)
      if (slot[i] >= 0) data.Q[slot[i]] += Qe[i];
  }
  for (const Bar3& bar : model.bars3)
    for (int end : bar.ends)
      for (int c = 0; c < 3; ++c)
        if (const int s = model.entities[end].slot[c]; s >= 0) data.Q[s] += 0.5 * bar.mass * g_SI[c];
  // Constant world point forces (a law's or a body frame's are force elements: AddElementForces);
  // the file's entities are the model's first ones, in the same order (CompileSpatial).
  for (const SpatialLoad& f : model.model.spatial.forces) {
    if (f.IsVarying()) continue;
    for (int c = 0; c < 3; ++c)
      if (const int s = model.entities[f.point].slot[c]; s >= 0) data.Q[s] += f.value[c];
  }
}

}  // namespace mechbench::numeric
