// Planar linkages by sequential closed-form dyads (modular kinematics / Assur groups).
//
// Starting from the fixed points and the driven inputs, the planner repeatedly finds a point or a
// body that one closed form determines from what is already known, until everything is known:
//   - place a body from two of its known points, or from one known point and a known direction
//     (a driven angle: the crank; or a known point sliding on its line: the slotted bar, §3.4);
//   - a point on two lines (fixed guide, driven coordinate, the line of a placed body): line–line;
//   - a point on a line and at a known distance from a known point: circle–line (RRP);
//   - a point at known distances from two known points: circle–circle (RRR). A distance may vary
//     in time: a driven linear actuator (§4.7), or the far side of the rigid triangle that two bars
//     with a driven relative angle form (law of cosines, §4.2/§4.3).
// Velocities and accelerations follow each step by the vector method (v_B = v_A + ω×AB,
// a_B = a_A + α×AB + ω×(ω×AB), sliding terms with Coriolis 2ω×v_rel), with at most a 2×2 system per
// dyad solved by Cramer's rule. No Newton iteration, no Jacobian, no system over q.
#pragma once

#include "mechbench/analytic/vector.h"
#include "mechbench/model.h"

#include <Eigen/Core>

#include <array>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace mechbench::analytic {

// Planar kinematic state of a point [length, length/s, length/s²].
struct PointState2 {
  Vec2 p{kNaN, kNaN}, v{kNaN, kNaN}, a{kNaN, kNaN};
};

// Planar state of a body: angle of its body-frame x axis from the ground x axis [rad], and its
// angular velocity and acceleration about the plane normal [rad/s, rad/s²].
struct BodyState2 {
  double angle = kNaN, omega = kNaN, alpha = kNaN;
};

// Everything the solver knows at one instant.
struct LinkageState {
  double t = 0;                        // [s]
  std::vector<PointState2> points;     // per Model::points
  std::vector<BodyState2> bodies;      // per Model::bodies
  std::vector<double> q, qd, qdd;      // per Model::coordinates (relative coordinates)
  std::vector<int> choice;             // discrete branch taken by each step (kept along a motion)
  std::vector<int> coord_choice;       // form branch of each relative coordinate (see FormBranch)
  double residual = 0;                 // max |constraint| over every equation of the model [length]
  // max |d/dt constraint| [length/s, rad/s]: catches over-specified inputs that agree at t0 but
  // not in their rates (a driver on a coordinate the closed forms already fix).
  double residual_rate = 0;
};

// A closed form that cannot be evaluated at some instant: a loop that cannot close, or a singular
// (toggle) position of a dyad. `where` names the body, driver or joint responsible.
// `out_of_reach`: the loop has no real solution there (a bar too short or too long for the
// driven input), as opposed to a singular position the closed form cannot follow.
class AssemblyError : public std::runtime_error {
 public:
  AssemblyError(SourceRef where, const std::string& problem, std::string fix, bool out_of_reach = false)
      : std::runtime_error(problem), where_(std::move(where)), fix_(std::move(fix)), out_of_reach_(out_of_reach) {}
  const SourceRef& where() const { return where_; }
  const std::string& fix() const { return fix_; }
  bool out_of_reach() const { return out_of_reach_; }

 private:
  SourceRef where_;
  std::string fix_;
  bool out_of_reach_ = false;
};

// A line a point must lie on.
struct LineSource {
  enum class Kind { kFixedGuide, kDrivenX, kDrivenY, kBodySlider };
  Kind kind = Kind::kFixedGuide;
  int joint = -1;   // kFixedGuide, kBodySlider
  int driver = -1;  // kDrivenX / kDrivenY: the point's coordinate is prescribed
};

// A known (possibly time-varying) distance from a known point.
struct DistanceSource {
  enum class Kind { kBody, kDrivenDistance, kTriangle };
  Kind kind = Kind::kBody;
  int from = -1;         // the known end
  int body = -1;         // kBody
  double length = 0;     // kBody [length]
  int coordinate = -1;   // kDrivenDistance, kTriangle
  int driver = -1;       // kDrivenDistance, kTriangle
  double la = 0, lb = 0;  // kTriangle: the two bar lengths that meet at the shared point
  double sign = 1;        // kTriangle: cos(interior angle) = sign · cos(angle between the vectors)
};

