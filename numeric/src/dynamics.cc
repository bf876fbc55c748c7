#include "mechbench/numeric/dynamics.h"

#include "mechbench/errors.h"

#include <Eigen/SparseCore>

#include <array>
#include <vector>

namespace mechbench::numeric {
namespace {

// C(ξ, η): r = C [r_i; r_j] for the material point at body-frame (ξ, η), see dynamics.h.
Eigen::Matrix<double, 2, 4> Interpolation(double L, const Eigen::Vector2d& xi) {
  const double a = xi.x() / L, b = xi.y() / L;
  Eigen::Matrix<double, 2, 4> C;
  // (1 − a) I − b P | a I + b P, with P = [0 −1; 1 0].
  C << 1 - a, b, a, -b,
       -b, 1 - a, b, a;
  return C;
}

// The four q slots of a body's basic points (−1 for constant coordinates).
std::array<int, 4> BodySlots(const NaturalModel& model, const Body& body) {
  const auto& s0 = model.point_slot[body.points[0]];
  const auto& s1 = model.point_slot[body.points[1]];
  return {s0[0], s0[1], s1[0], s1[1]};
}

}  // namespace

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
}

void GeneralizedForces(const NaturalModel& model, NaturalData& data) {
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
  for (const PointForce& f : model.model.forces)
    for (int axis = 0; axis < 2; ++axis) {
      const int s = model.point_slot[f.point][axis];
      if (s >= 0) data.Q[s] += f.f_W[axis];
    }
}

}  // namespace mechbench::numeric
