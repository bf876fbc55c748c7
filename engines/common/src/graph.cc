#include "mechbench/format.h"
#include "mechbench/engines/graph.h"

#include "mechbench/errors.h"
#include "mechbench/numeric/constraints.h"
#include "mechbench/numeric/natural_data.h"
#include "mechbench/numeric/natural_model.h"
#include "mechbench/numeric/solver.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <numeric>
#include <queue>
#include <sstream>

namespace mechbench::engines {
namespace {

constexpr double kPi = std::numbers::pi;

double Cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }
Eigen::Vector2d Perp(const Eigen::Vector2d& a) { return {-a.y(), a.x()}; }
Eigen::Matrix2d Rot(double th) {
  Eigen::Matrix2d r;
  r << std::cos(th), -std::sin(th), std::sin(th), std::cos(th);
  return r;
}
double WrapNear(double x, double ref) { return x + 2 * kPi * std::round((ref - x) / (2 * kPi)); }

// Angle of vector x and its first two time derivatives, from x, ẋ, ẍ.
struct AngleKin { double th, w, a; };
AngleKin VectorAngle(const Eigen::Vector2d& x, const Eigen::Vector2d& xd, const Eigen::Vector2d& xdd) {
  const double n2 = x.squaredNorm();
  const double w = Cross(x, xd) / n2;
  const double a = Cross(x, xdd) / n2 - 2 * Cross(x, xd) * x.dot(xd) / (n2 * n2);
  return {std::atan2(x.y(), x.x()), w, a};
}

// A model body that contains both points (or -1 = ground when both are fixed; -2 = none).
int BodyWithBoth(const Model& m, int a, int b) {
  for (size_t i = 0; i < m.bodies.size(); ++i) {
    const auto& ps = m.bodies[i].points;
    if (std::find(ps.begin(), ps.end(), a) != ps.end() && std::find(ps.begin(), ps.end(), b) != ps.end())
      return static_cast<int>(i);
  }
  if (m.points[a].fixed && m.points[b].fixed) return -1;
  return -2;
}

// θ = offset + σ·geo where geo is the geometric angle (vector from reference). The form decides
// which branches Φ allows: cross and cos+sin pin θ ≡ geo; cos and dot allow θ ≡ ±geo; sin allows
// θ ≡ geo or π − geo. The branch is the one the assembled θ0 is on.
struct Branch { double sigma = 1, offset = 0; };
Branch AngleBranch(const Coordinate& c, double th0, double geo0) {
  auto dist = [](double x, double target) { return std::fabs(std::remainder(x - target, 2 * kPi)); };
  const double d_plus = dist(th0 - geo0, 0);
  double d_minus = 1e300;
  if (c.type == CoordinateType::kAngle) {
    if (c.form == AngleForm::kCos || c.form == AngleForm::kDot) d_minus = dist(th0 + geo0, 0);
    if (c.form == AngleForm::kSin) d_minus = dist(th0 + geo0, kPi);
  }
  if (d_plus <= d_minus) return {1.0, th0 - geo0};
  return {-1.0, th0 + geo0};
}

}  // namespace

Eigen::Vector2d PlanarState::PointPos(const Eigen::Vector2d& p_B) const { return p + Rot(angle) * p_B; }
Eigen::Vector2d PlanarState::PointVel(const Eigen::Vector2d& p_B) const { return v + omega * Perp(Rot(angle) * p_B); }
Eigen::Vector2d PlanarState::PointAcc(const Eigen::Vector2d& p_B) const {
  const Eigen::Vector2d r = Rot(angle) * p_B;
  return a + alpha * Perp(r) - omega * omega * r;
}

Eigen::Vector2d SpringForceOnB(const GraphSpring& s, const Eigen::Vector2d& p_a, const Eigen::Vector2d& v_a,
                               const Eigen::Vector2d& p_b, const Eigen::Vector2d& v_b) {
  const Eigen::Vector2d d = p_b - p_a;
  const double L = d.norm();
  if (!(L > 0)) return {0, 0};
  const Eigen::Vector2d e = d / L;
  return -s.Tension(L, e.dot(v_b - v_a)) * e;
}

double GraphSpring::Tension(double L, double L_dot, const double* x) const {
  const double k = law[0] ? law[0]->Eval(x) : stiffness, c = law[1] ? law[1]->Eval(x) : damping;
  const double L0 = law[2] ? law[2]->Eval(x) : free_length, F0 = law[3] ? preload_scale * law[3]->Eval(x) : preload;
  return k * (L - L0) + c * L_dot + F0;
}

Eigen::Vector2d SpringForceOnB(const GraphSpring& s, const Eigen::Vector2d& p_a, const Eigen::Vector2d& v_a,
                               const Eigen::Vector2d& p_b, const Eigen::Vector2d& v_b, const double* x) {
  const Eigen::Vector2d d = p_b - p_a;
  const double L = d.norm();
  if (!(L > 0)) return {0, 0};
  const Eigen::Vector2d e = d / L;
  return -s.Tension(L, e.dot(v_b - v_a), x) * e;
}

Eigen::Vector2d GraphForce::Eval(const double* x, double angle) const {
  if (!Varies()) return f_W;
  Eigen::Vector2d F = components;
  for (int k = 0; k < 2; ++k)
    if (law[k]) F[k] = scale * law[k]->Eval(x);
  return in_body_frame ? Rotate(angle, F) : F;
}

bool HasVaryingForces(const Graph& g) {
  for (const GraphForce& f : g.forces)
    if (f.Varies()) return true;
  return false;
}

size_t StateForceLaws(const Graph& g) {
  size_t n = 0;
  for (const GraphForce& f : g.state_forces) n += f.spring < 0;
  return n;
}

int Graph::TreeJointOf(int body) const {
  for (size_t j = 0; j < joints.size(); ++j)
    if (joints[j].in_tree && joints[j].child == body) return static_cast<int>(j);
  return -1;
}
int Graph::CountTree() const {
  return static_cast<int>(std::count_if(joints.begin(), joints.end(), [](const GraphJoint& j) { return j.in_tree; }));
}

std::optional<std::string> GraphApplicability(const Model& m) {
  if (m.kind == ScenarioKind::kSpatial) return "spatial scenes: the planar graph does not take them (BuildSpatialGraph, spatial_graph.h, does)";
  if (m.kind == ScenarioKind::kLinkage) {
    for (const Body& b : m.bodies)
      if (b.points.empty()) return "body " + b.name + " has no points: no frame for a rigid body";
    for (const Coordinate& c : m.coordinates)
      if (c.type == CoordinateType::kRotation)
        return "coordinate " + c.name + ": a rotation coordinate in a linkage scene has no joint in the graph";
  }
  return std::nullopt;
}

namespace {

// Builds the angle maps θ = offset + σ·geo for every relative-angle and rotation slot.
struct SlotAngle {
  bool is_angle = false;
  double sigma = 1, offset = 0;
};

class Builder {
 public:
  Builder(const Model& m, const GraphOptions& o) : m_(m), o_(o) {}

  GraphOrReason Build() {
    GraphOrReason out;
    if (auto why = GraphApplicability(m_)) {
      out.reason = *why;
      return out;
    }
    if (!Assemble(out.reason)) return out;
    g_.driven = !m_.drivers.empty();
    g_.initial = Sample{m_.analysis.t0, data_->q, data_->qd, data_->qdd, 0.0};
    g_.t0 = m_.analysis.t0;
    g_.gravity = m_.gravity;
    g_.length_scale = nm_->length_scale;
    g_.meters_per_unit = nm_->meters_per_unit;
    if (m_.analysis.HasMotion())
      for (int k = 0; k < m_.analysis.samples; ++k) g_.sample_times.push_back(m_.analysis.TimeAt(k));
    else
      g_.sample_times.push_back(m_.analysis.t0);
    if (m_.frame) g_.platform = Platform(*m_.frame);
    std::string why;
    const bool ok = m_.kind == ScenarioKind::kGearTrain ? BuildGears(why) : BuildLinkage(why);
    if (!ok) {
      out.reason = why;
      return out;
    }
    if (!SpanningTree(why) || !MapDrivers(why) || !MapCouplings(why) || !MapForces(why) || !CheckMassProperties(why)) {
      out.reason = why;
      return out;
    }
    if (m_.kind == ScenarioKind::kGearTrain && !m_.gear_axes.empty()) FileGearLayout();
    g_.settings["graph.link_default_mass"] = Fmt(o_.link_mass_per_length) + " kg/m uniform bar between a massless link's first two points";
    g_.settings["graph.block_mass_ratio"] = Fmt(o_.block_mass_ratio) + " (slider block and actuator halves ÷ lightest link)";
    g_.settings["graph.block_radius"] = Fmt(o_.block_radius) + " × length scale (their radius of gyration)";
    out.graph = std::move(g_);
    return out;
  }

  const numeric::NaturalModel& nm() const { return *nm_; }

