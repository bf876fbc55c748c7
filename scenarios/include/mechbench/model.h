// The engine-neutral scenario model: what a mechanism *is*, never how a method solves it.
//
// A Model is built once by the loader (LoadScenario) and is immutable afterwards. Every method
// (analytic, numeric, engines) consumes the same Model; per-run state lives in each method's own
// data object, never here.
//
// Conventions
//  - Planar mechanisms live in a plane with in-plane coordinates (x, y); `embedding` maps them to
//    3-D for the few 3-D problems (§3.1, §3.2). Angles are counter-clockwise about the plane normal.
//  - Internal units: lengths in the file's length unit (`units.length`), angles in [rad],
//    time in [s], mass in [kg]. Unit words such as `deg` or `rpm` are only multipliers used when
//    reading values and when printing book values.
//  - Names follow the book: point "1" has coordinates "x1", "y1"; a relative coordinate keeps its
//    own name ("theta").
#pragma once

#include "mechbench/compiled_expr.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace mechbench {

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Where an element was declared, for messages that name the file and line.
struct SourceRef {
  std::string file;
  int line = 0;  // 1-based; 0 when unknown
  std::string Str() const { return file + ":" + std::to_string(line); }
};

enum class ScenarioKind {
  kLinkage,    // planar linkage in natural coordinates (possibly embedded in 3-D)
  kGearTrain,  // rotating members coupled by gear meshes; no point positions
  kSpatial,    // 3-D linkage in spatial natural coordinates (Model::spatial); the planar lists stay empty
};

struct Point {
  std::string name;
  bool fixed = false;
  Eigen::Vector2d p_W{kNaN, kNaN};  // fixed position, or initial guess of a moving point [length]
  SourceRef src;
};

// A rigid body. Planar linkage bodies are defined by their basic points (the first two define
// the body frame: origin at points[0], x axis towards points[1]). Gear-train members have no
// points: they are shafts that turn about a fixed axis, with a `rotation` coordinate.
// A linkage body may have one point (a point body: a slider block, a piston, a point mass). It
// adds no constraint; its frame has its origin at the point and, when the point is the sliding
// point of a slider joint (`guide`), its x axis along that joint's guide, from line[0] towards
// line[1]: the block translates with the point and turns with the guide (a fixed guide: not at
// all; a guide along a moving body: with that body). Without a guide it has no orientation, so
// its centre of mass is the point and its inertia 0 (the loader refuses anything else).
struct Body {
  std::string name;
  std::vector<int> points;  // indices into Model::points
  // Each point in the body frame [length]: p_B[0] = (0, 0), p_B[1] = (L, 0). From the body's
  // `length`/`shape` in the file, else from the points' positions in the file.
  std::vector<Eigen::Vector2d> p_B;
  double Length() const { return p_B.size() > 1 ? p_B[1].x() : kNaN; }
  // Mass properties; NaN in kinematics-only scenes.
  double mass = kNaN;                         // [kg]
  Eigen::Vector2d com_B{kNaN, kNaN};          // centre of mass in the body frame [length]
  double inertia_com = kNaN;                  // polar moment about the centre of mass [kg·length²]
  bool HasMass() const { return mass == mass; }
  // A point body: the slider joint (index into Model::joints) whose sliding point is its point,
  // which gives its frame a direction (the first of several: loader.cc); -1 for none.
  int guide = -1;
  bool IsPointBody() const { return points.size() == 1; }
  // Gear-train member geometry, when the file gives it (Model::gear_axes has what follows):
  Eigen::Vector2d centre{kNaN, kNaN};  // `centre:` its axis on the frame [length]; NaN: not given
  double arm = kNaN;                   // `arm:` a carrier's arm, its axis to its planets' [length]
  int planets = 0;                     // `planets:` a carrier's number of planets; 0: not given
  // A gear train's sliding member (a rack), when the file gives `slides:`: it translates along this
  // unit direction on the frame (its travel coordinate, CoordinateType::kTravel, is the distance
  // moved along it) and meshes a turning member through a rack joint (Coupling). NaN: it turns.
  Eigen::Vector2d slides{kNaN, kNaN};
  // `at:` a point of its pitch line at travel 0, on the frame [length]; NaN when not given.
  Eigen::Vector2d pitch_point{kNaN, kNaN};
  bool IsSliding() const { return slides.allFinite(); }
  SourceRef src;
};

