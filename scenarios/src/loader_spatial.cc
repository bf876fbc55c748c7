// Spatial scenes (kind: spatial): points and unit vectors in 3-D, bodies on them, the few joints
// that sharing entities cannot say, `along` coordinates and gravity as a 3-vector. See
// loader_spatial.h and scenarios/FORMAT.md "Spatial scenes".
#include "loader_spatial.h"

#include "mechbench/errors.h"
#include "mechbench/expr.h"
#include "mechbench/format.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <set>
#include <utility>
#include <vector>

namespace mechbench::detail {
namespace {

using V3 = Eigen::Vector3d;
using M3 = Eigen::Matrix3d;

// A unit vector's length may differ from 1 by this much (a file writes ten digits or an
// expression such as [cos(30 deg), 0, sin(30 deg)]); the builder's rows need it to round-off.
constexpr double kUnitTolerance = 1e-9;
// A point on an `along` line: off the line by at most this × (1 + its distance from `from`).
constexpr double kOnLineTolerance = 1e-9;
// A basis is coplanar when |det X| ≤ this × the product of its columns' lengths (the sine of
// the angles between them): below it the body's frame and its mass matrix are lost to rounding.
constexpr double kCoplanar = 1e-6;
// An inertia tensor is symmetric to this × its largest entry, and its principal moments are
// non-negative and obey the triangle inequality to this × their sum.
constexpr double kInertiaTolerance = 1e-9;

std::string Join(const std::vector<std::string>& v) {
  std::string s;
  for (size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + v[i];
  return s;
}

std::string Xyz(const V3& v, int digits = 9) {
  return "[" + Fmt(v.x(), digits) + ", " + Fmt(v.y(), digits) + ", " + Fmt(v.z(), digits) + "]";
}

class SpatialReader {
 public:
  SpatialReader(std::string file, Model& m, const ConstantUnitMap& constant_units)
      : file_(std::move(file)), m_(m), s_(m.spatial), constant_units_(constant_units) {}
  const std::string& LengthUnit() const { return m_.length_unit; }

  void Read(const YAML::Node& root) {
    for (const char* key : {"plane", "frame_rotation", "synthesis", "reference"})
      if (root[key])
        throw ScenarioError(At(root[key]), std::string("`") + key + "` is not yet available in a spatial scene",
                            "remove it (spatial scenes take points, vectors, bodies, joints, coordinates, gravity, "
                            "forces (torsion, spring–dampers, point forces, torques), drivers or initial, analysis, constants, book and criteria: scenarios/FORMAT.md, "
                            "Spatial scenes)");
    if (!root["points"]) throw ScenarioError({file_, 1}, "a spatial scene needs points:", "declare its fixed and moving points");
    ReadEntities(root["points"], false);
    if (root["vectors"]) ReadEntities(root["vectors"], true);
    ReadBodies(root["bodies"]);
    ReadJoints(root["joints"]);
    ReadCoordinates(root["coordinates"]);
    if (root["gravity"]) {
      s_.gravity = Vec3(root["gravity"], "gravity", UnitField::kAcceleration, LengthUnit() + "/s²");
      m_.gravity_src = At(root["gravity"]);
    }
    CheckVectorsBelong();
    BuildLayout();
    for (const auto& kv : m_.constants)
      if (s_.EntityIndex(kv.first) >= 0 || m_.SlotIndex(kv.first) >= 0)
        throw ScenarioError({file_, 1}, "constant " + kv.first + " has the name of a point, vector or coordinate", "rename it");
  }

 private:
  SourceRef At(const YAML::Node& n) const { return {file_, n.Mark().line >= 0 ? n.Mark().line + 1 : 0}; }

  void Keys(const YAML::Node& map, const std::string& what, const std::vector<std::string>& allowed) {
    if (!map.IsMap())
      throw ScenarioError(At(map), what + " must be a mapping of keys to values", "write it as {key: value, ...}");
    std::set<std::string> seen;
    for (const auto& kv : map) {
      if (!kv.first.IsScalar()) throw ScenarioError(At(kv.first), "a key in " + what + " is not a plain name",
                          "write the key as a plain name (letters, digits, _), not a list or a mapping");
      const std::string key = kv.first.as<std::string>();
      if (!seen.insert(key).second) throw ScenarioError(At(kv.first), "duplicate key '" + key + "' in " + what, "keep only one");
      if (std::find(allowed.begin(), allowed.end(), key) == allowed.end())
        throw ScenarioError(At(kv.first), "unknown key '" + key + "' in " + what, "known keys are: " + Join(allowed));
    }
  }
  std::string Str(const YAML::Node& n, const std::string& what) {
    if (!n.IsScalar()) throw ScenarioError(At(n), what + " must be a single value",
                          "write one value here, not a list or a mapping");
    return n.as<std::string>();
  }
  // A number or an expression of the constants. `field` says which unit words the value may carry
  // (outside function arguments: `L*cos(30 deg)` is a length); `unit` names its unit for the
  // message when one does not fit ("mass: 2 deg" would silently be 0.035 kg).
  double Num(const YAML::Node& n, const std::string& what, UnitField field = UnitField::kAny,
             const std::string& unit = "") {
    if (!n.IsScalar()) throw ScenarioError(At(n), what + " must be a number or an expression such as 35 deg",
                          "write one number or expression on this line, not a list or a mapping");
    std::vector<std::string> units, names;
    double v = 0;
    try {
      v = EvalExpr(n.as<std::string>(), [this](const std::string& name) -> std::optional<double> {
        if (auto it = m_.constants.find(name); it != m_.constants.end()) return it->second;
        return std::nullopt;
      }, &units, &names);
      if (!std::isfinite(v)) throw ExprError("the value is not finite");
    } catch (const ExprError& e) {
      throw ScenarioError(At(n), what + ": " + e.what(),
                          e.fix.empty() ? "write a number or an expression such as 15*sin(35 deg)" : e.fix);
    }
    CheckUnitWords(n, what, units, names, field, unit);
    return v;
  }
  // The unit words of a value against its field (UnitWordsProblem), then those of the constants
  // it names (`names`: its variables outside function arguments; constant_units.h).
  void CheckUnitWords(const YAML::Node& n, const std::string& what, const std::vector<std::string>& units,
                      const std::vector<std::string>& names, UnitField field, const std::string& unit) {
    std::string fix;
    if (const std::string problem = FieldUnitWordsProblem(constant_units_, units, names, field, m_.length_unit,
                                                                  n.as<std::string>(), unit, fix);
        !problem.empty())
      throw ScenarioError(At(n), what + " " + problem, fix);
  }
  std::vector<YAML::Node> Seq(const YAML::Node& n, const std::string& what, size_t size) {
    if (!n.IsSequence() || (size && n.size() != size))
      throw ScenarioError(At(n), what + " must be a list" + (size ? " of " + std::to_string(size) + " items" : ""),
                          size == 3 ? "write it as [x, y, z]" : "write it as [a, b, ...]");
    return {n.begin(), n.end()};
  }
  V3 Vec3(const YAML::Node& n, const std::string& what, UnitField field = UnitField::kAny, const std::string& unit = "") {
    const auto s = Seq(n, what, 3);
    return {Num(s[0], what + "[0]", field, unit), Num(s[1], what + "[1]", field, unit), Num(s[2], what + "[2]", field, unit)};
  }

  // A point or vector by name; `vector` −1: either, 0: a point, 1: a vector.
  int EntityRef(const YAML::Node& n, const std::string& what, int vector) {
    const std::string name = Str(n, what);
    const int i = s_.EntityIndex(name);
    if (i < 0) {
      std::vector<std::string> names;
      for (const SpatialEntity& e : s_.entities)
        if (vector < 0 || e.vector == (vector == 1)) names.push_back(e.name);
      throw ScenarioError(At(n), what + " names unknown " + (vector == 1 ? "vector" : vector == 0 ? "point" : "point or vector") +
                                     " '" + name + "'",
                          "declared ones are: " + Join(names));
    }
    if (vector >= 0 && s_.entities[i].vector != (vector == 1))
      throw ScenarioError(At(n), what + " names " + (vector == 1 ? "point" : "vector") + " " + name + " where a " +
                                     (vector == 1 ? "unit vector" : "point") + " belongs",
                          vector == 1 ? "name one of the vectors: entries" : "name one of the points: entries");
    return i;
  }

  void ReadEntities(const YAML::Node& map, bool vector) {
    const std::string kind = vector ? "vector" : "point";
    const std::string form = vector ? "{fixed: [ux, uy, uz]} or {at: [ux, uy, uz]}" : "{fixed: [x, y, z]} or {at: [x, y, z]}";
    if (!map.IsMap()) throw ScenarioError(At(map), kind + "s must be a mapping name: " + form,
                          "write each " + kind + " on its own line under " + kind + "s:, e.g. A: " + form.substr(0, form.find(" or ")));
    for (const auto& kv : map) {
      SpatialEntity e;
      e.name = Str(kv.first, kind + " name");
      e.vector = vector;
      e.src = At(kv.first);
      if (s_.EntityIndex(e.name) >= 0)
        throw ScenarioError(e.src, kind + " '" + e.name + "' declared twice (points and vectors share one set of names)", "rename one");
      const std::string what = kind + " " + e.name;
      Keys(kv.second, what, {"fixed", "at"});
      if (kv.second["fixed"] && kv.second["at"]) throw ScenarioError(e.src, what + " is both fixed and moving", "keep fixed: or at:");
      if (!kv.second["fixed"] && !kv.second["at"]) throw ScenarioError(e.src, what + " needs " + form,
                          "give fixed: for a ground " + kind + " or at: for a moving one");
      e.fixed = static_cast<bool>(kv.second["fixed"]);
      const YAML::Node v = kv.second[e.fixed ? "fixed" : "at"];
      e.r_W = vector ? Vec3(v, what, UnitField::kPlain, "a unit vector's components") : Vec3(v, what, UnitField::kLength, LengthUnit());
      if (vector && std::fabs(e.r_W.norm() - 1) > kUnitTolerance) {
        if (!(e.r_W.norm() > 0))
          throw ScenarioError(At(v), what + " is zero: a basic vector of natural coordinates has length 1",
                              "give its direction as a unit vector");
        throw ScenarioError(At(v), what + " has length " + Fmt(e.r_W.norm(), 12) +
                                       ", not 1: a basic vector of natural coordinates is a unit vector",
                            "write it normalized, " + Xyz(e.r_W.normalized(), 12) + " (or as an expression such as "
                            "[cos(30 deg), 0, sin(30 deg)])");
      }
      s_.entities.push_back(e);
    }
  }

  // A body's inertia: [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] or a 3×3 list of rows, about the centre of
  // mass in world axes; symmetric, positive semi-definite and physical (triangle inequality).
  M3 ReadInertia(const YAML::Node& n, const std::string& what) {
    M3 I;
    if (n.IsSequence() && n.size() == 6) {
      const auto s = Seq(n, what, 6);
      const std::string u = "kg·" + LengthUnit() + "²";
      const UnitField f = UnitField::kPlain;
      const double xx = Num(s[0], what + " Ixx", f, u), yy = Num(s[1], what + " Iyy", f, u), zz = Num(s[2], what + " Izz", f, u);
      const double xy = Num(s[3], what + " Ixy", f, u), xz = Num(s[4], what + " Ixz", f, u), yz = Num(s[5], what + " Iyz", f, u);
      I << xx, xy, xz, xy, yy, yz, xz, yz, zz;
    } else if (n.IsSequence() && n.size() == 3) {
      const auto rows = Seq(n, what, 3);
      for (int r = 0; r < 3; ++r) I.row(r) = Vec3(rows[r], what + " row " + std::to_string(r), UnitField::kPlain, "kg·" + LengthUnit() + "²").transpose();
      const double scale = I.cwiseAbs().maxCoeff();
      if ((I - I.transpose()).cwiseAbs().maxCoeff() > kInertiaTolerance * scale)
        throw ScenarioError(At(n), what + " is not symmetric (an inertia tensor is: I_xy = I_yx, …)",
                            "give the same product of inertia on both sides of the diagonal, or write the six numbers "
                            "[Ixx, Iyy, Izz, Ixy, Ixz, Iyz]");
      I = 0.5 * (I + I.transpose()).eval();
    } else {
      throw ScenarioError(At(n), what + " must be six numbers [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] or a 3×3 list of rows",
                          "e.g. inertia: [0.1, 0.1, 0.02, 0, 0, 0] (about the centre of mass, world axes, at the file's pose)");
    }
    const Eigen::SelfAdjointEigenSolver<M3> eig(I);
    const V3 p = eig.eigenvalues();  // ascending
    const double sum = std::max(p.sum(), 0.0);
    if (p[0] < -kInertiaTolerance * sum)
      throw ScenarioError(At(n), what + " has a negative principal moment (" + Fmt(p[0], 6) + "; principal moments " +
                                     Xyz(p, 6) + "): not an inertia tensor",
                          "products of inertia enter with the sign of I = ∫ (r²1 − r rᵀ) dm: I_xy = −∫ x y dm; check "
                          "their signs and sizes");
    if (p[2] > p[0] + p[1] + kInertiaTolerance * sum)
      throw ScenarioError(At(n), what + " breaks the triangle inequality: its largest principal moment " + Fmt(p[2], 6) +
                                     " exceeds the sum of the other two (" + Fmt(p[0] + p[1], 6) + "), which no mass distribution gives",
                          "check the moments (a thin rod has two equal moments and ~0 about its axis; a thin plate "
                          "I_normal = I_1 + I_2)");
    return I;
  }

  void ReadBodies(const YAML::Node& bodies) {
    if (!bodies) throw ScenarioError({file_, 1}, "a spatial scene needs bodies:", "declare its links (scenarios/FORMAT.md, Spatial scenes)");
    if (!bodies.IsMap()) throw ScenarioError(At(bodies), "bodies must be a mapping name: {points: [...], vectors: [...]}",
                          "write each body on its own line under bodies:, e.g. rod: {points: [A, B], mass: 1}");
    std::set<std::string> names;
    for (const auto& kv : bodies) {
      SpatialBody b;
      b.name = Str(kv.first, "body name");
      b.src = At(kv.first);
      if (!names.insert(b.name).second) throw ScenarioError(b.src, "body '" + b.name + "' declared twice",
                          "rename one of the two, or remove the copy");
      const std::string what = "body " + b.name;
      const YAML::Node n = kv.second;
      Keys(n, what, {"points", "vectors", "mass", "com", "inertia"});
      if (!n["points"]) throw ScenarioError(b.src, what + " needs points: [P, ...] (its first point is its origin)",
                          "add points: [P, ...]");
      int npoints = 0, nvectors = 0;
      for (const YAML::Node& p : Seq(n["points"], what + " points", 0)) b.entities.push_back(EntityRef(p, what, 0)), ++npoints;
      if (n["vectors"])
        for (const YAML::Node& v : Seq(n["vectors"], what + " vectors", 0)) b.entities.push_back(EntityRef(v, what, 1)), ++nvectors;
      if (npoints == 0) throw ScenarioError(At(n["points"]), what + " needs at least one point",
                          "list its points: [P, ...]");
      if (std::set<int>(b.entities.begin(), b.entities.end()).size() != b.entities.size())
        throw ScenarioError(b.src, what + " lists an entity twice",
                          "list each point and vector once");
      const size_t count = b.entities.size();
      const bool point_mass = count == 1, bar = npoints == 2 && nvectors == 0;
      if (!point_mass && !bar && count < 4)
        throw ScenarioError(b.src, what + " has " + std::to_string(count) +
                                       " entities: a rigid body in 3-D needs four that are not coplanar (its basis)",
                            "add a point or a unit vector of the body (e.g. a vector across it), or make it a bar (two "
                            "points) or a point mass (one point)");
      if (bar && !((s_.entities[b.entities[1]].r_W - s_.entities[b.entities[0]].r_W).norm() > 0)) {
        const std::string& a = s_.entities[b.entities[0]].name;
        const std::string& c = s_.entities[b.entities[1]].name;
        throw ScenarioError(At(n["points"]), what + " is a bar whose points " + a + " and " + c +
                                                 " are drawn at one place: its length must be positive",
                            "draw " + c + " at the bar's length from " + a + " under points: (the file's pose gives "
                            "every length; initial values move it afterwards)");
      }
      if (count >= 4) CheckBasis(b, n, what);
      if (n["mass"] || n["com"] || n["inertia"]) {
        if (bar && (n["com"] || n["inertia"]))
          throw ScenarioError(At(n["com"] ? n["com"] : n["inertia"]),
                              what + " is a bar (two points): its mass is a slender uniform rod's, centre of mass at "
                              "its middle, no inertia about its own axis, so it takes mass alone",
                              "give `mass:` alone (the rod's mass in kg), or give the body a basis (two unit vectors across it) to make it a "
                              "rigid body with com and inertia");
        if (!n["mass"]) throw ScenarioError(b.src, what + " gives com or inertia without mass", "give mass: [kg]");
        b.mass = Num(n["mass"], what + " mass", UnitField::kPlain, "kg");
        if (!(b.mass >= 0) || b.mass > 1e100) throw ScenarioError(At(n["mass"]), what + " mass must be between 0 and 1e100 kg",
                          "give a mass of 0 (massless) up to 1e100 kg");
        if (bar) {  // a slender uniform rod: M = m/6 [2 1; 1 2] ⊗ I₃ on its two points (spatial.h)
          b.com_W = 0.5 * (s_.entities[b.entities[0]].r_W + s_.entities[b.entities[1]].r_W);
        } else if (point_mass) {
          if (n["com"] || n["inertia"])
            throw ScenarioError(At(n["com"] ? n["com"] : n["inertia"]),
                                what + " is a point mass (one point): its centre of mass is its point and its inertia 0",
                                "give mass alone, or give the body a basis (four entities) for com and inertia");
          b.com_W = s_.entities[b.entities[0]].r_W;
        } else {
          if (!n["com"] || !n["inertia"])
            throw ScenarioError(b.src, what + " gives only part of its mass properties", "give mass, com and inertia together");
          b.com_W = Vec3(n["com"], what + " com", UnitField::kLength, LengthUnit());
          b.inertia_W = ReadInertia(n["inertia"], what + " inertia");
          if (b.mass == 0 && b.inertia_W.cwiseAbs().maxCoeff() != 0)
            throw ScenarioError(At(n["inertia"]), what + " has inertia but no mass", "give its mass, or inertia 0 for a massless body");
          if (b.inertia_W.cwiseAbs().maxCoeff() > 1e100)
            throw ScenarioError(At(n["inertia"]), what + " inertia beyond 1e100 kg·length²",
                          "give moments and products of inertia within 1e100 kg·length² (scenarios/FORMAT.md, limits)");
        }
      }
      s_.bodies.push_back(b);
    }
  }

  // The first entity a point, the first four not coplanar.
  void CheckBasis(const SpatialBody& b, const YAML::Node& n, const std::string& what) {
    const V3 e0 = s_.entities[b.entities[0]].r_W;
    M3 X;
    std::string names;
    for (int k = 1; k < 4; ++k) {
      const SpatialEntity& e = s_.entities[b.entities[k]];
      X.col(k - 1) = e.vector ? e.r_W : V3(e.r_W - e0);
      names += (k > 1 ? ", " : "") + e.name;
    }
    const double norms = X.colwise().norm().prod();
    if (!(norms > 0) || std::fabs(X.determinant()) <= kCoplanar * norms)
      throw ScenarioError(At(n["points"]), what + ": its basis " + s_.entities[b.entities[0]].name + " with " + names +
                                               " is coplanar (|det X| = " + Fmt(std::fabs(X.determinant()), 3) +
                                               " of " + Fmt(norms, 3) + "), so it fixes no frame",
                          "list first four entities that span space: e.g. two points and two unit vectors across "
                          "the segment between them and across each other");
  }

  // One side of a dot product: a vector name, or a segment [P, Q] (from P to Q).
  std::array<int, 2> Side(const YAML::Node& n, const std::string& what) {
    if (n.IsSequence()) {
      const auto s = Seq(n, what, 2);
      const int p = EntityRef(s[0], what, 0), q = EntityRef(s[1], what, 0);
      if (p == q) throw ScenarioError(At(n), what + " is a segment from a point to itself", "name two points");
      return {q, p};  // A = q − p
    }
    return {EntityRef(n, what, 1), -1};
  }
  V3 SideValue(const std::array<int, 2>& s) const {
    return s_.entities[s[0]].r_W - (s[1] >= 0 ? s_.entities[s[1]].r_W : V3::Zero());
  }

  void ReadJoints(const YAML::Node& joints) {
    if (!joints) return;
    for (const YAML::Node& n : Seq(joints, "joints", 0)) {
      SpatialJoint j;
      j.src = At(n);
      if (!n.IsMap() || !n["type"])
        throw ScenarioError(j.src, "a spatial joint needs a type", "type: distance (points: [A, B]) or type: dot (between: [u, [A, B]])");
      const std::string type = Str(n["type"], "joint type");
      if (type == "distance") {
        Keys(n, "distance joint", {"type", "points"});
        if (!n["points"]) throw ScenarioError(j.src, "a distance joint needs points: [A, B]",
                          "add points: [A, B] (the two points whose distance is kept)");
        const auto s = Seq(n["points"], "distance joint points", 2);
        j.type = SpatialJoint::Type::kDistance;
        j.a = {EntityRef(s[0], "distance joint", 0), EntityRef(s[1], "distance joint", 0)};
        j.name = "distance " + s_.entities[j.a[0]].name + "-" + s_.entities[j.a[1]].name;
        if (!((s_.entities[j.a[0]].r_W - s_.entities[j.a[1]].r_W).norm() > 0))
          throw ScenarioError(j.src, j.name + ": the points are at one place, so there is no distance to keep",
                              "keep two points at one place by sharing one point between the bodies (a spherical joint)");
      } else if (type == "dot") {
        Keys(n, "dot joint", {"type", "between"});
        if (!n["between"]) throw ScenarioError(j.src, "a dot joint needs between: [X, Y] (vectors or segments [P, Q])",
                          "add between: [u, v] (two unit vectors, or a segment [P, Q] for either)");
        const auto s = Seq(n["between"], "dot joint between", 2);
        j.type = SpatialJoint::Type::kDot;
        j.a = Side(s[0], "dot joint");
        j.b = Side(s[1], "dot joint");
        j.name = "dot";
        if (!(SideValue(j.a).norm() > 0 && SideValue(j.b).norm() > 0))
          throw ScenarioError(j.src, "a dot joint's segment has zero length", "name two points apart");
      } else {
        throw ScenarioError(At(n["type"]), "unknown spatial joint type '" + type + "'",
                            "use distance or dot; a spherical joint is a point and a revolute a point and a vector "
                            "shared by two bodies; a prism or cylinder is an `along` coordinate");
      }
      // The same constraint twice would be a redundant row the user did not mean (a copy-paste):
      // the same two points, or the same two sides in either order (a segment either way round).
      const auto side = [](std::array<int, 2> x) {
        if (x[1] >= 0 && x[1] < x[0]) std::swap(x[0], x[1]);
        return x;
      };
      const auto pair = [&](std::array<int, 2> x, std::array<int, 2> y) {
        if (y < x) std::swap(x, y);
        return std::array<std::array<int, 2>, 2>{x, y};
      };
      for (const SpatialJoint& e : s_.joints) {
        const bool same = e.type == j.type &&
                          (j.type == SpatialJoint::Type::kDistance ? side(e.a) == side(j.a)
                                                                   : pair(side(e.a), side(e.b)) == pair(side(j.a), side(j.b)));
        if (same)
          throw ScenarioError(j.src, "this " + std::string(j.type == SpatialJoint::Type::kDot ? "dot" : "distance") +
                                         " joint repeats the one on line " + std::to_string(e.src.line) +
                                         " (the same pair): its constraint would be counted twice",
                              "remove one of the two entries");
      }
      s_.joints.push_back(j);
    }
  }

  void ReadCoordinates(const YAML::Node& coords) {
    if (!coords) return;
    if (!coords.IsMap()) throw ScenarioError(At(coords), "coordinates must be a mapping name: {type: along, ...}",
                          "write each coordinate on its own line under coordinates:, e.g. s: {type: along, point: P, from: A, direction: u}");
    for (const auto& kv : coords) {
      SpatialCoordinate c;
      c.name = Str(kv.first, "coordinate name");
      c.src = At(kv.first);
      const std::string what = "coordinate " + c.name;
      const YAML::Node n = kv.second;
      if (!n.IsMap() || !n["type"]) throw ScenarioError(c.src, what + " needs a type", "type: along, or type: angle");
      const std::string type = Str(n["type"], what + " type");
      if (type == "angle") {
        ReadAngle(n, what, c);
      } else if (type == "along") {
        Keys(n, what, {"type", "point", "from", "direction"});
        for (const char* k : {"point", "from", "direction"})
          if (!n[k]) throw ScenarioError(c.src, what + " needs " + k + ":", "{type: along, point: P, from: A, direction: u}");
        c.point = EntityRef(n["point"], what + " point", 0);
        c.from = EntityRef(n["from"], what + " from", 0);
        c.direction = EntityRef(n["direction"], what + " direction", 1);
        const V3 d = s_.entities[c.point].r_W - s_.entities[c.from].r_W, u = s_.entities[c.direction].r_W;
        c.value = d.dot(u);
        if ((d - c.value * u).norm() > kOnLineTolerance * (1 + d.norm())) {
          // Both fixes: P moved onto the line, or the direction that puts the given P on it (a
          // vector of the scene's with that direction named, fixed or moving as the one given).
          const V3 towards = d / d.norm();
          std::string named;
          for (int pass = 0; pass < 2 && named.empty(); ++pass)
            for (const SpatialEntity& e : s_.entities)
              if (e.vector && named.empty() && e.r_W.dot(towards) > 1 - 1e-12 &&
                  (pass == 1 || e.fixed == s_.entities[c.direction].fixed))
                named = " (the vector " + e.name + ": direction: " + e.name + ")";
          throw ScenarioError(At(n["point"]), what + ": point " + s_.entities[c.point].name + " is " + Fmt((d - c.value * u).norm(), 3) +
                                                  " off the line through " + s_.entities[c.from].name + " along " +
                                                  s_.entities[c.direction].name + " (the file's pose is an assembled pose)",
                              "put it on the line, e.g. at " + Xyz(s_.entities[c.from].r_W + c.value * u, 12) +
                                  "; or, if " + s_.entities[c.point].name + " is where it belongs, give the line the "
                                  "direction (" + s_.entities[c.point].name + " − " +
                                  s_.entities[c.from].name + ")/|" + s_.entities[c.point].name + " − " +
                                  s_.entities[c.from].name + "| = " + Xyz(towards, 12) + " at this pose" + named);
        }
      } else {
        throw ScenarioError(At(n["type"]), what + ": unknown spatial coordinate type '" + type + "'",
                            "use along (a distance along a unit vector: {type: along, point: P, from: A, direction: u}) "
                            "or angle (about an axis: {type: angle, axis: a, from: u, to: w})");
      }
      s_.coordinates.push_back(c);
    }
  }

  // θ from u to w about a, right handed: u and w perpendicular to a at the file's pose (the rows
  // of the bodies that carry them keep them so: a revolute joint's axis in both bodies).
  void ReadAngle(const YAML::Node& n, const std::string& what, SpatialCoordinate& c) {
    Keys(n, what, {"type", "axis", "from", "to"});
    for (const char* k : {"axis", "from", "to"})
      if (!n[k]) throw ScenarioError(c.src, what + " needs " + k + ":", "{type: angle, axis: a, from: u, to: w}");
    c.type = SpatialCoordinate::Type::kAngle;
    c.direction = EntityRef(n["axis"], what + " axis", 1);
    c.from = EntityRef(n["from"], what + " from", 1);
    c.to = EntityRef(n["to"], what + " to", 1);
    if (c.from == c.to || c.from == c.direction || c.to == c.direction)
      throw ScenarioError(c.src, what + ": axis, from and to must be three different vectors",
                          "from: a vector across one body, to: a vector across the other, axis: the joint's axis");
    const V3 a = s_.entities[c.direction].r_W.normalized(), u = s_.entities[c.from].r_W.normalized(),
             w = s_.entities[c.to].r_W.normalized();
    // Each vector across the axis at the pose, and kept across it along the motion: through a
    // rigid body that carries both, a dot joint, or both fixed. Otherwise the row
    // cos θ (u × w)·a − sin θ u·w loses its meaning as they leave the plane (u along a makes it
    // −sin θ u·w, which θ = 0 satisfies whatever the mechanism does).
    for (const auto& [key, e] : {std::pair{"from", c.from}, std::pair{"to", c.to}}) {
      const V3 v = s_.entities[e].r_W.normalized();
      const std::string& name = s_.entities[e].name;
      const std::string& axis = s_.entities[c.direction].name;
      if (std::fabs(v.dot(a)) > kOnLineTolerance)
        throw ScenarioError(At(n[key]), what + ": vector " + name + " is not perpendicular to the axis " + axis + " (cosine " +
                                            Fmt(v.dot(a), 3) + "): the angle is measured in the plane across the axis",
                            "give " + name + " a direction across the axis, e.g. " + Xyz((v - v.dot(a) * a).normalized(), 12));
      if (!KeptTogether(e, c.direction))
        throw ScenarioError(At(n[key]), what + ": nothing keeps vector " + name + " across the axis " + axis +
                                            " as the mechanism moves (no rigid body carries both, no dot joint holds them, "
                                            "they are not both fixed)",
                            "measure the angle at a revolute joint: list " + axis + " among the vectors of the body that carries " +
                                name + " (the joint's shared axis), or add {type: dot, between: [" + name + ", " + axis + "]}");
    }
    if (s_.entities[c.from].fixed && s_.entities[c.to].fixed)
      throw ScenarioError(c.src, what + ": vectors " + s_.entities[c.from].name + " and " + s_.entities[c.to].name +
                                     " are both fixed, so the angle never changes",
                          "measure it to a vector of the moving body (to: a vector across it)");
    c.value = std::atan2(u.cross(w).dot(a), u.dot(w));
  }

  // Whether the rows keep the dot product of vectors u and v constant: both fixed, both carried by
  // one rigid body (four entities or more), or a dot joint between the two vectors themselves.
  bool KeptTogether(int u, int v) const {
    if (s_.entities[u].fixed && s_.entities[v].fixed) return true;
    for (const SpatialBody& b : s_.bodies)
      if (b.entities.size() >= 4 && std::count(b.entities.begin(), b.entities.end(), u) &&
          std::count(b.entities.begin(), b.entities.end(), v))
        return true;
    for (const SpatialJoint& j : s_.joints)
      if (j.type == SpatialJoint::Type::kDot && j.a[1] < 0 && j.b[1] < 0 &&
          ((j.a[0] == u && j.b[0] == v) || (j.a[0] == v && j.b[0] == u)))
        return true;
    return false;
  }

  // A moving unit vector keeps its length only through a body's rows.
  void CheckVectorsBelong() {
    std::vector<bool> in_body(s_.entities.size(), false);
    for (const SpatialBody& b : s_.bodies)
      if (b.entities.size() >= 4)
        for (int e : b.entities) in_body[e] = true;
    for (size_t e = 0; e < s_.entities.size(); ++e)
      if (s_.entities[e].vector && !s_.entities[e].fixed && !in_body[e])
        throw ScenarioError(s_.entities[e].src, "vector " + s_.entities[e].name + " moves but belongs to no rigid body, so nothing keeps it a unit vector",
                            "list it in a body's vectors: (a body of four entities or more), or make it fixed");
  }

  // Moving points in file order (xP, yP, zP), then moving vectors (xu, yu, zu), then coordinates.
  void BuildLayout() {
    // Model::spatial.entities holds the points, then the vectors (read in that order), in file order.
    for (size_t e = 0; e < s_.entities.size(); ++e) {
      if (s_.entities[e].fixed) continue;
      for (int axis = 0; axis < 3; ++axis) {
        Model::Slot slot;
        slot.name = std::string(1, "xyz"[axis]) + s_.entities[e].name;
        slot.axis = axis;
        slot.entity = static_cast<int>(e);
        m_.q_layout.push_back(slot);
      }
    }
    for (size_t c = 0; c < s_.coordinates.size(); ++c) {
      if (m_.SlotIndex(s_.coordinates[c].name) >= 0 || s_.EntityIndex(s_.coordinates[c].name) >= 0)
        throw ScenarioError(s_.coordinates[c].src,
                            "coordinate " + s_.coordinates[c].name + " clashes with the name of a point, a vector or one of their coordinates",
                            "rename it");
      Model::Slot slot;
      slot.name = s_.coordinates[c].name;
      slot.spatial_coordinate = static_cast<int>(c);
      m_.q_layout.push_back(slot);
    }
    if (m_.q_layout.empty()) throw ScenarioError({file_, 1}, "the scenario has nothing that moves", "add moving points");
  }

  std::string file_;
  Model& m_;
  SpatialModel& s_;
  const ConstantUnitMap& constant_units_;
};

}  // namespace

void ReadSpatialScene(const YAML::Node& root, const std::string& file, Model& m, const ConstantUnitMap& constant_units) {
  SpatialReader(file, m, constant_units).Read(root);
}

void CheckSpatialScene(const YAML::Node& root, const std::string& file, const Model& m) {
  if (!m.drivers.empty() || !m.analysis.HasMotion()) return;
  bool any = false;
  for (const SpatialBody& b : m.spatial.bodies) any = any || (b.HasMass() && b.mass > 0);
  if (!any)
    throw ScenarioError({file, root["bodies"].Mark().line + 1},
                        "a free scene (no drivers) with a motion, but no body has mass: nothing has inertia for its loads to accelerate",
                        "give the bodies mass, com and inertia, or drive a coordinate (drivers:) for kinematics");
}

}  // namespace mechbench::detail
