// Kinematic quantities derived from a solved instant (data.q, data.qd, data.qdd): angular rates of
// bodies, slider velocities, and 3-D world values through the model's embedding and frame.
#pragma once

#include "mechbench/numeric/natural_data.h"
#include "mechbench/numeric/natural_model.h"

#include <Eigen/Core>

#include <optional>

namespace mechbench::numeric {

struct BodyRates {
  double omega = 0.0;  // planar angular velocity [rad/s], counter-clockwise
  double alpha = 0.0;  // planar angular acceleration [rad/s²]
};
// For a body with 2+ points, from r01 = r1 − r0 (|r01| is constant):
//   ω = cross(r01, ṙ01) / |r01|²,  α = cross(r01, r̈01) / |r01|²  (d/dt cross(r, ṙ) = cross(r, r̈));
// for a gear member, its rotation coordinate's rate and acceleration. nullopt otherwise.
std::optional<BodyRates> BodyAngularRates(const NaturalModel& model, const NaturalData& data,
                                          int body);

struct SlideRates {
  double v = 0.0;  // velocity of the point relative to the body, along û [length/s]
  double a = 0.0;  // its rate of change along û [length/s²]
};
// For a slider along a body: (ṙ_P − ṙ_M)·û with M the body's material point under P and û the
// unit vector from the body's first to its second point; likewise (r̈_P − r̈_M)·û (the Coriolis
// term 2ω×v_rel is normal to û). nullopt for other joints.
std::optional<SlideRates> SliderRates(const NaturalModel& model, const NaturalData& data, int joint);

struct WorldPoint {
  Eigen::Vector3d p, v, a;  // world position [length], velocity [length/s], acceleration [length/s²]
};
// A point in 3-D through the embedding p_W = origin + u x + v y (relative to the frame when it turns).
WorldPoint PointInWorld(const NaturalModel& model, const NaturalData& data, int point);

// The centre of a gear-train member's axis when the file places it (Model::gear_axes), from the
// solved coordinates: a fixed axis at rest; a planet at p = c + A(φ_c) s with s = (arm, 0) and A the
// rotation matrix of its carrier's coordinate, ṗ = φ̇_c A' s, p̈ = φ̈_c A' s + φ̇_c² A'' s
// (A' = dA/dφ, A'' = −A). nullopt when the member is not placed.
std::optional<WorldPoint> MemberCentreInWorld(const NaturalModel& model, const NaturalData& data, int body);

// Absolute values when the whole frame turns at constant ω about a fixed axis through c, in
// matrix form at the instant (R = I, Ṙ = [ω]×, R̈ = [ω]×²):
//   v_abs = Ṙ (p − c) + R v,   a_abs = R̈ (p − c) + 2 Ṙ v + R a.
WorldPoint AbsolutePoint(const FrameRotation& frame, const WorldPoint& relative);

}  // namespace mechbench::numeric
