// The engine-neutral rigid multibody graph every engine adapter consumes (no engine headers here).
//
// BuildGraph() translates a mechbench::Model into rigid bodies with planar poses at t0, mass
// properties, joints (revolute, prismatic, gear coupling), a spanning tree with loop closures for
// reduced-coordinate engines, the drivers mapped onto joint coordinates, and an Observer that turns
// engine body states back into a Sample in Model::q_layout order. Everything is planar: engines
// simulate in their XY plane (z = 0, rotations about +z); the model's embedding is applied only to
// the reported 3-D quantities.
//
// Conventions
//  - A body's frame is the model's: origin at its first point, x towards its second. Added bodies
//    (slider blocks, actuator halves) state theirs below. Ground is body index -1.
//  - Every joint coordinate is zero at t0 (the assembled configuration): a revolute coordinate is
//    (θ_child − θ_parent) − its value at t0; a prismatic coordinate is the child's displacement
//    along the axis since t0. Engines build their joints so that this holds.
//  - Units are the scene's: lengths in the file's unit, kg, s. Gravity and forces as in the file.
#pragma once

#include "mechbench/method.h"
#include "mechbench/model.h"
#include "mechbench/numeric/reactions.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

namespace mechbench::engines {

// Planar rigid-body state of a body frame's origin: pose, velocity, acceleration.
struct PlanarState {
  Eigen::Vector2d p{0, 0};  // origin position [length]
  double angle = 0;         // frame angle from the x axis [rad] (any 2π branch)
  Eigen::Vector2d v{0, 0};  // origin velocity [length/s]
  double omega = 0;         // [rad/s]
  Eigen::Vector2d a{0, 0};  // origin acceleration [length/s²]
  double alpha = 0;         // [rad/s²]
  // A body-fixed point (body-frame coordinates) in the world, and its velocity and acceleration.
  Eigen::Vector2d PointPos(const Eigen::Vector2d& p_B) const;
  Eigen::Vector2d PointVel(const Eigen::Vector2d& p_B) const;
  Eigen::Vector2d PointAcc(const Eigen::Vector2d& p_B) const;
};

enum class BodyKind {
  kLink,         // a Model body with points
  kSliderBlock,  // added: the block of a slider joint (carries the sliding point at its origin)
  kActuator,     // added: cylinder (origin at the first end) or rod (origin at the second end)
  kGearMember,   // a gear-train member turning about a fixed axis
};

struct GraphBody {
  std::string name;
  BodyKind kind = BodyKind::kLink;
  int model_body = -1;  // index into Model::bodies, -1 for added bodies
  PlanarState initial;  // at t0 (accelerations only in driven scenes; 0 otherwise)
  // Mass properties, body frame [kg, length, kg·length²].
  double mass = 0;
  Eigen::Vector2d com_B{0, 0};
  double inertia_com = 0;
  std::string mass_source;  // "model", or the stated default that was used
};

enum class PairType { kRevolute, kPrismatic, kGear };

struct GraphJoint {
  PairType type = PairType::kRevolute;
  std::string name;         // "revolute crank-coupler at 1", "prismatic block.A on ground"
  int parent = -1;          // graph body, -1 = ground
  int child = -1;           // graph body
  int point = -1;           // the model point the joint sits at (revolute), or slides (prismatic)
  std::string point_name;   // that point's name in the model (reaction quantities name it; "" when none)
  // Revolute: the joint point in each body's frame. Prismatic: a point on the axis in each frame
  // (coincident at t0), the axis direction (unit) in the parent frame, and the child frame's
  // fixed angle relative to the parent.
  Eigen::Vector2d at_parent_B{0, 0}, at_child_B{0, 0};
  Eigen::Vector2d axis_parent_B{1, 0};
  double angle0 = 0;        // revolute/prismatic: θ_child − θ_parent at t0 [rad]
  // Gear: Z_a (ω_a − ω_c) + z_b (ω_b − ω_c) = 0 with a = parent, b = child, c = carrier
  // (-1 = ground, ω_c = 0), z_b = ±Z_b (− for an internal mesh). Never a tree joint.
  int carrier = -1;
  double z_a = 0, z_b = 0;
  int model_joint = -1;     // the Model joint it came from, -1 for pin joints at shared points
  bool in_tree = false;     // tree mobilizer, else a loop-closure constraint (gears: always)
  bool reversed = false;    // parent and child swapped when the tree was oriented from ground
};

// A scenario driver realised by a tree joint's coordinate:
//   joint coordinate(t) = scale · (law(t) − law(t0)).
struct DriverMap {
  int joint = -1;
  double scale = 1;
  Driver law;
  std::string coordinate;  // the driven slot's name
  double Position(double t, double t0) const { return scale * (law.At(t, t0) - law.value); }
  double Rate(double t, double t0) const { return scale * law.RateAt(t, t0); }
  double Acceleration(double t, double t0) const { return scale * law.AccelerationAt(t, t0); }
};

// A coupling (Model::couplings: a rack and pinion, a belt) between two tree joints' coordinates,
//   coordinate of joint_b = ratio · coordinate of joint_a   (both zero at t0),
// from q_b − q_b(t0) = k (q_a − q_a(t0)) with each joint's scale as for a driver (DriverMap).
struct CouplingMap {
  std::string name;  // the model's, e.g. "rack xR1 by theta"
  int joint_a = -1, joint_b = -1;
  double ratio = 0;  // [joint b's unit per joint a's unit]
};

// A force on a body-fixed point: constant in the world (f_W), or varying (Model's PointForce with
// a law or in a body's frame): components scale · law or the constants, in the world or in the
// body's own frame (the model's, graph conventions), so turning with it. Laws of t alone are in
// Graph::forces; laws that read q./qd. in Graph::state_forces, evaluated by StateLoads. Engines
// apply a varying force where they evaluate forces (see each adapter's "varying_forces" setting).
struct GraphForce {
  int body = -1;
  Eigen::Vector2d at_B{0, 0};  // [length]
  Eigen::Vector2d f_W{0, 0};   // [kg·length/s²]: the model's newtons / meters_per_unit
  Eigen::Vector2d components{0, 0};  // a varying force's constant components [kg·length/s²]
  std::array<std::shared_ptr<const CompiledExpr>, 2> law;  // over [t, q, q̇] (Graph::state_forces) or t alone
  double scale = 1;                  // law [N] → [kg·length/s²]
  bool in_body_frame = false;
  // One moving end of a spring–damper with laws (Graph::state_springs[spring], end 0 = a, 1 = b):
  // StateLoads gives its force from both ends' states; the fields above are unused then.
  int spring = -1, end = -1;
  bool Varies() const { return in_body_frame || law[0] || law[1]; }
  // The world force at time t [s] with the body at `angle` [rad] (unused unless in_body_frame).
  Eigen::Vector2d At(double t, double angle) const { return Eval(&t, angle); }
  // The same with the laws' variables [t, q, q̇] (LoadVarQ/LoadVarQd order; `x` = &t for laws of t).
  Eigen::Vector2d Eval(const double* x, double angle) const;
};

// A linear spring–damper between two points, each on a body or fixed (body -1: `at` is the point in
// the world). In the engines' units (kg, the scene's length, s) its tension along the line is
//   F = k (L − L0) + c L̇ + F0   [kg·length/s²], positive pulling the ends together,
// with k [N/m = kg/s²] and c [N·s/m = kg/s] as the file gives them (they do not change with the
// length unit), L0 in the file's length unit and F0 the model's newtons / meters_per_unit.
struct GraphSpring {
  std::string name;                    // "spring S-A"
  int body_a = -1, body_b = -1;        // graph bodies, -1 = ground
  Eigen::Vector2d at_a{0, 0}, at_b{0, 0};  // body frame (world when on ground) [length]
  double stiffness = 0;                // [kg/s²]
  double damping = 0;                  // [kg/s]
  double free_length = 0;              // [length]
  double preload = 0;                  // [kg·length/s²]
  // The tension for the ends' separation L [length] and its rate L̇ [length/s].
  double Tension(double L, double L_dot) const { return stiffness * (L - free_length) + damping * L_dot + preload; }
  // Laws per SpringDamper::Param (null = the constant above) over the load variables [t, q, q̇]
  // (model.h): such a spring is in Graph::state_springs, evaluated by StateLoads at each of the
  // engine's force evaluations (the constants above then hold the laws' values at t0).
  std::array<std::shared_ptr<const CompiledExpr>, 4> law;
  double preload_scale = 1;  // a preload law [N] → [kg·length/s²]
  bool HasLaw() const { return law[0] || law[1] || law[2] || law[3]; }
  // The tension with the laws at the load variables x.
  double Tension(double L, double L_dot, const double* x) const;
};

// A constant torque on a body [kg·length²/s²]: the model's N·m / meters_per_unit², counter-clockwise.
struct GraphTorque {
  int body = -1;
  double torque = 0;  // [kg·length²/s²]: the model's N·m / meters_per_unit²
  // A torque given as a law of t alone (one that reads the state is in Graph::state_torques): torque(t) =
  // scale · law(t). Engines apply it at the start of each step (explicit), Simbody in its own
  // force evaluation.
  std::shared_ptr<const CompiledExpr> law;
  double scale = 1;
  double At(double t) const { return law ? scale * law->Eval(&t) : torque; }
};

// A torsional spring–damper (Model::torsions) between two graph bodies: on the angle coordinate
//   θ = offset + σ (θ_vec − θ_ref)    (θ_vec, θ_ref the bodies' continuous frame angles; ground 0)
// (σ = −1 on a form's negative branch, as the Observer's angle maps), its torque
//   T = −k (θ − θ0) − c θ̇ + T0   [kg·length²/s²]
// is a generalized force on θ: σT on the vector's body and −σT on the reference's (equal and
// opposite couples about +z). k, c and T0 are the model's N·m units / meters_per_unit².
struct GraphTorsion {
  std::string name;             // "torsion theta"
  int body_ref = -1;            // graph body of θ's reference, -1 = ground
  int body_vec = -1;            // graph body of θ's vector
  double sigma = 1;
  double offset = 0;            // [rad], fixed at build time from the assembled t0 pose
  double stiffness = 0;         // [kg·length²/s²/rad]
  double damping = 0;           // [kg·length²/s/rad]
  double free_angle = 0;        // θ0 [rad]
  double preload = 0;           // T0 [kg·length²/s²]
  double Torque(double th, double th_dot) const { return -stiffness * (th - free_angle) - damping * th_dot + preload; }
};

// The world force on end b of `s` [kg·length/s²] (end a receives the opposite), from the ends'
// world positions and velocities: the explicit evaluation the stepping engines apply each step.
// Ends that coincide give no direction: zero (the tension along no line).
Eigen::Vector2d SpringForceOnB(const GraphSpring& s, const Eigen::Vector2d& p_a, const Eigen::Vector2d& v_a,
                               const Eigen::Vector2d& p_b, const Eigen::Vector2d& v_b);
// The same for a spring with laws, evaluated at the load variables x [t, q, q̇].
Eigen::Vector2d SpringForceOnB(const GraphSpring& s, const Eigen::Vector2d& p_a, const Eigen::Vector2d& v_a,
                               const Eigen::Vector2d& p_b, const Eigen::Vector2d& v_b, const double* x);

// Stated defaults for what the scene does not give (see BuildGraph).
struct GraphOptions {
  double link_mass_per_length = 1.0;  // [kg/m] uniform bar for a massless link (kinematic scenes)
  double block_mass_ratio = 1e-2;     // slider block / actuator half mass ÷ the lightest link's mass
  double block_radius = 1e-2;         // block's radius of gyration ÷ the scene's length scale
  // A link with mass and inertia 0 about its centre of mass (a lumped mass) gets this × its
  // inertia about its point farthest from the centre of mass (0: refused with the reason instead).
  double point_inertia_ratio = 1e-12;
  double gear_mass = 1.0;             // [kg] per gear member
  double gear_radius = 0.1;           // [m] its radius of gyration
};

// ---- the turning frame (Model::frame, issue 13's first slice) ------------------------------
//
// A 3-D rigid-body state in an engine's world: a body frame's orientation and origin, and the
// origin's velocity and acceleration, the angular velocity and acceleration, all in the world.
struct SpatialState {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  // body frame → world
  Eigen::Vector3d p = Eigen::Vector3d::Zero();      // origin [length]
  Eigen::Vector3d v = Eigen::Vector3d::Zero();      // [length/s]
  Eigen::Vector3d omega = Eigen::Vector3d::Zero();  // [rad/s]
  Eigen::Vector3d a = Eigen::Vector3d::Zero();      // [length/s²]
  Eigen::Vector3d alpha = Eigen::Vector3d::Zero();  // [rad/s²]
  // A body-fixed point (body-frame coordinates) in the world, and its velocity and acceleration.
  Eigen::Vector3d PointPos(const Eigen::Vector3d& p_B) const { return p + R * p_B; }
  Eigen::Vector3d PointVel(const Eigen::Vector3d& p_B) const { return v + omega.cross(R * p_B); }
  Eigen::Vector3d PointAcc(const Eigen::Vector3d& p_B) const {
    const Eigen::Vector3d r = R * p_B;
    return a + alpha.cross(r) + omega.cross(omega.cross(r));
  }
};

// The platform a scene with frame_rotation is mounted on: a body whose frame is the plane's
// (origin, axes u, v, n = u × v at t0) turning at the constant rate omega about the fixed world
// axis through axis_point, a hinge driven like the scene's drivers. The planar graph is the
// mechanism relative to the platform: every graph pose, joint and ground point (body -1) is in
// the platform's frame, z = 0. Lengths are the scene's.
struct GraphPlatform {
  Eigen::Vector3d axis_point{0, 0, 0};  // world [length]
  Eigen::Vector3d axis{0, 0, 1};        // world, unit
  double omega = 0;                     // [rad/s]
  Eigen::Vector3d origin{0, 0, 0};      // the platform frame's origin at t0 (the plane's), world
  Eigen::Matrix3d R0 = Eigen::Matrix3d::Identity();  // its axes at t0: columns u, v, n
  // The scene's gravity (in-plane, Graph::gravity) as the world vector it is at t0: constant in
  // the world while the platform turns [length/s²].
  Eigen::Vector3d gravity_W{0, 0, 0};
  // The hinge's angle since t0 [rad], and the platform's exact state at t (for a check of an
  // engine's own, and for engines that prescribe the platform's pose).
  double Angle(double t, double t0) const { return omega * (t - t0); }
  SpatialState At(double t, double t0) const;
  // A planar point or direction of the platform frame in the world at t0.
  Eigen::Vector3d PointAtT0(const Eigen::Vector2d& x) const { return origin + R0 * Eigen::Vector3d(x.x(), x.y(), 0); }
  Eigen::Vector3d DirectionAtT0(const Eigen::Vector2d& d) const { return R0 * Eigen::Vector3d(d.x(), d.y(), 0); }
  // A graph body's world state at t0 from its planar state relative to the platform: pose, and
  // absolute velocities (the platform's rotation added); accelerations are left zero.
  SpatialState LiftAtT0(const PlanarState& s) const;
};

// The planar states relative to the platform (its frame's x, y; the rates as seen on the
// platform) from world states: r = Rᵀ(p − o), v_rel = Rᵀ(v − v_o − ω_P × (p − o)), a_rel =
// Rᵀ(a − a_o − α_P × d − ω_P × (ω_P × d) − 2 ω_P × R v_rel), ω_rel = (Rᵀ(ω − ω_P))_z,
// α_rel = (Rᵀ(α − α_P − ω_P × ω))_z with R, o the platform's.
std::vector<PlanarState> RelativeToPlatform(const SpatialState& platform, const std::vector<SpatialState>& bodies);
// What keeps an adapter from mounting `g` on its platform in this slice, or nullopt: a load
// (force, torque, spring, torsion) or a gear train, whose world directions and ground ends are
// not mapped onto a turning frame (the frame's scenes are driven linkages).
struct Graph;
std::optional<std::string> PlatformLoadsReason(const Graph& g);

struct GearLayout;

struct Graph {
  std::vector<GraphBody> bodies;
  std::vector<GraphJoint> joints;  // tree joints first: each tree joint's parent precedes its child
  std::vector<DriverMap> drivers;
  std::vector<CouplingMap> couplings;
  std::vector<GraphForce> forces;
  std::vector<GraphSpring> springs;
  std::vector<GraphTorque> torques;
  std::vector<GraphTorsion> torsions;
  // Torque laws that read the state (q.<slot>, qd.<slot>): evaluated by StateLoads from the
  // scene's coordinates, observed from the engine's body states; `model` is kept for that.
  std::vector<GraphTorque> state_torques;
  // Point forces whose laws read the state (at a fixed point of their body, in the world or the
  // body's frame), evaluated by StateLoads as state_torques are.
  std::vector<GraphForce> state_forces;
  // Spring–dampers with a law (of t or of the state) in any parameter: not in `springs` (an engine's
  // own spring element holds constants); each moving end is a state_forces entry (GraphForce::spring)
  // whose force StateLoads computes from both ends, so every engine applies them where it applies
  // the state's force laws.
  std::vector<GraphSpring> state_springs;
  std::shared_ptr<const Model> model;  // set only when state_torques or state_forces is not empty
  Eigen::Vector2d gravity{0, 0};
  bool driven = false;              // the scene has drivers (else free: forward dynamics)
  double t0 = 0;
  Sample initial;                   // q, q̇, q̈ at t0 as assembled (q̈ zero in a free scene)
  std::vector<double> sample_times;  // where the trajectory is observed (t0 alone for an instant)
  double length_scale = 1;           // typical length [length]
  double meters_per_unit = 1;
  // A gear train whose file places every member and sizes every mesh (Model::gear_axes, each mesh's
  // radii): its layout at t0, in graph indices (a planet at its carrier's angle). Null otherwise.
  std::shared_ptr<const GearLayout> file_gear_layout;
  // The turning frame's platform when the scene has frame_rotation (Model::frame), else empty;
  // an engine that builds it records with the platform's and the bodies' world states.
  std::optional<GraphPlatform> platform;
  std::vector<std::string> notes;    // modelling choices every output should show
  std::map<std::string, std::string> settings;  // the defaults above, as Result::settings entries