 private:
  // The turning frame's platform: the plane's frame at t0 on the file's axis (GraphPlatform).
  GraphPlatform Platform(const FrameRotation& f) const {
    GraphPlatform p;
    const Embedding& e = m_.embedding;
    p.axis_point = f.axis_point;
    p.axis = f.axis.normalized();
    p.omega = f.omega;
    p.origin = e.origin;
    p.R0.col(0) = e.u;
    p.R0.col(1) = e.v;
    p.R0.col(2) = e.Normal();
    p.gravity_W = e.u * m_.gravity.x() + e.v * m_.gravity.y();
    return p;
  }
  // t0 with the numeric solver: positions, velocities, accelerations of every point.
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
      if (m.drivers.empty()) {  // a free scene without initial conditions: at rest
        data_->qd.setZero(nm_->n);
        data_->qdd.setZero(nm_->n);
      }
      if (m_.drivers.empty()) data_->qdd.setZero(nm_->n);  // a free scene's q̈ needs dynamics
      numeric::UpdatePoints(*nm_, *data_, data_->q);
      numeric::UpdatePointVelocities(*nm_, *data_, data_->qd);
      numeric::UpdatePointAccelerations(*nm_, *data_, data_->qdd);
    } catch (const ScenarioError&) {
      throw;  // an impossible scene is not an engine's limitation
    } catch (const std::exception& e) {
      why = std::string("cannot assemble t0 with the numeric solver: ") + e.what();
      return false;
    }
    return true;
  }

  // The file's mass properties as an engine needs them: every link a rigid body with mass > 0
  // (ODE aborts on a massless body, Bullet makes it static) and inertia > 0 about its centre of
  // mass (ODE's mass check and its quaternion update fail on a zero inertia). A link whose mass is
  // all at one point (a point mass on a massless rod, or the file's inertia 0) gets a substitute
  // inertia (SubstituteInertia), stated in a note with its effect on the motion.
  bool CheckMassProperties(std::string& why) {
    for (GraphBody& b : g_.bodies) {
      if (b.kind != BodyKind::kLink || b.mass_source != "model") continue;
      if (b.mass <= 0)
        why = "body " + b.name +
              (m_.bodies[static_cast<size_t>(b.model_body)].HasMass() ? " has mass 0"
                                                                      : " has no mass: (massless in a free scene, whose motion is its masses')") +
              ": the engines model every link as a rigid body with mass (ODE aborts "
              "on a massless body, Bullet makes it static); give it its mass, com and inertia";
      else if (b.inertia_com <= 0 && !SubstituteInertia(b))
        why = NoInertiaReason(b);
      if (!why.empty()) return false;
    }
    g_.settings["graph.point_inertia_ratio"] =
        Fmt(o_.point_inertia_ratio) + " (a link with inertia 0 about its centre of mass ÷ its inertia about its farthest point)";
    return true;
  }

  // The point bodies (CarryPointBodies) folded into link b, as "point body bob (3 kg at 1)".
  std::vector<std::string> LumpedInto(const GraphBody& b) const {
    std::vector<std::string> lumped;
    for (size_t i = 0; i < m_.bodies.size(); ++i) {
      const Body& pb = m_.bodies[i];
      if (pb.IsPointBody() && pb.guide < 0 && pb.HasMass() && pb.mass > 0 && i < body_of_model_.size() &&
          body_of_model_[i] >= 0 && &g_.bodies[body_of_model_[i]] == &b)
        lumped.push_back("point body " + pb.name + " (" + Fmt(pb.mass, 3) + " kg at " + m_.points[pb.points[0]].name + ")");
    }
    return lumped;
  }
  static std::string JoinNames(const std::vector<std::string>& names) {
    std::string s;
    for (size_t k = 0; k < names.size(); ++k) s += (k == 0 ? "" : (k + 1 == names.size() ? " and " : ", ")) + names[k];
    return s;
  }

  // A link with mass and no inertia about its centre of mass (all its mass on one point: a point
  // mass on a massless rod, A01's lumped bob) gets ε = point_inertia_ratio × I_P, I_P = m d² its
  // inertia about its point P farthest from the centre of mass, the engines' rigid bodies need
  // one. Turning about P (a pendulum), the link's period grows by the relative ε / (2 I_P): over
  // the horizon H its motion lags by at most H ε / (2 I_P), at most v H ε / (2 I_P) in position
  // with v = √(v0² + 4 |g| d) the fastest its centre of mass can get falling about P (energy).
  // The note gives those figures for the scene. False when no point is off the centre of mass.
  bool SubstituteInertia(GraphBody& b) {
    const Body& link = m_.bodies[static_cast<size_t>(b.model_body)];
    double d = 0;
    int far = -1;
    for (size_t k = 0; k < link.p_B.size(); ++k)
      if ((link.p_B[k] - b.com_B).norm() > d) d = (link.p_B[k] - b.com_B).norm(), far = link.points[k];
    if (!(d > 0) || !(o_.point_inertia_ratio > 0)) return false;
    const double I_P = b.mass * d * d, eps = o_.point_inertia_ratio * I_P;
    const double H = m_.analysis.HasMotion() ? m_.analysis.t1 - m_.analysis.t0 : 0;
    const double v0 = b.initial.PointVel(b.com_B).norm(), v = std::sqrt(v0 * v0 + 4 * m_.gravity.norm() * d);
    const double lag = H * eps / (2 * I_P);
    b.inertia_com = eps;
    b.mass_source = "model, inertia " + Fmt(eps, 3) + " (" + Fmt(o_.point_inertia_ratio) + " × its inertia about " +
                    m_.points[static_cast<size_t>(far)].name + ") for 0";
    const std::vector<std::string> lumped = LumpedInto(b);
    const std::string u = m_.length_unit;
    std::string what = lumped.empty() ? "inertia 0 about its centre of mass in the file"
                                      : (link.HasMass() && link.mass > 0 ? "" : "massless, ") + JoinNames(lumped) +
                                            " folded into it: no inertia about its centre of mass";
    std::string note = "link " + b.name + " (" + what + ") gets a substitute inertia " + Fmt(eps, 3) + " kg·" + u +
                       "² about its centre of mass, " + Fmt(o_.point_inertia_ratio) + " × its inertia about " +
                       m_.points[static_cast<size_t>(far)].name + " (" + Fmt(I_P, 3) + " kg·" + u +
                       "²), because the engines' rigid bodies need inertia > 0. Turning about " +
                       m_.points[static_cast<size_t>(far)].name + ", it swings slower by the relative " + Fmt(eps / (2 * I_P), 3);
    if (H > 0)
      note += ": over the " + Fmt(H, 4) + " s analysed a lag of at most " + Fmt(lag, 3) + " s, at most " + Fmt(v * lag, 3) + " " + u +
              " at its centre of mass (at ≤ " + Fmt(v, 3) + " " + u + "/s, the fastest its fall about " +
              m_.points[static_cast<size_t>(far)].name + " allows)";
    // The figures are the substitute's effect on the motion, not a solver's accuracy: an engine
    // whose joints do not hold on a body this light in rotation says so in its own note.
    note += "; that is the substitute's own effect, for a solver that holds the joints (each engine's error comes on top)";
    g_.notes.push_back(note);
    return true;
  }

  // Why a link with mass and no inertia about its centre of mass is refused (no substitute: none of
  // its points is off its centre of mass, or the substitute is switched off). With point masses
  // folded into it (CarryPointBodies), the lumped body is what has none: say so, naming them.
  std::string NoInertiaReason(const GraphBody& b) const {
    const std::vector<std::string> lumped = LumpedInto(b);
    const std::string need = "the engines' rigid bodies need inertia > 0 (ODE aborts on a zero inertia)";
    if (lumped.empty())
      return "body " + b.name + " has mass but no inertia about its centre of mass: " + need + "; give its inertia";
    const std::string names = JoinNames(lumped);
    const Body& link = m_.bodies[static_cast<size_t>(b.model_body)];
    const bool own = link.HasMass() && link.mass > 0;
    return "link " + b.name + (own ? " with " : " (massless) with ") + names +
           " folded into it is one rigid body with zero rotational inertia about its centre of mass (" +
           (own ? "all its mass on one point" : "a point mass") + "): " + need +
           "; the natural-coordinate formulations take it as written. If the bob or the link has a size, give the link "
           "that inertia (inertia: m k², k its radius of gyration, with its mass and com)";
  }

  // A point body with mass whose point slides on a guide: that slider's block (model.h: the
  // block's frame is the point body's), or -1 when the scene leaves the block massless.
  int PointBodyOfJoint(int joint) const {
    for (const Body& b : m_.bodies)
      if (b.IsPointBody() && b.guide == joint && b.HasMass() && b.mass > 0) return static_cast<int>(&b - m_.bodies.data());
    return -1;
  }

  // The block takes the file's mass, centre of mass and inertia. An inertia of 0 (a block given
  // only its mass) becomes m·(block_radius · length scale)², because the engines' rigid bodies
  // need one: on a fixed guide the block does not turn and it changes nothing; on a moving guide
  // it adds that much to what turns with the guide, and the note says so.
  void BlockFromPointBody(const Body& b, GraphBody& gb) {
    gb.mass = b.mass;
    gb.com_B = b.com_B;
    gb.inertia_com = b.inertia_com;
    gb.mass_source = "model";
    if (b.inertia_com > 0) return;
    const double rg = o_.block_radius * g_.length_scale;
    gb.inertia_com = b.mass * rg * rg;
    gb.mass_source = "model, inertia " + Fmt(gb.inertia_com, 3) + " (radius of gyration " + Fmt(o_.block_radius) +
                     " × length scale) for the file's 0";
    g_.notes.push_back("body " + b.name + ": a block with inertia 0 in the file gets " + Fmt(gb.inertia_com, 3) +
                       " kg·length² (the engines' rigid bodies need inertia > 0)" +
                       (m_.joints[b.guide].type == JointType::kPointOnBody
                            ? std::string(": it turns with its guide, so the engines carry that much more inertia")
                            : std::string(": its guide is fixed, so it does not turn and this changes nothing")));
  }

  // Point bodies without a guide (point masses) ride on the first link that holds their point:
  // a point mass pinned at a point of a link moves with that point and has no inertia of its own,
  // so adding its mass to that link's mass, centre of mass and inertia (parallel axes) is exact,
  // whichever link at the pin takes it. A point body on a guide becomes its slider's block.
  bool CarryPointBodies(std::string& why) {
    for (size_t i = 0; i < m_.bodies.size(); ++i) {
      const Body& pb = m_.bodies[i];
      if (!pb.IsPointBody() || pb.guide >= 0) continue;
      const int P = pb.points[0];
      int link = -1;
      int k = -1;
      for (size_t l = 0; l < m_.bodies.size() && link < 0; ++l) {
        if (m_.bodies[l].IsPointBody()) continue;
        const auto& pts = m_.bodies[l].points;
        const auto it = std::find(pts.begin(), pts.end(), P);
        if (it != pts.end()) link = static_cast<int>(l), k = static_cast<int>(it - pts.begin());
      }
      if (link < 0) {
        why = "body " + pb.name + " is a point body at " + m_.points[P].name +
              " that no link holds and no slider guides: the engines have no rigid body to carry it";
        return false;
      }
      body_of_model_[i] = body_of_model_[link];
      if (!pb.HasMass() || pb.mass == 0) continue;
      GraphBody& gl = g_.bodies[body_of_model_[link]];
      const Eigen::Vector2d p = m_.bodies[link].p_B[k];
      const double M = gl.mass + pb.mass;
      const Eigen::Vector2d c = (gl.mass * gl.com_B + pb.mass * p) / M;
      gl.inertia_com += gl.mass * (gl.com_B - c).squaredNorm() + pb.mass * (p - c).squaredNorm();
      gl.com_B = c;
      gl.mass = M;
      g_.notes.push_back("point body " + pb.name + " (" + Fmt(pb.mass, 3) + " kg at " + m_.points[P].name +
                         ") rides on link " + gl.name + ": its mass is added to the link's mass, centre of mass and "
                         "inertia, which is exact for a point mass at a pin");
    }
    return true;
  }

  double LightestLinkMass() const {
    double lo = 0;
    for (const GraphBody& b : g_.bodies)
      if (b.kind == BodyKind::kLink && (lo == 0 || b.mass < lo)) lo = b.mass;
    return lo > 0 ? lo : 1.0;
  }

  int AddBody(GraphBody b) {
    g_.bodies.push_back(std::move(b));
    return static_cast<int>(g_.bodies.size()) - 1;
  }

  PlanarState StateOfFrame(const Eigen::Vector2d& p, const Eigen::Vector2d& v, const Eigen::Vector2d& a,
                           const AngleKin& th) const {
    PlanarState s;
    s.p = p;
    s.v = v;
    s.a = a;
    s.angle = th.th;
    s.omega = th.w;
    s.alpha = th.a;
    return s;
  }

  bool BuildLinkage(std::string& why) {
    const auto& r = data_->r;
    const auto& rd = data_->rd;
    const auto& rdd = data_->rdd;
    // Links.
    for (size_t i = 0; i < m_.bodies.size(); ++i) {
      const Body& b = m_.bodies[i];
      GraphBody gb;
      gb.name = b.name;
      gb.kind = BodyKind::kLink;
      gb.model_body = static_cast<int>(i);
      if (b.IsPointBody()) {  // carried by its slider's block or by a link: CarryPointBodies
        body_of_model_.push_back(-1);
        continue;
      }
      const int p0 = b.points[0], p1 = b.points[1];
      const AngleKin th = VectorAngle(r[p1] - r[p0], rd[p1] - rd[p0], rdd[p1] - rdd[p0]);
      gb.initial = StateOfFrame(r[p0], rd[p0], rdd[p0], th);
      if (b.HasMass()) {
        gb.mass = b.mass;
        gb.com_B = b.com_B;
        gb.inertia_com = b.inertia_com;
        gb.mass_source = "model";
      } else if (m_.drivers.empty()) {
        // A free scene's motion is its masses': a link without `mass:` is massless there, as the
        // formulations take it (a point body on it is then all the mass it has), never a default bar.
        gb.mass = 0;
        gb.com_B = {0, 0};
        gb.inertia_com = 0;
        gb.mass_source = "model";
      } else {
        const double L = b.Length();
        gb.mass = o_.link_mass_per_length * L * g_.meters_per_unit;
        gb.com_B = {L / 2, 0};
        gb.inertia_com = gb.mass * L * L / 12;
        gb.mass_source = "default: uniform bar " + Fmt(o_.link_mass_per_length) + " kg/m";
      }
      body_of_model_.push_back(AddBody(gb));
    }
    if (!CarryPointBodies(why)) return false;
    const double mb = o_.block_mass_ratio * LightestLinkMass();
    const double rg = o_.block_radius * g_.length_scale;
    auto small_body = [&](GraphBody& gb) {
      gb.mass = mb;
      gb.com_B = {0, 0};
      gb.inertia_com = mb * rg * rg;
      gb.mass_source = "default: " + Fmt(o_.block_mass_ratio) + " × lightest link";
    };
    // Groups of bodies that share each point (pinned there).
    groups_.assign(m_.points.size(), {});
    for (size_t i = 0; i < m_.bodies.size(); ++i)
      if (!m_.bodies[i].IsPointBody())
        for (size_t k = 0; k < m_.bodies[i].points.size(); ++k)
          groups_[m_.bodies[i].points[k]].push_back({body_of_model_[i], m_.bodies[i].p_B[k]});
    // Links that only translate (TranslatingLinks): the link itself is the prismatic link.
    const std::vector<int> translating = TranslatingLinks();
    // Slider blocks: prismatic on ground or on the guide body, pinned to the point's group.
    for (size_t j = 0; j < m_.joints.size(); ++j) {
      const Joint& mj = m_.joints[j];
      if (mj.type == JointType::kGear) {
        why = "joint " + mj.name + ": a gear mesh in a linkage scene is not expressed by the graph";
        return false;
      }
      if (translating[j] >= 0) {
        AddTranslatingLink(static_cast<int>(j), translating[j]);
        continue;
      }
      const int P = mj.point;
      GraphBody gb;
      gb.kind = BodyKind::kSliderBlock;
      GraphJoint pj;
      pj.type = PairType::kPrismatic;
      pj.point = P;
      pj.point_name = m_.points[P].name;
      pj.model_joint = static_cast<int>(j);
      if (mj.type == JointType::kPointOnFixedLine) {
        const Eigen::Vector2d u = (m_.points[mj.line[1]].p_W - m_.points[mj.line[0]].p_W).normalized();
        gb.name = "block." + m_.points[P].name + ".ground";
        gb.initial = StateOfFrame(r[P], rd[P], rdd[P], {std::atan2(u.y(), u.x()), 0, 0});
        pj.parent = -1;
        pj.axis_parent_B = u;
        pj.at_parent_B = r[P];
        pj.angle0 = gb.initial.angle;
        pj.name = "prismatic " + gb.name + " on " + m_.points[mj.line[0]].name + "-" + m_.points[mj.line[1]].name;
      } else {
        const int guide = body_of_model_[mj.body];
        const PlanarState& gs = g_.bodies[guide].initial;
        gb.name = "block." + m_.points[P].name + "." + m_.bodies[mj.body].name;
        // The block turns with the guide: same angle, ω, α; origin at P.
        PlanarState s = gs;
        s.p = r[P];
        s.v = rd[P];
        s.a = rdd[P];
        gb.initial = s;
        pj.parent = guide;
        pj.axis_parent_B = {1, 0};
        pj.at_parent_B = Rot(-gs.angle) * (r[P] - gs.p);
        pj.angle0 = 0;
        pj.name = "prismatic " + gb.name + " along " + m_.bodies[mj.body].name;
      }
      const int carried = PointBodyOfJoint(static_cast<int>(j));
      if (carried >= 0)
        BlockFromPointBody(m_.bodies[carried], gb);
      else
        small_body(gb);
      pj.child = AddBody(gb);
      if (carried >= 0) body_of_model_[carried] = pj.child;
      pj.at_child_B = {0, 0};
      g_.joints.push_back(pj);
      groups_[P].push_back({pj.child, {0, 0}});
    }
    // Linear actuators: a driven distance between points of different bodies.
    for (size_t c = 0; c < m_.coordinates.size(); ++c) {
      const Coordinate& co = m_.coordinates[c];
      if (co.type != CoordinateType::kDistance || !IsDriven(co.name)) continue;
      const int a = co.vec[0], b = co.vec[1];
      const Eigen::Vector2d d = r[b] - r[a];
      const AngleKin th = VectorAngle(d, rd[b] - rd[a], rdd[b] - rdd[a]);
      GraphBody cyl, rod;
      cyl.kind = rod.kind = BodyKind::kActuator;
      cyl.name = "actuator." + co.name + ".cylinder";
      rod.name = "actuator." + co.name + ".rod";
      cyl.initial = StateOfFrame(r[a], rd[a], rdd[a], th);
      rod.initial = StateOfFrame(r[b], rd[b], rdd[b], th);
      small_body(cyl);
      small_body(rod);
      GraphJoint pj;
      pj.type = PairType::kPrismatic;
      pj.parent = AddBody(cyl);
      pj.child = AddBody(rod);
      pj.axis_parent_B = {1, 0};
      pj.at_parent_B = {d.norm(), 0};
      pj.at_child_B = {0, 0};
      pj.point = b;
      pj.name = "prismatic actuator " + co.name + " (" + m_.points[a].name + "-" + m_.points[b].name + ")";
      actuator_joint_[co.name] = static_cast<int>(g_.joints.size());
      g_.joints.push_back(pj);
      groups_[a].push_back({pj.parent, {0, 0}});
      groups_[b].push_back({pj.child, {0, 0}});
    }
    // Revolutes: each point's group in a star around its first member (ground first when fixed).
    for (size_t P = 0; P < m_.points.size(); ++P) {
      std::vector<Member> mem = groups_[P];
      if (m_.points[P].fixed) mem.insert(mem.begin(), Member{-1, r[P]});
      if (mem.empty()) {
        why = "point " + m_.points[P].name + " belongs to no body and no slider: nothing carries it";
        return false;
      }
      for (size_t k = 1; k < mem.size(); ++k) {
        GraphJoint rj;
        rj.type = PairType::kRevolute;
        rj.parent = mem[0].body;
        rj.child = mem[k].body;
        rj.point = static_cast<int>(P);
        rj.point_name = m_.points[P].name;
        rj.at_parent_B = mem[0].p_B;
        rj.at_child_B = mem[k].p_B;
        rj.angle0 = g_.bodies[rj.child].initial.angle - (rj.parent < 0 ? 0.0 : g_.bodies[rj.parent].initial.angle);
        rj.name = "revolute " + (rj.parent < 0 ? std::string("ground") : g_.bodies[rj.parent].name) + "-" +
                  g_.bodies[rj.child].name + " at " + m_.points[P].name;
        g_.joints.push_back(rj);
      }
    }
    return true;
  }

  // A link two of whose points slide on parallel fixed guides (a rack, a Scotch yoke) cannot turn:
  // it only translates along the guides. The engines need no slider blocks for it — the link is
  // the prismatic link itself, with its own mass and inertia, on one prismatic joint to ground
  // along the guide at its first such slider (AddTranslatingLink); its other sliders on guides
  // parallel to that one are redundant then and dropped (every engine: a prismatic joint already
  // holds the link's angle and its offset from the guide). Per model joint: the link's model body
  // when the joint is such a slider, else -1. A slider whose point carries a point body (that
  // block is in the file) keeps its block, and so does a slider on a guide that is not parallel.
  std::vector<int> TranslatingLinks() const {
    std::vector<int> of(m_.joints.size(), -1);
    for (size_t b = 0; b < m_.bodies.size(); ++b) {
      const Body& link = m_.bodies[b];
      if (link.IsPointBody()) continue;
      std::vector<int> on;  // fixed-guide sliders at this link's points, without a point body
      for (size_t j = 0; j < m_.joints.size(); ++j) {
        const Joint& mj = m_.joints[j];
        if (mj.type != JointType::kPointOnFixedLine || of[j] >= 0 || PointBodyOfJoint(static_cast<int>(j)) >= 0) continue;
        if (std::find(link.points.begin(), link.points.end(), mj.point) != link.points.end()) on.push_back(static_cast<int>(j));
      }
      if (on.size() < 2) continue;
      const Eigen::Vector2d u = GuideDirection(on[0]);
      const Eigen::Vector2d p0 = m_.points[m_.joints[on[0]].point].p_W;
      std::vector<int> parallel{on[0]};
      for (size_t k = 1; k < on.size(); ++k) {
        const Eigen::Vector2d d = m_.points[m_.joints[on[k]].point].p_W - p0;
        if (std::fabs(Cross(u, GuideDirection(on[k]))) < 1e-12 && d.norm() > 1e-9 * g_.length_scale)
          parallel.push_back(on[k]);
      }
      if (parallel.size() < 2) continue;
      for (int j : parallel) of[j] = static_cast<int>(b);
    }
    return of;
  }
  Eigen::Vector2d GuideDirection(int joint) const {
    const Joint& mj = m_.joints[joint];
    return (m_.points[mj.line[1]].p_W - m_.points[mj.line[0]].p_W).normalized();
  }

  // Slider `joint` of a translating link (TranslatingLinks): the first of the link's becomes its
  // prismatic joint to ground (the link's frame and mass, no block); the others are recorded as
  // redundant (their points' coordinates map onto that joint: CandidateJoint).
  void AddTranslatingLink(int joint, int model_body) {
    const Joint& mj = m_.joints[joint];
    const auto it = translating_joint_.find(model_body);
    const int link = body_of_model_[model_body];
    const GraphBody& gb = g_.bodies[link];
    if (it != translating_joint_.end()) {
      redundant_slider_[mj.point] = it->second;
      g_.notes.push_back("link " + gb.name + " translates: " + mj.name + " is redundant with its prismatic joint and dropped");
      return;
    }
    const Body& b = m_.bodies[model_body];
    const int P = mj.point;
    const size_t k = static_cast<size_t>(std::find(b.points.begin(), b.points.end(), P) - b.points.begin());
    GraphJoint pj;
    pj.type = PairType::kPrismatic;
    pj.point = P;
    pj.point_name = m_.points[P].name;
    pj.model_joint = joint;
    pj.parent = -1;
    pj.child = link;
    pj.axis_parent_B = GuideDirection(joint);
    pj.at_parent_B = data_->r[P];
    pj.at_child_B = b.p_B[k];
    pj.angle0 = gb.initial.angle;
    pj.name = "prismatic " + gb.name + " on " + m_.points[mj.line[0]].name + "-" + m_.points[mj.line[1]].name + " at " +
              m_.points[P].name;
    translating_joint_[model_body] = joint;
    g_.joints.push_back(pj);
    g_.notes.push_back("link " + gb.name + " only translates (points on parallel fixed guides): it is the prismatic link "
                       "itself on " + mj.name + ", with its own mass, and no slider blocks");
  }

  // Graph::file_gear_layout from the file's geometry, when it places every meshing member and
  // sizes every mesh (else a note, and engines choose a module as without geometry).
  void FileGearLayout() {
    const int nb = static_cast<int>(g_.bodies.size());
    auto L = std::make_shared<GearLayout>();
    L->from_file = true;
    L->axis.assign(nb, Eigen::Vector2d(0, 0));
    L->carrier_of.assign(nb, -1);
    std::string missing;
    std::vector<bool> meshing(nb, false);
    for (const GraphJoint& gj : g_.joints)
      if (gj.type == PairType::kGear)
        for (int b : {gj.parent, gj.child, gj.carrier})
          if (b >= 0) meshing[b] = true;
    for (int b = 0; b < nb; ++b) {
      const int mb = g_.bodies[b].model_body;
      const GearAxis& a = m_.gear_axes[mb];
      if (!a.Known()) {
        if (meshing[b]) missing += (missing.empty() ? "" : ", ") + g_.bodies[b].name;
        continue;
      }
      L->axis[b] = a.centre;
      if (a.carrier < 0) continue;
      const int c = body_of_model_[a.carrier];
      L->carrier_of[b] = c;
      const double phi_c = data_->q[nm_->member_slot[a.carrier]];
      L->axis[b] += a.arm * Eigen::Vector2d(std::cos(phi_c), std::sin(phi_c));
    }
    for (size_t ji = 0; ji < g_.joints.size(); ++ji) {
      const GraphJoint& gj = g_.joints[ji];
      if (gj.type != PairType::kGear) continue;
      const Joint& mj = m_.joints[gj.model_joint];
      if (!(mj.radii[0] == mj.radii[0])) {
        missing += (missing.empty() ? "the radii of " : ", the radii of ") + mj.name;
        continue;
      }
      GearMeshLayout m;
      m.joint = static_cast<int>(ji);
      m.internal = mj.internal;
      if (gj.carrier >= 0) {
        m.planet = L->carrier_of[gj.parent] >= 0 ? gj.parent : gj.child;
        m.central = m.planet == gj.parent ? gj.child : gj.parent;
      }
      m.distance = (L->axis[gj.child] - L->axis[gj.parent]).norm();
      m.r_a = mj.radii[0];
      m.r_b = mj.radii[1];
      m.module = mj.Module();
      if (L->meshes.empty()) L->module = m.module;
      L->meshes.push_back(m);
    }
    if (!missing.empty()) {
      g_.notes.push_back("the file's gear geometry leaves out " + missing +
                         ": engines that lay the wheels out choose a module instead");
      return;
    }
    g_.file_gear_layout = std::move(L);
  }

  // A gear train's sliding member (a rack, Body::slides): a body on a prismatic joint to ground
  // along its direction (frame x along it, origin at its pitch point or the frame's origin moved by
  // its travel), with the stated gear mass; a rack joint couples its travel to a member's rotation
  // through Graph::couplings (MapCouplings), as a linkage's rack.
  bool AddSlidingMember(int body, std::string& why) {
    const Body& b = m_.bodies[body];
    int slot = -1;
    for (size_t c = 0; c < m_.coordinates.size(); ++c)
      if (m_.coordinates[c].type == CoordinateType::kTravel && m_.coordinates[c].body == body)
        slot = m_.SlotIndex(m_.coordinates[c].name);
    if (slot < 0) {
      why = "sliding member " + b.name + " has no travel coordinate";
      return false;
    }
    const Eigen::Vector2d d = b.slides;
    const Eigen::Vector2d p0 = b.pitch_point.allFinite() ? b.pitch_point : Eigen::Vector2d(0, 0);
    GraphBody gb;
    gb.name = b.name;
    gb.kind = BodyKind::kGearMember;
    gb.model_body = body;
    gb.initial.p = p0 + d * data_->q[slot];
    gb.initial.v = d * data_->qd[slot];
    gb.initial.a = d * data_->qdd[slot];
    gb.initial.angle = std::atan2(d.y(), d.x());
    gb.mass = o_.gear_mass;
    const double rg = o_.gear_radius / nm_->meters_per_unit;
    gb.inertia_com = gb.mass * rg * rg;
    gb.mass_source = "default: " + Fmt(o_.gear_mass) + " kg, radius of gyration " + Fmt(o_.gear_radius) + " m";
    body_of_model_.push_back(AddBody(gb));
    GraphJoint pj;
    pj.type = PairType::kPrismatic;
    pj.parent = -1;
    pj.child = body_of_model_.back();
    pj.axis_parent_B = d;
    pj.at_parent_B = gb.initial.p;
    pj.angle0 = gb.initial.angle;
    pj.name = "prismatic ground-" + b.name;
    g_.joints.push_back(pj);
    return true;
  }

  bool BuildGears(std::string& why) {
    g_.notes.push_back("gear-train members: the graph turns each about its own axis and couples their absolute rotations by "
                       "Willis' relation; an engine that lays out the wheels and puts the planets on their carriers (orbit "
                       "simulated) records it under gear_layout");
    for (size_t i = 0; i < m_.bodies.size(); ++i) {
      if (m_.bodies[i].IsSliding()) {
        if (!AddSlidingMember(static_cast<int>(i), why)) return false;
        continue;
      }
      GraphBody gb;
      gb.name = m_.bodies[i].name;
      gb.kind = BodyKind::kGearMember;
      gb.model_body = static_cast<int>(i);
      const int slot = nm_->member_slot[i];
      if (slot < 0) {
        why = "gear member " + gb.name + " has no rotation coordinate";
        return false;
      }
      gb.initial.angle = data_->q[slot];
      gb.initial.omega = data_->qd[slot];
      gb.initial.alpha = data_->qdd[slot];
      gb.mass = o_.gear_mass;
      const double rg = o_.gear_radius / nm_->meters_per_unit;
      gb.inertia_com = gb.mass * rg * rg;
      gb.mass_source = "default: " + Fmt(o_.gear_mass) + " kg, radius of gyration " + Fmt(o_.gear_radius) + " m";
      body_of_model_.push_back(AddBody(gb));
      GraphJoint rj;
      rj.type = PairType::kRevolute;
      rj.parent = -1;
      rj.child = body_of_model_.back();
      rj.angle0 = gb.initial.angle;
      rj.name = "revolute ground-" + gb.name;
      g_.joints.push_back(rj);
    }
    for (size_t j = 0; j < m_.joints.size(); ++j) {
      const Joint& mj = m_.joints[j];
      if (mj.type != JointType::kGear) {
        why = "joint " + mj.name + ": a slider in a gear-train scene";
        return false;
      }
      GraphJoint gj;
      gj.type = PairType::kGear;
      gj.parent = body_of_model_[mj.members[0]];
      gj.child = body_of_model_[mj.members[1]];
      gj.carrier = mj.carrier < 0 ? -1 : body_of_model_[mj.carrier];
      gj.z_a = mj.teeth[0];
      gj.z_b = (mj.internal ? -1.0 : 1.0) * mj.teeth[1];
      gj.model_joint = static_cast<int>(j);
      gj.name = "gear " + g_.bodies[gj.parent].name + "-" + g_.bodies[gj.child].name +
                (gj.carrier >= 0 ? " on carrier " + g_.bodies[gj.carrier].name : std::string());
      g_.joints.push_back(gj);
    }
    return true;
  }

  bool IsDriven(const std::string& coord) const {
    for (const Driver& d : m_.drivers)
      if (d.coordinate == coord) return true;
    return false;
  }

  // Kruskal: prismatic joints first (they form a forest), then driven revolutes, then the rest;
  // then oriented from ground by breadth-first search.
  bool SpanningTree(std::string& why) {
    const int nb = static_cast<int>(g_.bodies.size());
    std::vector<int> parent(nb + 1);
    std::iota(parent.begin(), parent.end(), 0);
    auto find = [&](int x) {
      while (parent[x] != x) x = parent[x] = parent[parent[x]];
      return x;
    };
    auto id = [&](int b) { return b < 0 ? nb : b; };
    std::vector<int> order;
    std::vector<bool> driven(g_.joints.size(), false);
    for (const Driver& d : m_.drivers) {
      const int j = CandidateJoint(d.coordinate);
      if (j >= 0) driven[j] = true;
    }
    for (const Coupling& c : m_.couplings)  // a coupling's coordinates are joints of the tree, as drivers'
      for (const std::string& coord : c.coordinates) {
        const int j = CandidateJoint(coord);
        if (j >= 0) driven[j] = true;
      }
    for (int pass = 0; pass < 3; ++pass)
      for (size_t j = 0; j < g_.joints.size(); ++j) {
        const GraphJoint& gj = g_.joints[j];
        if (gj.type == PairType::kGear) continue;
        const bool pris = gj.type == PairType::kPrismatic;
        if ((pass == 0 && pris) || (pass == 1 && !pris && driven[j]) || (pass == 2 && !pris && !driven[j]))
          order.push_back(static_cast<int>(j));
      }
    for (int j : order) {
      GraphJoint& gj = g_.joints[j];
      const int a = find(id(gj.parent)), b = find(id(gj.child));
      if (a == b) continue;
      parent[a] = b;
      gj.in_tree = true;
    }
    for (int b = 0; b < nb; ++b)
      if (find(b) != find(nb)) {
        why = "body " + g_.bodies[b].name + " is connected to ground by no joint";
        return false;
      }
    // Orient from ground.
    std::vector<int> depth(nb, -1);
    std::vector<int> tree_order;
    std::queue<int> frontier;
    frontier.push(-1);
    std::vector<bool> done(g_.joints.size(), false);
    // The tree joints at each body (ground last), in joint order: the search visits them as a scan
    // of every joint per body would, in O(bodies + joints) rather than O(bodies × joints).
    std::vector<std::vector<int>> at_body(nb + 1);
    for (size_t j = 0; j < g_.joints.size(); ++j) {
      const GraphJoint& gj = g_.joints[j];
      if (!gj.in_tree) continue;
      at_body[id(gj.parent)].push_back(static_cast<int>(j));
      if (id(gj.child) != id(gj.parent)) at_body[id(gj.child)].push_back(static_cast<int>(j));
    }
    while (!frontier.empty()) {
      const int at = frontier.front();
      frontier.pop();
      for (const int j : at_body[id(at)]) {
        GraphJoint& gj = g_.joints[j];
        if (done[j]) continue;
        if (gj.parent != at && gj.child != at) continue;
        if (gj.child == at) Reverse(gj);
        done[j] = true;
        tree_order.push_back(static_cast<int>(j));
        frontier.push(gj.child);
      }
    }
    std::vector<GraphJoint> sorted;
    for (int j : tree_order) sorted.push_back(g_.joints[j]);
    for (const GraphJoint& gj : g_.joints)
      if (!gj.in_tree && gj.type != PairType::kGear) sorted.push_back(gj);
    for (const GraphJoint& gj : g_.joints)
      if (gj.type == PairType::kGear) sorted.push_back(gj);
    // Keep the actuator joint indices valid.
    for (auto& [name, j] : actuator_joint_)
      for (size_t k = 0; k < sorted.size(); ++k)
        if (sorted[k].name == g_.joints[j].name) {
          j = static_cast<int>(k);
          break;
        }
    g_.joints = std::move(sorted);
    return true;
  }

  // Swaps parent and child (the coordinate changes sign).
  void Reverse(GraphJoint& j) const {
    const double th_p = j.parent < 0 ? 0.0 : g_.bodies[j.parent].initial.angle;
    const double th_c = g_.bodies[j.child].initial.angle;
    std::swap(j.parent, j.child);
    std::swap(j.at_parent_B, j.at_child_B);
    if (j.type == PairType::kPrismatic) j.axis_parent_B = Rot(-(th_c - th_p)) * j.axis_parent_B;
    j.angle0 = -j.angle0;
    j.reversed = !j.reversed;
  }

  // The joint that would realise a driver on `coord`, before orientation (-1: none).
  // `sign` is +1 when the joint coordinate grows with the coordinate's geometric value.
  int CandidateJoint(const std::string& coord, double* sign = nullptr) const {
    double dummy;
    if (!sign) sign = &dummy;
    const int slot = m_.SlotIndex(coord);
    if (slot < 0) return -1;
    const Model::Slot& s = m_.q_layout[slot];
    if (s.point >= 0) {
      for (size_t j = 0; j < g_.joints.size(); ++j) {
        const GraphJoint& gj = g_.joints[j];
        const auto red = redundant_slider_.find(s.point);
        const bool carries = gj.point == s.point || (red != redundant_slider_.end() && gj.model_joint == red->second);
        if (gj.type == PairType::kPrismatic && gj.model_joint >= 0 && carries &&
            m_.joints[gj.model_joint].type == JointType::kPointOnFixedLine) {
          *sign = gj.reversed ? -1.0 : 1.0;
          return static_cast<int>(j);
        }
      }
      return -1;
    }
    const Coordinate& c = m_.coordinates[s.coordinate];
    if (c.type == CoordinateType::kDistance) {
      const auto it = actuator_joint_.find(c.name);
      if (it == actuator_joint_.end()) return -1;
      *sign = g_.joints[it->second].reversed ? -1.0 : 1.0;
      return it->second;
    }
    if (c.type == CoordinateType::kTravel) {  // a sliding member's prismatic joint (AddSlidingMember)
      for (size_t j = 0; j < g_.joints.size(); ++j) {
        const GraphJoint& gj = g_.joints[j];
        if (gj.type == PairType::kPrismatic && gj.parent < 0 && gj.child == body_of_model_[c.body]) {
          *sign = 1.0;
          return static_cast<int>(j);
        }
      }
      return -1;
    }
    int vb = -2, rb = -1;
    if (c.type == CoordinateType::kRotation) {
      vb = body_of_model_[c.body];
    } else {
      const int mv = BodyWithBoth(m_, c.vec[0], c.vec[1]);
      if (mv < -1) return -1;
      vb = mv < 0 ? -1 : body_of_model_[mv];
      if (c.ref[0] >= 0) {
        const int mr = BodyWithBoth(m_, c.ref[0], c.ref[1]);
        if (mr < -1) return -1;
        rb = mr < 0 ? -1 : body_of_model_[mr];
      }
    }
    for (size_t j = 0; j < g_.joints.size(); ++j) {
      const GraphJoint& gj = g_.joints[j];
      if (gj.type != PairType::kRevolute) continue;
      if (gj.parent == rb && gj.child == vb) {
        *sign = 1.0;
        return static_cast<int>(j);
      }
      if (gj.parent == vb && gj.child == rb) {
        *sign = -1.0;
        return static_cast<int>(j);
      }
    }
    return -1;
  }

  bool MapDrivers(std::string& why) {
    const std::vector<SlotAngle> maps = AngleMaps();
    for (const Driver& d : m_.drivers) {
      const int slot = m_.SlotIndex(d.coordinate);
      double sign = 1;
      const int j = CandidateJoint(d.coordinate, &sign);  // g_.joints is sorted and oriented by now
      if (slot < 0 || j < 0 || !g_.joints[j].in_tree) {
        why = "driver " + d.coordinate + " (" + d.src.Str() + ") is realised by no tree joint of the graph";
        return false;
      }
      const GraphJoint& gj = g_.joints[j];
      const Model::Slot& s = m_.q_layout[slot];
      DriverMap dm;
      dm.joint = j;
      dm.law = d;
      dm.coordinate = d.coordinate;
      const double flip = sign;
      if (s.point >= 0) {
        const double u = gj.axis_parent_B[s.axis];  // parent is ground: world axis
        if (std::fabs(u) < 1e-9) {
          why = "driver " + d.coordinate + ": the guide is normal to that axis";
          return false;
        }
        dm.scale = flip / u;
      } else {
        dm.scale = flip * maps[slot].sigma;
      }
      g_.drivers.push_back(dm);
    }
    return true;
  }

  // Each coupling onto two tree joints: joint = scale (q − q(t0)) at both ends (as MapDrivers), so
  // joint_b = (k scale_b / scale_a) joint_a.
  bool MapCouplings(std::string& why) {
    const std::vector<SlotAngle> maps = AngleMaps();
    for (const Coupling& c : m_.couplings) {
      int joint[2];
      double scale[2];
      for (int e = 0; e < 2; ++e) {
        double sign = 1;
        const int slot = c.slots[e];
        const int j = CandidateJoint(c.coordinates[e], &sign);
        if (j < 0 || !g_.joints[j].in_tree) {
          why = c.name + " (" + c.src.Str() + "): " + c.coordinates[e] +
                " is the coordinate of no tree joint of the graph (a slider on a fixed guide, a pin's angle, a "
                "member's rotation)";
          return false;
        }
        const Model::Slot& s = m_.q_layout[slot];
        if (s.point >= 0) {
          const double u = g_.joints[j].axis_parent_B[s.axis];  // parent is ground: world axis
          if (std::fabs(u) < 1e-9) {
            why = c.name + ": the guide of " + c.coordinates[e] + " is normal to that axis";
            return false;
          }
          scale[e] = sign / u;
        } else {
          scale[e] = sign * maps[slot].sigma;
        }
        joint[e] = j;
      }
      if (joint[0] == joint[1]) {
        why = c.name + ": both coordinates are one joint's";
        return false;
      }
      g_.couplings.push_back({c.name, joint[0], joint[1], c.ratio * scale[1] / scale[0]});
    }
    return true;
  }

  // A point force with a law of t or in a body's frame: on the frame body's member at the point
  // (the loader puts the point on that body), else on the first body that carries it.
  bool MapVaryingForce(const PointForce& f, std::string& why) {
    const std::string name = "force at " + m_.points[f.point].name;
    bool reads_state = false;  // a law of q./qd.: StateLoads evaluates it from the engine's state
    for (const auto& law : f.law)
      if (law)
        for (int var : law->variables()) reads_state = reads_state || var != kLoadVarTime;
    const Member* mem = &groups_[f.point].front();
    if (f.frame >= 0) {
      mem = nullptr;
      const int gb = f.frame < static_cast<int>(body_of_model_.size()) ? body_of_model_[f.frame] : -1;
      for (const Member& c : groups_[f.point])
        if (gb >= 0 && c.body == gb) mem = &c;
      if (!mem) {
        why = name + " in the frame of " + m_.bodies[f.frame].name + ": the graph has no rigid body for it at the point";
        return false;
      }
    }
    GraphForce gf;
    gf.body = mem->body;
    gf.at_B = mem->p_B;
    gf.scale = 1 / g_.meters_per_unit;
    gf.components = f.components * gf.scale;
    gf.law = f.law;
    gf.in_body_frame = f.frame >= 0;
    gf.f_W = f.f_W * gf.scale;  // its value at t0 (for sizes only)
    (reads_state ? g_.state_forces : g_.forces).push_back(gf);
    return true;
  }

  // A spring–damper with laws: Graph::state_springs, and a state_forces entry per moving end.
  void MapLawSpring(const SpringDamper& sd, GraphSpring gs) {
    gs.law = sd.law;
    gs.preload_scale = 1 / g_.meters_per_unit;
    const int index = static_cast<int>(g_.state_springs.size());
    g_.state_springs.push_back(gs);
    for (int e = 0; e < 2; ++e) {
      const int body = e == 0 ? gs.body_a : gs.body_b;
      if (body < 0) continue;  // a fixed end
      GraphForce gf;
      gf.body = body;
      gf.at_B = e == 0 ? gs.at_a : gs.at_b;
      gf.spring = index, gf.end = e;
      g_.state_forces.push_back(gf);
    }
  }

  bool MapForces(std::string& why) {
    for (const PointForce& f : m_.forces) {
      if (groups_.empty() || groups_[f.point].empty()) {
        why = "force on point " + m_.points[f.point].name + ": no body carries it";
        return false;
      }
      if (!f.IsConstantWorld()) {
        if (!MapVaryingForce(f, why)) return false;
        continue;
      }
      const Member& mem = groups_[f.point].front();
      // The model's load is in N; the engines work in kg and the scene's length unit.
      GraphForce gf;
      gf.body = mem.body;
      gf.at_B = mem.p_B;
      gf.f_W = f.f_W / g_.meters_per_unit;
      g_.forces.push_back(gf);
    }
    // Spring–dampers: a fixed end on ground (whatever body is pinned there), a moving end on the
    // first body that carries it, as for point forces. k and c in N/m and N·s/m are kg/s² and kg/s
    // in any length unit; L0 is in the file's unit already.
    const double u = g_.meters_per_unit;
    for (const SpringDamper& sd : m_.springs) {
      GraphSpring gs;
      gs.name = "spring " + m_.points[sd.points[0]].name + "-" + m_.points[sd.points[1]].name;
      int* body[2] = {&gs.body_a, &gs.body_b};
      Eigen::Vector2d* at[2] = {&gs.at_a, &gs.at_b};
      for (int e = 0; e < 2; ++e) {
        const int P = sd.points[e];
        if (m_.points[P].fixed) {
          *body[e] = -1;
          *at[e] = m_.points[P].p_W;
        } else if (!groups_.empty() && !groups_[P].empty()) {
          *body[e] = groups_[P].front().body;
          *at[e] = groups_[P].front().p_B;
        } else {
          why = gs.name + ": no body carries point " + m_.points[P].name;
          return false;
        }
      }
      gs.stiffness = sd.stiffness;
      gs.damping = sd.damping;
      gs.free_length = sd.free_length;
      gs.preload = sd.preload / u;
      if (sd.HasLaw()) {
        MapLawSpring(sd, gs);
        continue;
      }
      g_.springs.push_back(gs);
    }
    for (const BodyTorque& bt : m_.torques) {
      if (bt.body < 0 || bt.body >= static_cast<int>(body_of_model_.size())) {
        why = "torque on body " + m_.bodies[bt.body].name + ": the graph has no rigid body for it";
        return false;
      }
      bool reads_state = false;
      if (bt.law)
        for (int var : bt.law->variables()) reads_state = reads_state || var != kLoadVarTime;
      GraphTorque gt{body_of_model_[bt.body], bt.torque / (u * u), bt.law, 1 / (u * u)};
      (reads_state ? g_.state_torques : g_.torques).push_back(gt);
    }
    if (!g_.state_torques.empty() || !g_.state_forces.empty()) g_.model = std::make_shared<const Model>(m_);
    return MapTorsions(why);
  }

  // Each torsion onto the graph bodies of its coordinate's vector and reference, with the offset
  // that gives the assembled θ0 from the t0 body angles (θ = offset + σ (θ_vec − θ_ref)).
  bool MapTorsions(std::string& why) {
    if (m_.torsions.empty()) return true;
    const std::vector<SlotAngle> maps = AngleMaps();
    const double u = g_.meters_per_unit;
    for (const TorsionSpring& ts : m_.torsions) {
      const std::string head = "torsional spring–damper on " + ts.coordinate + " (" + ts.src.Str() + "): ";
      const Model::Slot& sl = m_.q_layout[ts.slot];
      const Coordinate& c = m_.coordinates[sl.coordinate];
      if (c.type != CoordinateType::kAngle || !maps[ts.slot].is_angle) {
        why = head + "not an angle coordinate";
        return false;
      }
      // The graph body whose frame carries both points of a vector (-1 ground; -2 none).
      auto body_of = [&](int a, int b, const char* what) {
        const int mb = BodyWithBoth(m_, a, b);
        if (mb == -1) return -1;
        if (mb < 0 || mb >= static_cast<int>(body_of_model_.size()) || body_of_model_[mb] < 0) {
          why = head + "its " + what + " " + m_.points[a].name + "→" + m_.points[b].name +
                " is not fixed in one rigid body, so the angle is not a rotation the engines' bodies have";
          return -2;
        }
        return body_of_model_[mb];
      };
      GraphTorsion gt;
      gt.name = "torsion " + ts.coordinate;
      gt.body_vec = body_of(c.vec[0], c.vec[1], "vector");
      if (gt.body_vec == -2) return false;
      if (gt.body_vec == -1) {
        why = head + "its vector is fixed (both points on the ground): nothing for the torque to turn";
        return false;
      }
      gt.body_ref = c.ref[0] < 0 ? -1 : body_of(c.ref[0], c.ref[1], "reference");
      if (gt.body_ref == -2) return false;
      if (gt.body_ref == gt.body_vec) {
        why = head + "its vector and reference are on one body: the angle cannot change";
        return false;
      }
      const double th_ref = gt.body_ref < 0 ? 0.0 : g_.bodies[gt.body_ref].initial.angle;
      gt.sigma = maps[ts.slot].sigma;
      gt.offset = data_->q[ts.slot] - gt.sigma * (g_.bodies[gt.body_vec].initial.angle - th_ref);
      gt.stiffness = ts.stiffness / (u * u);
      gt.damping = ts.damping / (u * u);
      gt.free_angle = ts.free_angle;
      gt.preload = ts.preload / (u * u);
      g_.torsions.push_back(gt);
    }
    return true;
  }

 public:
  std::vector<SlotAngle> AngleMaps() const {
    std::vector<SlotAngle> out(m_.q_layout.size());
    const auto& r = data_->r;
    for (size_t i = 0; i < m_.q_layout.size(); ++i) {
      const Model::Slot& s = m_.q_layout[i];
      if (s.coordinate < 0) continue;
      const Coordinate& c = m_.coordinates[s.coordinate];
      const double th0 = data_->q[i];
      double geo0;
      if (c.type == CoordinateType::kRotation) {
        geo0 = th0;
      } else if (c.type == CoordinateType::kAngle) {
        const Eigen::Vector2d v = r[c.vec[1]] - r[c.vec[0]];
        const Eigen::Vector2d rho = c.ref[0] < 0 ? Eigen::Vector2d(1, 0) : Eigen::Vector2d(r[c.ref[1]] - r[c.ref[0]]);
        geo0 = std::atan2(Cross(rho, v), rho.dot(v));
      } else {
        continue;
      }
      out[i].is_angle = true;
      const Branch br = AngleBranch(c, th0, geo0);
      out[i].sigma = br.sigma;
      out[i].offset = br.offset;
    }
    return out;
  }

  struct Member {
    int body = -1;
    Eigen::Vector2d p_B{0, 0};
  };
  const std::vector<std::vector<Member>>& groups() const { return groups_; }

 private:
  const Model& m_;
  GraphOptions o_;
  Graph g_;
  std::optional<numeric::NaturalModel> nm_;
  std::optional<numeric::NaturalData> data_;
  std::vector<int> body_of_model_;
  std::vector<std::vector<Member>> groups_;
  std::map<std::string, int> actuator_joint_;
  std::map<int, int> translating_joint_;  // translating link's model body → its prismatic joint's model joint
  std::map<int, int> redundant_slider_;   // a dropped slider's point → the model joint that carries its link
};

}  // namespace

