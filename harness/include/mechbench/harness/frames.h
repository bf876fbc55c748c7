// The motion as a few frames for drawing: every point of the mechanism at evenly spread sample
// times, from a trajectory in Model::q_layout order. Run records carry the method's frames and
// those of the motion it was judged against, so the report can animate both, overlaid.
#pragma once

#include "mechbench/method.h"
#include "mechbench/model.h"

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace mechbench::harness {

// Every point of `m` in model order for the configuration q: a moving point's coordinates from q,
// a fixed point's (and a coordinate a guide eliminates) from the model.
std::vector<Eigen::Vector2d> PointPositions(const Model& m, const Eigen::VectorXd& q);

// A spatial scene's points (its entities that are points, not unit vectors) in entity order, in 3-D
// for the configuration q: a moving point's coordinates from q, a fixed point's from the model.
// DrawnPointNames gives their names in the same order (a drawing's "order").
std::vector<Eigen::Vector3d> SpatialPointPositions(const Model& m, const Eigen::VectorXd& q);
std::vector<std::string> DrawnPointNames(const Model& m);

inline constexpr int kMaxFrames = 36;

// The sample indices a drawing of `m`'s motion shows: at most `max_frames` of analysis.samples,
// evenly spread, the first and the last included.
std::vector<int> FrameSamples(const Model& m, int max_frames = kMaxFrames);

// {"t": [t_0, …], "p": [[x_0, y_0, x_1, y_1, …] per frame]} (points in model order, 6 significant
// digits: a drawing's precision) for the frames of FrameSamples found in `trajectory` (a motion that
// stopped early has fewer); a spatial scene's has "dim": 3 and x, y, z per point (its points in
// SpatialPointPositions' order). null for a gear train or a scene with no motion.
nlohmann::json MotionFrames(const Model& m, const std::vector<Sample>& trajectory, int max_frames = kMaxFrames);

}  // namespace mechbench::harness