  // Tree joint whose child is `body`, or -1 (a body attached to ground by nothing).
  int TreeJointOf(int body) const;
  int CountTree() const;
  // World position and velocity of a spring's end on `body` (-1: fixed at `at`) from body states.
  static Eigen::Vector2d EndPos(const std::vector<PlanarState>& st, int body, const Eigen::Vector2d& at) {
    return body < 0 ? at : st[body].PointPos(at);
  }
  static Eigen::Vector2d EndVel(const std::vector<PlanarState>& st, int body, const Eigen::Vector2d& at) {
    return body < 0 ? Eigen::Vector2d(0, 0) : st[body].PointVel(at);
  }
};

// Whether a force of the graph is a varying one (GraphForce::Varies).
bool HasVaryingForces(const Graph& g);
// The state_forces entries that are point-force laws (not a spring–damper's end).
size_t StateForceLaws(const Graph& g);

// Reconstructs Model::q_layout (q, q̇, q̈) and instant quantities from body states. Keeps the last
// sample to unwrap angles continuously.
class Observer {
 public:
  Observer(const Model& model, const Graph& graph);
  // `states` has one entry per graph body; `with_acc` false leaves q̈ empty.
  Sample Observe(double t, const std::vector<PlanarState>& states, bool with_acc = true);
  // q./qd./qdd.<slot>, p./v./a.<point>.x|y|z (through the embedding) and omega./alpha.<body>.
  Quantities InstantQuantities(const Sample& s, const std::vector<PlanarState>& states, bool with_acc) const;
  // With a platform (Graph::platform): vabs./aabs.<point>.x|y|z (a fixed point on the platform)
  // and omegaabs.<body>.x|y|z from the world states; `with_acc` false leaves aabs out.
  Quantities AbsoluteQuantities(const SpatialState& platform, const std::vector<SpatialState>& states,
                                bool with_acc) const;

