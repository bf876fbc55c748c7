// Closed forms of the classic spatial one-loop kinds: two points, each on a one-parameter path
// fixed to the ground, joined by a bar with spherical joints at both ends (or a `distance` joint).
//   - a crank: a rigid body turning about a fixed axis (a revolute to the ground: a fixed point
//     and a fixed unit vector among its entities, everything else on it moving); its path
//     parameter is its turn δ [rad] from the file's pose;
//   - a slider: a point on a fixed line (an `along` coordinate from a fixed point along a fixed
//     vector: a prismatic pair); its parameter is that coordinate s [length].
// Crank + crank is the RSSR four-bar, crank + slider the spatial slider-crank (RSSP); one of the
// two is driven (the input). The kind is recognised from the bodies, shared entities, joints and
// coordinates of Model::spatial, never from names.
//
// Position: B on the input path at x1 (from the driver), then C on the output path with
// |C − B| = L: a crank's A cos δ + B sin δ = C, δ = atan2(B, A) ± acos(C / √(A² + B²)); a slider's
// s² + 2 s d·(F − B) + |F − B|² − L² = 0. The sign (the assembly branch) is the one nearest the
// file's pose at t0, then kept. Velocity and acceleration by differentiating |C − B|² = L²
// analytically (r = C − B, C' = dC/dx2): ẋ2 = r·Ḃ / r·C',
// ẍ2 = (r·B̈ − ẋ2² r·C'' − |ṙ|²) / r·C'.
#pragma once

#include "mechbench/analytic/kinematics.h"
#include "mechbench/analytic/vector.h"
#include "mechbench/model.h"

#include <Eigen/Core>

#include <optional>
#include <string>
#include <vector>

namespace mechbench::analytic {

// One path of the loop.
struct SpatialPath {
  bool crank = true;       // else a slider
  int body = -1;           // crank: its body (SpatialModel::bodies)
  int origin = -1;         // the fixed point: the crank's axis point, or the slider's `from`
  int axis = -1;           // the fixed unit vector: the crank's axis, or the slider's direction
  int end = -1;            // the point the bar joins (an entity)
  int coordinate = -1;     // slider: its `along` coordinate (SpatialModel::coordinates)
  std::vector<int> moving;  // every moving entity whose place this path's parameter gives
  double x_file = 0;       // the parameter at the file's pose (crank 0, slider its s)
};

// The state at one instant: each path's parameter and its rates, and the branches taken.
struct SpatialLoopState {
  double t = 0;
  double x[2] = {0, 0}, xd[2] = {0, 0}, xdd[2] = {0, 0};  // [0] the input, [1] the output
  int branch_in = 0;   // a point slot driving a crank: the sign of its acos (0: not used)
  int branch_out = 0;  // the output's sign, chosen at t0
  double residual = 0;       // | |C − B| − L | [length]
  double residual_rate = 0;  // |r·ṙ| / L [length/s]
};

class SpatialLoopSolver {
 public:
  explicit SpatialLoopSolver(const Model& m);
  // Why the closed forms do not apply (the recogniser's or the driver's reason), or nothing.
  const std::optional<std::string>& why_not() const { return why_not_; }
  // What was recognised, for the run's settings.
  std::string Describe() const;
  // The state at t; `prev` (nullptr at t0) keeps the branches and the turns continuous. Throws
  // AssemblyError where the loop cannot close or sits at a dead point.
  SpatialLoopState Solve(double t, const SpatialLoopState* prev) const;
  // An entity's place and rates at `s` (a point or a unit vector; fixed ones at rest).
  PointState3 Entity(const SpatialLoopState& s, int entity) const;
  void ToLayout(const SpatialLoopState& s, Eigen::VectorXd& q, Eigen::VectorXd& qd, Eigen::VectorXd& qdd) const;

 private:
  const Model& m_;
  std::optional<std::string> why_not_;
  SpatialPath path_[2];  // [0] the input (driven), [1] the output
  double length_ = 0;    // the bar's |C − B| at the file's pose
  int driver_slot_ = -1;
  // How the driver gives x1: 0 the path's own coordinate (a slider's `along`), 1 a crank's angle
  // coordinate (x1 = sign (θ − θ_file)), 2 a slot of an entity on the input path.
  int driver_kind_ = 0;
  double angle_sign_ = 1, angle_file_ = 0;
  int driven_entity_ = -1, driven_axis_ = -1;
  std::vector<int> path_of_;     // per entity: 0, 1, or -1 (fixed)
  std::vector<int> coord_path_;  // per spatial coordinate: the path it measures
  std::vector<int> coord_sign_;  // and its sign (an angle from the crank back to a fixed vector: −1)

  std::optional<std::string> Recognise();
  std::optional<std::string> CheckDriver();
  // The input's parameter from the driver at t (value, rate, acceleration); branch_in in/out.
  bool Input(double t, const SpatialLoopState* prev, SpatialLoopState& s, std::string& why) const;
  // The driven slot's component as k0 + k1 cos δ + k2 sin δ on a crank, k0 + k1 s on a slider.
  void SlotTerms(double& k0, double& k1, double& k2) const;
  double SlotReach() const;   // √(k1² + k2²)
  double SlotCentre() const;  // k0
  // The path's end at parameter x, and its first and second derivatives along x.
  void End(int k, double x, Vec3& p, Vec3& d1, Vec3& d2) const;
};

}  // namespace mechbench::analytic
