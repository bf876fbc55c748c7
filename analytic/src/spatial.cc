#include "mechbench/analytic/spatial.h"

#include "mechbench/analytic/linkage.h"  // AssemblyError
#include "mechbench/errors.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

namespace mechbench::analytic {

namespace {

constexpr double kLoopTwoPi = 2 * std::numbers::pi;
const std::string kLoopOnly = "no closed form for this spatial mechanism (RSSR and spatial slider-crank only): ";

std::string LoopNum(double x) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6g", x);
  return buf;
}

// rel turned by delta about the unit vector u (Rodrigues).
Vec3 LoopTurn(const Vec3& u, double delta, const Vec3& rel) {
  const Vec3 par = u.dot(rel) * u;
  return par + std::cos(delta) * (rel - par) + std::sin(delta) * Cross(u, rel);
}

// Of a ± b, the one nearest `target` (a crank's turn: modulo 2π), as the sign of b.
int NearestSign(double a, double b, double target, bool angle) {
  const auto dist = [&](double x) { return std::fabs(angle ? std::remainder(x - target, kLoopTwoPi) : x - target); };
  return dist(a + b) <= dist(a - b) ? 1 : -1;
}

}  // namespace

SpatialLoopSolver::SpatialLoopSolver(const Model& m) : m_(m) {
  MB_ASSERT(m.kind == ScenarioKind::kSpatial, "SpatialLoopSolver on a planar scene");
  why_not_ = Recognise();
  if (!why_not_) why_not_ = CheckDriver();
}

