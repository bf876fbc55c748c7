// Point kinematics of the book's chapter 2: intrinsic coordinates of a path point (§2.2), a point
// of a rigid body (§2.3.3, eq. 2.11) and a point moving in a moving frame (§2.3.4, eq. 2.12).
// All vectors are in one (global) frame, as the book recommends.
#pragma once

#include "mechbench/analytic/vector.h"

namespace mechbench::analytic {

// Position, velocity and acceleration of a point [length, length/s, length/s²].
struct PointState3 {
  Vec3 p = Vec3::Zero(), v = Vec3::Zero(), a = Vec3::Zero();
};

// Eq. 2.11: B on the rigid body that carries A, with angular velocity omega [rad/s] and angular
// acceleration alpha [rad/s²]: v_B = v_A + ω×AB, a_B = a_A + α×AB + ω×(ω×AB).
PointState3 RigidBodyPoint(const PointState3& A, const Vec3& omega, const Vec3& alpha, const Vec3& p_B);

// Eq. 2.12: B moves relative to a frame whose origin A has state `A` and which turns at omega,
// alpha; (v_B)_A, (a_B)_A are B's velocity and acceleration seen in that frame:
// v_B = v_A + (v_B)_A + ω×AB, a_B = a_A + (a_B)_A + α×AB + ω×(ω×AB) + 2ω×(v_B)_A (Coriolis).
PointState3 MovingFramePoint(const PointState3& A, const Vec3& omega, const Vec3& alpha, const Vec3& p_B,
                             const Vec3& v_rel, const Vec3& a_rel);

// Intrinsic coordinates of a path point (§2.2): a = s̈ ε_t + (v²/R) ε_n.
struct Intrinsic {
  double speed = 0;    // |v| = ṡ [length/s]
  double a_t = 0;      // s̈, signed tangential acceleration [length/s²]
  double a_n = 0;      // v²/R ≥ 0, centripetal acceleration [length/s²]
  double radius = 0;   // R = |v|³/|v×a| (eq. 2.7) [length]; +inf on a straight path
  Vec3 e_t = Vec3::Zero();  // unit tangent (along v)
  Vec3 e_n = Vec3::Zero();  // unit normal towards the centre of curvature; zero on a straight path
  Vec3 centre = Vec3::Zero();  // centre of curvature p + R ε_n (NaN-free only when R is finite)
};
// Needs |v| > 0. `p` only places the centre of curvature.
Intrinsic IntrinsicCoordinates(const Vec3& p, const Vec3& v, const Vec3& a);

}  // namespace mechbench::analytic
