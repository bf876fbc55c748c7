// The engines' spatial graph (spatial_graph.h): bodies, joints by shared entities, a spanning
// tree, loads, and the observer back to Model::q_layout.
#include "mechbench/engines/spatial_graph.h"

#include "load_variables.h"

#include "mechbench/errors.h"
#include "mechbench/format.h"
#include "mechbench/numeric/natural_data.h"
#include "mechbench/numeric/natural_model.h"
#include "mechbench/numeric/solver.h"
#include "mechbench/numeric/spatial.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <queue>
#include <sstream>
#include <tuple>

namespace mechbench::engines {
namespace {

using V3 = Eigen::Vector3d;

// ω of a set of body-fixed directions d_k with rates ḋ_k = ω × d_k (least squares over the
// directions, exact on a rigid set): Σ_k [d_k]ₓᵀ [d_k]ₓ ω = Σ_k d_k × ḋ_k.
V3 AngularVelocity(const std::vector<V3>& d, const std::vector<V3>& dd) {
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  V3 b = V3::Zero();
  for (size_t k = 0; k < d.size(); ++k) {
    A += d[k].squaredNorm() * Eigen::Matrix3d::Identity() - d[k] * d[k].transpose();
    b += d[k].cross(dd[k]);
  }
  // One direction (a bar): A is singular along it; the spin about it is zero (the pseudo-inverse).
  if (d.size() == 1) return d[0].squaredNorm() > 0 ? V3(b / d[0].squaredNorm()) : V3::Zero();
  return A.ldlt().solve(b);
}

class SpatialBuilderOfGraph {
 public:
  SpatialBuilderOfGraph(const Model& m, const SpatialGraphOptions& o) : m_(m), s_(m.spatial), o_(o) {}

  SpatialGraphOrReason Build() {
    SpatialGraphOrReason out;
    if (auto why = Refusal()) {
      out.reason = *why;
      return out;
    }
    if (!Assemble(out.reason)) return out;
    g_.t0 = m_.analysis.t0;
    g_.gravity = s_.gravity;
    g_.length_scale = nm_->length_scale;
    g_.meters_per_unit = nm_->meters_per_unit;
    g_.initial = Sample{m_.analysis.t0, data_->q, data_->qd, data_->qdd, 0.0};
    g_.driven = !m_.drivers.empty();
    if (m_.analysis.HasMotion())
      for (int k = 0; k < m_.analysis.samples; ++k) g_.sample_times.push_back(m_.analysis.TimeAt(k));
    else
      g_.sample_times.push_back(m_.analysis.t0);
    std::string why;
    if (!Bodies(why) || !Joints(why) || !Tree(why) || !Drivers(why) || !Loads(why)) {
      out.reason = why;
      return out;
    }
    g_.settings["graph.frames"] = "every body's frame at its first point, with the world's axes at t0 (assembled by numeric)";
    g_.settings["graph.bar_axial_inertia"] = Fmt(o_.bar_axial_inertia_ratio) +
                                             " × m L²/12 about a bar's own axis (a slender rod has none; engines need a "
                                             "positive-definite inertia; no torque about the axis: it changes nothing)";
    g_.settings["graph.point_mass_inertia"] = "m (" + Fmt(o_.point_radius) +
                                              " × length scale)² about each axis of a point mass (its rotation is free "
                                              "and uncoupled: it changes nothing)";
    if (std::any_of(g_.joints.begin(), g_.joints.end(), [](const SpatialGraphJoint& j) { return j.along >= 0; }))
      g_.settings["graph.sliders"] =
          "an `along` coordinate: a prismatic joint along its direction from ground (a fixed line) or from the "
          "line's body (a line of a moving body); on its point's body when that is a one-point body "
          "(on a fixed line its rotation is free and uncoupled; on a moving one it turns with the line's body, whose "
          "inertia gives up what the point mass's body gets: it changes nothing) or a body that shares the line body's orientation "
          "(two non-parallel vectors: a prismatic pair), else on an added slider "
          "body of " + Fmt(o_.slider_mass_ratio) + " × the scene's body mass in a free scene (it changes the motion "
          "by about that fraction), " + Fmt(o_.driven_slider_mass_ratio) + " × in a driven one (the motion is "
          "prescribed: it changes no coordinate), a point mass's inertia, joined to the point's body by a ball "
          "there (a revolute about the direction when that body shares it: a cylindrical pair)";
    if (g_.Closures() > 0)
      g_.settings["graph.closures"] =
          "loop closures: a ball at a shared point; a revolute as two balls on its axis (at the point and " +
          Fmt(o_.closure_axis_length) + " × length scale along it: six rows of rank five)";
    out.graph = std::move(g_);
    return out;
  }

 private:
  // What this slice does not map, before any work.
  std::optional<std::string> Refusal() const {
    for (const Driver& d : m_.drivers) {
      const int slot = m_.SlotIndex(d.coordinate);
      const int c = slot < 0 ? -1 : m_.q_layout[slot].spatial_coordinate;
      if (c < 0)
        return "a driven scene (driver on " + d.coordinate + ", " + d.src.Str() +
               "): the spatial graph maps drivers on angle coordinates about a revolute joint's axis and on "
               "`along` coordinates only";
    }
    for (const SpatialJoint& j : s_.joints)
      return std::string("joint ") + (j.name.empty() ? "" : j.name + " ") + "(" + j.src.Str() + "): a constant " +
             (j.type == SpatialJoint::Type::kDistance ? "distance" : "dot product") +
             " between bodies has no joint of the spatial graph yet (shared points and axes only)";
    for (const SpatialCoordinate& c : s_.coordinates)
      if (!c.IsAngle())
        if (auto why = AlongRefusal(c)) return why;
    for (const SpatialBody& b : s_.bodies)
      if ((!b.HasMass() || !(b.mass > 0)) && (m_.drivers.empty() || b.entities.size() < 2 || s_.entities[b.entities[1]].vector))
        return "body " + b.name + " (" + b.src.Str() + ") has no mass: " +
               (m_.drivers.empty() ? "a free scene's engine body needs one (numeric runs it massless; for the engines "
                                     "give it a small `mass:` — a bar with `mass:` alone is a uniform rod — and compare "
                                     "how much that changes numeric's motion)"
                                   : "a driven scene's gets a uniform rod between its first two points, and it has no two "
                                     "(give it a `mass:` and, with vectors, its com and inertia)") +
               PointBodiesOn(b);
    return std::nullopt;
  }
  // A massless body's one-point bodies with mass (a bob at a rod's tip): the planar engines fold such
  // a point mass into its link (README "Point bodies"); the spatial graph does not yet, so a
  // refusal names them and a small mass to give it.
  std::string PointBodiesOn(const SpatialBody& b) const {
    std::string on;
    double carried = 0;
    for (const SpatialBody& pb : s_.bodies)
      if (&pb != &b && pb.entities.size() == 1 && pb.HasMass() && pb.mass > 0 &&
          std::find(b.entities.begin(), b.entities.end(), pb.entities[0]) != b.entities.end()) {
        on += std::string(on.empty() ? "" : ", ") + pb.name + " (" + Fmt(pb.mass, 3) + " kg at " +
              s_.entities[pb.entities[0]].name + ")";
        carried += pb.mass;
      }
    if (on.empty()) return "";
    return "; it carries the point body " + on + ", which the spatial graph does not fold into it (the planar "
           "engines do): e.g. `mass: " + Fmt(0.01 * carried, 3) + "` on " + b.name + " (1% of what it carries), then "
           "`--method numeric` with and without it shows how much that changes the motion";
  }