enum class JointType {
  kPointOnFixedLine,  // a point slides on a fixed guide line through two fixed points
  kPointOnBody,       // a point slides along the line of a moving body (its first two points)
  kGear,              // a gear mesh between two rotating members
};

struct Joint {
  JointType type = JointType::kPointOnFixedLine;
  std::string name;  // for messages, e.g. "slider 3 on C-D"
  // kPointOnFixedLine / kPointOnBody
  int point = -1;                   // the sliding point
  std::array<int, 2> line{-1, -1};  // two points that define the guide line
  int body = -1;                    // kPointOnBody: the body it slides along
  // kPointOnFixedLine on a horizontal or vertical guide: the constant coordinate of the sliding
  // point is left out of q (as the book does). `eliminate: false` keeps it, with a collinearity
  // equation instead (the book's §4.2 and §4.4 formulation).
  bool eliminate = true;
  // kGear: member a drives member b. Mesh relation, in the carrier's frame when there is one:
  //   Z_a (φ_a − φ_c) + s Z_b (φ_b − φ_c) = const,  s = +1 external mesh, −1 internal.
  std::array<int, 2> members{-1, -1};  // bodies
  std::array<int, 2> teeth{0, 0};
  bool internal = false;
  int carrier = -1;  // body, or -1 for a fixed frame
  // Pitch radii of a's and b's wheels [length], in the ratio Z_a : Z_b: from `module:` (r = m Z / 2)
  // or `radii:`, else from the centre distance the file's centres or carrier arm give
  // (external r_a + r_b, internal |r_a − r_b|); NaN when the file gives no geometry.
  std::array<double, 2> radii{kNaN, kNaN};
  double Module() const { return 2 * radii[0] / teeth[0]; }
  SourceRef src;
};

// Where a gear-train member's axis is, resolved by the loader from the file's `centre:`, `arm:`
// and the meshes' radii (Model::gear_axes). A member on a fixed axis: `centre`. A planet: its axis
// rides on `carrier`'s arm at distance `arm` from the carrier's axis `centre`, along the carrier's
// rotation coordinate φ_c (at φ_c = 0 the planet's centre is at centre + (arm, 0)):
//   p = centre + arm (cos φ_c, sin φ_c).
struct GearAxis {
  int carrier = -1;                    // a planet's carrier (body), -1 on a fixed axis
  Eigen::Vector2d centre{kNaN, kNaN};  // the fixed axis, or the carrier's [length]
  double arm = kNaN;                   // a planet: centre distance to the carrier's axis [length]
  bool Known() const { return centre.allFinite() && (carrier < 0 || arm == arm); }
};

// A linear relation between two coordinates of q (a rack and pinion, a belt, a cable drum):
//   q_b = ratio · q_a + offset,
// with the offset from the file's values of the two coordinates (the points' positions and the
// coordinates' guesses, Model::GuessQ), so that b − b_file = ratio (a − a_file): the file draws
// the mechanism where the coupling holds. One holonomic row with a constant Jacobian.
// A rack and pinion is the form with a = the pinion's angle [rad] (an angle or rotation
// coordinate), b = the rack's travel [length] (a sliding point's x or y, or a distance), and
// ratio = ±r, the pinion's pitch radius: a counter-clockwise turn moves the rack coordinate by
// +r Δθ (−r Δθ with `reverse: true`). In a gear train a = a member's rotation (absolute: the rack
// slides on the frame, so φ_c = 0) and b = a sliding member's travel (CoordinateType::kTravel).
struct Coupling {
  std::string name;                  // for messages: "rack xR by theta", "coupling phi2 by phi1"
  bool rack = false;                 // written as a rack and pinion (ratio = ±radius)
  std::array<std::string, 2> coordinates;  // {a, b}: names in q_layout
  std::array<int, 2> slots{-1, -1};  // their q slots
  double ratio = kNaN;               // ∂q_b/∂q_a [unit of b per unit of a]
  double offset = kNaN;              // q_b − ratio q_a [unit of b]
  SourceRef src;
};

