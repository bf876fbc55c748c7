#include "mechbench/references/cranks.h"

#include "mechbench/format.h"

#include <cmath>
#include <map>
#include <numbers>

namespace mechbench::references {

bool AnalyzeParallelCranks(const Model& m, ParallelCranks& out, std::string& why) {
  out = ParallelCranks{};
  const auto fail = [&](const std::string& w) {
    why = w;
    return false;
  };
  if (m.kind != ScenarioKind::kLinkage) return fail("it is not a linkage");
  if (!m.drivers.empty()) return fail("it has drivers: the closed form is a free motion");
  if (!m.joints.empty()) return fail("it has joints (" + std::to_string(m.joints.size()) + "): only pinned bars are described");
  // One crank's angle may be a coordinate (checked against the crank below); nothing else.
  if (m.coordinates.size() > 1)
    return fail("it has " + std::to_string(m.coordinates.size()) +
                " relative coordinates: the closed form describes the points' coordinates and at most the crank's angle "
                "(remove the others)");
  if (m.coordinates.size() == 1) {
    const Coordinate& c = m.coordinates[0];
    if (c.type != CoordinateType::kAngle || c.ref[0] >= 0)
      return fail("its coordinate " + c.name +
                  " is not the crank's angle from the ground x axis (type: angle, vector: [pivot, tip], no reference): "
                  "remove it, or write it so");
  }
  if (!m.forces.empty() || m.HasForceElements()) return fail("it has loads besides gravity");
  if (m.gravity.x() != 0 || !(m.gravity.y() < 0)) return fail("its gravity is not along −y");
  if (m.frame) return fail("it has a rotating frame");
  if (!m.analysis.HasMotion()) return fail("it has no motion (analysis t1, samples)");
  out.g = -m.gravity.y();
  const double scale = m.LengthScale();
  const double tol = 1e-12 * scale;
  // Bodies with one fixed and one moving point are cranks; with two moving points, couplers.
  std::map<int, int> crank_of_tip;  // moving point → crank body
  std::vector<int> couplers, lumped;  // lumped: point bodies (a mass at a crank's tip)
  for (size_t b = 0; b < m.bodies.size(); ++b) {
    const Body& body = m.bodies[b];
    if (body.IsPointBody()) {
      if (body.guide >= 0) return fail("body " + body.name + " is a block on a guide");
      if (!body.HasMass()) return fail("point body " + body.name + " has no mass: give it its mass, {points: [P], mass: m}");
      if (m.points[body.points[0]].fixed) return fail("point body " + body.name + " sits on a fixed point");
      lumped.push_back(static_cast<int>(b));
      continue;
    }
    if (body.points.size() != 2) return fail("body " + body.name + " does not have two points");
    if (!body.HasMass())
      return fail("body " + body.name + " has no mass: the closed form needs every body's mass stated (a massless "
                  "crank or coupler is mass: 0, com: [0, 0], inertia: 0)");
    const bool f0 = m.points[body.points[0]].fixed, f1 = m.points[body.points[1]].fixed;
    if (f0 && f1) return fail("body " + body.name + " joins two fixed points");
    if (f0 != f1) {
      const int tip = f0 ? body.points[1] : body.points[0];
      if (!crank_of_tip.emplace(tip, static_cast<int>(b)).second)
        return fail("point " + m.points[tip].name + " is the tip of two bars pinned to ground");
    } else {
      couplers.push_back(static_cast<int>(b));
    }
  }
  if (crank_of_tip.empty()) return fail("no body is pinned to ground");
  if (couplers.size() + 1 != crank_of_tip.size())
    return fail(std::to_string(crank_of_tip.size()) + " bars pinned to ground and " + std::to_string(couplers.size()) +
                " couplers: a row of parallelograms has one coupler fewer than cranks");
  size_t moving = 0;
  for (const Point& p : m.points) moving += p.fixed ? 0 : 1;
  if (moving != crank_of_tip.size()) return fail("a moving point is not the tip of a crank");
  for (int b : lumped)
    if (!crank_of_tip.count(m.bodies[b].points[0]))
      return fail("point body " + m.bodies[b].name + " is not at a crank's tip");
  // The couplers join the tips in a row: a path through every tip.
  std::map<int, std::vector<int>> next;  // tip → neighbouring tips
  for (int c : couplers) {
    const Body& body = m.bodies[c];
    if (!crank_of_tip.count(body.points[0]) || !crank_of_tip.count(body.points[1]))
      return fail("coupler " + body.name + " does not join two crank tips");
    next[body.points[0]].push_back(body.points[1]);
    next[body.points[1]].push_back(body.points[0]);
  }
  int start = -1;
  if (couplers.empty()) {
    start = crank_of_tip.begin()->first;
  } else {
    for (const auto& [tip, nb] : next) {
      if (nb.size() > 2) return fail("point " + m.points[tip].name + " joins more than two couplers");
      if (nb.size() == 1 && (start < 0 || crank_of_tip[tip] < crank_of_tip[start])) start = tip;
    }
    if (start < 0) return fail("the couplers close a ring: a row of parallelograms has two ends");
  }
  for (int prev = -1, at = start; at >= 0;) {
    out.tip.push_back(at);
    int go = -1;
    for (int nb : next[at])
      if (nb != prev) go = nb;
    prev = at, at = go;
    if (out.tip.size() > crank_of_tip.size()) return fail("the couplers do not form one row");
  }
  if (out.tip.size() != crank_of_tip.size()) return fail("the couplers do not join every crank in one row");
  // Geometry: every crank the same vector from its pivot to its tip (hence the couplers are
  // parallel to the ground line between pivots), the centres of mass on the cranks' lines.
  Eigen::Vector2d arm;
  for (size_t i = 0; i < out.tip.size(); ++i) {
    const Body& body = m.bodies[crank_of_tip[out.tip[i]]];
    const int fixed_at = m.points[body.points[0]].fixed ? 0 : 1;
    const int pivot = body.points[fixed_at];
    out.ground.push_back(pivot);
    const Eigen::Vector2d a = m.points[out.tip[i]].p_W - m.points[pivot].p_W;
    if (i == 0) {
      arm = a;
      out.L = body.Length();
      if (!(out.L > 0)) return fail("crank " + body.name + " has no length");
      if (std::fabs(a.norm() - out.L) > tol)
        return fail("crank " + body.name + ": its tip is " + Fmt(a.norm(), 6) + " from its pivot at the start, its length " +
                    Fmt(out.L, 6));
    } else if ((a - arm).norm() > tol || std::fabs(body.Length() - out.L) > tol) {
      return fail("crank " + body.name + " is not parallel to and as long as the first: the mechanism is not a row of "
                  "parallelograms");
    }
    out.x.push_back(m.SlotOf(out.tip[i], 0));
    out.y.push_back(m.SlotOf(out.tip[i], 1));
    if (out.x.back() < 0 || out.y.back() < 0) return fail("a crank tip's coordinate is not in q");
    const Eigen::Vector2d p0 = body.p_B[fixed_at], u = (body.p_B[1 - fixed_at] - p0) / body.Length();
    const Eigen::Vector2d d = body.com_B - p0;
    const double off = d.x() * u.y() - d.y() * u.x();
    if (std::fabs(off) > tol)
      return fail("crank " + body.name + "'s centre of mass is " + Fmt(std::fabs(off), 3) + " off its line");
  }
  // J and K in the bodies' file order.
  for (const Body& body : m.bodies) {
    if (body.IsPointBody()) {  // a mass at a tip moves as the tip does: as a coupler's mass
      out.J += body.mass * out.L * out.L, out.K += body.mass * out.L;
      continue;
    }
    const bool f0 = m.points[body.points[0]].fixed, f1 = m.points[body.points[1]].fixed;
    if (f0 != f1) {
      const int fixed_at = f0 ? 0 : 1;
      const Eigen::Vector2d p0 = body.p_B[fixed_at], u = (body.p_B[1 - fixed_at] - p0) / body.Length();
      const Eigen::Vector2d d = body.com_B - p0;
      out.J += body.inertia_com + body.mass * d.squaredNorm(), out.K += body.mass * (d.x() * u.x() + d.y() * u.y());
    } else {
      out.J += body.mass * out.L * out.L, out.K += body.mass * out.L;
      const double drawn = (m.points[body.points[1]].p_W - m.points[body.points[0]].p_W).norm();
      if (std::fabs(body.Length() - drawn) > tol)
        return fail("coupler " + body.name + " is " + Fmt(body.Length(), 6) + " long, its tips " + Fmt(drawn, 6) + " apart");
    }
  }
  if (!(out.J > 0)) return fail("its moment of inertia about the pivots is 0");
  out.couplers = static_cast<int>(couplers.size());
  out.theta0 = std::atan2(arm.y(), arm.x());
  // The crank's angle as a coordinate: along the one crank, either way round.
  double angle_drawn = 0;  // the coordinate's angle as drawn, in (−π, π]
  if (m.coordinates.size() == 1) {
    const Coordinate& c = m.coordinates[0];
    if (out.couplers != 0)
      return fail("it has the coordinate " + c.name +
                  ": the N-four-bar's closed form describes the tips' coordinates only (remove `coordinates:` and put "
                  "the initial condition on a tip's x or y)");
    const int pivot = out.ground[0], tip = out.tip[0];
    if (!((c.vec[0] == pivot && c.vec[1] == tip) || (c.vec[0] == tip && c.vec[1] == pivot)))
      return fail("its coordinate " + c.name + " is not along the crank (vector: [" + m.points[pivot].name + ", " +
                  m.points[tip].name + "])");
    out.angle_slot = m.SlotIndex(c.name);
    angle_drawn = c.vec[0] == pivot ? out.theta0 : std::remainder(out.theta0 + std::numbers::pi, 2 * std::numbers::pi);
    // The branch the file draws: nearest its guess (the numeric solver's start), as q holds it.
    const double guess = m.GuessQ()[out.angle_slot];
    out.angle0 = guess + std::remainder(angle_drawn - guess, 2 * std::numbers::pi);
  }
  // One initial condition, on a tip coordinate (or the crank's angle) at its drawn value.
  if (m.initial.size() != 1) return fail("it has " + std::to_string(m.initial.size()) + " initial conditions, not one");
  const Driver& d = m.initial[0];
  const int slot = m.SlotIndex(d.coordinate);
  if (out.angle_slot >= 0 && slot == out.angle_slot) {
    if (std::fabs(std::remainder(d.value - angle_drawn, 2 * std::numbers::pi)) > 1e-12 * std::max(1.0, std::fabs(d.value)))
      return fail("its initial condition moves " + d.coordinate + " from where the crank is drawn");
    if (d.acceleration != 0) return fail("its initial condition gives an acceleration");
    out.angle0 = d.value;
    out.omega0 = d.velocity;
    return true;
  }
  int axis = -1;
  for (size_t i = 0; i < out.tip.size() && axis < 0; ++i)
    axis = slot == out.x[i] ? 0 : slot == out.y[i] ? 1 : -1;
  if (axis < 0)
    return fail(out.angle_slot >= 0 ? "its initial condition is not on the crank's angle or a tip's x or y"
                                    : "its initial condition is not on a crank tip's x or y");
  const int point = m.q_layout[slot].point;
  if (std::fabs(d.value - m.points[point].p_W[axis]) > tol)
    return fail("its initial condition moves " + d.coordinate + " from where the point is drawn");
  if (d.acceleration != 0) return fail("its initial condition gives an acceleration");
  const double rate = axis == 0 ? -out.L * std::sin(out.theta0) : out.L * std::cos(out.theta0);
  if (std::fabs(rate) < 1e-9 * out.L) {
    if (d.velocity != 0) return fail("its initial velocity is along the crank");
    out.omega0 = 0;
  } else {
    out.omega0 = d.velocity / rate;
  }
  return true;
}

}  // namespace mechbench::references
