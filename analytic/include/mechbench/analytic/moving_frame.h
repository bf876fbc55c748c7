// 3-D views of a planar solution (Model::embedding) and absolute kinematics when the whole
// mechanism's frame turns at a constant rate about a fixed axis (Model::frame; §3.1, §3.2).
//
// Two independent routes, as the book's §3.2 does it:
//  1. moving frame (eq. 2.12): each point moves relative to the turning frame, so
//     v = v_rel + Ω×r, a = a_rel + Ω×(Ω×r) + 2Ω×v_rel, r from a point on the axis;
//  2. rigid-body chain (eq. 2.11): each link's absolute angular velocity is ω n + Ω (n, the plane
//     normal, turns with the frame, so its absolute angular acceleration is α n + Ω×(ω n)), and
//     v_B = v_A + ω_abs×AB, a_B = a_A + α_abs×AB + ω_abs×(ω_abs×AB) from a point on the axis.
#pragma once

#include "mechbench/analytic/kinematics.h"
#include "mechbench/analytic/linkage.h"
#include "mechbench/model.h"

#include <vector>

namespace mechbench::analytic {

// In-plane vector -> world vector (u x + v y), and a point -> world point (origin + u x + v y).
Vec3 EmbedVector(const Embedding& e, const Vec2& r);
PointState3 EmbedPoint(const Embedding& e, const PointState2& s);

// Route 1 (eq. 2.12): absolute state of a point whose state relative to the turning frame is
// `rel` (world components at the instant, when the frame and the world coincide).
PointState3 AbsoluteInTurningFrame(const FrameRotation& f, const PointState3& rel);

// Route 2: absolute angular velocity/acceleration of every placed body and the absolute state of
// every point that the rigid-body chain reaches from the points at rest in the frame.
struct BodyChainResult {
  std::vector<Vec3> omega_abs, alpha_abs;  // per body; NaN for bodies without a planar state
  std::vector<PointState3> points;         // per point; meaningful where reached[i]
  std::vector<bool> reached;
};
BodyChainResult AbsoluteByBodyChain(const Model& m, const LinkageState& s);


}  // namespace mechbench::analytic