enum class CoordinateType {
  kAngle,     // angle of vector `vec` relative to vector `ref` (or to the ground x axis) [rad]
  kDistance,  // distance between two points (a linear actuator's length) [length]
  kRotation,  // rotation of a gear-train member about its fixed axis [rad]
  kTravel,    // travel of a gear train's sliding member (a rack) along its `slides:` direction [length]
};

// How a relative angle is tied to the points in Φ. The choice is part of a natural-coordinate
// model (the book's printed Jacobians depend on it), not of a solver.
enum class AngleForm {
  kCross,   // rotate ref by θ, then cross(ref_rotated, vec) = 0; well conditioned for every θ
  kDot,     // ref·vec − |ref||vec| cos θ = 0 (book §4.2, §4.3); singular at θ = 0, π
  kCos,     // vec_x − |vec| cos θ = 0 (book §4.1, §4.5, §4.8); ground reference only
  kSin,     // vec_y − |vec| sin θ = 0; ground reference only
  kCosSin,  // both rows (book §4.4): one redundant equation
};

struct Coordinate {
  std::string name;
  CoordinateType type = CoordinateType::kAngle;
  std::array<int, 2> vec{-1, -1};  // kAngle: from point vec[0] to vec[1]; kDistance: the two ends
  std::array<int, 2> ref{-1, -1};  // kAngle: reference vector; {-1,-1} = ground x axis
  AngleForm form = AngleForm::kCross;
  int body = -1;                   // kRotation, kTravel: the member
  double guess = kNaN;             // initial value; NaN = computed from the points' guesses
  SourceRef src;
};

// A prescribed coordinate. Either the polynomial
//   q_i(t) = value + velocity (t − t0) + ½ acceleration (t − t0)²
// or a law: an expression of absolute time t (`law:`), with its rate and acceleration worked out
// by automatic differentiation (compiled_expr.h). For a law, value, velocity and acceleration hold
// its value and derivatives at t0. The same law serves an instant (t = t0) and a motion.
struct Driver {
  std::string coordinate;  // a name in the coordinate layout, e.g. "theta" or "yA"
  double value = kNaN, velocity = 0.0, acceleration = 0.0;
  std::shared_ptr<const CompiledExpr> law;  // x(t) [coordinate's unit]; null = the polynomial
  SourceRef src;
  double At(double t, double t0) const;
  double RateAt(double t, double t0) const;
  double AccelerationAt(double t, double t0) const;
  Jet2 JetAt(double t, double t0) const;  // value, rate and acceleration at once
  // The coordinate stays at its value for all t (no law, no velocity, no acceleration).
  bool IsStill() const { return !law && velocity == 0 && acceleration == 0; }
  // The same motion (the law's text, or the polynomial's numbers).
  bool SameMotion(const Driver& o) const;
};

// A force at a point [N]. Its two components are each a constant or an expression F(t, q, q̇)
// over the load variables below (a force ramp, F0 sin ωt), in the world frame or, with `frame`,
// in a body's frame (x along its first two points): a follower force that turns with the body.
// The point is then one of that body's points. Only a constant world force is a constant load
// (numeric's Q, a potential −F·r); the others are force elements (varying loads).
struct PointForce {
  int point = -1;
  // A constant world force; otherwise its world value at t0 in the file's guesses at rest (a size
  // for the comparisons' scales, as BodyTorque::torque).
  Eigen::Vector2d f_W{0.0, 0.0};
  Eigen::Vector2d components{0.0, 0.0};  // the constant components as given, in `frame` [N]
  std::array<std::shared_ptr<const CompiledExpr>, 2> law;  // per component; null = the constant
  int frame = -1;  // the body whose frame the components are in (≥ 2 points); -1 = the world
  bool IsConstantWorld() const { return frame < 0 && !law[0] && !law[1]; }
  bool HasLaw() const { return law[0] || law[1]; }
  SourceRef src;
};

