// The compiled natural-coordinate model: the constraint rows Φ(q) of a mechbench::Model, in the
// book's order, with every constant they need. Built once by Compile() and never modified
// (Pinocchio's model/data split); per-run state lives in NaturalData.
//
// Row order (it must match the book's printed Jacobians, see scenarios/FORMAT.md):
//   1. bodies in file order: one distance row between the first two points, then two linear rows
//      (x, y) per extra point;
//   2. joints in file order: one collinearity row per slider whose point keeps both coordinates
//      in q, and one row per gear mesh;
//   3. relative coordinates in file order: one row per angle (two for the cos+sin form), one per
//      distance; rotations add none;
//   4. couplings (racks and linear couplings) in file order: one row each.
// Driver rows ("B" rows in the book) are not part of Φ; they follow it in the augmented systems.
#pragma once

#include "mechbench/model.h"

#include <Eigen/Core>

#include <array>
#include <string>
#include <vector>

namespace mechbench::numeric {

enum class RowKind {
  kBodyDistance,  // |r1 − r0|² − L²                                     points {r0, r1}
  kBodyLinearX,   // [r_k − r0 − a(r1 − r0) − b·perp(r1 − r0)]_x            points {r0, r1, r_k}
  kBodyLinearY,   // same, y component
  kPointOnLine,   // cross(P − L0, L1 − L0), L0/L1 fixed or a body's first two points {P, L0, L1}
  kGear,          // Z_a(φ_a − φ_c) + s·Z_b(φ_b − φ_c) − c                slots {φ_a, φ_b, φ_c}
  kAngleCos,      // (x_b − x_a) − L cos θ                                points {a, b}, slot θ
  kAngleSin,      // (y_b − y_a) − L sin θ
  kAngleDot,      // ρ·v − |ρ||v| cos θ, ρ = ref vector, v = b − a        ref {c, d}, points {a, b}
  kAngleCross,    // cross(R(θ)ρ, v); ρ = (1, 0) for the ground x axis
  kDistance,      // |r_b − r_a|² − s²                                    points {a, b}, slot s
  kCoupling,      // q_b − k q_a − c (a rack, a belt): constant Jacobian   slots {q_a, q_b}
  // Spatial rows (NaturalModel::dim = 3; ent = entities, points or unit vectors; see "Spatial
  // models" below). A = e0 − e1, B = e2 − e3 (a −1 entity counts as zero):
  kUnit3,         // A·B − c with A = B = u: |u|² − 1                    ent {u, −1, u, −1}
  kDistance3,     // A·B − c with A = B = r_j − r_i: |r_j − r_i|² − L²    ent {j, i, j, i}
  kDot3,          // A·B − c: two vectors, a vector and a segment, two segments
  kLinear3,       // [Σ_k coef_k e_k]_axis: a point or vector e0 as a linear combination of a
                  // body's basis e1 … e4 (coef_0 = 1)
  kPointOnLine3,  // [e0 − e1 − s (e2 − e3)]_axis: point e0 on the line through e1 along
                  // e2 − e3 (a vector, or a segment), s its distance coordinate (slots[0])
  kAngle3,        // cos θ (u × w)·a − sin θ (u·w) = sin(φ − θ), φ the angle from u to w about a:
                  // ent {u, w, a}, θ = slots[0]; one smooth row (no switch between a cos and a
                  // sin form), well conditioned at every θ (∂/∂θ = −1 where it holds)
};
const char* ToString(RowKind kind);

struct ConstraintRow {
  RowKind kind = RowKind::kBodyDistance;
  std::string element;  // what the row comes from, for messages: "body coupler", "coordinate theta (cos)"
  SourceRef src;        // where that element is declared
  std::array<int, 3> pts{-1, -1, -1};  // point indices, meaning per kind (see RowKind)
  std::array<int, 2> ref{-1, -1};      // angle reference vector's points; -1 = ground x axis
  std::array<int, 3> slots{-1, -1, -1};  // q slots of relative coordinates (θ, s, φ_a, φ_b, φ_c)
  double L = 0.0;        // distance/cos/sin: the length; dot: |ρ||v| [length or length²]
  double a = 0.0, b = 0.0;  // linear rows: the extra point's body-frame coordinates divided by L
  double z_a = 0.0, z_b = 0.0;  // gear: Z_a and s·Z_b (s = −1 for an internal mesh)
  double c = 0.0;        // gear: the constant, from the initial guesses [teeth·rad]; coupling: c
  double k = 0.0;        // coupling: the ratio ∂q_b/∂q_a
  double scale = 1.0;    // typical size of the row's terms, so residuals compare across rows
  // Spatial rows only: the entities (NaturalModel::entities, −1 = none), their coefficients
  // (kLinear3) and the component (kLinear3, kPointOnLine3: 0, 1, 2 = x, y, z); c is the dot
  // product's constant.
  std::array<int, 5> ent{-1, -1, -1, -1, -1};
  std::array<double, 5> coef{};
  int axis = 0;
  // "body coupler (scenarios/x.yaml:14)"
  std::string Where() const;
};

// A prescribed coordinate: the row q_slot − f(t), f from the Driver's law.
struct DriverRow {
  int slot = -1;
  Driver law;
};

// ---- Spatial models (dim = 3; García de Jalón & Bayo ch. 2–3) ----------------------------------
// Basic coordinates are points and unit vectors, three slots each (−1: a constant component).
// Points, vectors and distance/angle coordinates share one q; rows use them through `ent`.
enum class EntityKind { kPoint, kVector };
struct Entity3 {
  std::string name;
  EntityKind kind = EntityKind::kPoint;
  std::array<int, 3> slot{-1, -1, -1};            // q slot of x, y, z (−1: constant)
  Eigen::Vector3d value = Eigen::Vector3d::Zero(); // constant components, and the build pose [length or 1]
};
// A rigid body with basis entities e0 (a point) and e1, e2, e3 (points or vectors) whose columns
// X = [e1 − e0 or e1, …] are non-coplanar. A material point at r̄ (body frame, relative to e0)
// is r = e0 + X c with c = X̄⁻¹ r̄, X̄ = X in the body frame (constant: the book's matrix relating
// the body's frame to its basic coordinates). Mass properties in the body frame.
struct RigidBody3 {
  std::string name;
  std::array<int, 4> basis{-1, -1, -1, -1};
  Eigen::Matrix3d X_B = Eigen::Matrix3d::Identity();  // X̄: the basis columns in the body frame
  double mass = 0.0;                                  // [kg]
  Eigen::Vector3d com_B = Eigen::Vector3d::Zero();    // centre of mass relative to e0, body frame [length]
  Eigen::Matrix3d inertia_com = Eigen::Matrix3d::Zero();  // inertia tensor about the centre of mass, body axes [kg·length²]
};

// A bar with mass (two points a, b): a slender uniform rod, no inertia about its own axis. With
// r(s) = (1 − s) r_a + s r_b, s ∈ [0, 1], M_e = m ∫ [(1 − s)²  s(1 − s); s(1 − s)  s²] ds ⊗ I₃ =
// m/6 [2 1; 1 2] ⊗ I₃: exact and constant; its weight m g/2 on each end.
struct Bar3 {
  std::string name;
  std::array<int, 2> ends{-1, -1};  // entities (points)
  double mass = 0.0;                // [kg]
};

struct NaturalModel {
  Model model;  // the source scene (a copy: the compiled model owns everything it needs)
  int n = 0;    // number of coordinates, q_layout.size()
  std::vector<ConstraintRow> rows;  // Φ, m = rows.size()
  std::vector<DriverRow> drivers;   // f = drivers.size()

