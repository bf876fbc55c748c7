// The engines' spatial graph (issue 13): a spatial scene (kind: spatial, Model::spatial) as rigid
// bodies in 3-D with ball, revolute and free joints, a spanning tree from ground and loop
// closures, for the engines that simulate 3-D scenes. It stands beside the planar graph (graph.h),
// which stays planar; nothing here is engine-specific.
//
// Conventions
//  - One graph body per model body. Its frame: origin at the body's first entity (a point), axes
//    the world's at t0 (R = 1 at t0), so every entity's body coordinates are its assembled world
//    value at t0 minus the origin (a point) or as it is (a unit vector). Ground is body -1; fixed
//    entities are ground.
//  - Joints are inferred from shared entities: two bodies (or a body and ground, through the
//    fixed entities it lists) sharing one point are a spherical joint there; one point and one
//    unit vector a revolute joint about it. A body joined to nothing gets a free joint from
//    ground. The tree is a breadth-first spanning tree from ground; the remaining joints are loop
//    closures: a ball closure holds the shared point; a revolute closure is two ball closures on
//    its axis, at the point and one length scale along the axis (six rows of rank five: the
//    engines' constraint solvers take the redundant one).
//  - Mass properties in the body frame (world axes at t0) about the centre of mass. A bar is a
//    slender uniform rod with a stated small axial inertia (engines need a positive-definite
//    inertia); a point mass a body with a stated small isotropic inertia. For axially symmetric
//    bodies on joints at points of their axis neither changes the motion (no torque about the
//    axis, Euler's equation about it is İ ω̇ = 0).
//  - An `along` coordinate (P − A = s d) is a prismatic joint along d (its coordinate s − s(t0))
//    from the line's body: ground when A and d are fixed, else the model body that lists both A
//    and d (d is fixed in it). Its child: P's body when that is a one-point body (a slider block or a
//    bead: on a fixed line its rotation is free and uncoupled; on a moving line it turns with the
//    line's body, which gives up the inertia the point mass's body is given, so the pair's is the
//    file's) or a body that shares two non-parallel
//    vectors with the line's body (a prismatic pair: no relative rotation; those shared vectors
//    make no other joint); else a graph body of its own, "slider of s" (no model body; a stated
//    small mass), joined to P's body by a ball at P, or by a revolute about d at P when P's body
//    shares d with the line's body (a cylindrical pair).
//  - Units as in graph.h: lengths in the file's unit, kg, s; forces in kg·length/s² (the model's
//    newtons / meters_per_unit), torques in kg·length²/s².
#pragma once

#include "mechbench/engines/graph.h"
#include "mechbench/method.h"
#include "mechbench/model.h"

#include <Eigen/Core>

#include <array>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace mechbench::engines {

// Stated defaults for what a spatial scene does not give an engine.
struct SpatialGraphOptions {
  double bar_axial_inertia_ratio = 1e-4;  // a bar's inertia about its own axis ÷ its transverse m L²/12
  double point_radius = 1e-2;             // a point mass's radius of gyration ÷ the scene's length scale
  double closure_axis_length = 1.0;       // a revolute closure's second ball on its axis, × the length scale
  // A driven scene's massless body: a uniform rod of this many kg per metre between its first two
  // points (the planar graph's default, GraphOptions::link_mass_per_length).
  double link_mass_per_length = 1.0;
  // An added slider body (an `along` coordinate on a point of a bar or a rigid body): its mass ÷
  // the scene's total body mass (1 kg when the scene has none); its inertia a point mass's. In a
  // free scene it changes the motion by about its ratio (spatial_bar_on_rail: 2.5 × the ratio,
  // relative), so it is tiny; in a driven scene the motion is prescribed, and a mass like the
  // bodies' keeps the explicit engines well conditioned (MuJoCo's Euler came apart at 1e-4).
  double slider_mass_ratio = 1e-8;
  double driven_slider_mass_ratio = 0.25;
};

enum class SpatialJointType { kBall, kRevolute, kFree, kPrismatic };

struct SpatialGraphBody {
  std::string name;
  int model_body = -1;        // index into Model::spatial.bodies; -1 for an added slider body
  SpatialState initial;       // at t0: R = 1, p = the first entity, v and omega assembled; a, alpha 0
  double mass = 0;            // [kg]
  Eigen::Vector3d com_B{0, 0, 0};                       // [length]
  Eigen::Matrix3d inertia_B = Eigen::Matrix3d::Zero();  // about the centre of mass, body axes [kg·length²]
  std::string mass_source;    // "model", or the stated default used
};