GraphOrReason BuildGraph(const Model& model, const GraphOptions& options) {
  Builder b(model, options);
  return b.Build();
}

// ---------------------------------------------------------------------------------------------
// Observer

Observer::Observer(const Model& model, const Graph& graph) : model_(&model), graph_(&graph) {
  points_.resize(model.points.size());
  for (size_t P = 0; P < model.points.size(); ++P) {
    PointRef& pr = points_[P];
    if (model.points[P].fixed) {
      pr.body = -1;
      pr.fixed = model.points[P].p_W;
      continue;
    }
    // The first link that lists the point, else the first added body whose origin it is.
    for (size_t b = 0; b < graph.bodies.size() && pr.body < 0; ++b) {
      const GraphBody& gb = graph.bodies[b];
      if (gb.model_body < 0 || gb.kind != BodyKind::kLink) continue;
      const Body& mb = model.bodies[gb.model_body];
      for (size_t k = 0; k < mb.points.size(); ++k)
        if (mb.points[k] == static_cast<int>(P)) {
          pr.body = static_cast<int>(b);
          pr.p_B = mb.p_B[k];
          break;
        }
    }
    for (const GraphJoint& j : graph.joints) {
      if (pr.body >= 0) break;
      if (j.type == PairType::kPrismatic && j.point == static_cast<int>(P) && j.model_joint >= 0) {
        const int block = graph.bodies[j.child].kind == BodyKind::kSliderBlock ? j.child : j.parent;
        pr.body = block;
        pr.p_B = {0, 0};
      }
    }
  }
  // Angle maps: θ = offset + σ·geo, from the graph's t0 state and the t0 coordinates (the same
  // rule as the driver map: σ = +1 when θ0 and the geometric angle agree modulo 2π, else −1, which
  // covers the cos form's negative branch, the sin form's θ = π − geo and the dot form's |geo|).
  angles_.resize(model.q_layout.size());
  std::vector<PlanarState> st;
  for (const GraphBody& b : graph.bodies) st.push_back(b.initial);
  for (size_t i = 0; i < model.q_layout.size(); ++i) {
    const Model::Slot& s = model.q_layout[i];
    if (s.coordinate < 0) continue;
    const Coordinate& c = model.coordinates[s.coordinate];
    if (c.type == CoordinateType::kDistance || c.type == CoordinateType::kTravel) continue;
    double geo0;
    if (c.type == CoordinateType::kRotation) {
      int b = -1;
      for (size_t k = 0; k < graph.bodies.size(); ++k)
        if (graph.bodies[k].model_body == c.body) b = static_cast<int>(k);
      geo0 = st[b].angle;
    } else {
      Eigen::Vector2d p0, p1, v, a, q0, q1;
      PointKin(c.vec[0], st, p0, v, a);
      PointKin(c.vec[1], st, p1, v, a);
      Eigen::Vector2d rho(1, 0);
      if (c.ref[0] >= 0) {
        PointKin(c.ref[0], st, q0, v, a);
        PointKin(c.ref[1], st, q1, v, a);
        rho = q1 - q0;
      }
      const Eigen::Vector2d vec = p1 - p0;
      geo0 = std::atan2(Cross(rho, vec), rho.dot(vec));
    }
    const double th0 = graph.initial.q[static_cast<long>(i)];
    const Branch br = AngleBranch(c, th0, geo0);
    angles_[i].sigma = br.sigma;
    angles_[i].offset = br.offset;
  }
}