std::optional<std::string> SpatialLoopSolver::Recognise() {
  const SpatialModel& sm = m_.spatial;
  const auto& E = sm.entities;
  const auto name = [&](int e) { return "'" + E[e].name + "'"; };
  path_of_.assign(E.size(), -1);
  std::vector<SpatialPath> paths;
  std::vector<std::array<int, 2>> bars;
  for (size_t b = 0; b < sm.bodies.size(); ++b) {
    const SpatialBody& body = sm.bodies[b];
    const std::vector<int>& es = body.entities;
    if (es.size() == 1) continue;  // a point mass: no rows, it moves with its point
    if (es.size() == 2) {          // a bar
      if (E[es[0]].fixed || E[es[1]].fixed)
        return kLoopOnly + std::string("bar '") + body.name + "' has a fixed end (a point on a sphere)";
      bars.push_back({es[0], es[1]});
      continue;
    }
    SpatialPath p;
    p.body = static_cast<int>(b);
    int fixed = 0;
    for (int e : es) {
      if (!E[e].fixed) {
        p.moving.push_back(e);
        continue;
      }
      ++fixed;
      (E[e].vector ? p.axis : p.origin) = e;
    }
    if (fixed != 2 || p.origin < 0 || p.axis < 0)
      return kLoopOnly + std::string("body '") + body.name +
             "' does not turn about a fixed axis (a crank carries one fixed point and one fixed vector, the rest moving)";
    paths.push_back(p);
  }
  for (const SpatialJoint& j : sm.joints) {
    if (j.type == SpatialJoint::Type::kDot) return kLoopOnly + std::string("a dot joint ('") + j.name + "')";
    if (E[j.a[0]].fixed || E[j.a[1]].fixed)
      return kLoopOnly + std::string("distance joint '") + j.name + "' has a fixed end (a point on a sphere)";
    bars.push_back({j.a[0], j.a[1]});
  }
  for (size_t c = 0; c < sm.coordinates.size(); ++c) {
    const SpatialCoordinate& co = sm.coordinates[c];
    if (co.type != SpatialCoordinate::Type::kAlong) continue;
    if (!E[co.from].fixed || !E[co.direction].fixed || E[co.point].fixed)
      return kLoopOnly + std::string("'") + co.name + "' is not a point sliding on a fixed line (fixed `from` and `direction`)";
    SpatialPath p;
    p.crank = false;
    p.origin = co.from, p.axis = co.direction, p.end = co.point, p.coordinate = static_cast<int>(c);
    p.moving = {co.point};
    p.x_file = (E[co.point].r_W - E[co.from].r_W).dot(E[co.direction].r_W);
    paths.push_back(p);
  }
  if (bars.size() != 1)
    return kLoopOnly + std::to_string(bars.size()) + " bars or distance joints (the loop has exactly one, spherical at both ends)";
  if (paths.size() != 2) {
    const auto count = [&](bool crank, const std::string& word) {
      const auto n = std::count_if(paths.begin(), paths.end(), [&](const SpatialPath& p) { return p.crank == crank; });
      return std::to_string(n) + " " + word + (n == 1 ? "" : "s");
    };
    return kLoopOnly + count(true, "crank") + " and " + count(false, "slider") +
           " (the loop has two: crank–crank or crank–slider)";
  }
  for (int k = 0; k < 2; ++k)
    for (int e : paths[k].moving) {
      if (path_of_[e] >= 0) return kLoopOnly + name(e) + " is on two cranks or sliders";
      path_of_[e] = k;
    }
  for (size_t e = 0; e < E.size(); ++e)
    if (!E[e].fixed && path_of_[e] < 0) return kLoopOnly + name(static_cast<int>(e)) + " is on no crank or slider";
  const int k0 = path_of_[bars[0][0]], k1 = path_of_[bars[0][1]];
  if (k0 == k1) return kLoopOnly + "the bar " + name(bars[0][0]) + "–" + name(bars[0][1]) + " does not join the two paths";
  for (int i = 0; i < 2; ++i) {
    SpatialPath& p = paths[path_of_[bars[0][i]]];
    if (p.crank) p.end = bars[0][i];
    else if (p.end != bars[0][i]) return kLoopOnly + "the bar does not end at the slider's point " + name(p.end);
    if (p.crank) {
      const Vec3 u = E[p.axis].r_W, rel = E[p.end].r_W - E[p.origin].r_W;
      if ((rel - u.dot(rel) * u).norm() <= 1e-9 * (1 + rel.norm()))
        return kLoopOnly + "the bar's end " + name(p.end) + " is on its crank's axis";
    }
  }
  length_ = (E[bars[0][1]].r_W - E[bars[0][0]].r_W).norm();
  if (!(length_ > 0)) return kLoopOnly + "the bar has no length";
  path_[0] = paths[0], path_[1] = paths[1];
  // Angle coordinates: a crank's joint angle, about its axis, between a fixed vector and one on it.
  coord_path_.assign(sm.coordinates.size(), -1);
  coord_sign_.assign(sm.coordinates.size(), 0);
  for (size_t c = 0; c < sm.coordinates.size(); ++c) {
    const SpatialCoordinate& co = sm.coordinates[c];
    if (co.type == SpatialCoordinate::Type::kAlong) {
      coord_path_[c] = path_[0].coordinate == static_cast<int>(c) ? 0 : 1;
      coord_sign_[c] = 1;
      continue;
    }
    for (int k = 0; k < 2; ++k) {
      if (!path_[k].crank || path_[k].axis != co.direction) continue;
      if (path_of_[co.to] == k && E[co.from].fixed) coord_path_[c] = k, coord_sign_[c] = 1;
      if (path_of_[co.from] == k && E[co.to].fixed) coord_path_[c] = k, coord_sign_[c] = -1;
    }
    if (coord_path_[c] < 0)
      return kLoopOnly + std::string("angle '") + co.name +
             "' is not a crank's turn (about its fixed axis, from a fixed vector to one on the crank or back)";
  }
  return std::nullopt;
}