  // How an `along` coordinate (P − A = s d) becomes joints: the line's body `line` (ground when A
  // and d are fixed, else a model body that lists both), P's body `body` (P's first), and the
  // device between them.
  enum class PairMode {
    kOwnBody,     // a prismatic joint from the line's body (ground or a moving one) to P's one-point body
    kDirect,      // P's body shares two non-parallel vectors with a moving line's body: a prismatic joint between them
    kAddedBall,   // an added "slider of s" on a prismatic joint from the line's body, a ball at P to P's body
    kAddedHinge,  // the same with a revolute about d at P (P's body shares d with the line's: a cylindrical pair)
  };
  struct Pair {
    int line = -1, body = -1;
    PairMode mode = PairMode::kAddedBall;
  };

  bool ListsModel(int b, int e) const {
    if (b < 0) return s_.entities[e].fixed;
    const auto& v = s_.bodies[b].entities;
    return std::find(v.begin(), v.end(), e) != v.end();
  }
  bool Parallel(int e1, int e2) const {
    const V3 a = s_.entities[e1].r_W.normalized(), b = s_.entities[e2].r_W.normalized();
    return a.cross(b).norm() < 1e-3;
  }

  // The pair of an `along` coordinate, or why the graph does not map it: a fixed point, a second
  // `along` on the same point, a line on no one body, P on the line's body, a point shared between
  // the two bodies, a shared vector across the line; on a fixed line, a body that carries d too.
  std::optional<std::string> PairOf(const SpatialCoordinate& c, Pair& out) const {
    const std::string head = "coordinate " + c.name + " (" + c.src.Str() + "): ";
    const std::string& pn = s_.entities[c.point].name;
    const std::string& dn = s_.entities[c.direction].name;
    if (s_.entities[c.point].fixed) return head + "its point " + pn + " is fixed: nothing slides";
    for (const SpatialCoordinate& o : s_.coordinates)
      if (&o != &c && !o.IsAngle() && o.point == c.point)
        return head + "a second `along` coordinate (" + o.name + ") on " + pn +
               ": a point on two lines (a planar or cylindrical pair) is not mapped yet";
    int pb = -1;
    for (size_t b = 0; b < s_.bodies.size() && pb < 0; ++b)
      if (ListsModel(static_cast<int>(b), c.point)) pb = static_cast<int>(b);
    if (pb < 0) return std::nullopt;  // a moving entity in no body: Bodies() says so
    out.body = pb;
    if (s_.entities[c.from].fixed && s_.entities[c.direction].fixed) {  // a fixed line
      out.line = -1;
      for (size_t k = 0; k < s_.bodies.size(); ++k)
        if (s_.bodies[k].entities.size() == 1 && s_.bodies[k].entities[0] == c.point) {
          out.body = static_cast<int>(k);
          out.mode = PairMode::kOwnBody;
          return std::nullopt;
        }
      const SpatialBody& b = s_.bodies[pb];
      if (ListsModel(pb, c.direction))
        return head + "body " + b.name + " carries both " + pn + " and the direction " + dn +
               " (a prismatic or cylindrical pair that holds the body's orientation on a fixed line): not mapped "
               "yet; the spatial graph maps a point sliding on a fixed line, or on a line of a moving body";
      out.mode = PairMode::kAddedBall;
      return std::nullopt;
    }
    // A moving line: on a body that lists both its `from` and its direction.
    out.line = -1;
    for (size_t b = 0; b < s_.bodies.size() && out.line < 0; ++b)
      if (static_cast<int>(b) != pb && ListsModel(static_cast<int>(b), c.from) && ListsModel(static_cast<int>(b), c.direction))
        out.line = static_cast<int>(b);
    if (out.line < 0)
      return head + "its line (from " + s_.entities[c.from].name + " along " + dn + ") moves and no body other than " +
             s_.bodies[pb].name + " (" + pn + "'s) carries both " + s_.entities[c.from].name + " and " + dn +
             ": the spatial graph maps a point sliding on a fixed line or on a line fixed in one moving body";
    const SpatialBody& L = s_.bodies[out.line];
    if (ListsModel(out.line, c.point))
      return head + "body " + L.name + " (the line's) lists " + pn + " too: " + pn + " cannot slide along the line";
    // A point mass on the line slides itself, turning with the line's body (Sliders() moves its
    // spin inertia out of that body's: exact).
    for (size_t k = 0; k < s_.bodies.size(); ++k)
      if (s_.bodies[k].entities.size() == 1 && s_.bodies[k].entities[0] == c.point) {
        out.body = static_cast<int>(k);
        out.mode = PairMode::kOwnBody;
        return std::nullopt;
      }
    const SpatialBody& B = s_.bodies[pb];
    std::vector<int> vectors;
    for (const int e : B.entities) {
      if (!ListsModel(out.line, e)) continue;
      if (!s_.entities[e].vector)
        return head + "bodies " + L.name + " (the line's) and " + B.name + " (" + pn + "'s) share the point " +
               s_.entities[e].name + ": " + pn + " cannot slide along the line";
      vectors.push_back(e);
    }
    bool across = false, two = false;
    for (const int e : vectors) {
      across = across || !Parallel(e, c.direction);
      for (const int f : vectors) two = two || !Parallel(e, f);
    }
    if (two) {
      out.mode = PairMode::kDirect;
    } else if (across) {
      return head + "bodies " + L.name + " and " + B.name + " share a vector across the line and no second one: "
             "not mapped (a prismatic pair shares two non-parallel vectors, a cylindrical one the direction only)";
    } else {
      out.mode = vectors.empty() ? PairMode::kAddedBall : PairMode::kAddedHinge;
    }
    return std::nullopt;
  }

  std::optional<std::string> AlongRefusal(const SpatialCoordinate& c) const {
    Pair p;
    return PairOf(c, p);
  }