void Observer::PointKin(int point, const std::vector<PlanarState>& st, Eigen::Vector2d& p, Eigen::Vector2d& v,
                        Eigen::Vector2d& a) const {
  const PointRef& pr = points_[point];
  if (pr.body < 0) {
    p = pr.fixed;
    v.setZero();
    a.setZero();
    return;
  }
  const PlanarState& s = st[pr.body];
  p = s.PointPos(pr.p_B);
  v = s.PointVel(pr.p_B);
  a = s.PointAcc(pr.p_B);
}

Sample Observer::Observe(double t, const std::vector<PlanarState>& st, bool with_acc) {
  const Model& m = *model_;
  const int n = static_cast<int>(m.q_layout.size());
  Sample s;
  s.t = t;
  s.q.resize(n);
  s.qd.resize(n);
  s.qdd.resize(n);
  for (int i = 0; i < n; ++i) {
    const Model::Slot& sl = m.q_layout[i];
    if (sl.point >= 0) {
      Eigen::Vector2d p, v, a;
      PointKin(sl.point, st, p, v, a);
      s.q[i] = p[sl.axis];
      s.qd[i] = v[sl.axis];
      s.qdd[i] = a[sl.axis];
      continue;
    }
    const Coordinate& c = m.coordinates[sl.coordinate];
    if (c.type == CoordinateType::kTravel) {  // along the member's direction, from its t0 place
      int b = -1;
      for (size_t k = 0; k < graph_->bodies.size(); ++k)
        if (graph_->bodies[k].model_body == c.body) b = static_cast<int>(k);
      const Eigen::Vector2d& d = m.bodies[c.body].slides;
      s.q[i] = graph_->initial.q[i] + (st[b].p - graph_->bodies[b].initial.p).dot(d);
      s.qd[i] = st[b].v.dot(d);
      s.qdd[i] = st[b].a.dot(d);
      continue;
    }
    if (c.type == CoordinateType::kRotation) {
      int b = -1;
      for (size_t k = 0; k < graph_->bodies.size(); ++k)
        if (graph_->bodies[k].model_body == c.body) b = static_cast<int>(k);
      double th = angles_[i].offset + angles_[i].sigma * st[b].angle;
      th = WrapNear(th, last_q_ ? (*last_q_)[i] : graph_->initial.q[i]);
      s.q[i] = th;
      s.qd[i] = angles_[i].sigma * st[b].omega;
      s.qdd[i] = angles_[i].sigma * st[b].alpha;
      continue;
    }
    Eigen::Vector2d pa, va, aa, pb, vb, ab;
    PointKin(c.vec[0], st, pa, va, aa);
    PointKin(c.vec[1], st, pb, vb, ab);
    const Eigen::Vector2d x = pb - pa, xd = vb - va, xdd = ab - aa;
    if (c.type == CoordinateType::kDistance) {
      const double L = x.norm(), Ld = x.dot(xd) / L;
      s.q[i] = L;
      s.qd[i] = Ld;
      s.qdd[i] = (xd.squaredNorm() + x.dot(xdd)) / L - Ld * Ld / L;
      continue;
    }
    AngleKin g = VectorAngle(x, xd, xdd);
    if (c.ref[0] >= 0) {
      Eigen::Vector2d pc, vc, ac, pd, vd, ad;
      PointKin(c.ref[0], st, pc, vc, ac);
      PointKin(c.ref[1], st, pd, vd, ad);
      const AngleKin rk = VectorAngle(pd - pc, vd - vc, ad - ac);
      g = {g.th - rk.th, g.w - rk.w, g.a - rk.a};
    }
    double th = angles_[i].offset + angles_[i].sigma * g.th;
    th = WrapNear(th, last_q_ ? (*last_q_)[i] : graph_->initial.q[i]);
    s.q[i] = th;
    s.qd[i] = angles_[i].sigma * g.w;
    s.qdd[i] = angles_[i].sigma * g.a;
  }
  if (!with_acc) s.qdd.resize(0);
  last_q_ = s.q;
  return s;
}