struct SpatialGraphJoint {
  SpatialJointType type = SpatialJointType::kBall;
  std::string name;            // "revolute rod1-rod2 at P2 about u2"
  int parent = -1, child = -1; // graph bodies, -1 = ground (a free joint's parent is ground)
  int point = -1, axis = -1;   // the shared entities (Model::spatial.entities); axis -1 for a ball
  Eigen::Vector3d at_parent_B{0, 0, 0}, at_child_B{0, 0, 0};  // the shared point in each frame (ground: world)
  Eigen::Vector3d axis_B{0, 0, 1};  // revolute, prismatic: the unit axis in both frames at t0 (both are world axes then)
  int along = -1;              // prismatic: its `along` coordinate (Model::spatial.coordinates); parent the line's body
  bool in_tree = false;
};

// A constant world force at a body-fixed point [kg·length/s²].
struct SpatialGraphForce {
  int body = -1;
  Eigen::Vector3d at_B{0, 0, 0};
  Eigen::Vector3d f_W{0, 0, 0};
};
// A constant world torque on a body [kg·length²/s²].
struct SpatialGraphTorque {
  int body = -1;
  Eigen::Vector3d torque_W{0, 0, 0};
};
// A linear spring–damper between two points, the tension k (L − L0) + c L̇ + F0 (graph.h's
// GraphSpring in 3-D), each end on a body or fixed (body -1: `at` in the world).
struct SpatialGraphSpring {
  std::string name;
  int body_a = -1, body_b = -1;
  Eigen::Vector3d at_a{0, 0, 0}, at_b{0, 0, 0};
  double stiffness = 0, damping = 0, free_length = 0, preload = 0;
};

// A torsional spring–damper (Model::torsions) on an angle coordinate θ = atan2((u × w)·a, u·w)
// (u = `from`, w = `to`, a = the axis): the torque T = −k (θ − θ0) − c θ̇ + T0, with k, c, T0 in
// kg·length²/s² (the model's N·m / meters_per_unit²). SpatialStateLoads applies it through θ's
// gradient: the body holding vector e (u, w or a) takes T e × ∂θ/∂e; on a hinge (u, w ⊥ a) that is
// +T a on `to`'s body and −T a on `from`'s, as numeric's generalized force T on θ's slot.
struct SpatialGraphTorsion {
  std::string coordinate;
  int slot = -1;  // θ's slot in Model::q_layout
  double stiffness = 0, damping = 0, free_angle = 0, preload = 0;
  std::array<int, 3> body{-1, -1, -1};  // the bodies holding u, w, a (-1: fixed)
  std::array<Eigen::Vector3d, 3> vec_B{Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ()};
  double Torque(double th, double th_dot) const { return -stiffness * (th - free_angle) - damping * th_dot + preload; }
};
// A load given by a law of t, q or q̇ (SpatialLoad::HasLaw) or in a body's frame: a point force
// at a body point or a world torque on a body, its components × scale (1/meters_per_unit for a
// force, its square for a torque) in the graph's units; evaluated by SpatialStateLoads. A follower
// force (`frame` ≥ 0, a graph body) has components in world axes at t0, turned by that body's R
// (graph bodies' frames have the world's axes at t0). Or, with `spring` set, a spring–damper with
// a law (SpringDamper::HasLaw) between `at_B` on `body` and `at_b` on `body_b` (-1: fixed, `at`
// in the world): its tension k (L − L0) + c L̇ + F0/meters_per_unit from the observed q, q̇.
struct SpatialGraphLawLoad {
  int body = -1;
  bool torque = false;
  Eigen::Vector3d at_B{0, 0, 0};
  SpatialLoad load;
  double scale = 1;
  int frame = -1;
  std::optional<SpringDamper> spring;
  int body_b = -1;
  Eigen::Vector3d at_b{0, 0, 0};
};

// A driver on an angle coordinate θ about a tree revolute joint's own axis, from a vector of one of
// its bodies to one of the other's: joint coordinate(t) = scale · (θ(t) − θ(t0)), scale = ±1; or
// on an `along` coordinate s, its prismatic joint: joint coordinate(t) = s(t) − s(t0), scale 1.
struct SpatialDriverMap {
  int joint = -1;
  double scale = 1;
  Driver law;
  std::string coordinate;
  double Position(double t, double t0) const { return scale * (law.At(t, t0) - law.value); }
  double Rate(double t, double t0) const { return scale * law.RateAt(t, t0); }
  double Acceleration(double t, double t0) const { return scale * law.AccelerationAt(t, t0); }
};