  // Whether model bodies x and y hold vector e equal by their own joint: a revolute about e (one
  // shared point and e the one shared vector), or an `along` pair that keeps it (kDirect: any
  // vector both list; kAddedHinge: one parallel to d).
  bool HoldsVector(int x, int y, int e) const {
    if (!ListsModel(x, e) || !ListsModel(y, e)) return false;
    int points = 0, vectors = 0;
    for (const int f : s_.bodies[y].entities) {
      if (!ListsModel(x, f)) continue;
      if (s_.entities[f].vector)
        ++vectors;
      else if (!s_.entities[f].fixed)
        ++points;
    }
    if (points == 1 && vectors == 1) return true;
    for (size_t ci = 0; ci < s_.coordinates.size(); ++ci) {
      if (s_.coordinates[ci].IsAngle() || pair_[ci].line < 0) continue;
      const Pair& p = pair_[ci];
      if (!((x == p.line && y == p.body) || (x == p.body && y == p.line))) continue;
      if (p.mode == PairMode::kDirect || (p.mode == PairMode::kAddedHinge && Parallel(e, s_.coordinates[ci].direction)))
        return true;
    }
    return false;
  }
  // Two moving bodies a, b that share vector e and no point: e is kept equal in both when a third
  // body holds it with each (HoldsVector), so the sharing is no joint of its own.
  bool HeldThroughThird(int a, int b, int e) const {
    for (int c = 0; c < static_cast<int>(s_.bodies.size()); ++c)
      if (c != a && c != b && HoldsVector(a, c, e) && HoldsVector(b, c, e)) return true;
    return false;
  }

  // Whether a shared set of entities between model bodies a (or ground, -1) and b is a joint the
  // `along` pairs hold already: the line's body and P's (vectors only), or ground and P's body
  // over fixed vectors the pair holds (kDirect: any the line's body lists; kAddedHinge: d's
  // parallels the line's body lists).
  bool HeldByPair(int a, int b, const std::vector<int>& points, const std::vector<int>& vectors) const {
    if (!points.empty()) return false;
    for (size_t ci = 0; ci < s_.coordinates.size(); ++ci) {
      const SpatialCoordinate& c = s_.coordinates[ci];
      if (c.IsAngle() || pair_[ci].line < 0) continue;
      const Pair& p = pair_[ci];
      const bool direct = p.mode == PairMode::kDirect, hinge = p.mode == PairMode::kAddedHinge;
      if (!direct && !hinge) continue;
      if ((a == p.line && b == p.body) || (a == p.body && b == p.line)) return true;
      if (a < 0 && b == p.body &&
          std::all_of(vectors.begin(), vectors.end(), [&](int e) {
            return ListsModel(p.line, e) && (direct || Parallel(e, c.direction));
          }))
        return true;
    }
    return false;
  }

  // t0 with the numeric solver, the initial conditions as drivers (as BuildGraph does).
  bool Assemble(std::string& why) {
    Model m = m_;
    if (m.drivers.empty()) {
      m.drivers = m.initial;
      m.initial.clear();
    }
    try {
      nm_.emplace(numeric::Compile(m));
      data_.emplace(*nm_);
      numeric::NewtonOptions opt;
      opt.record_iterates = false;
      numeric::SolveInstant(*nm_, *data_, m.analysis.t0, m.GuessQ(), opt);
    } catch (const ScenarioError&) {
      throw;  // an impossible scene is not an engine's limitation
    } catch (const std::exception& e) {
      why = std::string("cannot assemble t0 with the numeric solver: ") + e.what();
      return false;
    }
    if (m.drivers.empty()) data_->qd.setZero(nm_->n);  // no initial conditions: at rest
    if (m_.drivers.empty()) data_->qdd.setZero(nm_->n);  // a free scene's q̈ needs dynamics
    MB_ASSERT(nm_->entities.size() >= s_.entities.size(), "the compiled spatial model lost entities");
    for (size_t e = 0; e < s_.entities.size(); ++e) {
      MB_ASSERT(nm_->entities[e].name == s_.entities[e].name, "the compiled entities are not in the file's order");
      r_.push_back(numeric::EntityValue(*nm_, data_->q, static_cast<int>(e)));
      rd_.push_back(numeric::EntityRate(*nm_, data_->qd, static_cast<int>(e)));
    }
    return true;
  }

  bool Bodies(std::string& why) {
    owner_.assign(s_.entities.size(), -1);
    for (size_t bi = 0; bi < s_.bodies.size(); ++bi) {
      const SpatialBody& b = s_.bodies[bi];
      SpatialGraphBody gb;
      gb.name = b.name;
      gb.model_body = static_cast<int>(bi);
      const int e0 = b.entities[0];
      MB_ASSERT(!s_.entities[e0].vector, "a spatial body's first entity is a point");
      gb.initial.p = r_[e0];
      gb.initial.v = rd_[e0];
      gb.mass = b.mass;
      std::vector<V3> d, dd;
      const double L = g_.length_scale;
      const bool massless = !b.HasMass() || !(b.mass > 0);  // a driven scene's (Refusal)
      if (massless) {  // the stated uniform rod between its first two points
        const V3 axis = r_[b.entities[1]] - r_[e0];
        const double len = axis.norm();
        const V3 e = axis / len;
        gb.mass = o_.link_mass_per_length * len * nm_->meters_per_unit;
        const double It = gb.mass * len * len / 12;
        gb.com_B = axis / 2;
        gb.inertia_B = It * (Eigen::Matrix3d::Identity() - e * e.transpose()) + o_.bar_axial_inertia_ratio * It * e * e.transpose();
        gb.mass_source = "stated: " + Fmt(o_.link_mass_per_length) + " kg/m uniform rod between its first two points";
        g_.notes.push_back("body " + b.name + " has no mass in the file: the engines give it a " +
                           Fmt(o_.link_mass_per_length) + " kg/m uniform rod between its first two points (" +
                           Fmt(gb.mass) + " kg; the motion is driven, so it changes no coordinate)");
      }
      if (massless) {
        // its ω below from its basis (a rigid body) or its axis (a bar)
      } else if (b.entities.size() == 1) {  // a point mass
        const double rg = o_.point_radius * L;
        gb.inertia_B = b.mass * rg * rg * Eigen::Matrix3d::Identity();
        gb.mass_source = "model mass; stated isotropic inertia (point mass)";
      } else if (b.entities.size() == 2) {  // a bar: a slender uniform rod
        const V3 axis = r_[b.entities[1]] - r_[e0];
        const double len = axis.norm();
        const V3 e = axis / len;
        const double It = b.mass * len * len / 12;
        gb.com_B = axis / 2;
        gb.inertia_B = It * (Eigen::Matrix3d::Identity() - e * e.transpose()) + o_.bar_axial_inertia_ratio * It * e * e.transpose();
        gb.mass_source = "model mass, slender uniform rod; stated axial inertia";
        d.push_back(axis);
        dd.push_back(rd_[b.entities[1]] - rd_[e0]);
      } else {
        gb.com_B = b.com_W - s_.entities[e0].r_W;  // the file's pose: com and inertia are given there
        gb.inertia_B = b.inertia_W;
        gb.mass_source = "model";
        for (int k = 1; k < 4; ++k) {
          const int e = b.entities[k];
          d.push_back(s_.entities[e].vector ? r_[e] : V3(r_[e] - r_[e0]));
          dd.push_back(s_.entities[e].vector ? rd_[e] : V3(rd_[e] - rd_[e0]));
        }
        // The file's pose and the assembled one differ by a rigid motion of the body (an initial
        // condition moves it): com and inertia follow it. Its rotation from the file's basis.
        Eigen::Matrix3d X0, X;
        for (int k = 1; k < 4; ++k) {
          const int e = b.entities[k];
          const V3 f = s_.entities[e].vector ? V3(s_.entities[e].r_W.normalized()) : V3(s_.entities[e].r_W - s_.entities[e0].r_W);
          X0.col(k - 1) = f;
          X.col(k - 1) = d[k - 1];
        }
        const Eigen::Matrix3d Q = X * X0.inverse();  // a rotation up to the solver's tolerance
        const Eigen::JacobiSVD<Eigen::Matrix3d> svd(Q, Eigen::ComputeFullU | Eigen::ComputeFullV);
        const Eigen::Matrix3d Rf = svd.matrixU() * svd.matrixV().transpose();
        gb.com_B = Rf * gb.com_B;
        gb.inertia_B = Rf * gb.inertia_B * Rf.transpose();
      }
      if (massless) {
        const size_t nd = b.entities.size() >= 4 ? 3 : 1;
        for (size_t k = 1; k <= nd; ++k) {
          const int e = b.entities[k];
          d.push_back(s_.entities[e].vector ? r_[e] : V3(r_[e] - r_[e0]));
          dd.push_back(s_.entities[e].vector ? rd_[e] : V3(rd_[e] - rd_[e0]));
        }
      }
      gb.initial.omega = d.empty() ? V3::Zero() : AngularVelocity(d, dd);
      for (const int e : b.entities)
        if (!s_.entities[e].fixed && owner_[e] < 0) owner_[e] = static_cast<int>(bi);
      g_.bodies.push_back(gb);
    }
    for (size_t e = 0; e < s_.entities.size(); ++e)
      if (!s_.entities[e].fixed && owner_[e] < 0) {
        why = "entity " + s_.entities[e].name + " (" + s_.entities[e].src.Str() + ") moves but is in no body";
        return false;
      }
    SliderBodies();
    return true;
  }