Quantities Observer::InstantQuantities(const Sample& s, const std::vector<PlanarState>& st, bool with_acc) const {
  const Model& m = *model_;
  Quantities out;
  for (size_t i = 0; i < m.q_layout.size(); ++i) {
    const std::string& name = m.q_layout[i].name;
    out["q." + name] = s.q[i];
    out["qd." + name] = s.qd[i];
    if (with_acc && s.qdd.size() == s.q.size()) out["qdd." + name] = s.qdd[i];
  }
  const Embedding& e = m.embedding;
  if (m.kind == ScenarioKind::kLinkage)
    for (size_t P = 0; P < m.points.size(); ++P) {
      Eigen::Vector2d p, v, a;
      PointKin(static_cast<int>(P), st, p, v, a);
      const Eigen::Vector3d p3 = e.origin + e.u * p.x() + e.v * p.y();
      const Eigen::Vector3d v3 = e.u * v.x() + e.v * v.y();
      const Eigen::Vector3d a3 = e.u * a.x() + e.v * a.y();
      const std::string& name = m.points[P].name;
      const char* ax[3] = {".x", ".y", ".z"};
      for (int k = 0; k < 3; ++k) {
        out["p." + name + ax[k]] = p3[k];
        out["v." + name + ax[k]] = v3[k];
        if (with_acc) out["a." + name + ax[k]] = a3[k];
      }
    }
  for (size_t b = 0; b < graph_->bodies.size(); ++b) {
    const GraphBody& gb = graph_->bodies[b];
    if (gb.model_body < 0 || m.bodies[gb.model_body].IsSliding()) continue;  // a rack: qd of its travel
    out["omega." + gb.name] = st[b].omega;
    if (with_acc) out["alpha." + gb.name] = st[b].alpha;
  }
  return out;
}