std::optional<std::string> SpatialLoopSolver::CheckDriver() {
  if (m_.drivers.size() != 1)
    return m_.drivers.empty() ? std::string("no drivers: the closed forms are kinematic (a free scene needs forward dynamics)")
                              : std::string("more than one driver (the loop has one degree of freedom)");
  const Driver& dr = m_.drivers[0];
  driver_slot_ = m_.SlotIndex(dr.coordinate);
  MB_ASSERT(driver_slot_ >= 0, "the loader checks a driver's coordinate");
  const Model::Slot& sl = m_.q_layout[driver_slot_];
  int input = -1;
  if (sl.spatial_coordinate >= 0) {
    const SpatialCoordinate& co = m_.spatial.coordinates[sl.spatial_coordinate];
    input = coord_path_[sl.spatial_coordinate];
    driver_kind_ = co.IsAngle() ? 1 : 0;
    angle_sign_ = coord_sign_[sl.spatial_coordinate], angle_file_ = co.value;
  } else {
    MB_ASSERT(sl.entity >= 0, "a spatial slot is an entity's or a coordinate's");
    input = path_of_[sl.entity];
    driver_kind_ = 2;
    driven_entity_ = sl.entity, driven_axis_ = sl.axis;
  }
  MB_ASSERT(input >= 0, "every moving entity and coordinate is on a path");
  if (input == 1) {
    std::swap(path_[0], path_[1]);
    for (int& k : path_of_)
      if (k >= 0) k = 1 - k;
    for (int& k : coord_path_)
      if (k >= 0) k = 1 - k;
  }
  if (driver_kind_ != 2) return std::nullopt;
  // A slot: x = k0 + k1 cos δ + k2 sin δ on a crank (x' = 0 at its two ends), x = F + s d on a slider.
  const double r = SlotReach();
  if (!(r > 1e-9 * (1 + m_.LengthScale())))
    return "driver on " + dr.coordinate + ": that component does not move with the input (it cannot give the input's motion)";
  if (!path_[0].crank) return std::nullopt;
  // On a crank the slot gives the turn only on one side of its range's ends (x' ≠ 0): the law
  // must stay inside the range and be monotonic over the motion (a turn through an end would
  // reverse the law's rate there; so does a rocking crank, which the slot cannot tell apart).
  const int n = m_.analysis.HasMotion() ? m_.analysis.samples : 1;
  double t_up = kNaN, t_down = kNaN;
  for (int k = 0; k < n; ++k) {
    const double t = m_.analysis.TimeAt(k);
    const Jet2 j = dr.JetAt(t, m_.analysis.t0);
    const double u = (j.v - SlotCentre()) / r;
    if (!(std::fabs(u) < 1 - 1e-9))
      return "driver on " + dr.coordinate + ": at t = " + LoopNum(t) + " s it is " + LoopNum(j.v) +
             ", at or past the end of its range " + LoopNum(SlotCentre()) + " ± " + LoopNum(r) +
             " on the crank, where it no longer gives the crank's turn: drive an angle coordinate instead";
    if (j.d > 1e-12 * r && t_up != t_up) t_up = t;
    if (j.d < -1e-12 * r && t_down != t_down) t_down = t;
  }
  if (t_up == t_up && t_down == t_down)
    return "driver on " + dr.coordinate + ": not monotonic over the motion (rising at t = " + LoopNum(t_up) +
           " s, falling at t = " + LoopNum(t_down) +
           " s), so it does not tell which way the crank turns: drive an angle coordinate instead";
  return std::nullopt;
}

// The driven slot's component on a crank as k0 + k1 cos δ + k2 sin δ (a slider: its direction's).
void SpatialLoopSolver::SlotTerms(double& k0, double& k1, double& k2) const {
  const auto& E = m_.spatial.entities;
  const SpatialPath& p = path_[0];
  const Vec3 u = E[p.axis].r_W, base = E[driven_entity_].vector ? Vec3::Zero() : E[p.origin].r_W;
  if (!p.crank) {
    k0 = E[p.origin].r_W[driven_axis_], k1 = u[driven_axis_], k2 = 0;
    return;
  }
  const Vec3 rel = E[driven_entity_].r_W - base, par = u.dot(rel) * u;
  k0 = base[driven_axis_] + par[driven_axis_];
  k1 = (rel - par)[driven_axis_];
  k2 = Cross(u, rel)[driven_axis_];
}

double SpatialLoopSolver::SlotReach() const {
  double k0, k1, k2;
  SlotTerms(k0, k1, k2);
  return std::hypot(k1, k2);
}

double SpatialLoopSolver::SlotCentre() const {
  double k0, k1, k2;
  SlotTerms(k0, k1, k2);
  return k0;
}

std::string SpatialLoopSolver::Describe() const {
  const auto& sm = m_.spatial;
  const auto& E = sm.entities;
  const auto path = [&](const SpatialPath& p) {
    return p.crank ? "crank '" + sm.bodies[p.body].name + "' about " + E[p.axis].name + " through " + E[p.origin].name
                   : "slider " + E[p.end].name + " on the line through " + E[p.origin].name + " along " + E[p.axis].name;
  };
  const std::string kind = path_[0].crank && path_[1].crank   ? "RSSR four-bar"
                           : path_[0].crank || path_[1].crank ? "spatial slider-crank"
                                                              : "spatial double slider";
  return kind + ": input " + path(path_[0]) + ", output " + path(path_[1]) + ", bar " + E[path_[0].end].name + "–" +
         E[path_[1].end].name + " (length " + LoopNum(length_) + "); " +
         (path_[1].crank ? "A cos φ + B sin φ = C" : "s² + 2 s d·(F − B) + |F − B|² = L²") +
         ", rates by differentiating |C − B|² = L²";
}