  // Per `along` coordinate, the graph body on its prismatic joint: P's one-point body, or an added
  // "slider of s" at P (stated mass, a point mass's inertia).
  void SliderBodies() {
    slider_of_.assign(s_.coordinates.size(), -1);
    pair_.assign(s_.coordinates.size(), Pair{});
    double total = 0;
    for (const SpatialGraphBody& b : g_.bodies) total += b.mass;
    if (!(total > 0)) total = 1;
    for (size_t ci = 0; ci < s_.coordinates.size(); ++ci) {
      const SpatialCoordinate& c = s_.coordinates[ci];
      if (c.IsAngle()) continue;
      MB_ASSERT(!PairOf(c, pair_[ci]), "an `along` coordinate past Refusal without its pair");
      const Pair& p = pair_[ci];
      if (p.mode == PairMode::kOwnBody && p.line >= 0) TurnWithLine(c, p);
      if (p.mode == PairMode::kOwnBody || p.mode == PairMode::kDirect) {
        slider_of_[ci] = p.body;
        continue;
      }
      SpatialGraphBody gb;
      gb.name = "slider of " + c.name;
      gb.initial.p = r_[c.point];
      gb.initial.v = rd_[c.point];
      if (p.line >= 0) gb.initial.omega = g_.bodies[p.line].initial.omega;  // it turns with the line's body
      gb.mass = (m_.drivers.empty() ? o_.slider_mass_ratio : o_.driven_slider_mass_ratio) * total;
      const double rg = o_.point_radius * g_.length_scale;
      gb.inertia_B = gb.mass * rg * rg * Eigen::Matrix3d::Identity();
      gb.mass_source = "stated: " + Fmt(gb.mass / total) + " × the scene's body mass, a point mass's inertia";
      g_.notes.push_back("coordinate " + c.name + ": " + s_.entities[c.point].name + " is on body " +
                         s_.bodies[p.body].name + ", which does not slide itself: the engines add a slider body (" +
                         Fmt(gb.mass) + " kg) on a prismatic joint along " + s_.entities[c.direction].name +
                         (p.line >= 0 ? " from body " + s_.bodies[p.line].name : std::string()) + ", joined to it by a " +
                         (p.mode == PairMode::kAddedHinge ? "revolute about " + s_.entities[c.direction].name + " at "
                                                          : std::string("ball at ")) +
                         s_.entities[c.point].name);
      slider_of_[ci] = static_cast<int>(g_.bodies.size());
      g_.bodies.push_back(gb);
    }
  }

  // A point mass P on a line of the moving body L slides on its own prismatic joint from L, so it
  // turns with L. Its body needs an inertia (the engines take no zero one) and carries m rg² about
  // each axis; the same is taken out of L's, so the two, which share one angular velocity, have
  // the file's rotational inertia between them and the motion is the file's exactly (a point mass
  // has none of its own). rg is the point-mass radius unless L's smallest principal inertia is
  // below twice m rg²: then what keeps half of it.
  void TurnWithLine(const SpatialCoordinate& c, const Pair& p) {
    SpatialGraphBody& P = g_.bodies[p.body];
    SpatialGraphBody& L = g_.bodies[p.line];
    P.initial.omega = L.initial.omega;
    const double lmin = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(L.inertia_B, Eigen::EigenvaluesOnly).eigenvalues()[0];
    const double rg = o_.point_radius * g_.length_scale;
    const double i = std::min(P.mass * rg * rg, 0.5 * lmin);
    MB_ASSERT(i > 0, "a line's body has a positive-definite inertia and a point mass a positive mass");
    P.inertia_B = i * Eigen::Matrix3d::Identity();
    L.inertia_B -= P.inertia_B;
    P.mass_source = "model mass; an isotropic inertia of " + Fmt(i) + " moved from body " + L.name + "'s (it turns with it)";
    g_.notes.push_back("coordinate " + c.name + ": the point mass " + s_.bodies[p.body].name + " slides on " + L.name +
                       "'s line on its own prismatic joint and turns with it: the engines give it an inertia of " + Fmt(i) +
                       " about each axis and take the same out of " + L.name + "'s (the file's motion exactly)");
  }