  // For every point, the q slot of its x and y (−1 when the value is a constant), and those
  // constant values (fixed points, coordinates a fixed guide eliminates) [length].
  std::vector<std::array<int, 2>> point_slot;
  std::vector<Eigen::Vector2d> point_const;
  std::vector<int> coordinate_slot;  // q slot of each Model::coordinates entry
  std::vector<int> member_slot;      // q slot of each body's rotation coordinate, or −1

  double length_scale = 1.0;      // typical length of the scene [length]
  double meters_per_unit = 1.0;   // 1 for m, 1e-3 for mm, 1e-2 for cm
  Eigen::VectorXd q_scale;        // typical size of each slot: length_scale or 1 rad

  // 2: a planar model from Compile (the fields above); 3: a spatial model (SpatialBuilder,
  // spatial.h), whose coordinates are `entities` and whose rows are the spatial kinds; `model`,
  // point_slot and point_const then stay empty. Algorithms branch on it once per call, not per row.
  int dim = 2;
  std::vector<Entity3> entities;
  std::vector<RigidBody3> bodies3;
  std::vector<Bar3> bars3;
  Eigen::Vector3d gravity3 = Eigen::Vector3d::Zero();  // [length/s²]

  int m() const { return static_cast<int>(rows.size()); }
  int f() const { return static_cast<int>(drivers.size()); }
};

// Builds the constraint rows of `model`. Throws ScenarioError when a row cannot be formed (for
// example a cos-form angle between two points that no body keeps at a constant distance).
NaturalModel Compile(const Model& model);

}  // namespace mechbench::numeric