std::string Describe(const Graph& g) {
  std::ostringstream os;
  os << g.bodies.size() << " bodies, " << g.joints.size() << " joints (" << g.CountTree() << " tree), "
     << g.drivers.size() << " drivers";
  return os.str();
}

// ---------------------------------------------------------------------------------------------
// Gear layout

const GearMeshLayout* GearLayout::MeshOf(int joint) const {
  for (const GearMeshLayout& m : meshes)
    if (m.joint == joint) return &m;
  return nullptr;
}

std::string GearLayout::Describe(const Graph& g) const {
  std::ostringstream os;
  const double mm = 1e3 * g.meters_per_unit;
  const std::string unit = "mm";
  if (from_file) os << "from the file: ";
  for (size_t k = 0; k < meshes.size(); ++k) {
    const GearMeshLayout& m = meshes[k];
    const GraphJoint& j = g.joints[m.joint];
    if (k) os << "; ";
    os << g.bodies[j.parent].name << "-" << g.bodies[j.child].name << " " << (m.internal ? "internal" : "external")
       << ": pitch radii " << Fmt(mm * m.r_a) << " / " << Fmt(mm * m.r_b) << " " << unit << " (module " << Fmt(mm * m.module)
       << " " << unit << "), centre distance " << Fmt(mm * m.distance) << " " << unit;
    if (m.planet >= 0) os << ", " << g.bodies[m.planet].name << " on carrier " << g.bodies[carrier_of[m.planet]].name;
  }
  return os.str();
}