  V3 Local(int body, int e) const {
    if (body < 0) return r_[e];
    return s_.entities[e].vector ? r_[e] : V3(r_[e] - g_.bodies[body].initial.p);
  }

  // One candidate joint per pair of bodies (or body and ground) that share entities.
  bool Joints(std::string& why) {
    const int nb = static_cast<int>(s_.bodies.size());  // the model's bodies (added sliders come after them)
    auto lists = [&](int b, int e) {
      const auto& v = s_.bodies[b].entities;
      return std::find(v.begin(), v.end(), e) != v.end();
    };
    for (int a = -1; a < nb; ++a)
      for (int b = std::max(a + 1, 0); b < nb; ++b) {
        if (a == b) continue;
        std::vector<int> points, vectors;
        for (const int e : s_.bodies[b].entities) {
          const bool shared = a < 0 ? s_.entities[e].fixed : lists(a, e) && (s_.entities[e].vector || !s_.entities[e].fixed);
          if (!shared) continue;
          (s_.entities[e].vector ? vectors : points).push_back(e);
        }
        if (points.empty() && vectors.empty()) continue;
        if (HeldByPair(a, b, points, vectors)) continue;  // the `along` pair's prismatic joint holds them
        if (a >= 0 && points.empty() &&
            std::all_of(vectors.begin(), vectors.end(), [&](int e) { return HeldThroughThird(a, b, e); }))
          continue;  // each shared vector is kept equal through a third body's joints (A05's rods and slider on v)
        // Two moving bodies that list the same fixed vector and no common point: each keeps it
        // through its own joints (checked there), no joint between them.
        if (a >= 0 && points.empty() &&
            std::all_of(vectors.begin(), vectors.end(), [&](int e) { return s_.entities[e].fixed; }))
          continue;
        const std::string pa = a < 0 ? std::string("ground") : g_.bodies[a].name;
        const std::string pair = pa + "-" + g_.bodies[b].name;
        auto names = [&](const std::vector<int>& v) {
          std::string s;
          for (const int e : v) s += (s.empty() ? "" : ", ") + s_.entities[e].name;
          return s;
        };
        if (points.size() != 1 || vectors.size() > 1) {
          why = pair + " share " + (points.empty() ? "no point" : "points " + names(points)) +
                (vectors.empty() ? "" : " and vectors " + names(vectors)) +
                ": the spatial graph maps one shared point (spherical) or one point and one vector (revolute) only";
          return false;
        }
        SpatialGraphJoint j;
        j.parent = a;
        j.child = b;
        j.point = points[0];
        j.at_parent_B = Local(a, j.point);
        j.at_child_B = Local(b, j.point);
        if (vectors.empty()) {
          j.type = SpatialJointType::kBall;
          j.name = "spherical " + pair + " at " + s_.entities[j.point].name;
        } else {
          j.type = SpatialJointType::kRevolute;
          j.axis = vectors[0];
          j.axis_B = r_[j.axis].normalized();
          j.name = "revolute " + pair + " at " + s_.entities[j.point].name + " about " + s_.entities[j.axis].name;
        }
        candidates_.push_back(j);
      }
    SliderJoints();
    return true;
  }

  // Per `along` coordinate: its prismatic joint from the line's body (ground for a fixed line),
  // and an added slider's ball or revolute at P.
  void SliderJoints() {
    for (size_t ci = 0; ci < s_.coordinates.size(); ++ci) {
      const SpatialCoordinate& c = s_.coordinates[ci];
      if (c.IsAngle()) continue;
      const int sb = slider_of_[ci];
      const Pair& p = pair_[ci];
      SpatialGraphJoint j;
      j.type = SpatialJointType::kPrismatic;
      j.parent = p.line;
      j.child = sb;
      j.point = c.point;
      j.axis = c.direction;
      j.along = static_cast<int>(ci);
      j.at_parent_B = Local(p.line, c.point);
      j.at_child_B = r_[c.point] - g_.bodies[sb].initial.p;
      j.axis_B = r_[c.direction].normalized();
      j.name = "prismatic " + (p.line < 0 ? std::string("ground") : g_.bodies[p.line].name) + "-" + g_.bodies[sb].name +
               " at " + s_.entities[c.point].name + " along " + s_.entities[c.direction].name;
      candidates_.push_back(j);
      if (g_.bodies[sb].model_body >= 0) continue;
      SpatialGraphJoint b;
      b.type = p.mode == PairMode::kAddedHinge ? SpatialJointType::kRevolute : SpatialJointType::kBall;
      b.parent = p.body;
      b.child = sb;
      b.point = c.point;
      b.at_parent_B = Local(p.body, c.point);
      b.at_child_B = V3::Zero();
      const std::string pair = g_.bodies[p.body].name + "-" + g_.bodies[sb].name + " at " + s_.entities[c.point].name;
      if (b.type == SpatialJointType::kRevolute) {
        b.axis = c.direction;
        b.axis_B = r_[c.direction].normalized();
        b.name = "revolute " + pair + " about " + s_.entities[c.direction].name;
      } else {
        b.name = "spherical " + pair;
      }
      candidates_.push_back(b);
    }
  }

  // Breadth-first from ground; a body joined to nothing that reaches ground gets a free joint.
  bool Tree(std::string& why) {
    const int nb = static_cast<int>(g_.bodies.size());
    std::vector<bool> reached(nb, false), used(candidates_.size(), false);
    std::vector<SpatialGraphJoint> tree;
    std::queue<int> frontier;
    auto grow = [&](int from) {
      frontier.push(from);
      while (!frontier.empty()) {
        const int at = frontier.front();
        frontier.pop();
        for (size_t k = 0; k < candidates_.size(); ++k) {
          if (used[k]) continue;
          SpatialGraphJoint j = candidates_[k];
          int other = -2;
          if (j.parent == at && !reached[j.child]) other = j.child;
          if (j.child == at && j.parent >= 0 && !reached[j.parent]) {
            other = j.parent;
            std::swap(j.parent, j.child);
            std::swap(j.at_parent_B, j.at_child_B);
          }
          if (other < 0) continue;
          used[k] = true;
          reached[other] = true;
          j.in_tree = true;
          tree.push_back(j);
          frontier.push(other);
        }
      }
    };
    grow(-1);
    for (int b = 0; b < nb; ++b) {
      if (reached[b]) continue;
      SpatialGraphJoint f;
      f.type = SpatialJointType::kFree;
      f.parent = -1;
      f.child = b;
      f.in_tree = true;
      f.name = "free " + g_.bodies[b].name;
      tree.push_back(f);
      reached[b] = true;
      grow(b);
    }
    g_.joints = tree;
    for (size_t k = 0; k < candidates_.size(); ++k) {
      if (used[k]) continue;
      if (candidates_[k].type == SpatialJointType::kPrismatic) {
        why = candidates_[k].name + " (coordinate " + s_.coordinates[candidates_[k].along].name +
              ") closes a loop of the spatial graph's tree: a prismatic loop closure is not mapped yet";
        return false;
      }
      g_.joints.push_back(candidates_[k]);
    }
    return true;
  }

