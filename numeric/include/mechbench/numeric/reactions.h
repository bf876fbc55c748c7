// Joint reactions at revolute pins (issue 4): the force each body receives at a pin from
// everything else joined there, at the instant t0 of a free scene.
//
// Convention (the quantity names are listed in scenarios/include/mechbench/method.h):
//   reaction.<point>.<body>.x / .y  [N, world frame] — the force body <body> receives at the pin at
//   basic point <point> from everything else joined there: the other bodies that share the point,
//   or the ground when the point is fixed.
// Which (point, body) pairs (ReactionPins; the engine side, EngineReactionQuantities, applies the
// same rule to an engine's joints):
//  - a revolute pin is a Model::Point held by two or more bodies, or a fixed point held by one;
//  - sliders are left out: the sliding point of a slider joint (its block is joined there too, and a
//    fixed guide that eliminates a coordinate keeps no multiplier for it), and every pin of a
//    slider's guide body (in natural coordinates the slider's force on that body lands on its
//    basic points, mixed with their pin forces);
//  - a body with two or more fixed points is part of the ground (no rows, statically indeterminate).
// Applied point forces (Model::forces) are not reactions: a force on a shared point acts on the
// first body in file order that holds the point (as the engine graph applies it), so the pin
// forces never include it. A spring–damper's end forces are applied the same way; a torque acts on
// its own body, as the pair of forces at its first two points that does its work (dynamics.h).
//
// Natural coordinates (JointReactions): for body b with basic points i, j and extra points k,
//   F_b = M_e [r̈_i; r̈_j] + G_bᵀ λ_b − Q_b − F_applied   (every point coordinate, constants included)
// where M_e is the element mass matrix (dynamics.h), G_b the gradient of b's own rows (its distance
// row and the linear rows of its extra points) with respect to the coordinates of all its points,
// λ_b their multipliers from the index-1 solution, Q_b its weight through Cᵀ(com) m g; F_b's
// components at point P are the force b receives at P. Rows that belong to no body (a coordinate's
// angle or distance row) carry λ = 0 in a free scene (their coordinate has no mass and no load);
// a point they touch is left out if one does not (with a note). In M q̈ + Φ_qᵀ λ = Q / u (u =
// meters_per_unit, forward_dynamics.h) the first two terms are in kg·length/s², so they are
// multiplied by u to give newtons.
#pragma once

#include "mechbench/method.h"
#include "mechbench/model.h"
#include "mechbench/numeric/natural_model.h"

#include <Eigen/Core>

#include <string>
#include <vector>

namespace mechbench::numeric {

struct PinBody {
  int point = -1;  // index into Model::points
  int body = -1;   // index into Model::bodies
};

// The (point, body) pairs that get reaction quantities, by point then body in file order. Each
// point or body the rule leaves out that would otherwise qualify is described in `left_out`.
std::vector<PinBody> ReactionPins(const Model& model, std::vector<std::string>* left_out = nullptr);

// "reaction.<point>.<body>.x" (axis 0) or ".y" (axis 1).
std::string ReactionName(const std::string& point, const std::string& body, int axis);

struct PinReaction {
  PinBody pin;
  Eigen::Vector2d force{kNaN, kNaN};  // [N, world frame]
};
struct Reactions {
  std::vector<PinReaction> pins;
  std::vector<std::string> notes;  // what was left out and why
};

// The reactions from the index-1 solution at t0: the assembled q, q̇ (the dampers), its q̈, and λ for all m rows of
// `nm` (DynamicsSystem::FullLambda: 0 on `dropped` rows). When a body's own row was dropped as
// redundant, its multiplier is not its own force and no reaction is given (a note says so).
Reactions JointReactions(const NaturalModel& nm, const Eigen::VectorXd& q, const Eigen::VectorXd& qd,
                         const Eigen::VectorXd& qdd,
                         const Eigen::VectorXd& lambda, const std::vector<int>& dropped);

// reaction.<point>.<body>.x|y of `r` into `out`.
void AddReactionQuantities(const Model& model, const Reactions& r, Quantities& out);

// ---- engines -----------------------------------------------------------------------------------
// The same rule on an engine's joints (engine adapters describe each graph joint; engine-neutral,
// no graph or engine types here).
struct EngineJointForce {
  bool revolute = true;    // false: a prismatic joint (its point and any body at its ends are left out)
  int point = -1;          // the Model point the joint sits at (revolute) or slides (prismatic)
  std::string point_name;  // that point's name (prismatic: the slider's point, "" for an engine's own joint)
  // The two ends: a Model body's name, "" for the ground (then *_ground is true) or for a body the
  // engine added (slider block, actuator half).
  std::string parent, child;
  bool parent_ground = false, child_ground = false;
  Eigen::Vector2d on_child{kNaN, kNaN};  // revolute: force [N, world] the child receives from the parent
  // A coupling (a rack and pinion, a belt: Model::couplings) the engine applies on this joint's
  // coordinate, "" for none. Every engine couples two joint coordinates, so the tooth force acts
  // on the joint's bodies as a generalized force, not at a pitch point: their pins' reactions
  // cannot be told apart from it and are left out (natural coordinates leave them out too).
  std::string coupling;
};
struct EngineReactions {
  Quantities quantities;           // reaction.<point>.<body>.x|y
  std::vector<std::string> notes;  // what was left out and why
};
EngineReactions EngineReactionQuantities(const std::vector<EngineJointForce>& joints);

}  // namespace mechbench::numeric