struct SpatialGraph {
  std::vector<SpatialGraphBody> bodies;
  std::vector<SpatialGraphJoint> joints;  // tree joints first, each parent's before its child's
  std::vector<SpatialGraphForce> forces;
  std::vector<SpatialGraphTorque> torques;
  std::vector<SpatialGraphSpring> springs;
  std::vector<SpatialDriverMap> drivers;
  // Loads of the state and of t (SpatialStateLoads): torsions and laws; `model` (for the observer
  // that gives their q, q̇) is set only when one of them is not empty.
  std::vector<SpatialGraphTorsion> torsions;
  std::vector<SpatialGraphLawLoad> law_loads;
  std::shared_ptr<const Model> model;
  bool driven = false;
  Eigen::Vector3d gravity{0, 0, 0};  // [length/s²]
  double t0 = 0;
  Sample initial;                    // q, q̇ at t0 as assembled (q̈ too in a driven scene; zero in a free one)
  std::vector<double> sample_times;
  double length_scale = 1;
  double meters_per_unit = 1;
  std::vector<std::string> notes;
  std::map<std::string, std::string> settings;
  int TreeJointOf(int body) const;
  int Closures() const;
};

struct SpatialGraphOrReason {
  std::optional<SpatialGraph> graph;
  std::string reason;
};
// The spatial graph of a spatial scene, or why it cannot be built (a driver on anything but an
// angle about a tree revolute's axis or an `along` coordinate, a joint by a distance or a dot
// product, an `along` coordinate whose moving line is on no one body or that it cannot pair (PairOf
// in spatial_graph.cc), a prismatic pair that closes a loop, a massless
// body in a free scene (a driven scene's gets the stated rod), a sharing it does not map). Assembles t0 with the numeric solver (a free scene's `initial:`
// conditions as drivers at t0); a scene that cannot assemble throws the solver's ScenarioError.
SpatialGraphOrReason BuildSpatialGraph(const Model& model, const SpatialGraphOptions& options = {});

// A prismatic joint's travel: the child's copy of the joint point from the parent's, along the axis
// as the parent carries it (0 at t0); `parent` is a default SpatialState for ground.
double PrismaticTravel(const SpatialGraphJoint& j, const SpatialState& parent, const SpatialState& child);
// Its rate at t0 from the graph bodies' initial states (both frames have the world's axes then).
double PrismaticRateAtT0(const SpatialGraph& g, const SpatialGraphJoint& j);

// q, q̇, q̈ in Model::q_layout from the bodies' world states: a point is p + R r_B, a vector R u_B,
// an angle coordinate atan2((u × w)·a, u·w) followed continuously from its assembled value, an
// `along` coordinate (P − A)·d.
class SpatialObserver {
 public:
  SpatialObserver(const Model& model, const SpatialGraph& graph);
  // `states` has one entry per graph body; `with_acc` false leaves q̈ empty.
  Sample Observe(double t, const std::vector<SpatialState>& states, bool with_acc);
  // q./qd./qdd.<slot> and p./v./a.<entity>.x|y|z (fixed entities too).
  Quantities InstantQuantities(const Sample& s, const std::vector<SpatialState>& states, bool with_acc) const;

 private:
  struct Kin {
    Eigen::Vector3d p, v, a;
  };
  Kin EntityKin(int e, const std::vector<SpatialState>& st) const;
  const Model* model_;
  const SpatialGraph* graph_;
  std::vector<int> body_;                // per entity: the graph body it is fixed in, -1 fixed
  std::vector<Eigen::Vector3d> local_;   // per entity: body coordinates (or its constant value)
  std::optional<Eigen::VectorXd> last_q_;
};

// A world force through a body's centre of mass and a world torque about it.
struct SpatialWrench {
  Eigen::Vector3d force{0, 0, 0};   // [kg·length/s²]
  Eigen::Vector3d torque{0, 0, 0};  // [kg·length²/s²]
};

// The graph's torsions and load laws (SpatialGraph::torsions, law_loads) from an engine's body
// states, the spatial counterpart of StateLoads (graph.h): q and q̇ through a SpatialObserver (the
// laws' variables, θ and θ̇ of a torsion), each load reduced to a wrench at its body's centre of
// mass. Engines call Evaluate wherever they evaluate forces (every stage of their own integrator,
// or once at each step's start); the observer follows angles from the last call, so calls must be
// at states a step apart.
class SpatialStateLoads {
 public:
  explicit SpatialStateLoads(const SpatialGraph& g);
  bool empty() const { return g_->torsions.empty() && g_->law_loads.empty(); }
  // One wrench per graph body into `out` (resized); `st` needs poses and velocities only.
  void Evaluate(double t, const std::vector<SpatialState>& st, std::vector<SpatialWrench>& out);

 private:
  const SpatialGraph* g_;
  std::optional<SpatialObserver> obs_;
  std::vector<double> x_;  // [t, q, q̇] for the laws
};

std::string Describe(const SpatialGraph& g);

}  // namespace mechbench::engines