  bool Lists(int body, int e) const {
    if (body < 0) return s_.entities[e].fixed;
    if (g_.bodies[body].model_body < 0) return false;  // an added slider body
    const auto& v = s_.bodies[g_.bodies[body].model_body].entities;
    return std::find(v.begin(), v.end(), e) != v.end();
  }

  // Each driver onto the tree revolute whose axis is its angle's axis and whose two bodies carry
  // its `from` and `to` vectors (scale +1 from the parent's to the child's, −1 the other way).
  bool Drivers(std::string& why) {
    for (const Driver& d : m_.drivers) {
      const int ci = m_.q_layout[m_.SlotIndex(d.coordinate)].spatial_coordinate;
      const SpatialCoordinate& c = s_.coordinates[ci];
      SpatialDriverMap dm;
      if (!c.IsAngle()) {  // its prismatic joint (a tree joint), s − s(t0) along a unit axis
        for (size_t k = 0; k < g_.joints.size() && dm.joint < 0; ++k)
          if (g_.joints[k].along == ci) dm.joint = static_cast<int>(k);
        MB_ASSERT(dm.joint >= 0 && g_.joints[dm.joint].in_tree, "an `along` coordinate without its tree prismatic joint");
        // The tree may have turned it (the line's body its child): the joint's travel is then −(s − s(t0)).
        dm.scale = g_.joints[dm.joint].parent == pair_[ci].line ? 1 : -1;
        dm.law = d;
        dm.coordinate = d.coordinate;
        g_.drivers.push_back(dm);
        continue;
      }
      for (size_t k = 0; k < g_.joints.size() && dm.joint < 0; ++k) {
        const SpatialGraphJoint& j = g_.joints[k];
        if (j.type != SpatialJointType::kRevolute || j.axis != c.direction) continue;
        if (!j.in_tree) {
          why = "driver on " + d.coordinate + " (" + d.src.Str() + "): its joint, " + j.name +
                ", is a loop closure of the spatial graph's tree, and only tree joints are driven";
          return false;
        }
        if (Lists(j.parent, c.from) && Lists(j.child, c.to) && !Lists(j.child, c.from))
          dm.scale = 1;
        else if (Lists(j.child, c.from) && Lists(j.parent, c.to) && !Lists(j.parent, c.from))
          dm.scale = -1;
        else
          continue;
        dm.joint = static_cast<int>(k);
      }
      if (dm.joint < 0) {
        why = "driver on " + d.coordinate + " (" + d.src.Str() + "): no revolute joint about " + s_.entities[c.direction].name +
              " joins the bodies of " + s_.entities[c.from].name + " and " + s_.entities[c.to].name +
              " (the spatial graph drives an angle about a revolute joint's own axis only)";
        return false;
      }
      dm.law = d;
      dm.coordinate = d.coordinate;
      g_.drivers.push_back(dm);
    }
    return true;
  }

  // Where a point entity is: its owning body and body coordinates, or ground (-1, world).
  std::pair<int, V3> At(int e) const {
    const int b = s_.entities[e].fixed ? -1 : owner_[e];
    return {b, Local(b, e)};
  }

  bool Loads(std::string& why) {
    const double u = g_.meters_per_unit;
    for (const SpatialLoad& f : s_.forces) {
      const auto [b, at] = At(f.point);
      if (b < 0) continue;  // on a fixed point: no effect on the motion
      if (f.IsVarying()) {
        SpatialGraphLawLoad l;
        l.body = b, l.at_B = at, l.load = f, l.scale = 1 / u, l.frame = f.frame;
        g_.law_loads.push_back(l);
      } else
        g_.forces.push_back({b, at, f.value / u});
    }
    for (const SpatialLoad& t : s_.torques) {
      if (t.body < 0) {
        why = "a torque without a body (" + t.src.Str() + ")";
        return false;
      }
      if (t.HasLaw()) {
        SpatialGraphLawLoad l;
        l.body = t.body, l.torque = true, l.load = t, l.scale = 1 / (u * u);
        g_.law_loads.push_back(l);
      } else
        g_.torques.push_back({t.body, t.value / (u * u)});
    }
    if (!Torsions(why)) return false;
    for (const SpringDamper& s : s_.springs) {
      if (s.HasLaw()) {  // its tension from the observed q, q̇ (SpatialStateLoads)
        SpatialGraphLawLoad l;
        l.spring = s;
        std::tie(l.body, l.at_B) = At(s.points[0]);
        std::tie(l.body_b, l.at_b) = At(s.points[1]);
        l.scale = 1 / u;
        g_.law_loads.push_back(l);
        continue;
      }
      SpatialGraphSpring gs;
      gs.name = "spring " + s_.entities[s.points[0]].name + "-" + s_.entities[s.points[1]].name;
      std::tie(gs.body_a, gs.at_a) = At(s.points[0]);
      std::tie(gs.body_b, gs.at_b) = At(s.points[1]);
      gs.stiffness = s.stiffness;
      gs.damping = s.damping;
      gs.free_length = s.free_length;
      gs.preload = s.preload / u;
      g_.springs.push_back(gs);
    }
    if (!g_.torsions.empty() || !g_.law_loads.empty()) g_.model = std::make_shared<const Model>(m_);
    return true;
  }

  // Each torsion on its angle's three vectors: the body that holds each (its owner; ground when
  // fixed) and its body coordinates.
  bool Torsions(std::string& why) {
    const double u = g_.meters_per_unit;
    for (const TorsionSpring& ts : m_.torsions) {
      const int c = ts.slot < 0 ? -1 : m_.q_layout[ts.slot].spatial_coordinate;
      if (c < 0 || !s_.coordinates[c].IsAngle()) {
        why = "torsional spring–damper on " + ts.coordinate + " (" + ts.src.Str() + "): not an angle coordinate";
        return false;
      }
      const SpatialCoordinate& sc = s_.coordinates[c];
      SpatialGraphTorsion gt;
      gt.coordinate = ts.coordinate;
      gt.slot = ts.slot;
      gt.stiffness = ts.stiffness / (u * u);
      gt.damping = ts.damping / (u * u);
      gt.free_angle = ts.free_angle;
      gt.preload = ts.preload / (u * u);
      const int e[3] = {sc.from, sc.to, sc.direction};
      for (int k = 0; k < 3; ++k) {
        gt.body[k] = s_.entities[e[k]].fixed ? -1 : owner_[e[k]];
        gt.vec_B[k] = r_[e[k]].normalized();  // a vector's body coordinates are its t0 value
      }
      g_.torsions.push_back(gt);
    }
    return true;
  }