// A linear spring–damper between two points (either fixed or moving). With L = |r_b − r_a| and
// u = meters_per_unit, the tension [N] along the line between them is
//   F = k (L − L0) u + c L̇ u + F0,
// pulling the points together when positive. Potential ½ k ((L − L0) u)² + F0 (L − L0) u [J];
// the damper dissipates c (L̇ u)² [W].
// Each of k, c, L0, F0 may instead be a law p(t, q, q̇) over the load variables below (a preload
// ramp F0(t): an actuator; a free length L0(t): a spring whose anchor moves; k(q) a progressive
// spring). The tension is then the same formula with the laws' values, evaluated as given along
// a motion (a law that turns k or c negative there is the physics the file asks for: the loader
// checks k, c, L0 ≥ 0 at t0 only). A spring with a law has no potential: its whole tension's work
// ∫ −F L̇ u dt enters the energy balance, as a torque law's does.
struct SpringDamper {
  enum Param { kStiffness = 0, kDamping = 1, kFreeLength = 2, kPreload = 3 };
  std::array<int, 2> points{-1, -1};
  double stiffness = 0.0;      // k [N/m], ≥ 0
  double damping = 0.0;        // c [N·s/m], ≥ 0
  double free_length = kNaN;   // L0 [length], ≥ 0
  double preload = 0.0;        // F0 [N], tension at the free length
  // Per Param: the law, or null for the constant above (which then holds the law's value at t0 in
  // the file's guesses at rest: a size for the comparisons' scales, as BodyTorque::torque).
  std::array<std::shared_ptr<const CompiledExpr>, 4> law;
  bool HasLaw() const { return law[0] || law[1] || law[2] || law[3]; }
  // The constant of `p` (stiffness, damping, free_length or preload).
  double Constant(Param p) const {
    return p == kStiffness ? stiffness : p == kDamping ? damping : p == kFreeLength ? free_length : preload;
  }
  SourceRef src;
};

// A torque on a body with at least two points [N·m], counter-clockwise positive: a constant, or
// an expression T(t, q, q̇) (a force ramp, a motor curve T(ω)) over the load variables below.
struct BodyTorque {
  int body = -1;
  double torque = 0.0;  // the constant; for a law, its value at t0 in the file's guesses at rest
  std::shared_ptr<const CompiledExpr> law;  // null = constant
  SourceRef src;
};

// The variables a load expression may name, as indices into the array [t, q, q̇] of size 1 + 2n
// (n = q_layout.size()): `t` [s], `q.<slot>` and `qd.<slot>` for every name in the layout.
constexpr int kLoadVarTime = 0;
inline int LoadVarQ(int slot) { return 1 + slot; }
inline int LoadVarQd(int slot, int n) { return 1 + n + slot; }

// A torsional spring–damper on an angle coordinate θ (absolute, or relative: the angle between two
// bodies at their pin): the torque T = −k (θ − θ0) − c θ̇ + T0 [N·m] acts on the coordinate, i.e.
// between its reference (ground, or the `ref` body) and its vector's body. Potential
// ½ k (θ − θ0)² − T0 (θ − θ0) [J]; the damper dissipates c θ̇² [W].
struct TorsionSpring {
  std::string coordinate;
  int slot = -1;            // θ's slot in q_layout
  double stiffness = 0.0;   // k [N·m/rad], ≥ 0
  double damping = 0.0;     // c [N·m·s/rad], ≥ 0
  double free_angle = 0.0;  // θ0 [rad]
  double preload = 0.0;     // T0 [N·m], the torque at the free angle
  SourceRef src;
};

// Where the planar mechanism sits in 3-D: p_W = origin + u x + v y (u, v orthonormal).
struct Embedding {
  Eigen::Vector3d origin{0, 0, 0}, u{1, 0, 0}, v{0, 1, 0};
  Eigen::Vector3d Normal() const { return u.cross(v); }
};

// Optional: the mechanism's whole frame turns at a constant rate about a fixed axis (the
// carousel platform of §3.1, the thumb's ω3 in §3.2). Absolute quantities are reported too.
struct FrameRotation {
  Eigen::Vector3d axis_point{0, 0, 0};  // a point on the axis, world frame [length]
  Eigen::Vector3d axis{0, 0, 1};        // unit axis
  double omega = 0.0;                   // [rad/s], constant
};