 private:
  struct PointRef { int body = -1; Eigen::Vector2d p_B{0, 0}; Eigen::Vector2d fixed{0, 0}; };
  struct AngleMap { double sigma = 1, offset = 0; };  // θ = offset + σ·geometric angle (+2πk)
  void PointKin(int point, const std::vector<PlanarState>& st, Eigen::Vector2d& p, Eigen::Vector2d& v,
                Eigen::Vector2d& a) const;
  const Model* model_;
  const Graph* graph_;
  std::vector<PointRef> points_;
  std::vector<AngleMap> angles_;     // per q slot (relative-angle and rotation slots)
  std::optional<Eigen::VectorXd> last_q_;
};

// The loads that depend on the engine's state through the scene's coordinates: torsional
// spring–dampers (Graph::torsions), torque laws and point-force laws that read q./qd.
// (Graph::state_torques, Graph::state_forces), and spring–dampers with laws (Graph::state_springs,
// through their ends' state_forces entries). An engine calls Evaluate with its bodies' poses and
// velocities (accelerations unused) wherever it evaluates forces: once per step at its start
// (explicit), or at every stage of its own force evaluation. Keeps the last relative angles to
// follow each torsion's winding (a body's angle may come back on any 2π branch), and the Observer
// the last q to unwrap angles, so evaluations must be at states a step apart, not far apart.
class StateLoads {
 public:
  explicit StateLoads(const Graph& g);
  bool empty() const { return g_->torsions.empty() && g_->state_torques.empty() && g_->state_forces.empty(); }
  // The torque about +z on every graph body [kg·length²/s²] at time t, into `torque` (resized), and
  // the world force of every Graph::state_forces entry [kg·length/s²], into `force` (resized), to
  // be applied at that entry's point (body, at_B).
  void Evaluate(double t, const std::vector<PlanarState>& st, std::vector<double>& torque,
                std::vector<Eigen::Vector2d>& force);
  // The torques alone (a graph without state_forces).
  void BodyTorques(double t, const std::vector<PlanarState>& st, std::vector<double>& out);
  // θ and θ̇ of torsion k from the states (and the winding so far).
  std::pair<double, double> TorsionAngle(size_t k, const std::vector<PlanarState>& st);