enum class StepKind {
  kPlaceByTwoPoints,  // a body with two known points (and so all its points)
  kPlaceByAngle,      // a body with one known point and a driven angle along it (crank)
  kPlaceBySlider,     // a body with one known point on its line and a known point sliding on it
  kLineLine,          // a point on two lines
  kCircleLine,        // a point on a line at a known distance from a known point (RRP)
  kCircleCircle,      // a point at known distances from two known points (RRR)
  // A body that cannot turn (two of its points on parallel fixed guides, its angle ψ fixed):
  kPlaceByOrientation,  // with one known point
  kPlaceTranslating,    // with a known point sliding along its line, and a point on a fixed guide
                        // across that line (the Scotch yoke)
};

struct Step {
  StepKind kind = StepKind::kLineLine;
  int point = -1;       // dyad steps: the point solved
  int body = -1;        // placement steps: the body placed
  int known = -1;       // placement steps: the known body point it starts from
  int other = -1;       // kPlaceByTwoPoints: the second known point; kPlaceBySlider: the slider
  int coordinate = -1;  // kPlaceByAngle
  int driver = -1;      // kPlaceByAngle
  int joint = -1;       // kPlaceBySlider
  double psi = 0;       // kPlaceByOrientation, kPlaceTranslating: the body's fixed angle [rad]
  std::array<LineSource, 2> lines{};  // kPlaceTranslating: lines[0] is the fixed guide of `known`
  std::array<DistanceSource, 2> dists{};
  std::string text;     // e.g. "2 <- RRR(1, B)"
};

// A coupling (Model::couplings) used as an input once one of its two coordinates is known:
// q_to = k q_from + c. It acts as a driver whose law is read from the solved state.
struct CoupledInput {
  int coupling = -1;
  int from = -1, to = -1;  // q slots
  double k = 1, c = 0;
};

struct LinkagePlan {
  std::vector<Step> steps;
  // Driver index d < Model::drivers.size(): a driver; d = drivers.size() + i: coupled[i].
  std::vector<bool> driver_used;      // per driver, then per coupled input
  std::vector<CoupledInput> coupled;
  std::vector<int> slot_driver;       // per q slot: the driver (as above) that sets it, or −1
};

// Dry decomposition of the model into closed-form steps. nullopt when some point remains unknown
// or a driver is not used; `why_not` then says which.
std::optional<LinkagePlan> PlanLinkage(const Model& model, std::string* why_not);

// The sign of an angle coordinate's form: the direction angle α of `vec` (from `ref`, or from the
// ground x axis) is α = σ θ + c. cos/dot forms cannot tell θ from −θ, sin cannot tell θ from π − θ,
// cross cannot tell vec from −vec; the branch nearest the scenario's guess is kept.
struct FormBranch {
  double sigma = 1, c = 0;
};
std::vector<FormBranch> FormBranches(AngleForm form);

class LinkageSolver {
 public:
  // Throws std::invalid_argument with the reason when the model does not decompose.
  explicit LinkageSolver(const Model& model);

  const LinkagePlan& plan() const { return plan_; }

  // The configuration, velocities and accelerations at time t. With previous == nullptr the
  // branches come from the scenario's guesses; otherwise from that (earlier) sample: fixed choices
  // are kept and two-solution intersections take the root nearest the extrapolated position.
  // Throws AssemblyError when a loop cannot close or a dyad is singular.
  LinkageState Solve(double t, const LinkageState* previous = nullptr) const;

  // q, q̇, q̈ in Model::q_layout order.
  void ToLayout(const LinkageState& s, Eigen::VectorXd& q, Eigen::VectorXd& qd, Eigen::VectorXd& qdd) const;

  // Velocity of a point relative to the body it slides along, along the unit vector from the
  // body's first to its second point [length/s]; joint must be a kPointOnBody joint.
  double SlideVelocity(const LinkageState& s, int joint) const;

 private:
  const Model& m_;
  LinkagePlan plan_;
  Eigen::VectorXd guess_q_;  // Model::GuessQ(), for coordinate branches
};

// Rate of the direction angle of a vector r(t) with ṙ, r̈: φ̇ = (r × ṙ)/|r|²,
// φ̈ = (r × r̈ − 2 (r·ṙ) φ̇)/|r|² (valid when |r| varies, e.g. a sliding point).
void DirectionRates(const Vec2& r, const Vec2& rd, const Vec2& rdd, double& phi_d, double& phi_dd);

}  // namespace mechbench::analytic