struct Analysis {
  double t0 = 0.0;   // the instant (every scenario has one)
  double t1 = kNaN;  // end of the motion, NaN for instant-only scenarios [s]
  int samples = 1;   // samples over [t0, t1], both ends included
  bool HasMotion() const { return t1 == t1 && samples > 1; }
  double TimeAt(int k) const { return samples > 1 ? t0 + (t1 - t0) * k / (samples - 1) : t0; }
};

// A gear-ratio design goal (§6.2): find trains with ω_out/ω_in = ratio from spur gears with
// z_min ≤ Z ≤ z_max and at most max_pair_ratio:1 per pair.
struct Synthesis {
  double ratio = kNaN;
  int z_min = 10, z_max = 100;
  double max_pair_ratio = 5.0;
  SourceRef src;
};

// A value printed in the book, kept as printed: the number of digits is part of the claim.
struct BookValue {
  std::string quantity;    // a quantity name, see quantities.h
  std::string printed;     // literal as printed, e.g. "-0.8138"
  double value = kNaN;     // printed value in `unit`
  double last_digit = kNaN;  // one unit of the last printed digit, in `unit`; 0 = exact claim
  std::string unit;        // display unit ("rad/s", "rpm", "deg", "mm/s", "" = internal)
  double unit_factor = 1;  // internal value = printed value × unit_factor
  std::string where;       // "eq. 4.11"
  std::string note;        // known reason for a disagreement, if any
  // A claim about the motion at one of its sample times [s] (`at:`), judged on trajectories (a
  // free scene's: the confirmed reference, harness/reference.h); NaN = about the instant t0.
  double at = kNaN;
  int at_sample = -1;      // the sample k with analysis.TimeAt(k) = at; -1 for the instant
  // The precision the source states for its own value (`precision:`, e.g. an integrator's
  // rtol = atol), read as |error| ≤ precision · max(1, |value|) in `unit`; 0 = none stated.
  double precision = 0;
  bool AtTime() const { return at == at; }
  SourceRef src;
};

// The scene's exact motion, named from the reference registry (harness/references):
// `reference: {exact: nfourbar}`. A property of the mechanism, not a method setting. The loader
// reads the name; the registry (which sits above the loader) checks that it is one it knows and
// that the scene's structure is the one its closed form describes (harness::ValidateScene).
struct ExactReferenceName {
  std::string name;
  SourceRef src;
};

// A published benchmark's own precision criteria (IFToMM: the largest error of one point's
// position over the benchmark's output steps, against the reference, judged at each level):
// `criteria: {point: P1, levels: [1e-3, 1e-1], output_steps: 4000}`.
struct Criteria {
  int point = -1;              // the point whose position is judged (a spatial scene: its entity index)
  std::string name;            // that point's name
  std::vector<double> levels;  // allowed max position errors [length], ascending (finest first)
  int output_steps = 0;        // the motion's samples are output_steps + 1 (the loader checks)
  std::string source;          // where the levels come from
  SourceRef src;
};

// ---- Spatial scenes (kind: spatial; scenarios/FORMAT.md "Spatial scenes") ----------------------
// The 3-D description sits beside the planar one (whose lists stay empty in a spatial scene), so
// planar files, structs and code paths are untouched. Natural coordinates in 3-D (García de Jalón
// & Bayo ch. 2–3): basic points and unit vectors; a body lists the entities it carries, and a
// joint is mostly an entity shared by two bodies (spherical: a point; revolute: a point and a
// vector). The file's pose is an assembled pose: every constant (distances, dot products,
// linear-combination coefficients) is read off it.
struct SpatialEntity {
  std::string name;
  bool vector = false;                      // a unit vector (else a point)
  bool fixed = false;                       // constant (ground)
  Eigen::Vector3d r_W{kNaN, kNaN, kNaN};    // position [length], or unit vector [1], at the file's pose
  SourceRef src;
};