GearLayoutOrReason LayOutGears(const Graph& g, double module) {
  GearLayoutOrReason out;
  if (g.file_gear_layout) {
    out.layout = *g.file_gear_layout;
    return out;
  }
  const int nb = static_cast<int>(g.bodies.size());
  GearLayout L;
  L.module = module;
  L.axis.assign(nb, Eigen::Vector2d(0, 0));
  L.carrier_of.assign(nb, -1);
  std::vector<int> gears;
  for (size_t j = 0; j < g.joints.size(); ++j)
    if (g.joints[j].type == PairType::kGear) gears.push_back(static_cast<int>(j));
  auto name = [&](int b) { return g.bodies[b].name; };
  auto teeth = [&](const GraphJoint& j) { return std::pair{std::fabs(j.z_a), std::fabs(j.z_b)}; };
  // Centre distance at the stated module.
  auto nominal = [&](const GraphJoint& j) {
    const auto [za, zb] = teeth(j);
    return j.z_b < 0 ? module * std::fabs(za - zb) / 2 : module * (za + zb) / 2;
  };
  for (int ji : gears) {
    const GraphJoint& j = g.joints[ji];
    if (j.z_b < 0 && std::fabs(std::fabs(j.z_a) - std::fabs(j.z_b)) < 0.5) {
      out.reason = j.name + ": an internal mesh between equal tooth counts has no centre distance";
      return out;
    }
  }

  // Planets: two-colour each carrier's meshes.
  std::vector<int> central_of(nb, -1);  // central member -> its carrier
  std::map<int, std::vector<int>> by_carrier;
  for (int ji : gears)
    if (g.joints[ji].carrier >= 0) by_carrier[g.joints[ji].carrier].push_back(ji);
  for (const auto& [c, meshes] : by_carrier) {
    std::map<int, int> colour;
    std::map<int, int> degree;
    for (int ji : meshes) {
      ++degree[g.joints[ji].parent];
      ++degree[g.joints[ji].child];
    }
    for (const auto& kv : degree) {
      const int start = kv.first;
      if (colour.count(start)) continue;
      // One connected component: colour it, then pick its planet colour.
      std::vector<int> comp{start}, comp_meshes;
      colour[start] = 0;
      for (size_t k = 0; k < comp.size(); ++k)
        for (int ji : meshes) {
          const GraphJoint& j = g.joints[ji];
          int other;
          if (j.parent == comp[k]) other = j.child;
          else if (j.child == comp[k]) other = j.parent;
          else continue;
          if (std::find(comp_meshes.begin(), comp_meshes.end(), ji) == comp_meshes.end()) comp_meshes.push_back(ji);
          if (!colour.count(other)) {
            colour[other] = 1 - colour[comp[k]];
            comp.push_back(other);
          } else if (colour[other] == colour[comp[k]]) {
            out.reason = "the meshes on carrier " + name(c) + " do not pair planets with central members (" + j.name +
                         " closes an odd cycle): no layout with the planets on the carrier";
            return out;
          }
        }
      int planet_colour = -1;
      for (int ji : comp_meshes) {
        const GraphJoint& j = g.joints[ji];
        if (j.z_b >= 0) continue;
        const int smaller = std::fabs(j.z_a) < std::fabs(j.z_b) ? j.parent : j.child;
        if (planet_colour >= 0 && planet_colour != colour[smaller]) {
          out.reason = "the internal meshes on carrier " + name(c) + " disagree on which members are planets";
          return out;
        }
        planet_colour = colour[smaller];
      }
      if (planet_colour < 0) {
        int most[2] = {0, 0};
        for (int b : comp) most[colour[b]] = std::max(most[colour[b]], degree[b]);
        if (most[0] != most[1]) planet_colour = most[0] > most[1] ? 0 : 1;
        else if (comp_meshes.size() == 1) planet_colour = colour[g.joints[comp_meshes[0]].child];
        else {
          out.reason = "the meshes on carrier " + name(c) + " do not say which members are planets";
          return out;
        }
      }
      for (int b : comp) {
        if (b == c) {
          out.reason = "carrier " + name(c) + " is also one of its own meshing members";
          return out;
        }
        if (colour[b] == planet_colour) {
          if (L.carrier_of[b] >= 0 || central_of[b] >= 0) {
            out.reason = "member " + name(b) + " would ride on two carriers";
            return out;
          }
          L.carrier_of[b] = c;
        } else {
          if (L.carrier_of[b] >= 0 || (central_of[b] >= 0 && central_of[b] != c)) {
            out.reason = "member " + name(b) + " would be coaxial with two carriers";
            return out;
          }
          central_of[b] = c;
        }
      }
    }
  }
  for (int ji : gears) {
    const GraphJoint& j = g.joints[ji];
    for (int b : {j.parent, j.child})
      if (L.carrier_of[b] >= 0 && j.carrier != L.carrier_of[b]) {
        out.reason = "planet " + name(b) + " (on carrier " + name(L.carrier_of[b]) + ") also meshes in " + j.name +
                     ", which is not on that carrier: no fixed axis for it";
        return out;
      }
    if (j.carrier >= 0 && L.carrier_of[j.carrier] >= 0) {
      out.reason = "carrier " + name(j.carrier) + " rides on another carrier: nested carriers are not laid out";
      return out;
    }
  }

  // Axis groups: a carrier with its central members; every other member alone.
  std::vector<int> group(nb);
  std::iota(group.begin(), group.end(), 0);
  auto find = [&](int x) {
    while (group[x] != x) x = group[x] = group[group[x]];
    return x;
  };
  for (int b = 0; b < nb; ++b)
    if (central_of[b] >= 0) group[find(b)] = find(central_of[b]);
  for (int b = 0; b < nb; ++b) group[b] = find(b);
  std::vector<bool> placed(nb, false);  // per group representative
  std::vector<Eigen::Vector2d> gpos(nb, Eigen::Vector2d(0, 0));
  for (int seed = 0; seed < nb; ++seed) {
    const int gs = group[seed];
    if (L.carrier_of[seed] >= 0 || placed[gs]) continue;
    placed[gs] = true;
    gpos[gs] = Eigen::Vector2d(0, 0);
    // Breadth-first over the meshes without a carrier.
    std::vector<int> frontier{gs};
    for (size_t k = 0; k < frontier.size(); ++k)
      for (int ji : gears) {
        const GraphJoint& j = g.joints[ji];
        if (j.carrier >= 0) continue;
        const int ga = group[j.parent], gb = group[j.child];
        int from, to;
        if (ga == frontier[k]) { from = ga; to = gb; }
        else if (gb == frontier[k]) { from = gb; to = ga; }
        else continue;
        if (placed[to]) continue;
        placed[to] = true;
        gpos[to] = gpos[from] + Eigen::Vector2d(nominal(j), 0);
        frontier.push_back(to);
      }
  }
  for (int b = 0; b < nb; ++b)
    if (L.carrier_of[b] < 0) L.axis[b] = gpos[group[b]];
  // Planets: the first mesh's centre distance from the carrier's axis, along +x.
  for (int b = 0; b < nb; ++b) {
    const int c = L.carrier_of[b];
    if (c < 0) continue;
    for (int ji : gears) {
      const GraphJoint& j = g.joints[ji];
      if (j.carrier == c && (j.parent == b || j.child == b)) {
        L.axis[b] = L.axis[c] + Eigen::Vector2d(nominal(j), 0);
        break;
      }
    }
  }
  // Meshes: pitch radii from the actual centre distance.
  for (int ji : gears) {
    const GraphJoint& j = g.joints[ji];
    GearMeshLayout m;
    m.joint = ji;
    m.internal = j.z_b < 0;
    if (j.carrier >= 0) {
      m.planet = L.carrier_of[j.parent] >= 0 ? j.parent : j.child;
      m.central = m.planet == j.parent ? j.child : j.parent;
    }
    m.distance = (L.axis[j.child] - L.axis[j.parent]).norm();
    if (m.distance < 1e-9 * module) {
      out.reason = j.name + ": its two members are coaxial in the layout (no centre distance)";
      return out;
    }
    const auto [za, zb] = teeth(j);
    const double k = m.distance / (m.internal ? std::fabs(za - zb) : za + zb);
    m.r_a = k * za;
    m.r_b = k * zb;
    m.module = 2 * k;
    L.meshes.push_back(m);
  }
  out.layout = std::move(L);
  return out;
}