void SpatialLoopSolver::End(int k, double x, Vec3& p, Vec3& d1, Vec3& d2) const {
  const auto& E = m_.spatial.entities;
  const SpatialPath& pa = path_[k];
  const Vec3 o = E[pa.origin].r_W, u = E[pa.axis].r_W;
  if (!pa.crank) {
    p = o + x * u, d1 = u, d2 = Vec3::Zero();
    return;
  }
  const Vec3 w = LoopTurn(u, x, E[pa.end].r_W - o);
  p = o + w, d1 = Cross(u, w), d2 = Cross(u, d1);
}

bool SpatialLoopSolver::Input(double t, const SpatialLoopState* prev, SpatialLoopState& s, std::string& why) const {
  const Driver& dr = m_.drivers[0];
  const Jet2 j = dr.JetAt(t, m_.analysis.t0);
  if (driver_kind_ == 0) {
    s.x[0] = j.v, s.xd[0] = j.d, s.xdd[0] = j.dd;
    return true;
  }
  if (driver_kind_ == 1) {
    s.x[0] = angle_sign_ * (j.v - angle_file_), s.xd[0] = angle_sign_ * j.d, s.xdd[0] = angle_sign_ * j.dd;
    return true;
  }
  double k0, k1, k2;
  SlotTerms(k0, k1, k2);
  if (!path_[0].crank) {  // x = k0 + k1 s
    s.x[0] = (j.v - k0) / k1, s.xd[0] = j.d / k1, s.xdd[0] = j.dd / k1;
    return true;
  }
  const double r = std::hypot(k1, k2), c = (j.v - k0) / r;
  if (!(std::fabs(c) <= 1)) {
    why = dr.coordinate + " = " + LoopNum(j.v) + " is out of its range " + LoopNum(k0) + " ± " + LoopNum(r);
    return false;
  }
  const double mid = std::atan2(k2, k1), half = std::acos(c);
  s.branch_in = prev ? prev->branch_in : NearestSign(mid, half, 0, true);
  const double ref = prev ? prev->x[0] : 0;
  const double d = mid + s.branch_in * half;
  s.x[0] = ref + std::remainder(d - ref, kLoopTwoPi);
  const double x1 = -k1 * std::sin(s.x[0]) + k2 * std::cos(s.x[0]), x2 = -(j.v - k0);
  if (!(std::fabs(x1) > 1e-12 * r)) {
    why = dr.coordinate + " is at the end of its range (it no longer gives the crank's turn)";
    return false;
  }
  s.xd[0] = j.d / x1;
  s.xdd[0] = (j.dd - x2 * s.xd[0] * s.xd[0]) / x1;
  return true;
}