// A body on entities (indices into SpatialModel::entities), the first a point:
//  - four or more: a rigid body; the first four (non-coplanar) are its basis, the rest attached;
//  - two points: a bar (a constant distance; with mass, a slender uniform rod: no inertia about
//    its own axis, centre of mass at its middle);
//  - one point: a point mass (mass only; no rows).
// Mass properties at the file's pose, in world axes (SpatialBuilder's form).
struct SpatialBody {
  std::string name;
  std::vector<int> entities;
  double mass = kNaN;                                   // [kg]; NaN: massless (kinematics)
  Eigen::Vector3d com_W{kNaN, kNaN, kNaN};              // [length]
  Eigen::Matrix3d inertia_W = Eigen::Matrix3d::Zero();  // about the com, world axes [kg·length²]
  bool HasMass() const { return mass == mass; }
  SourceRef src;
};

// What sharing entities cannot say. Each side of a `dot` is a vector or a segment of two points
// (b = −1 for a vector alone); the constant is read off the file's pose.
struct SpatialJoint {
  enum class Type { kDistance, kDot };
  Type type = Type::kDistance;
  std::string name;                 // for messages
  std::array<int, 2> a{-1, -1};     // kDistance: the two points; kDot: the first side
  std::array<int, 2> b{-1, -1};     // kDot: the second side
  SourceRef src;
};

// A relative coordinate:
//  - `along`: the distance s of point `point` from point `from` along unit vector `direction`
//    (point − from = s · direction: a prismatic or cylindrical joint) [length];
//  - `angle`: the angle θ from unit vector `from` to unit vector `to` about unit vector `direction`
//    (the axis; both perpendicular to it: a revolute joint's axis and a vector across each of its
//    bodies), right handed [rad].
struct SpatialCoordinate {
  enum class Type { kAlong, kAngle };
  Type type = Type::kAlong;
  std::string name;
  int point = -1, from = -1, direction = -1, to = -1;
  double value = kNaN;  // at the file's pose
  bool IsAngle() const { return type == Type::kAngle; }
  SourceRef src;
};

// A load in a spatial scene, world components [N or N·m], each a number or a law p(t, q, q̇) over
// the load variables (LoadVarQ): a point force at `point` (an entity, a point), or a torque on
// `body` (a SpatialModel::bodies index, a rigid body of four entities or more).
// A point force with `frame` (a follower force) has its components in world axes at the file's
// pose, turning with rigid body `frame` (a bodies index, four entities or more, carrying `point`):
// f_W(q) = X(q) X̄⁻¹ F, X = the body's basis columns (X̄ at the file's pose), linear in q.
struct SpatialLoad {
  int point = -1, body = -1;
  int frame = -1;                  // a point force's body frame (the body it turns with); -1 = world
  Eigen::Vector3d value{0, 0, 0};  // the constants; for a law, its value at t0 in the file's guesses at rest
  std::array<std::shared_ptr<const CompiledExpr>, 3> law;  // per component; null = the constant
  bool HasLaw() const { return law[0] || law[1] || law[2]; }
  // A force element (numeric's varying loads): a law, or a body frame.
  bool IsVarying() const { return HasLaw() || frame >= 0; }
  SourceRef src;
};

struct SpatialModel {
  std::vector<SpatialEntity> entities;
  std::vector<SpatialBody> bodies;
  std::vector<SpatialJoint> joints;
  std::vector<SpatialCoordinate> coordinates;
  Eigen::Vector3d gravity{0, 0, 0};  // [length/s²]
  // Force elements in 3-D (Model::torsions serve both): spring–dampers between two points (the
  // planar element's semantics, laws included; `points` are entity indices), point forces and
  // body torques.
  std::vector<SpringDamper> springs;
  std::vector<SpatialLoad> forces, torques;
  bool HasVaryingForces() const;  // a point force with a law or a body frame
  int EntityIndex(const std::string& n) const;
};

struct Model {
  std::string name;     // file stem, e.g. "s4_1_two_sliders"
  std::string section;  // "§4.1"
  std::string title;
  std::string description;
  std::string source_file;
  ScenarioKind kind = ScenarioKind::kLinkage;
  std::string length_unit = "m";