  const Model& m_;
  const SpatialModel& s_;
  SpatialGraphOptions o_;
  SpatialGraph g_;
  std::optional<numeric::NaturalModel> nm_;
  std::optional<numeric::NaturalData> data_;
  std::vector<V3> r_, rd_;  // per file entity: assembled value and rate at t0
  std::vector<int> owner_;  // per entity: the first body that lists it (moving entities)
  std::vector<SpatialGraphJoint> candidates_;
  std::vector<int> slider_of_;  // per coordinate: an `along` one's graph body on its prismatic joint
  std::vector<Pair> pair_;      // per coordinate: an `along` one's pair (line's body, P's body, device)
};

}  // namespace

int SpatialGraph::TreeJointOf(int body) const {
  for (size_t k = 0; k < joints.size(); ++k)
    if (joints[k].in_tree && joints[k].child == body) return static_cast<int>(k);
  return -1;
}

double PrismaticTravel(const SpatialGraphJoint& j, const SpatialState& parent, const SpatialState& child) {
  return (child.PointPos(j.at_child_B) - parent.PointPos(j.at_parent_B)).dot(parent.R * j.axis_B);
}

double PrismaticRateAtT0(const SpatialGraph& g, const SpatialGraphJoint& j) {
  const SpatialState parent = j.parent < 0 ? SpatialState{} : g.bodies[j.parent].initial;
  const SpatialState& child = g.bodies[j.child].initial;
  return (child.PointVel(j.at_child_B) - parent.PointVel(j.at_parent_B)).dot(j.axis_B.normalized());
}

int SpatialGraph::Closures() const {
  return static_cast<int>(std::count_if(joints.begin(), joints.end(), [](const SpatialGraphJoint& j) { return !j.in_tree; }));
}

SpatialGraphOrReason BuildSpatialGraph(const Model& model, const SpatialGraphOptions& options) {
  MB_ASSERT(model.kind == ScenarioKind::kSpatial, "BuildSpatialGraph on a planar scene");
  return SpatialBuilderOfGraph(model, options).Build();
}

// ---------------------------------------------------------------------------------------------
// SpatialObserver

SpatialObserver::SpatialObserver(const Model& model, const SpatialGraph& graph) : model_(&model), graph_(&graph) {
  const SpatialModel& s = model.spatial;
  body_.assign(s.entities.size(), -1);
  local_.resize(s.entities.size());
  for (size_t e = 0; e < s.entities.size(); ++e) {
    local_[e] = s.entities[e].vector ? V3(s.entities[e].r_W.normalized()) : s.entities[e].r_W;
    if (s.entities[e].fixed) continue;
    for (size_t b = 0; b < graph.bodies.size() && body_[e] < 0; ++b) {
      if (graph.bodies[b].model_body < 0) continue;  // an added slider body carries no entity
      const auto& v = s.bodies[graph.bodies[b].model_body].entities;
      if (std::find(v.begin(), v.end(), static_cast<int>(e)) == v.end()) continue;
      body_[e] = static_cast<int>(b);
    }
    MB_ASSERT(body_[e] >= 0, "a moving entity in no graph body");
  }
  // Body coordinates from the assembled t0 (the graph's initial q): frames are the world's at t0.
  const Eigen::VectorXd& q = graph.initial.q;
  for (size_t i = 0; i < model.q_layout.size(); ++i) {
    const Model::Slot& sl = model.q_layout[i];
    if (sl.entity < 0) continue;
    local_[sl.entity][sl.axis] = q[static_cast<long>(i)];
  }
  for (size_t e = 0; e < s.entities.size(); ++e)
    if (body_[e] >= 0 && !s.entities[e].vector) local_[e] -= graph.bodies[body_[e]].initial.p;
}

SpatialObserver::Kin SpatialObserver::EntityKin(int e, const std::vector<SpatialState>& st) const {
  const int b = body_[e];
  if (b < 0) return {local_[e], V3::Zero(), V3::Zero()};
  const SpatialState& s = st[b];
  const V3 r = s.R * local_[e];
  const V3 w_r = s.omega.cross(r);
  const V3 a_rot = s.alpha.cross(r) + s.omega.cross(w_r);
  if (model_->spatial.entities[e].vector) return {r, w_r, a_rot};
  return {s.p + r, s.v + w_r, s.a + a_rot};
}

Sample SpatialObserver::Observe(double t, const std::vector<SpatialState>& st, bool with_acc) {
  const Model& m = *model_;
  const long n = static_cast<long>(m.q_layout.size());
  Sample out;
  out.t = t;
  out.q.resize(n);
  out.qd.resize(n);
  if (with_acc) out.qdd.resize(n);
  for (long i = 0; i < n; ++i) {
    const Model::Slot& sl = m.q_layout[i];
    if (sl.entity >= 0) {
      const Kin k = EntityKin(sl.entity, st);
      out.q[i] = k.p[sl.axis];
      out.qd[i] = k.v[sl.axis];
      if (with_acc) out.qdd[i] = k.a[sl.axis];
      continue;
    }
    MB_ASSERT(sl.spatial_coordinate >= 0, "a spatial slot that is neither an entity nor a coordinate");
    const SpatialCoordinate& c = m.spatial.coordinates[sl.spatial_coordinate];
    if (!c.IsAngle()) {  // s = (P − A)·d and its derivatives
      const Kin P = EntityKin(c.point, st), A = EntityKin(c.from, st), d = EntityKin(c.direction, st);
      const V3 r = P.p - A.p, rd = P.v - A.v, rdd = P.a - A.a;
      out.q[i] = r.dot(d.p);
      out.qd[i] = rd.dot(d.p) + r.dot(d.v);
      if (with_acc) out.qdd[i] = rdd.dot(d.p) + 2 * rd.dot(d.v) + r.dot(d.a);
      continue;
    }
    // θ = atan2(y, x), y = (u × w)·a, x = u·w, and its first two derivatives.
    const Kin u = EntityKin(c.from, st), w = EntityKin(c.to, st), a = EntityKin(c.direction, st);
    const V3 uw = u.p.cross(w.p), uw_d = u.v.cross(w.p) + u.p.cross(w.v);
    const V3 uw_dd = u.a.cross(w.p) + 2 * u.v.cross(w.v) + u.p.cross(w.a);
    const double y = uw.dot(a.p), x = u.p.dot(w.p);
    const double yd = uw_d.dot(a.p) + uw.dot(a.v), xd = u.v.dot(w.p) + u.p.dot(w.v);
    const double ydd = uw_dd.dot(a.p) + 2 * uw_d.dot(a.v) + uw.dot(a.a);
    const double xdd = u.a.dot(w.p) + 2 * u.v.dot(w.v) + u.p.dot(w.a);
    const double r2 = x * x + y * y;
    const double ref = last_q_ ? (*last_q_)[i] : graph_->initial.q[i];
    const double th = std::atan2(y, x);
    out.q[i] = th + 2 * std::numbers::pi * std::round((ref - th) / (2 * std::numbers::pi));
    const double num = x * yd - y * xd;
    out.qd[i] = num / r2;
    if (with_acc) out.qdd[i] = (x * ydd - y * xdd) / r2 - 2 * num * (x * xd + y * yd) / (r2 * r2);
  }
  last_q_ = out.q;
  return out;
}

Quantities SpatialObserver::InstantQuantities(const Sample& s, const std::vector<SpatialState>& st, bool with_acc) const {
  const Model& m = *model_;
  Quantities out;
  for (size_t i = 0; i < m.q_layout.size(); ++i) {
    const std::string& name = m.q_layout[i].name;
    out["q." + name] = s.q[static_cast<long>(i)];
    out["qd." + name] = s.qd[static_cast<long>(i)];
    if (with_acc && s.qdd.size() == s.q.size()) out["qdd." + name] = s.qdd[static_cast<long>(i)];
  }
  const char* ax[3] = {".x", ".y", ".z"};
  for (size_t e = 0; e < m.spatial.entities.size(); ++e) {
    const Kin k = EntityKin(static_cast<int>(e), st);
    const std::string& name = m.spatial.entities[e].name;
    for (int c = 0; c < 3; ++c) {
      out["p." + name + ax[c]] = k.p[c];
      out["v." + name + ax[c]] = k.v[c];
      if (with_acc) out["a." + name + ax[c]] = k.a[c];
    }
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// SpatialStateLoads

SpatialStateLoads::SpatialStateLoads(const SpatialGraph& g) : g_(&g) {
  if (empty()) return;
  MB_ASSERT(g.model != nullptr, "a spatial graph with torsions or load laws carries its model");
  obs_.emplace(*g.model, g);
  x_.assign(1 + 2 * g.model->q_layout.size(), 0.0);
}

void SpatialStateLoads::Evaluate(double t, const std::vector<SpatialState>& st, std::vector<SpatialWrench>& out) {
  const SpatialGraph& g = *g_;
  out.assign(g.bodies.size(), SpatialWrench{});
  if (empty()) return;
  const Sample s = obs_->Observe(t, st, false);
  SetLoadVariables(t, s, x_);
  auto com = [&](int b) { return st[b].PointPos(g.bodies[b].com_B); };
  // A world force f at a body point (body coordinates at_B) as a wrench at the body's centre of mass.
  auto apply = [&](int b, const V3& at_B, const V3& f) {
    if (b < 0) return;  // a fixed end
    out[b].force += f;
    out[b].torque += (st[b].PointPos(at_B) - com(b)).cross(f);
  };
  for (const SpatialGraphLawLoad& l : g.law_loads) {
    if (l.spring) {  // the tension k (L − L0) + c L̇ + F0/u, pulling the ends together when positive
      const SpringDamper& sp = *l.spring;
      double p[4] = {sp.stiffness, sp.damping, sp.free_length, sp.preload};
      for (int k = 0; k < 4; ++k)
        if (sp.law[k]) p[k] = sp.law[k]->Eval(x_.data());
      const V3 ra = l.body < 0 ? l.at_B : st[l.body].PointPos(l.at_B), rb = l.body_b < 0 ? l.at_b : st[l.body_b].PointPos(l.at_b);
      const V3 va = l.body < 0 ? V3::Zero() : st[l.body].PointVel(l.at_B);
      const V3 vb = l.body_b < 0 ? V3::Zero() : st[l.body_b].PointVel(l.at_b);
      const V3 d = rb - ra;
      const double L = d.norm();
      if (!(L > 0)) continue;  // coincident ends: no direction
      const V3 e = d / L;
      const double F = p[0] * (L - p[2]) + p[1] * e.dot(vb - va) + p[3] * l.scale;
      apply(l.body, l.at_B, F * e);
      apply(l.body_b, l.at_b, -F * e);
      continue;
    }
    V3 v = l.load.value;
    for (int c = 0; c < 3; ++c)
      if (l.load.law[c]) v[c] = l.load.law[c]->Eval(x_.data());
    v *= l.scale;
    if (l.frame >= 0) v = st[l.frame].R * v;  // a follower force: world axes at t0, turned with its body
    SpatialWrench& w = out[l.body];
    if (l.torque) {
      w.torque += v;
    } else {
      w.force += v;
      w.torque += (st[l.body].PointPos(l.at_B) - com(l.body)).cross(v);
    }
  }
  // θ = atan2(y, x), y = (u × w)·a, x = u·w: ∂θ/∂u = (x (w × a) − y w)/r², ∂θ/∂w = (x (a × u) − y u)/r²,
  // ∂θ/∂a = x (u × w)/r². A body turned by δφ moves its vector e by δφ × e, so by virtual work the
  // torque on it is T e × ∂θ/∂e (the three sum to zero: θ does not change when all turn together).
  for (const SpatialGraphTorsion& ts : g.torsions) {
    const double T = ts.Torque(s.q[ts.slot], s.qd[ts.slot]);
    V3 e[3];
    for (int k = 0; k < 3; ++k) e[k] = ts.body[k] < 0 ? ts.vec_B[k] : V3(st[ts.body[k]].R * ts.vec_B[k]);
    const V3 &u = e[0], &w = e[1], &a = e[2];
    const double y = u.cross(w).dot(a), x = u.dot(w), r2 = x * x + y * y;
    if (!(r2 > 0)) continue;  // u ∥ a or w ∥ a: no angle (numeric's rows have none either)
    const V3 grad[3] = {(x * w.cross(a) - y * w) / r2, (x * a.cross(u) - y * u) / r2, x * u.cross(w) / r2};
    for (int k = 0; k < 3; ++k)
      if (ts.body[k] >= 0) out[ts.body[k]].torque += T * e[k].cross(grad[k]);
  }
}

std::string Describe(const SpatialGraph& g) {
  std::ostringstream os;
  int ball = 0, rev = 0, fr = 0, pri = 0;
  for (const SpatialGraphJoint& j : g.joints)
    (j.type == SpatialJointType::kBall       ? ball
     : j.type == SpatialJointType::kRevolute ? rev
     : j.type == SpatialJointType::kPrismatic ? pri
                                              : fr)++;
  os << g.bodies.size() << " bodies, " << g.joints.size() << " joints (" << g.joints.size() - g.Closures()
     << " tree, " << g.Closures() << " closures; " << ball << " spherical, " << rev << " revolute, " << fr << " free"
     << (pri > 0 ? ", " + std::to_string(pri) + " prismatic" : std::string()) << ")";
  return os.str();
}

}  // namespace mechbench::engines