SpatialLoopState SpatialLoopSolver::Solve(double t, const SpatialLoopState* prev) const {
  MB_ASSERT(!why_not_, "Solve on a scene the closed forms do not describe");
  const auto& E = m_.spatial.entities;
  const SourceRef& where = m_.drivers[0].src;
  SpatialLoopState s;
  s.t = t;
  std::string why;
  if (!Input(t, prev, s, why)) throw AssemblyError(where, why, "keep the driver inside the input's range");
  Vec3 B, B1, B2;
  End(0, s.x[0], B, B1, B2);
  const Vec3 Bd = B1 * s.xd[0], Bdd = B1 * s.xdd[0] + B2 * s.xd[0] * s.xd[0];
  const SpatialPath& out = path_[1];
  const Vec3 o = E[out.origin].r_W, u = E[out.axis].r_W;
  const double L = length_;
  double mid, half;
  if (out.crank) {  // |g + cos δ e + sin δ f|² = L², g the circle's centre − B
    const Vec3 rel = E[out.end].r_W - o, par = u.dot(rel) * u, e = rel - par, f = Cross(u, e), g = o + par - B;
    const double A = 2 * g.dot(e), Bs = 2 * g.dot(f), C = L * L - g.squaredNorm() - e.squaredNorm();
    const double R = std::hypot(A, Bs);
    if (!(std::fabs(C) <= R))
      throw AssemblyError(where, "the bar cannot reach the output crank's circle (|C| = " + LoopNum(std::fabs(C)) +
                                     " > √(A² + B²) = " + LoopNum(R) + ")",
                          "check the lengths and the driver's range", true);
    mid = std::atan2(Bs, A), half = std::acos(C / R);
  } else {  // s² + 2 s d·h + |h|² − L² = 0, h = F − B
    const Vec3 h = o - B;
    const double dh = u.dot(h), disc = dh * dh - h.squaredNorm() + L * L;
    if (!(disc >= 0))
      throw AssemblyError(where, "the bar cannot reach the slider's line (discriminant " + LoopNum(disc) + ")",
                          "check the lengths and the driver's range", true);
    mid = -dh, half = std::sqrt(disc);
  }
  s.branch_out = prev ? prev->branch_out : NearestSign(mid, half, out.x_file, out.crank);
  const double x = mid + s.branch_out * half;
  const double ref = prev ? prev->x[1] : out.x_file;
  s.x[1] = out.crank ? ref + std::remainder(x - ref, kLoopTwoPi) : x;
  Vec3 C, C1, C2;
  End(1, s.x[1], C, C1, C2);
  const Vec3 r = C - B;
  const double den = r.dot(C1);
  if (!(std::fabs(den) > 1e-12 * r.norm() * C1.norm()))
    throw AssemblyError(where, "the output is at a dead point (the bar is square to its path)",
                        "keep the motion away from the output's dead points");
  s.xd[1] = r.dot(Bd) / den;
  const Vec3 rd = C1 * s.xd[1] - Bd;
  s.xdd[1] = (r.dot(Bdd) - s.xd[1] * s.xd[1] * r.dot(C2) - rd.squaredNorm()) / den;
  s.residual = std::fabs(r.norm() - L);
  s.residual_rate = std::fabs(r.dot(rd)) / L;
  return s;
}

PointState3 SpatialLoopSolver::Entity(const SpatialLoopState& s, int entity) const {
  const auto& E = m_.spatial.entities;
  PointState3 st;
  st.p = E[entity].r_W;
  const int k = path_of_[entity];
  if (k < 0) return st;  // fixed: at rest
  const SpatialPath& p = path_[k];
  const Vec3 u = E[p.axis].r_W;
  const double x = s.x[k], xd = s.xd[k], xdd = s.xdd[k];
  if (!p.crank) {
    st.p = E[p.origin].r_W + x * u, st.v = xd * u, st.a = xdd * u;
    return st;
  }
  const Vec3 base = E[entity].vector ? Vec3::Zero() : E[p.origin].r_W;
  const Vec3 w = LoopTurn(u, x, E[entity].r_W - base), d1 = Cross(u, w), d2 = Cross(u, d1);
  st.p = base + w, st.v = d1 * xd, st.a = d1 * xdd + d2 * xd * xd;
  return st;
}

void SpatialLoopSolver::ToLayout(const SpatialLoopState& s, Eigen::VectorXd& q, Eigen::VectorXd& qd,
                                 Eigen::VectorXd& qdd) const {
  const size_t n = m_.q_layout.size();
  q.resize(n), qd.resize(n), qdd.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const Model::Slot& sl = m_.q_layout[i];
    if (sl.entity >= 0) {
      const PointState3 e = Entity(s, sl.entity);
      q[i] = e.p[sl.axis], qd[i] = e.v[sl.axis], qdd[i] = e.a[sl.axis];
      continue;
    }
    const int c = sl.spatial_coordinate;
    MB_ASSERT(c >= 0, "a spatial slot is an entity's or a coordinate's");
    const int k = coord_path_[c];
    const double sg = coord_sign_[c];
    const double file = m_.spatial.coordinates[c].IsAngle() ? m_.spatial.coordinates[c].value : 0;
    q[i] = file + sg * s.x[k], qd[i] = sg * s.xd[k], qdd[i] = sg * s.xdd[k];
  }
}

}  // namespace mechbench::analytic