 private:
  const Graph* g_;
  std::optional<Observer> obs_;      // only for state_torques and state_forces
  std::vector<double> last_rel_;     // per torsion: θ_vec − θ_ref at the last evaluation
  std::vector<double> x_;            // [t, q, q̇] for the laws
};

// The graph of `model`, or the reason the graph cannot express it. Assembles t0 with the numeric
// solver (for a free scene, its `initial:` conditions act as drivers at t0); a scene that cannot
// assemble throws the solver's ScenarioError.
struct GraphOrReason {
  std::optional<Graph> graph;
  std::string reason;
};
GraphOrReason BuildGraph(const Model& model, const GraphOptions& options = {});

// A planar vector turned by th [rad].
Eigen::Vector2d Rotate(double th, const Eigen::Vector2d& p);

// A joint's rate at t0 from the graph's initial body states (revolute: ω_child − ω_parent;
// prismatic: the sliding speed along the axis, relative to the parent's material point).
double InitialJointRate(const Graph& g, const GraphJoint& j);

// ---- gear geometry for engines that need it --------------------------------------------------
//
// The graph couples gear members by tooth counts only (Willis' relation); an engine whose mesh
// is a contact between two wheels (ODE's transmission joint) or whose planet must ride on its
// carrier (a btMultiBody link under the carrier's) needs axis positions and pitch radii. The
// scene gives none, so LayOutGears chooses them from one stated module:
//  - planets: on each carrier, the meshes form a two-coloured graph (every mesh is between a
//    planet and a member coaxial with the carrier); the planets are the colour of the smaller
//    wheel of an internal mesh, else the colour with the most meshes, else (one external mesh)
//    the mesh's second member. A planet rides on its carrier only (no other mesh, no carrier).
//  - axes: the carrier and its central members share an axis; meshes without a carrier join
//    axes at the centre distance m (Z_a + Z_b)/2 (external) or m |Z_a − Z_b|/2 (internal), laid
//    out along +x from the first member at the origin, so every fixed axis is on the world x axis;
//    a planet's axis is at its first mesh's centre distance from its carrier's axis, along +x at t0.
//  - pitch radii: each mesh divides its actual centre distance in the ratio of its tooth counts
//    (a mesh whose two axes were already placed keeps their distance; its module follows).
struct GearMeshLayout {
  int joint = -1;                // the graph's gear joint
  bool internal = false;
  int planet = -1;               // graph body riding on the carrier (-1: both axes fixed)
  int central = -1;              // the other member, coaxial with the carrier (-1: no carrier)
  double distance = 0;           // centre distance [length]
  double r_a = 0, r_b = 0;       // pitch radii of the joint's parent (a) and child (b) [length]
  double module = 0;             // 2 r_a / Z_a [length]
};
struct GearLayout {
  double module = 0;                   // the stated module [length] (from the file: its first mesh's)
  bool from_file = false;              // the file's geometry (Graph::file_gear_layout), not a chosen module
  std::vector<Eigen::Vector2d> axis;   // per graph body: its axis in the world at t0 [length]
  std::vector<int> carrier_of;         // per graph body: the carrier it rides on, or -1
  std::vector<GearMeshLayout> meshes;  // one per gear joint, in graph order
  const GearMeshLayout* MeshOf(int joint) const;
  bool IsPlanet(int body) const { return body >= 0 && carrier_of[body] >= 0; }
  // Every mesh: members, kind, pitch radii, module, centre distance (in mm), planet.
  std::string Describe(const Graph& g) const;
};
struct GearLayoutOrReason {
  std::optional<GearLayout> layout;
  std::string reason;
};
// `module` in the scene's length unit. When the file gives the train's geometry
// (Graph::file_gear_layout), that layout, whatever the module.
GearLayoutOrReason LayOutGears(const Graph& g, double module);

// Why the graph cannot express `model` (cheap checks only, no assembly), or nullopt.
std::optional<std::string> GraphApplicability(const Model& model);

// A one-line summary of the graph, for tests and messages.
std::string Describe(const Graph& g);

// A graph joint for numeric::EngineReactionQuantities, with the force [N, world] its child
// receives from its parent (each engine reads that force its own way).
numeric::EngineJointForce PinForce(const Graph& g, const GraphJoint& j, const Eigen::Vector2d& on_child);

}  // namespace mechbench::engines