  std::vector<Point> points;
  std::vector<Body> bodies;
  std::vector<Joint> joints;
  std::vector<Coupling> couplings;  // written under joints: (type rack or coupling)
  std::vector<Coordinate> coordinates;
  std::vector<Driver> drivers;
  // Initial conditions of a free scene: coordinates set at t0 (value, velocity) to assemble the
  // starting state, then released to move under the loads (forward dynamics).
  std::vector<Driver> initial;
  SourceRef initial_src;  // the `initial:` key's line
  bool IsFree() const { return drivers.empty(); }
  // The same scene with its initial conditions as drivers at t0 only (their accelerations are
  // unknown: forward dynamics decides them) — how every method places a free scene.
  Model InitialAsDrivers() const;
  Eigen::Vector2d gravity{0.0, 0.0};  // [length/s²]
  SourceRef gravity_src;              // the `gravity:` line (planar or spatial), for messages
  std::vector<PointForce> forces;     // point forces (constant or varying, PointForce)
  std::vector<SpringDamper> springs;  // force elements whose loads depend on q and q̇
  std::vector<BodyTorque> torques;
  std::vector<TorsionSpring> torsions;
  // Spring–dampers, torques or varying point forces: loads that depend on the state or on t
  // (constant world point forces and gravity do not).
  bool HasForceElements() const {
    return !springs.empty() || !torques.empty() || !torsions.empty() || HasVaryingPointForces() ||
           !spatial.springs.empty() || !spatial.torques.empty();
  }
  // A point force given by a law or in a body's frame (PointForce::IsConstantWorld false), or a
  // spatial point force with a law or a body frame.
  bool HasVaryingPointForces() const;
  // A torque, a point force or a spring–damper's parameter given as an expression (of t or of the state).
  bool HasLoadLaws() const;
  // A spring–damper with a law (SpringDamper::HasLaw), planar or spatial.
  bool HasSpringLaws() const;
  Embedding embedding;
  std::optional<FrameRotation> frame;
  Analysis analysis;
  std::optional<Synthesis> synthesis;
  std::vector<BookValue> book;
  // Named numbers the book's formulas use (L_B1, …), for book quantities written in the book's
  // own notation: "(x1 - xB)^2 + (y1 - yB)^2 - L_B1^2".
  std::map<std::string, double> constants;
  std::optional<ExactReferenceName> exact_reference;
  std::optional<Criteria> criteria;
  // Per body of a gear train whose file gives geometry (centres, module, radii, an arm): its axis,
  // Known() or not. Empty when the file gives none: the train is tooth counts only.
  std::vector<GearAxis> gear_axes;
  // kind spatial: the 3-D scene (the planar lists above are empty).
  SpatialModel spatial;

  // The coordinate layout q, fixed at load time and shared by every method so that results
  // line up: moving points in file order (x then y, minus coordinates a fixed guide eliminates),
  // then the relative coordinates in file order.
  struct Slot {
    std::string name;   // "x1", "yA", "theta"
    int point = -1;     // point slot: the point, and axis 0 = x, 1 = y
    int axis = -1;
    int coordinate = -1;  // relative-coordinate slot: index into `coordinates`
    // Spatial scenes: an entity's slot (index into spatial.entities; axis 0, 1, 2 = x, y, z), or a
    // spatial relative coordinate's (index into spatial.coordinates).
    int entity = -1;
    int spatial_coordinate = -1;
  };
  std::vector<Slot> q_layout;

  int PointIndex(const std::string& n) const;
  int BodyIndex(const std::string& n) const;
  int SlotIndex(const std::string& n) const;  // -1 when absent
  // For every point and axis, the slot that holds it, or -1 when the value is constant
  // (fixed points, and coordinates a fixed guide eliminates).
  int SlotOf(int point, int axis) const;
  // The initial guess as a q vector (points' guesses, coordinates' guesses).
  Eigen::VectorXd GuessQ() const;
  bool HasMass() const;
  // The scene's size [length]: the largest |p| of a point's position or guess, or of a body's
  // point in its own frame (1 when there is none). Relative tolerances of lengths use it.
  double LengthScale() const;
};

}  // namespace mechbench
