#include "mechbench/numeric/reactions.h"

#include "mechbench/errors.h"
#include "mechbench/format.h"
#include "mechbench/numeric/constraints.h"
#include "mechbench/numeric/dynamics.h"
#include "mechbench/numeric/natural_data.h"
#include "planar.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

namespace mechbench::numeric {
namespace {

using V2 = Eigen::Vector2d;

bool IsBodyRow(RowKind k) {
  return k == RowKind::kBodyDistance || k == RowKind::kBodyLinearX || k == RowKind::kBodyLinearY;
}

using planar::Interpolation;

// The first body in file order that holds point p (the one an applied point force acts on), or -1.
int FirstHolder(const Model& m, int p) {
  for (size_t b = 0; b < m.bodies.size(); ++b) {
    const auto& ps = m.bodies[b].points;
    if (std::find(ps.begin(), ps.end(), p) != ps.end()) return static_cast<int>(b);
  }
  return -1;
}

// Partials of a body row with respect to the points it uses (constants included): Φ's gradient
// at each of its points, as (point, ∂Φ/∂r_point) pairs.
std::vector<std::pair<int, V2>> BodyRowGradient(const ConstraintRow& row, const std::vector<V2>& r) {
  const int p0 = row.pts[0], p1 = row.pts[1];
  if (row.kind == RowKind::kBodyDistance) {
    const V2 v = r[p1] - r[p0];
    return {{p1, 2 * v}, {p0, -2 * v}};
  }
  // [r_k − r0 − a(r1 − r0) − b P(r1 − r0)]_c, P = [0 −1; 1 0] (constraints.cc).
  const int c = row.kind == RowKind::kBodyLinearX ? 0 : 1;
  const V2 e = c == 0 ? V2(1, 0) : V2(0, 1);
  const V2 P_row = c == 0 ? V2(0, -1) : V2(1, 0);  // row c of P
  return {{row.pts[2], e}, {p0, -(1 - row.a) * e + row.b * P_row}, {p1, -row.a * e - row.b * P_row}};
}

}  // namespace

std::string ReactionName(const std::string& point, const std::string& body, int axis) {
  return "reaction." + point + "." + body + (axis == 0 ? ".x" : ".y");
}

std::vector<PinBody> ReactionPins(const Model& m, std::vector<std::string>* left_out) {
  std::vector<std::string> notes;
  std::set<int> slider_points, guide_bodies, ground_bodies;
  for (const Joint& j : m.joints) {
    if (j.type == JointType::kGear) continue;
    slider_points.insert(j.point);
    if (j.type == JointType::kPointOnBody && j.body >= 0) guide_bodies.insert(j.body);
  }
  for (size_t b = 0; b < m.bodies.size(); ++b) {
    int fixed = 0;
    for (int p : m.bodies[b].points) fixed += m.points[p].fixed;
    if (fixed >= 2) ground_bodies.insert(static_cast<int>(b));
  }
  // The bodies holding each point, in body order (one pass: O(points + bodies) for long chains).
  std::vector<std::vector<int>> holders_of(m.points.size());
  for (size_t b = 0; b < m.bodies.size(); ++b)
    for (int p : m.bodies[b].points)
      if (holders_of[p].empty() || holders_of[p].back() != static_cast<int>(b)) holders_of[p].push_back(static_cast<int>(b));
  std::vector<PinBody> out;
  for (size_t p = 0; p < m.points.size(); ++p) {
    const std::vector<int>& holders = holders_of[p];
    if (holders.empty() || holders.size() + (m.points[p].fixed ? 1 : 0) < 2) continue;  // not a pin
    const std::string& pn = m.points[p].name;
    if (slider_points.count(static_cast<int>(p))) {
      notes.push_back("point " + pn + ": a slider's point (sliders are left out)");
      continue;
    }
    for (int b : holders) {
      const std::string& bn = m.bodies[b].name;
      if (guide_bodies.count(b))
        notes.push_back("body " + bn + " at " + pn + ": a slider's guide body (its basic points carry the slider's force)");
      else if (ground_bodies.count(b))
        notes.push_back("body " + bn + " at " + pn + ": two or more fixed points (part of the ground)");
      else
        out.push_back({static_cast<int>(p), b});
    }
  }
  // A slider's point on one body (a rack's, a block's on its guide) is no pin, so the loop above
  // passes it by; its force from the guide is left out all the same, and says so.
  for (int p : slider_points) {
    if (p < 0) continue;  // a joint without a point of its own
    const std::vector<int>& holders = holders_of[p];
    if (holders.empty() || holders.size() + (m.points[p].fixed ? 1 : 0) >= 2) continue;  // a pin: noted above
    notes.push_back("point " + m.points[p].name + ": a slider's point (sliders are left out: the force of its guide on " +
                    m.bodies[holders.front()].name + " is not a pin's reaction)");
  }
  if (left_out) left_out->insert(left_out->end(), notes.begin(), notes.end());
  return out;
}

Reactions JointReactions(const NaturalModel& nm, const Eigen::VectorXd& q, const Eigen::VectorXd& qd,
                         const Eigen::VectorXd& qdd,
                         const Eigen::VectorXd& lambda, const std::vector<int>& dropped) {
  const Model& m = nm.model;
  MB_ASSERT(lambda.size() == nm.m(), "one multiplier per row");
  Reactions out;
  const std::vector<PinBody> pins = ReactionPins(m, &out.notes);
  if (pins.empty()) return out;
  if (!m.torsions.empty())
    out.notes.push_back("torsional spring–dampers act on their angle coordinate, not on points: the pin reactions "
                        "leave their torque out");
  for (int i : dropped)
    if (IsBodyRow(nm.rows[i].kind)) {
      out.notes.push_back("no reactions: the row of " + nm.rows[i].Where() +
                          " was left out as redundant, so its multiplier is not that body's own force");
      return out;
    }
  NaturalData data(nm);
  UpdatePoints(nm, data, q);
  UpdatePointAccelerations(nm, data, qdd);
  const double u = nm.meters_per_unit;
  const V2 g_SI = m.gravity * u;

  // Each body's rows, in Compile's order (natural_model.h): a distance row, then x and y rows per
  // extra point, for every body whose first two points are not both constant.
  std::vector<std::vector<int>> rows_of(m.bodies.size());
  {
    auto moves = [&](int p) { return nm.point_slot[p][0] >= 0 || nm.point_slot[p][1] >= 0; };
    int i = 0;
    for (size_t b = 0; b < m.bodies.size(); ++b) {
      const Body& body = m.bodies[b];
      if (body.points.size() < 2 || (!moves(body.points[0]) && !moves(body.points[1]))) continue;
      const int count = 1 + 2 * static_cast<int>(body.points.size() - 2);
      for (int k = 0; k < count; ++k, ++i) {
        MB_ASSERT(i < nm.m() && IsBodyRow(nm.rows[i].kind) && nm.rows[i].pts[0] == body.points[0] &&
                      nm.rows[i].pts[1] == body.points[1],
                  "body rows out of Compile's order");
        rows_of[b].push_back(i);
      }
    }
  }

  // F_b at every point of b [N].
  std::map<std::pair<int, int>, V2> force;  // (body, point) → force
  double scale = 0;
  for (size_t bi = 0; bi < m.bodies.size(); ++bi) {
    const Body& body = m.bodies[bi];
    const int b = static_cast<int>(bi);
    if (body.IsPointBody()) {
      // A point body at a pin (not a slider's point, which is left out): its centre of mass is
      // its point, so the rest applies m (a − g) there.
      const int p = body.points[0];
      force[{b, p}] = body.HasMass() ? V2(body.mass * (data.rdd[p] * u - g_SI)) : V2::Zero();
      if (body.HasMass()) scale = std::max(scale, body.mass * g_SI.norm());
      continue;
    }
    if (body.points.size() < 2) continue;
    for (int p : body.points) force[{b, p}] = V2::Zero();
    const int p0 = body.points[0], p1 = body.points[1];
    if (body.HasMass()) {
      const double L = body.Length();
      Eigen::Vector4d a;
      a << data.rdd[p0], data.rdd[p1];
      const Eigen::Vector4d inertia = ElementMassMatrix(body.mass, L, body.com_B, body.inertia_com) * a * u;
      const Eigen::Vector4d weight = Interpolation(L, body.com_B).transpose() * (body.mass * g_SI);
      force[{b, p0}] += inertia.head<2>() - weight.head<2>();
      force[{b, p1}] += inertia.tail<2>() - weight.tail<2>();
      scale = std::max(scale, body.mass * g_SI.norm());
    }
    for (int i : rows_of[bi])
      for (const auto& [p, grad] : BodyRowGradient(nm.rows[i], data.r)) force[{b, p}] += grad * lambda[i] * u;
  }
  for (const PointForce& f : m.forces) {
    if (!f.IsConstantWorld()) continue;  // with the elements below
    const int b = FirstHolder(m, f.point);
    if (b >= 0) force[{b, f.point}] -= f.f_W;
    scale = std::max(scale, f.f_W.norm());
  }
  for (const ElementPointForce& f : ElementPointForces(nm, q, qd, m.analysis.t0)) {
    const int b = f.body >= 0 ? f.body : FirstHolder(m, f.point);
    if (b >= 0 && force.count({b, f.point})) force[{b, f.point}] -= f.f_W;
    scale = std::max(scale, f.f_W.norm());
  }
  for (const auto& [key, f] : force) scale = std::max(scale, f.norm());

  // Rows that belong to no body: a pin they touch is left out unless their multiplier vanishes.
  EvalJacobian(nm, data, q);
  std::set<int> tainted;
  for (int i = 0; i < nm.m(); ++i) {
    const ConstraintRow& row = nm.rows[i];
    if (IsBodyRow(row.kind) || row.kind == RowKind::kPointOnLine) continue;  // sliders: left out by the rule
    double w = 0;
    if (data.sparse) {
      for (SparseJacobian::Matrix::InnerIterator it(data.jac.J(), i); it; ++it) w = std::max(w, std::fabs(it.value() * lambda[i]));
      w *= u;
    } else {
      w = (data.Phi_q.row(i) * lambda[i]).cwiseAbs().maxCoeff() * u;
    }
    if (!(w <= 1e-9 * scale)) {
      for (int p : row.pts)
        if (p >= 0) tainted.insert(p);
      for (int p : row.ref)
        if (p >= 0) tainted.insert(p);
      for (int slot : row.slots)  // a coupling acts on point coordinates directly (a rack's x)
        if (slot >= 0 && nm.model.q_layout[slot].point >= 0) tainted.insert(nm.model.q_layout[slot].point);
      out.notes.push_back(row.Where() + " carries a force (" + Fmt(w, 3) +
                          " N): the points it joins are left out, that force is no pin's");
    }
  }
  for (const PinBody& pin : pins) {
    if (tainted.count(pin.point)) continue;
    out.pins.push_back({pin, force.at({pin.body, pin.point})});
  }
  return out;
}

void AddReactionQuantities(const Model& model, const Reactions& r, Quantities& out) {
  for (const PinReaction& pr : r.pins)
    for (int axis = 0; axis < 2; ++axis)
      out[ReactionName(model.points[pr.pin.point].name, model.bodies[pr.pin.body].name, axis)] = pr.force[axis];
}

EngineReactions EngineReactionQuantities(const std::vector<EngineJointForce>& joints) {
  EngineReactions out;
  for (const EngineJointForce& j : joints)
    if (j.revolute && j.point_name.empty()) {
      out.notes.push_back("no reactions: a revolute joint at point index " + std::to_string(j.point) + " has no point name");
      return out;
    }
  std::set<int> slider_points;
  std::set<std::string> guide_bodies;
  std::map<std::string, std::string> coupled_bodies;  // body -> the coupling acting on its joint
  for (const EngineJointForce& j : joints)
    if (!j.coupling.empty())
      for (const std::string& b : {j.parent, j.child})
        if (!b.empty()) coupled_bodies.emplace(b, j.coupling);
  for (const EngineJointForce& j : joints)
    if (!j.revolute) {
      slider_points.insert(j.point);
      if (!j.parent.empty()) guide_bodies.insert(j.parent);
      if (!j.child.empty()) guide_bodies.insert(j.child);
    }
  // Per point: the Model bodies and whether the ground is there; per body: its ground pins.
  std::map<int, std::set<std::string>> links;
  std::map<int, bool> grounded;
  std::map<int, std::string> names;
  std::map<std::string, std::set<int>> ground_pins;
  for (const EngineJointForce& j : joints) {
    if (!j.revolute) continue;
    const auto [it, fresh] = names.emplace(j.point, j.point_name);
    MB_ASSERT(fresh || it->second == j.point_name, "one name per point");
    for (const auto& [name, ground, other] :
         {std::tuple{j.parent, j.parent_ground, j.child}, std::tuple{j.child, j.child_ground, j.parent}}) {
      if (!name.empty()) links[j.point].insert(name);
      if (ground) {
        grounded[j.point] = true;
        if (!other.empty()) ground_pins[other].insert(j.point);
      }
    }
  }
  std::map<std::pair<int, std::string>, Eigen::Vector2d> sum;
  for (const EngineJointForce& j : joints) {
    if (!j.revolute) continue;
    if (!j.child.empty()) sum.try_emplace({j.point, j.child}, Eigen::Vector2d::Zero()).first->second += j.on_child;
    if (!j.parent.empty()) sum.try_emplace({j.point, j.parent}, Eigen::Vector2d::Zero()).first->second -= j.on_child;
  }
  for (const auto& [key, f] : sum) {
    const auto& [p, body] = key;
    if (links[p].size() + (grounded[p] ? 1 : 0) < 2) continue;  // not a pin of the model
    if (slider_points.count(p)) {
      out.notes.push_back("point " + names[p] + ": a slider's point (sliders are left out)");
      continue;
    }
    if (guide_bodies.count(body)) {
      out.notes.push_back("body " + body + " at " + names[p] + ": a slider's guide body (left out as in natural coordinates)");
      continue;
    }
    if (const auto c = coupled_bodies.find(body); c != coupled_bodies.end()) {
      out.notes.push_back("body " + body + " at " + names[p] + ": " + c->second +
                          " acts on it as a force on its joint's coordinate (the engine couples two joint "
                          "coordinates, with no tooth force at a pitch point), so its pin's reaction cannot "
                          "be told apart from the tooth force");
      continue;
    }
    if (ground_pins[body].size() >= 2) {
      out.notes.push_back("body " + body + " at " + names[p] + ": two or more fixed points (part of the ground)");
      continue;
    }
    for (int axis = 0; axis < 2; ++axis) out.quantities[ReactionName(names[p], body, axis)] = f[axis];
  }
  // A slider's point on one body (a rack's, a block's on its guide) is no pin, so the loop above
  // passes it by; its force from the guide is left out all the same, and says so.
  std::set<std::string> said;
  for (const EngineJointForce& j : joints) {
    if (j.revolute || j.point_name.empty() || !said.insert(j.point_name).second) continue;
    if (links[j.point].size() + (grounded[j.point] ? 1 : 0) >= 2) continue;  // a pin's point: noted above
    const std::string& body = j.child.empty() ? j.parent : j.child;
    out.notes.push_back("point " + j.point_name + ": a slider's point (sliders are left out: the force of its guide" +
                        (body.empty() ? std::string() : " on " + body) + " is not a pin's reaction)");
  }
  return out;
}

}  // namespace mechbench::numeric
