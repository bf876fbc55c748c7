// Spatial (3-D) natural-coordinate models (issue 13; García de Jalón & Bayo, Kinematic and Dynamic
// Simulation of Multibody Systems, ch. 2–3): points and unit vectors as basic coordinates, the
// rows they need (unit length, dot product, constant distance, linear combination, point on a
// line; RowKind k*3 in natural_model.h), the 3-D mass matrix and gravity's generalized force.
// Planar models (NaturalModel::dim = 2) never reach this code: the algorithms branch once per
// call on the dimension. A spatial model is built in code with SpatialBuilder until the file
// format has 3-D scenes.
#pragma once

#include "mechbench/numeric/natural_data.h"
#include "mechbench/numeric/natural_model.h"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <array>
#include <string>
#include <vector>

namespace mechbench::numeric {

// Builds a NaturalModel with dim = 3. Entities are added with their build pose; every constant
// of a row (distances, dot products, linear-combination coefficients) is read off that pose, so
// the pose must be an assembled one (a rigid body's basis as the body has it).
class SpatialBuilder {
 public:
  // A point or unit vector: three q slots, or constant (`fixed`). Returns its entity index.
  int Point(const std::string& name, const Eigen::Vector3d& r, bool fixed = false);
  int Vector(const std::string& name, const Eigen::Vector3d& u, bool fixed = false);  // |u| = 1
  // A relative coordinate (a distance along a line, an angle): one q slot. Returns the slot.
  int Coordinate(const std::string& name, double value, bool is_length);

  // A rigid body on basis {e0 (a point), e1, e2, e3} (points or vectors, X non-coplanar): its six
  // rows (X_a·X_b constant for a ≤ b: distance / unit / dot rows, the book's six constraints) and
  // its mass properties, given in the world frame at the build pose [kg, length, kg·length²]
  // (mass 0: no mass). Rows among fixed entities only are left out (a ground basis adds none).
  // Returns the body index.
  int Body(const std::string& name, const std::array<int, 4>& basis, double mass = 0.0,
           const Eigen::Vector3d& com_W = Eigen::Vector3d::Zero(),
           const Eigen::Matrix3d& inertia_com_W = Eigen::Matrix3d::Zero());
  // A bar between points a and b: one distance row, and with mass > 0 a slender uniform rod's mass
  // (Bar3, natural_model.h).
  void Bar(const std::string& name, int a, int b, double mass = 0.0);
  // A further point or vector of `body`: three linear-combination rows (kLinear3).
  void Attach(int body, int entity);
  // Constant distance between two points (kDistance3); constant dot product of A = a0 − a1 and
  // B = b0 − b1 (−1 for a vector alone: kDot3, or kUnit3 for u·u); point p on the line through
  // point a along w0 − w1 (w1 = −1: the vector w0) at distance coordinate `slot` (kPointOnLine3).
  void Distance(int a, int b);
  void Dot(int a0, int a1, int b0, int b1);
  void PointOnLine(int p, int a, int w0, int w1, int slot);
  // Angle coordinate `slot` from unit vector u to unit vector w about unit vector a (both
  // perpendicular to a: a revolute joint's axis and a vector across each of its bodies), right
  // handed (kAngle3).
  void Angle(int u, int w, int a, int slot);
  // Prescribes q[slot] = law(t) (a driver row).
  void Drive(int slot, const Driver& law);
  void Gravity(const Eigen::Vector3d& g) { nm_.gravity3 = g; }

  int Slot(int entity, int axis) const { return nm_.entities[entity].slot[axis]; }
  int n() const { return static_cast<int>(q0_.size()); }
  int rows() const { return static_cast<int>(nm_.rows.size()); }  // rows so far (Build keeps their order)
  Eigen::VectorXd q0() const { return Eigen::Map<const Eigen::VectorXd>(q0_.data(), n()); }  // the build pose
  NaturalModel Build() const;

 private:
  int Entity(const std::string& name, EntityKind kind, const Eigen::Vector3d& v, bool fixed);
  bool Moves(int e) const { return e >= 0 && nm_.entities[e].slot[0] >= 0; }
  Eigen::Vector3d At(int e) const { return e < 0 ? Eigen::Vector3d::Zero() : nm_.entities[e].value; }
  std::vector<bool> length_slot_;
  NaturalModel nm_;
  std::vector<double> q0_;
};

// A spatial scene file (Model::spatial, kind: spatial) as a NaturalModel through SpatialBuilder:
// entities in the model's q layout order, bodies (a rigid body on its first four entities with
// the rest attached; a bar: one distance row; a point mass: mass on its point), joints, `along`
// coordinates, drivers. The compiled model's `model` is the file's Model. Compile() calls it.
NaturalModel CompileSpatial(const Model& model);

// The 12 × 12 element mass matrix of a spatial body in the order [e0; e1; e2; e3] (x, y, z each):
// M_e = ∫ Cᵀ C dm with r = C(r̄) q_e = Σ_k w_k(r̄) e_k, w = T [1; X̄⁻¹ r̄] (T subtracts the
// coefficients of point basis entities from e0's), so M_e = (T S Tᵀ) ⊗ I₃ with
// S = [m, m c_Gᵀ; m c_G, X̄⁻¹ J_O X̄⁻ᵀ], c_G = X̄⁻¹ r̄_G, J_O = m r̄_G r̄_Gᵀ + ½ tr(I_G) 1 − I_G.
Eigen::Matrix<double, 12, 12> SpatialElementMassMatrix(const NaturalModel& model, const RigidBody3& body);
// Its weight Cᵀ(r̄_G) m g [N] (g in m/s²), same order.
Eigen::Matrix<double, 12, 1> SpatialBodyWeight(const NaturalModel& model, const RigidBody3& body,
                                               const Eigen::Vector3d& g_SI);
// The body's q slots in that order (−1: a constant component).
std::array<int, 12> SpatialBodySlots(const NaturalModel& model, const RigidBody3& body);
// Assembled M → data.M (dense) or data.M_sparse, and the weights → data.Q [N]: what MassMatrix
// and GeneralizedForces (dynamics.h) do for a spatial model. Bodies, bars with mass, and the
// constant point forces of the file (SpatialModel::forces without a law) in Q.
void SpatialMassMatrix(const NaturalModel& model, NaturalData& data);
void SpatialGeneralizedForces(const NaturalModel& model, NaturalData& data);

// ∂²Φ_i/∂q² of a spatial row at q, full and symmetric, as (slot, slot, value) triplets (those of
// one entry summed by setFromTriplets): constant for the dot-product rows (±1 blocks), ∓1 between
// s and the direction for kPointOnLine3, zero for kLinear3; for kAngle3 it depends on q (the
// triple product's cross blocks and θ's trigonometry). What ALI3-P's tangent adds per row.
void SpatialRowHessian(const NaturalModel& model, const ConstraintRow& row, const Eigen::VectorXd& q,
                       std::vector<Eigen::Triplet<double>>& out);

// The position and velocity of an entity at q, q̇ (constants included) [length or 1].
Eigen::Vector3d EntityValue(const NaturalModel& model, const Eigen::VectorXd& q, int e);
Eigen::Vector3d EntityRate(const NaturalModel& model, const Eigen::VectorXd& qd, int e);

}  // namespace mechbench::numeric