Eigen::Vector2d Rotate(double th, const Eigen::Vector2d& p) { return Rot(th) * p; }

double InitialJointRate(const Graph& g, const GraphJoint& j) {
  const PlanarState& c = g.bodies[j.child].initial;
  const PlanarState p = j.parent < 0 ? PlanarState{} : g.bodies[j.parent].initial;
  if (j.type == PairType::kRevolute) return c.omega - p.omega;
  const Eigen::Vector2d rel = c.PointVel(j.at_child_B) - p.PointVel(j.at_parent_B);
  return rel.dot(Rotate(p.angle, j.axis_parent_B));
}

numeric::EngineJointForce PinForce(const Graph& g, const GraphJoint& j, const Eigen::Vector2d& on_child) {
  numeric::EngineJointForce e;
  e.revolute = j.type == PairType::kRevolute;
  e.point = j.point;
  e.point_name = j.point_name;  // a prismatic joint's: the slider's point, "" for an engine's own
  auto link = [&](int b) { return b >= 0 && g.bodies[b].kind == BodyKind::kLink ? g.bodies[b].name : std::string(); };
  e.parent = link(j.parent);
  e.child = link(j.child);
  e.parent_ground = j.parent < 0;
  e.child_ground = j.child < 0;
  e.on_child = on_child;
  for (const CouplingMap& c : g.couplings)
    for (const int ji : {c.joint_a, c.joint_b})
      if (ji >= 0 && static_cast<size_t>(ji) < g.joints.size() && &g.joints[static_cast<size_t>(ji)] == &j) e.coupling = c.name;
  return e;
}

}  // namespace mechbench::engines
