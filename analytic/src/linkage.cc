#include "mechbench/analytic/linkage.h"

#include "mechbench/errors.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>
#include <optional>

namespace mechbench::analytic {

namespace {

constexpr double kPi = std::numbers::pi;

// x + 2πk nearest to target.
double WrapNear(double x, double target) { return x + 2 * kPi * std::round((target - x) / (2 * kPi)); }

double Angle(const Vec2& r) { return std::atan2(r.y(), r.x()); }

Vec2 Rotate(const Vec2& r, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  return Vec2(c * r.x() - s * r.y(), s * r.x() + c * r.y());
}

int IndexInBody(const Body& b, int point) {
  for (size_t i = 0; i < b.points.size(); ++i)
    if (b.points[i] == point) return static_cast<int>(i);
  return -1;
}

// Constant distance between two points of one body, if some body holds both.
std::optional<double> BodyDistance(const Model& m, int i, int j, int* body = nullptr) {
  for (size_t b = 0; b < m.bodies.size(); ++b) {
    const int ii = IndexInBody(m.bodies[b], i), jj = IndexInBody(m.bodies[b], j);
    if (ii >= 0 && jj >= 0) {
      if (body) *body = static_cast<int>(b);
      return (m.bodies[b].p_B[ii] - m.bodies[b].p_B[jj]).norm();
    }
  }
  return std::nullopt;
}

// Is body point k on the line through the body's points l0, l1 (body frame)?
bool OnBodyLine(const Body& b, int k, int l0, int l1) {
  const Vec2 d = b.p_B[l1] - b.p_B[l0];
  const Vec2 r = b.p_B[k] - b.p_B[l0];
  return std::fabs(Cross2(d, r)) <= 1e-9 * d.squaredNorm();
}

struct Triangle {
  int coordinate, driver, P, R;  // far ends of the two bars
  double la, lb, sign;
};

// Triangles made rigid by a driven relative angle between two bars that share a point.
std::vector<Triangle> FindTriangles(const Model& m, const std::vector<int>& coord_driver) {
  std::vector<Triangle> out;
  for (size_t c = 0; c < m.coordinates.size(); ++c) {
    const Coordinate& co = m.coordinates[c];
    if (co.type != CoordinateType::kAngle || co.ref[0] < 0 || coord_driver[c] < 0) continue;
    if (co.form != AngleForm::kDot && co.form != AngleForm::kCross) continue;
    int S = -1;
    for (int r : co.ref)
      for (int v : co.vec)
        if (r == v) S = r;
    if (S < 0) continue;
    const int P = co.ref[0] == S ? co.ref[1] : co.ref[0];
    const int R = co.vec[0] == S ? co.vec[1] : co.vec[0];
    const auto la = BodyDistance(m, S, P), lb = BodyDistance(m, S, R);
    if (!la || !lb || P == R) continue;
    // The bars' vectors point away from S (+1) or towards it (−1).
    const double s_ref = co.ref[0] == S ? 1.0 : -1.0, s_vec = co.vec[0] == S ? 1.0 : -1.0;
    out.push_back({static_cast<int>(c), coord_driver[c], P, R, *la, *lb, s_ref * s_vec});
  }
  return out;
}

// A driver's coordinate, or the coordinate a coupled input sets (driver index past the drivers).
std::string DrivenText(const Model& m, const std::vector<CoupledInput>& coupled, int d) {
  const int nd = static_cast<int>(m.drivers.size());
  if (d < nd) return "driven " + m.drivers[d].coordinate;
  const CoupledInput& in = coupled[d - nd];
  return m.q_layout[in.to].name + " by " + m.couplings[in.coupling].name;
}

std::string LineText(const Model& m, const std::vector<CoupledInput>& coupled, const LineSource& l) {
  switch (l.kind) {
    case LineSource::Kind::kFixedGuide:
      return "guide " + m.points[m.joints[l.joint].line[0]].name + "-" + m.points[m.joints[l.joint].line[1]].name;
    case LineSource::Kind::kDrivenX:
    case LineSource::Kind::kDrivenY: return DrivenText(m, coupled, l.driver);
    case LineSource::Kind::kBodySlider: return "line of " + m.bodies[m.joints[l.joint].body].name;
  }
  return "?";
}

std::string DistText(const Model& m, const DistanceSource& d) {
  const std::string from = m.points[d.from].name;
  switch (d.kind) {
    case DistanceSource::Kind::kBody: return from + " (" + m.bodies[d.body].name + ")";
    case DistanceSource::Kind::kDrivenDistance: return from + " (driven " + m.coordinates[d.coordinate].name + ")";
    case DistanceSource::Kind::kTriangle: return from + " (triangle of driven " + m.coordinates[d.coordinate].name + ")";
  }
  return "?";
}

// A body that cannot turn: two of its points (at distinct body positions) on parallel fixed
// guides. Its angle ψ then solves (R(ψ) d_B)·n = h, d_B the two points' body-frame offset, n the
// guides' normal and h the guides' offset along it: two roots, the one the drawing shows is kept.
std::optional<double> FixedOrientation(const Model& m, int b) {
  const Body& body = m.bodies[b];
  std::vector<std::pair<int, int>> guided;  // (index in body, joint)
  for (size_t j = 0; j < m.joints.size(); ++j) {
    const Joint& jt = m.joints[j];
    if (jt.type != JointType::kPointOnFixedLine) continue;
    const int i = IndexInBody(body, jt.point);
    if (i >= 0) guided.emplace_back(i, static_cast<int>(j));
  }
  for (size_t u = 0; u < guided.size(); ++u)
    for (size_t w = u + 1; w < guided.size(); ++w) {
      const auto [i, ji] = guided[u];
      const auto [k, jk] = guided[w];
      const Vec2 d_B = body.p_B[k] - body.p_B[i];
      const double d = d_B.norm();
      if (!(d > 0)) continue;
      const Joint &gi = m.joints[ji], &gk = m.joints[jk];
      const Vec2 oi = m.points[gi.line[0]].p_W, ok = m.points[gk.line[0]].p_W;
      const Vec2 ei = Unit(Vec2(m.points[gi.line[1]].p_W - oi)), ek = Unit(Vec2(m.points[gk.line[1]].p_W - ok));
      if (std::fabs(Cross2(ei, ek)) > 1e-12) continue;
      const double h = (ok - oi).dot(Perp(ei));
      if (!(std::fabs(h) <= d)) continue;
      const double gamma = Angle(ei), s = std::asin(h / d);
      const double drawn = Angle(Vec2(m.points[body.points[k]].p_W - m.points[body.points[i]].p_W));
      double beta = gamma + s;
      const double other = gamma + kPi - s;
      if (std::fabs(std::remainder(other - drawn, 2 * kPi)) < std::fabs(std::remainder(beta - drawn, 2 * kPi))) beta = other;
      return beta - Angle(d_B);
    }
  return std::nullopt;
}

}  // namespace

void DirectionRates(const Vec2& r, const Vec2& rd, const Vec2& rdd, double& phi_d, double& phi_dd) {
  const double r2 = r.squaredNorm();
  phi_d = Cross2(r, rd) / r2;
  phi_dd = (Cross2(r, rdd) - 2 * r.dot(rd) * phi_d) / r2;
}

std::vector<FormBranch> FormBranches(AngleForm form) {
  switch (form) {
    case AngleForm::kCross: return {{1, 0}, {1, kPi}};
    case AngleForm::kDot: return {{1, 0}, {-1, 0}};
    case AngleForm::kCos: return {{1, 0}, {-1, 0}};
    case AngleForm::kSin: return {{1, 0}, {-1, kPi}};
    case AngleForm::kCosSin: return {{1, 0}};
  }
  return {{1, 0}};
}

// ---------------------------------------------------------------------------------------------
// Planning: which closed form determines what, from the model alone.

std::optional<LinkagePlan> PlanLinkage(const Model& m, std::string* why_not) {
  auto fail = [&](const std::string& why) -> std::optional<LinkagePlan> {
    if (why_not) *why_not = why;
    return std::nullopt;
  };
  if (m.kind != ScenarioKind::kLinkage) return fail("not a linkage");
  if (m.drivers.empty())
    return fail("no drivers: the vector method needs prescribed inputs, and this scene moves under its loads "
                "(forward dynamics)");
  const int np = static_cast<int>(m.points.size()), nb = static_cast<int>(m.bodies.size());

  // Which drivers prescribe which point coordinate or relative coordinate.
  std::vector<std::array<int, 2>> axis_driver(np, {-1, -1});
  std::vector<int> coord_driver(m.coordinates.size(), -1);
  for (size_t d = 0; d < m.drivers.size(); ++d) {
    const int slot = m.SlotIndex(m.drivers[d].coordinate);
    if (slot < 0) return fail("driver " + m.drivers[d].coordinate + " names no coordinate");
    const Model::Slot& s = m.q_layout[slot];
    if (s.point >= 0) axis_driver[s.point][s.axis] = static_cast<int>(d);
    else coord_driver[s.coordinate] = static_cast<int>(d);
  }
  const std::vector<Triangle> triangles = FindTriangles(m, coord_driver);

  LinkagePlan plan;
  plan.driver_used.assign(m.drivers.size(), false);
  plan.slot_driver.assign(m.q_layout.size(), -1);
  for (size_t d = 0; d < m.drivers.size(); ++d) plan.slot_driver[m.SlotIndex(m.drivers[d].coordinate)] = static_cast<int>(d);
  std::vector<bool> coupling_used(m.couplings.size(), false);
  std::vector<std::optional<double>> orientation(nb);
  for (int b = 0; b < nb; ++b) orientation[b] = FixedOrientation(m, b);
  std::vector<bool> known(np, false), placed(nb, false);
  for (int i = 0; i < np; ++i) known[i] = m.points[i].fixed;
  auto name = [&](int p) { return m.points[p].name; };

  auto place = [&](Step st) {
    placed[st.body] = true;
    for (int p : m.bodies[st.body].points) known[p] = true;
    plan.steps.push_back(std::move(st));
  };

  // A slot's value is known once its point is known, or once a driver or coupling sets it.
  auto slot_known = [&](int slot) {
    const Model::Slot& sl = m.q_layout[slot];
    return (sl.point >= 0 && known[sl.point]) || plan.slot_driver[slot] >= 0;
  };
  for (bool progress = true; progress;) {
    progress = false;
    // Couplings: a known coordinate drives the other one, like a driver whose law is read from the
    // solved state (a driven pinion moves its rack, a rack placed by a dyad turns its pinion).
    for (size_t c = 0; c < m.couplings.size() && !progress; ++c) {
      if (coupling_used[c]) continue;
      const Coupling& cp = m.couplings[c];
      for (int dir = 0; dir < 2 && !progress; ++dir) {
        const int from = cp.slots[dir], to = cp.slots[1 - dir];
        if (!slot_known(from) || slot_known(to)) continue;
        CoupledInput in;
        in.coupling = static_cast<int>(c), in.from = from, in.to = to;
        in.k = dir == 0 ? cp.ratio : 1 / cp.ratio;
        in.c = dir == 0 ? cp.offset : -cp.offset / cp.ratio;
        const int id = static_cast<int>(m.drivers.size() + plan.coupled.size());
        plan.coupled.push_back(in);
        plan.driver_used.push_back(false);
        plan.slot_driver[to] = id;
        const Model::Slot& sl = m.q_layout[to];
        if (sl.point >= 0) axis_driver[sl.point][sl.axis] = id;
        else coord_driver[sl.coordinate] = id;
        coupling_used[c] = true;
        progress = true;
      }
    }
    if (progress) continue;
    // Bodies first: placing one makes all its points known without a branch.
    for (int b = 0; b < nb && !progress; ++b) {
      const Body& body = m.bodies[b];
      if (placed[b] || body.points.size() < 2) continue;
      std::vector<int> kp;
      for (int p : body.points)
        if (known[p]) kp.push_back(p);
      if (kp.empty()) continue;
      const int K = kp[0];
      if (kp.size() >= 2) {
        // Two known points at distinct body positions fix the body.
        for (size_t j = 1; j < kp.size() && !progress; ++j) {
          if ((body.p_B[IndexInBody(body, K)] - body.p_B[IndexInBody(body, kp[j])]).norm() == 0) continue;
          Step st;
          st.kind = StepKind::kPlaceByTwoPoints;
          st.body = b, st.known = K, st.other = kp[j];
          st.text = "body " + body.name + " from " + name(K) + ", " + name(kp[j]);
          place(st);
          progress = true;
        }
        if (progress) break;
      }
      // A driven angle along the body, with a known reference direction: the crank.
      for (size_t c = 0; c < m.coordinates.size() && !progress; ++c) {
        const Coordinate& co = m.coordinates[c];
        if (co.type != CoordinateType::kAngle || coord_driver[c] < 0) continue;
        const int i0 = IndexInBody(body, co.vec[0]), i1 = IndexInBody(body, co.vec[1]);
        if (i0 < 0 || i1 < 0 || (body.p_B[i0] - body.p_B[i1]).norm() == 0) continue;
        if (co.ref[0] >= 0 && !(known[co.ref[0]] && known[co.ref[1]])) continue;
        Step st;
        st.kind = StepKind::kPlaceByAngle;
        st.body = b, st.known = K, st.coordinate = static_cast<int>(c), st.driver = coord_driver[c];
        st.text = "body " + body.name + " from " + name(K) + " at angle " + co.name + " (" +
                  DrivenText(m, plan.coupled, coord_driver[c]) + ")";
        plan.driver_used[coord_driver[c]] = true;
        place(st);
        progress = true;
      }
      // A body that cannot turn, with a known point: it translates with that point.
      if (orientation[b] && !progress) {
        Step st;
        st.kind = StepKind::kPlaceByOrientation;
        st.body = b, st.known = K, st.psi = *orientation[b];
        st.text = "body " + body.name + " from " + name(K) + " at its fixed angle (it translates)";
        place(st);
        progress = true;
        break;
      }
      // A known point sliding on the body's line gives its direction: the slotted bar (§3.4).
      for (size_t j = 0; j < m.joints.size() && !progress; ++j) {
        const Joint& jt = m.joints[j];
        if (jt.type != JointType::kPointOnBody || jt.body != b || !known[jt.point]) continue;
        const int l0 = IndexInBody(body, jt.line[0]), l1 = IndexInBody(body, jt.line[1]);
        int Kon = -1;  // a known body point on the line
        for (int p : kp)
          if (OnBodyLine(body, IndexInBody(body, p), l0, l1)) Kon = p;
        if (Kon < 0 || Kon == jt.point) continue;
        Step st;
        st.kind = StepKind::kPlaceBySlider;
        st.body = b, st.known = Kon, st.other = jt.point, st.joint = static_cast<int>(j);
        st.text = "body " + body.name + " from " + name(Kon) + " through slider " + name(jt.point);
        place(st);
        progress = true;
      }
    }
    if (progress) continue;

    // A body that cannot turn and has no known point, but a known point slides along its line and
    // one of its points runs on a fixed guide across that line: the Scotch yoke.
    for (int b = 0; b < nb && !progress; ++b) {
      const Body& body = m.bodies[b];
      if (placed[b] || !orientation[b] || body.points.size() < 2) continue;
      const Vec2 e_b = Rotate(Vec2(body.p_B[1] - body.p_B[0]), *orientation[b]);
      for (size_t j = 0; j < m.joints.size() && !progress; ++j) {
        const Joint& slot = m.joints[j];
        if (slot.type != JointType::kPointOnBody || slot.body != b || !known[slot.point]) continue;
        for (size_t g = 0; g < m.joints.size() && !progress; ++g) {
          const Joint& guide = m.joints[g];
          if (guide.type != JointType::kPointOnFixedLine || IndexInBody(body, guide.point) < 0) continue;
          const Vec2 e_g = m.points[guide.line[1]].p_W - m.points[guide.line[0]].p_W;
          if (!(std::fabs(Cross2(Unit(e_g), Unit(e_b))) > 1e-9)) continue;
          Step st;
          st.kind = StepKind::kPlaceTranslating;
          st.body = b, st.known = guide.point, st.other = slot.point, st.joint = static_cast<int>(j);
          st.psi = *orientation[b];
          st.lines[0] = {LineSource::Kind::kFixedGuide, static_cast<int>(g), -1};
          st.text = "body " + body.name + " translating: " + name(guide.point) + " on its guide, its line through " +
                    name(slot.point);
          place(st);
          progress = true;
        }
      }
    }
    if (progress) continue;

    // Then one point by a dyad.
    for (int P = 0; P < np && !progress; ++P) {
      if (known[P]) continue;
      std::vector<LineSource> lines;
      std::vector<DistanceSource> dists;
      for (size_t j = 0; j < m.joints.size(); ++j) {
        const Joint& jt = m.joints[j];
        if (jt.point != P) continue;
        if (jt.type == JointType::kPointOnFixedLine) lines.push_back({LineSource::Kind::kFixedGuide, static_cast<int>(j), -1});
        if (jt.type == JointType::kPointOnBody && placed[jt.body])
          lines.push_back({LineSource::Kind::kBodySlider, static_cast<int>(j), -1});
      }
      if (axis_driver[P][0] >= 0) lines.push_back({LineSource::Kind::kDrivenX, -1, axis_driver[P][0]});
      if (axis_driver[P][1] >= 0) lines.push_back({LineSource::Kind::kDrivenY, -1, axis_driver[P][1]});
      auto has_from = [&](int q) {
        return std::any_of(dists.begin(), dists.end(), [&](const DistanceSource& d) { return d.from == q; });
      };
      for (int b = 0; b < nb; ++b) {
        const Body& body = m.bodies[b];
        const int iP = IndexInBody(body, P);
        if (iP < 0) continue;
        for (size_t k = 0; k < body.points.size(); ++k) {
          const int q = body.points[k];
          if (q == P || !known[q] || has_from(q)) continue;
          DistanceSource d;
          d.kind = DistanceSource::Kind::kBody, d.from = q, d.body = b;
          d.length = (body.p_B[iP] - body.p_B[k]).norm();
          if (d.length > 0) dists.push_back(d);
        }
      }
      for (size_t c = 0; c < m.coordinates.size(); ++c) {
        const Coordinate& co = m.coordinates[c];
        if (co.type != CoordinateType::kDistance || coord_driver[c] < 0) continue;
        const int q = co.vec[0] == P ? co.vec[1] : co.vec[1] == P ? co.vec[0] : -1;
        if (q < 0 || !known[q] || has_from(q)) continue;
        DistanceSource d;
        d.kind = DistanceSource::Kind::kDrivenDistance, d.from = q, d.coordinate = static_cast<int>(c);
        d.driver = coord_driver[c];
        dists.push_back(d);
      }
      for (const Triangle& t : triangles) {
        const int q = t.P == P ? t.R : t.R == P ? t.P : -1;
        if (q < 0 || !known[q] || has_from(q)) continue;
        DistanceSource d;
        d.kind = DistanceSource::Kind::kTriangle, d.from = q, d.coordinate = t.coordinate, d.driver = t.driver;
        d.la = t.la, d.lb = t.lb, d.sign = t.sign;
        dists.push_back(d);
      }
      Step st;
      st.point = P;
      if (lines.size() >= 2) {
        st.kind = StepKind::kLineLine;
        st.lines = {lines[0], lines[1]};
        st.text = name(P) + " <- line-line (" + LineText(m, plan.coupled, lines[0]) + ", " + LineText(m, plan.coupled, lines[1]) + ")";
      } else if (lines.size() == 1 && !dists.empty()) {
        st.kind = StepKind::kCircleLine;
        st.lines[0] = lines[0];
        st.dists[0] = dists[0];
        st.text = name(P) + " <- RRP (" + LineText(m, plan.coupled, lines[0]) + ", distance from " + DistText(m, dists[0]) + ")";
      } else if (dists.size() >= 2) {
        st.kind = StepKind::kCircleCircle;
        st.dists = {dists[0], dists[1]};
        st.text = name(P) + " <- RRR (" + DistText(m, dists[0]) + ", " + DistText(m, dists[1]) + ")";
      } else {
        continue;
      }
      for (const LineSource& l : st.lines)
        if (l.driver >= 0 && st.kind != StepKind::kCircleCircle) plan.driver_used[l.driver] = true;
      for (int k = 0; k < (st.kind == StepKind::kCircleCircle ? 2 : st.kind == StepKind::kCircleLine ? 1 : 0); ++k)
        if (st.dists[k].driver >= 0) plan.driver_used[st.dists[k].driver] = true;
      known[P] = true;
      plan.steps.push_back(st);
      progress = true;
    }
  }

  for (size_t c = 0; c < m.couplings.size(); ++c) {
    if (coupling_used[c]) continue;
    const Coupling& cp = m.couplings[c];
    if (slot_known(cp.slots[0]) && slot_known(cp.slots[1]))
      return fail(cp.name + " relates " + cp.coordinates[0] + " and " + cp.coordinates[1] +
                  ", which the drivers and closed forms already determine (over-specified)");
    return fail(cp.name + ": neither " + cp.coordinates[0] + " nor " + cp.coordinates[1] +
                " becomes known from the drivers, fixed points and point positions (a coupling from a relative "
                "coordinate that the closed forms compute from points is not written)");
  }
  std::string left;
  for (int p = 0; p < np; ++p)
    if (!known[p]) left += (left.empty() ? "" : ", ") + name(p);
  if (!left.empty())
    return fail("no closed-form decomposition: points " + left +
                " remain (no dyad, crank or slider form determines them from the known points and drivers)");
  for (size_t d = 0; d < m.drivers.size(); ++d)
    if (!plan.driver_used[d])
      return fail("driver " + m.drivers[d].coordinate +
                  " is not used by any closed form (over-specified, or an input the vector method cannot start from)");
  for (size_t i = 0; i < plan.coupled.size(); ++i) {
    if (plan.driver_used[m.drivers.size() + i]) continue;
    const CoupledInput& in = plan.coupled[i];
    // A coupled relative coordinate no step used is still known (it is an output); a point's.
    if (m.q_layout[in.to].point < 0) continue;
    return fail(m.couplings[in.coupling].name + " sets " + m.q_layout[in.to].name +
                ", which no closed form uses (over-specified, or a point the vector method cannot place from it)");
  }
  return plan;
}

// ---------------------------------------------------------------------------------------------
// Evaluation.

LinkageSolver::LinkageSolver(const Model& model) : m_(model) {
  std::string why;
  auto p = PlanLinkage(model, &why);
  if (!p) throw std::invalid_argument(why);
  plan_ = std::move(*p);
  guess_q_ = model.GuessQ();
}

namespace {

// One way of reaching the unknown point: along a line (unknown slip rate λ̇) or on a circle about a
// known point (unknown angular rate of the radius). Each gives v_P = v_known + x·col and
// a_P = a_known(x) + y·col; two of them meet in a 2×2 system (Cramer).
struct Path {
  bool is_line = true;
  // Line: P = o + λ e, the line turning at omega, alpha.
  Vec2 o, v_o, a_o, e;
  double omega = 0, alpha = 0;
  // Circle: |P − c| = d(t).
  Vec2 c, v_c, a_c;
  double d = 0, dd = 0, ddd = 0;

  Vec2 Col(const Vec2& P) const { return is_line ? e : Perp(P - c); }
  Vec2 VKnown(const Vec2& P) const {
    if (is_line) return v_o + (P - o).dot(e) * omega * Perp(e);
    return v_c + dd * Unit(Vec2(P - c));
  }
  Vec2 AKnown(const Vec2& P, double x) const {
    if (is_line) {
      const double lambda = (P - o).dot(e);
      // a_o + α×(λe) + ω×(ω×λe) + 2ω×(λ̇e): the last term is the Coriolis acceleration.
      return a_o + lambda * alpha * Perp(e) - lambda * omega * omega * e + 2 * omega * x * Perp(e);
    }
    const Vec2 r = P - c, er = Unit(r);
    return a_c - x * x * r + ddd * er + 2 * x * dd * Perp(er);
  }
};

}  // namespace

LinkageState LinkageSolver::Solve(double t, const LinkageState* prev) const {
  const Model& m = m_;
  const int np = static_cast<int>(m.points.size()), nb = static_cast<int>(m.bodies.size());
  const double t0 = m.analysis.t0;
  const double dt = prev ? t - prev->t : 0.0;
  LinkageState s;
  s.t = t;
  s.points.assign(np, {});
  s.bodies.assign(nb, {});
  s.q.assign(m.coordinates.size(), kNaN);
  s.qd = s.q;
  s.qdd = s.q;
  s.choice = prev ? prev->choice : std::vector<int>(plan_.steps.size(), 0);
  s.coord_choice = prev ? prev->coord_choice : std::vector<int>(m.coordinates.size(), 0);
  std::vector<bool> have(np, false);
  for (int i = 0; i < np; ++i)
    if (m.points[i].fixed) {
      s.points[i] = {m.points[i].p_W, Vec2::Zero(), Vec2::Zero()};
      have[i] = true;
    }
  auto name = [&](int p) { return m.points[p].name; };
  const int nd = static_cast<int>(m.drivers.size());
  // A driver's law, or a coupled input's: q_to = k q_from + c, q_from from the state solved so far.
  std::function<void(int, double&, double&, double&)> drive = [&](int d, double& x, double& xd, double& xdd) {
    if (d < nd) {
      const Driver& dr = m.drivers[d];
      x = dr.At(t, t0), xd = dr.RateAt(t, t0), xdd = dr.AccelerationAt(t, t0);
      return;
    }
    const CoupledInput& in = plan_.coupled[d - nd];
    const Model::Slot& from = m.q_layout[in.from];
    double f, fd, fdd;
    if (plan_.slot_driver[in.from] >= 0) {
      drive(plan_.slot_driver[in.from], f, fd, fdd);  // a driven coordinate: known before its point is placed
    } else {
      MB_ASSERT(from.point >= 0, "coupled input from an unknown coordinate");
      const PointState2& p = s.points[from.point];  // placed by an earlier step (the planner's order)
      f = p.p[from.axis], fd = p.v[from.axis], fdd = p.a[from.axis];
    }
    x = in.k * f + in.c, xd = in.k * fd, xdd = in.k * fdd;
  };
  // Where a point is expected: its guess at the first sample, else extrapolated from the last.
  auto expect = [&](int p) -> Vec2 {
    if (!prev) return m.points[p].p_W;
    const PointState2& q = prev->points[p];
    return q.p + q.v * dt + 0.5 * q.a * dt * dt;
  };
  auto ref_dir = [&](const Coordinate& co, double& phi, double& phi_d, double& phi_dd) {
    phi = phi_d = phi_dd = 0;
    if (co.ref[0] < 0) return;
    const PointState2 &a = s.points[co.ref[0]], &b = s.points[co.ref[1]];
    phi = Angle(b.p - a.p);
    DirectionRates(b.p - a.p, b.v - a.v, b.a - a.a, phi_d, phi_dd);
  };
  // All points of body b from its known point K, its angle and rates (eq. 2.11 in the plane).
  auto place_body = [&](int b, int K, double psi, double omega, double alpha) {
    const Body& body = m.bodies[b];
    s.bodies[b] = {psi, omega, alpha};
    const Vec2 pB_K = body.p_B[IndexInBody(body, K)];
    const PointState2 k = s.points[K];
    for (size_t i = 0; i < body.points.size(); ++i) {
      const int p = body.points[i];
      if (have[p]) continue;
      const Vec2 r = Rotate(body.p_B[i] - pB_K, psi);
      s.points[p] = {k.p + r, k.v + omega * Perp(r), k.a + alpha * Perp(r) - omega * omega * r};
      have[p] = true;
    }
  };
  auto line_path = [&](const LineSource& l) {
    Path path;
    path.is_line = true;
    path.v_o = path.a_o = Vec2::Zero();
    switch (l.kind) {
      case LineSource::Kind::kFixedGuide: {
        const Joint& j = m.joints[l.joint];
        path.o = s.points[j.line[0]].p;
        path.e = Unit(Vec2(s.points[j.line[1]].p - path.o));
        break;
      }
      case LineSource::Kind::kDrivenX:
      case LineSource::Kind::kDrivenY: {
        // A prescribed x (or y) is the line x = x(t), which translates without turning.
        double x, xd, xdd;
        drive(l.driver, x, xd, xdd);
        const bool is_x = l.kind == LineSource::Kind::kDrivenX;
        path.o = is_x ? Vec2(x, 0) : Vec2(0, x);
        path.v_o = is_x ? Vec2(xd, 0) : Vec2(0, xd);
        path.a_o = is_x ? Vec2(xdd, 0) : Vec2(0, xdd);
        path.e = is_x ? Vec2(0, 1) : Vec2(1, 0);
        break;
      }
      case LineSource::Kind::kBodySlider: {
        const Joint& j = m.joints[l.joint];
        const PointState2& o = s.points[j.line[0]];
        path.o = o.p, path.v_o = o.v, path.a_o = o.a;
        path.e = Unit(Vec2(s.points[j.line[1]].p - o.p));
        path.omega = s.bodies[j.body].omega, path.alpha = s.bodies[j.body].alpha;
        break;
      }
    }
    return path;
  };
  auto circle_path = [&](const DistanceSource& d, int P) {
    Path path;
    path.is_line = false;
    const PointState2& c = s.points[d.from];
    path.c = c.p, path.v_c = c.v, path.a_c = c.a;
    switch (d.kind) {
      case DistanceSource::Kind::kBody: path.d = d.length; break;
      case DistanceSource::Kind::kDrivenDistance: drive(d.driver, path.d, path.dd, path.ddd); break;
      case DistanceSource::Kind::kTriangle: {
        // Law of cosines on the rigid triangle: d² = la² + lb² − 2 la lb g cos θ.
        double th, thd, thdd;
        drive(d.driver, th, thd, thdd);
        const Coordinate& co = m.coordinates[d.coordinate];
        const auto branches = FormBranches(co.form);
        auto length = [&](int ch) {
          const double g = d.sign * std::cos(branches[ch].c);
          return std::sqrt(std::max(0.0, d.la * d.la + d.lb * d.lb - 2 * d.la * d.lb * g * std::cos(th)));
        };
        if (!prev && co.form == AngleForm::kCross) {
          // cross(ref rotated by θ, vec) = 0 also holds for −vec: keep the branch the guesses show.
          const double dg = (m.points[P].p_W - m.points[d.from].p_W).norm();
          s.coord_choice[d.coordinate] = std::fabs(length(1) - dg) < std::fabs(length(0) - dg) ? 1 : 0;
        }
        const int ch = s.coord_choice[d.coordinate];
        const double g = d.sign * std::cos(branches[ch].c), k = d.la * d.lb * g;
        path.d = length(ch);
        if (!(path.d > 0))
          throw AssemblyError(co.src, "the triangle of " + co.name + " collapses (its two bars overlap)",
                              "drive the angle away from 0 and pi");
        path.dd = k * std::sin(th) * thd / path.d;
        path.ddd = (k * (std::cos(th) * thd * thd + std::sin(th) * thdd) - path.dd * path.dd) / path.d;
        break;
      }
    }
    return path;
  };
  auto dist_src = [&](const DistanceSource& d) -> SourceRef {
    if (d.kind == DistanceSource::Kind::kBody) return m.bodies[d.body].src;
    if (d.driver >= nd) return m.couplings[plan_.coupled[d.driver - nd].coupling].src;
    return m.drivers[d.driver].src;
  };

  for (size_t k = 0; k < plan_.steps.size(); ++k) {
    const Step& st = plan_.steps[k];
    switch (st.kind) {
      case StepKind::kPlaceByTwoPoints: {
        const Body& body = m.bodies[st.body];
        const PointState2 &a = s.points[st.known], &b = s.points[st.other];
        const Vec2 r = b.p - a.p;
        double w, al;
        DirectionRates(r, b.v - a.v, b.a - a.a, w, al);
        const double psi = Angle(r) - Angle(Vec2(body.p_B[IndexInBody(body, st.other)] - body.p_B[IndexInBody(body, st.known)]));
        place_body(st.body, st.known, psi, w, al);
        break;
      }
      case StepKind::kPlaceByAngle: {
        const Body& body = m.bodies[st.body];
        const Coordinate& co = m.coordinates[st.coordinate];
        double th, thd, thdd, phr, phr_d, phr_dd;
        drive(st.driver, th, thd, thdd);
        ref_dir(co, phr, phr_d, phr_dd);
        const auto branches = FormBranches(co.form);
        const Vec2 vec_B = body.p_B[IndexInBody(body, co.vec[1])] - body.p_B[IndexInBody(body, co.vec[0])];
        auto psi_of = [&](const FormBranch& fb) { return phr + fb.sigma * th + fb.c - Angle(vec_B); };
        if (!prev && branches.size() > 1) {
          // The form cannot tell the branches apart: take the one the drawing (guesses) shows.
          const Vec2 pB_K = body.p_B[IndexInBody(body, st.known)];
          double best = INFINITY;
          for (size_t ch = 0; ch < branches.size(); ++ch) {
            double err = 0;
            for (size_t i = 0; i < body.points.size(); ++i)
              err += (s.points[st.known].p + Rotate(body.p_B[i] - pB_K, psi_of(branches[ch])) - m.points[body.points[i]].p_W)
                         .squaredNorm();
            if (err < best - 1e-12) best = err, s.choice[k] = static_cast<int>(ch);
          }
        }
        const FormBranch fb = branches[s.choice[k]];
        place_body(st.body, st.known, psi_of(fb), phr_d + fb.sigma * thd, phr_dd + fb.sigma * thdd);
        break;
      }
      case StepKind::kPlaceBySlider: {
        const Body& body = m.bodies[st.body];
        const Joint& j = m.joints[st.joint];
        const PointState2 &K = s.points[st.known], &S = s.points[st.other];
        const Vec2 r = S.p - K.p;
        if (!(r.norm() > 1e-12 * (1 + K.p.norm())))
          throw AssemblyError(j.src, "slider " + name(st.other) + " is at " + name(st.known) + ", so the line of " + body.name + " is undefined",
                              "move the slider off the pivot");
        if (!prev) {
          // Is the body's line direction (first to second point) along K→S or against it?
          const Vec2 g = m.points[st.other].p_W - m.points[st.known].p_W;
          const Vec2 gl = m.points[j.line[1]].p_W - m.points[j.line[0]].p_W;
          s.choice[k] = g.dot(gl) < 0 ? 1 : 0;
        }
        const double eta_angle = s.choice[k] ? kPi : 0.0;
        const Vec2 dB = body.p_B[IndexInBody(body, j.line[1])] - body.p_B[IndexInBody(body, j.line[0])];
        double w, al;
        DirectionRates(r, S.v - K.v, S.a - K.a, w, al);
        place_body(st.body, st.known, Angle(r) + eta_angle - Angle(dB), w, al);
        break;
      }
      case StepKind::kPlaceByOrientation:
        place_body(st.body, st.known, st.psi, 0, 0);
        break;
      case StepKind::kPlaceTranslating: {
        // Point k of the body on its guide o + μ e_g; the body's line (direction e_b) through A:
        // cross(A − o − μ e_g + w_k, e_b) = 0 with w_k = k's offset from the line's first point.
        const Body& body = m.bodies[st.body];
        const Joint& slot = m.joints[st.joint];
        const Joint& guide = m.joints[st.lines[0].joint];
        const Vec2 o = s.points[guide.line[0]].p, e_g = Unit(Vec2(s.points[guide.line[1]].p - o));
        const Vec2 e_b = Unit(Rotate(Vec2(body.p_B[IndexInBody(body, slot.line[1])] - body.p_B[IndexInBody(body, slot.line[0])]), st.psi));
        const Vec2 w_k = Rotate(Vec2(body.p_B[IndexInBody(body, st.known)] - body.p_B[IndexInBody(body, slot.line[0])]), st.psi);
        const double den = Cross2(e_g, e_b);
        if (!(std::fabs(den) > 1e-12))
          throw AssemblyError(slot.src, "the line of " + body.name + " runs along the guide of " + name(st.known),
                              "a translating body needs its slot across its guide");
        const PointState2& A = s.points[st.other];
        const double mu = Cross2(Vec2(A.p - o + w_k), e_b) / den;
        s.points[st.known] = {o + mu * e_g, Cross2(A.v, e_b) / den * e_g, Cross2(A.a, e_b) / den * e_g};
        have[st.known] = true;
        place_body(st.body, st.known, st.psi, 0, 0);
        break;
      }
      case StepKind::kLineLine:
      case StepKind::kCircleLine:
      case StepKind::kCircleCircle: {
        const int P = st.point;
        Path p1, p2;
        Vec2 pos;
        if (st.kind == StepKind::kLineLine) {
          p1 = line_path(st.lines[0]);
          p2 = line_path(st.lines[1]);
          double lambda, mu;
          if (!SolveCramer2(p1.e, -p2.e, p2.o - p1.o, lambda, mu, 1e-9))
            throw AssemblyError(m.points[P].src, "the two lines of " + name(P) + " are parallel (" + st.text + ")",
                                "check the guides and drivers of " + name(P));
          pos = p1.o + lambda * p1.e;
        } else if (st.kind == StepKind::kCircleLine) {
          p1 = line_path(st.lines[0]);
          p2 = circle_path(st.dists[0], P);
          // |o + λe − c| = d: λ² + 2λ e·w + |w|² − d² = 0 with w = o − c.
          const Vec2 w = p1.o - p2.c;
          const double b = p1.e.dot(w), disc = b * b - w.squaredNorm() + p2.d * p2.d;
          const double scale = p2.d * p2.d + w.squaredNorm();
          if (disc < -1e-10 * scale)
            throw AssemblyError(dist_src(st.dists[0]),
                                "cannot assemble: " + name(P) + " at " + std::to_string(p2.d) + " from " + name(st.dists[0].from) +
                                    " does not reach its line (" + LineText(m, plan_.coupled, st.lines[0]) + ")",
                                "lengthen the link or move the guide", true);
          const double h = std::sqrt(std::max(0.0, disc));
          const Vec2 cand[2] = {p1.o + (-b + h) * p1.e, p1.o + (-b - h) * p1.e};
          // The root nearest the drawing (first sample) or the extrapolated last sample.
          s.choice[k] = (cand[1] - expect(P)).norm() < (cand[0] - expect(P)).norm() ? 1 : 0;
          pos = cand[s.choice[k]];
        } else {
          p1 = circle_path(st.dists[0], P);
          p2 = circle_path(st.dists[1], P);
          const Vec2 c1 = p1.c, c2 = p2.c;
          const double D = (c2 - c1).norm();
          if (!(D > 0))
            throw AssemblyError(m.points[P].src, "the two centres of " + name(P) + " coincide (" + st.text + ")", "");
          const double a = (p1.d * p1.d - p2.d * p2.d + D * D) / (2 * D);
          const double h2 = p1.d * p1.d - a * a;
          if (h2 < -1e-10 * p1.d * p1.d) {
            const bool too_far = D > p1.d + p2.d;
            throw AssemblyError(dist_src(st.dists[h2 < 0 && st.dists[1].kind != DistanceSource::Kind::kBody ? 1 : 0]),
                                "cannot assemble: " + name(P) + " cannot be at " + std::to_string(p1.d) + " from " +
                                    name(st.dists[0].from) + " and " + std::to_string(p2.d) + " from " + name(st.dists[1].from) +
                                    " (they are " + std::to_string(D) + " apart: " +
                                    (too_far ? "the links are too short to close the loop" : "one link is too long") + ")",
                                "change the link lengths or the driven input", true);
          }
          const double h = std::sqrt(std::max(0.0, h2));
          const Vec2 e = (c2 - c1) / D;
          const Vec2 cand[2] = {c1 + a * e + h * Perp(e), c1 + a * e - h * Perp(e)};
          if (!prev) {
            // Branch by the side of the line c1→c2 on which the drawing puts P.
            const double side = Cross2(m.points[st.dists[1].from].p_W - m.points[st.dists[0].from].p_W,
                                       m.points[P].p_W - m.points[st.dists[0].from].p_W);
            s.choice[k] = side < 0 ? 1 : 0;
          } else {
            s.choice[k] = (cand[1] - expect(P)).norm() < (cand[0] - expect(P)).norm() ? 1 : 0;
          }
          pos = cand[s.choice[k]];
        }
        // Velocity and acceleration: v_P = v1 + x1 col1 = v2 + x2 col2 (Cramer), same for a.
        const Vec2 col1 = p1.Col(pos), col2 = p2.Col(pos);
        double x1, x2, y1, y2;
        if (!SolveCramer2(col1, -col2, p2.VKnown(pos) - p1.VKnown(pos), x1, x2, 1e-10))
          throw AssemblyError(m.points[P].src, "singular position of " + name(P) + " (" + st.text + "): its two paths are tangent",
                              "avoid the toggle (dead-centre) position");
        const Vec2 a1 = p1.AKnown(pos, x1), a2 = p2.AKnown(pos, x2);
        SolveCramer2(col1, -col2, a2 - a1, y1, y2, 1e-10);
        s.points[P] = {pos, p1.VKnown(pos) + x1 * col1, a1 + y1 * col1};
        have[P] = true;
        break;
      }
    }
  }

  // Relative coordinates that are not driven follow from the points, on the form's branch.
  for (size_t c = 0; c < m.coordinates.size(); ++c) {
    const Coordinate& co = m.coordinates[c];
    const int slot = m.SlotIndex(co.name);
    const int drv = plan_.slot_driver[slot];  // a driver, or a coupling from a known coordinate
    if (drv >= 0) {
      drive(drv, s.q[c], s.qd[c], s.qdd[c]);
      continue;
    }
    const PointState2 &a = s.points[co.vec[0]], &b = s.points[co.vec[1]];
    const Vec2 r = b.p - a.p, rd = b.v - a.v, rdd = b.a - a.a;
    if (co.type == CoordinateType::kDistance) {
      const double L = r.norm();
      s.q[c] = L;
      s.qd[c] = r.dot(rd) / L;
      s.qdd[c] = (rd.squaredNorm() + r.dot(rdd) - s.qd[c] * s.qd[c]) / L;
      continue;
    }
    if (co.type != CoordinateType::kAngle) continue;
    double phv_d, phv_dd, phr, phr_d, phr_dd;
    DirectionRates(r, rd, rdd, phv_d, phv_dd);
    ref_dir(co, phr, phr_d, phr_dd);
    const double alpha = Angle(r) - phr;
    const auto branches = FormBranches(co.form);
    const double target = prev ? prev->q[c] : guess_q_[slot];
    if (!prev) {
      double best = INFINITY;
      for (size_t ch = 0; ch < branches.size(); ++ch) {
        const double th = WrapNear(branches[ch].sigma * (alpha - branches[ch].c), target);
        if (std::fabs(th - target) < best - 1e-12) best = std::fabs(th - target), s.coord_choice[c] = static_cast<int>(ch);
      }
    }
    const FormBranch fb = branches[s.coord_choice[c]];
    s.q[c] = WrapNear(fb.sigma * (alpha - fb.c), target);
    s.qd[c] = fb.sigma * (phv_d - phr_d);
    s.qdd[c] = fb.sigma * (phv_dd - phr_dd);
  }

  // Residual of every equation of the model: an independent check that the closed forms closed
  // every loop (redundant equations, such as cos+sin, included).
  double res = 0;
  auto upd = [&](double x) { res = std::max(res, std::fabs(x)); };
  for (const Body& body : m.bodies)
    for (size_t i = 0; i < body.points.size(); ++i)
      for (size_t j = i + 1; j < body.points.size(); ++j) {
        upd((s.points[body.points[i]].p - s.points[body.points[j]].p).norm() - (body.p_B[i] - body.p_B[j]).norm());
        if (body.points.size() > 2 && i == 0 && j >= 2)  // no mirror image of a plate
          upd(Cross2(s.points[body.points[1]].p - s.points[body.points[0]].p, s.points[body.points[j]].p - s.points[body.points[0]].p) /
                  body.Length() -
              Cross2(body.p_B[1] - body.p_B[0], body.p_B[j] - body.p_B[0]) / body.Length());
      }
  for (const Joint& j : m.joints) {
    if (j.type == JointType::kGear) continue;
    const Vec2 o = s.points[j.line[0]].p, e = Unit(Vec2(s.points[j.line[1]].p - o));
    upd(Cross2(e, s.points[j.point].p - o));
  }
  for (size_t c = 0; c < m.coordinates.size(); ++c) {
    const Coordinate& co = m.coordinates[c];
    const Vec2 v = s.points[co.vec[1]].p - s.points[co.vec[0]].p;
    if (co.type == CoordinateType::kDistance) upd(v.norm() - s.q[c]);
    if (co.type != CoordinateType::kAngle) continue;
    const Vec2 ref = co.ref[0] < 0 ? Vec2(1, 0) : Unit(Vec2(s.points[co.ref[1]].p - s.points[co.ref[0]].p));
    const double th = s.q[c], L = v.norm();
    switch (co.form) {
      case AngleForm::kCross: upd(Cross2(Rotate(ref, th), v)); break;
      case AngleForm::kDot: upd(ref.dot(v) - L * std::cos(th)); break;
      case AngleForm::kCos: upd(v.x() - L * std::cos(th)); break;
      case AngleForm::kSin: upd(v.y() - L * std::sin(th)); break;
      case AngleForm::kCosSin: upd(v.x() - L * std::cos(th)), upd(v.y() - L * std::sin(th)); break;
    }
  }
  for (const Driver& d : m.drivers) {
    const Model::Slot& sl = m.q_layout[m.SlotIndex(d.coordinate)];
    if (sl.point >= 0) upd(s.points[sl.point].p[sl.axis] - d.At(t, t0));
  }
  // Couplings, every one (also those no step used): q_b − k q_a − c and its rate.
  auto slot_value = [&](int slot, int order) {
    const Model::Slot& sl = m.q_layout[slot];
    if (sl.point >= 0) {
      const PointState2& p = s.points[sl.point];
      return order == 0 ? p.p[sl.axis] : p.v[sl.axis];
    }
    return order == 0 ? s.q[sl.coordinate] : s.qd[sl.coordinate];
  };
  for (const Coupling& cp : m.couplings)
    upd(slot_value(cp.slots[1], 0) - cp.ratio * slot_value(cp.slots[0], 0) - cp.offset);
  s.residual = res;

  // The same equations differentiated once: every rate the closed forms produced must agree with
  // every equation, including the ones no step used.
  double rres = 0;
  auto rupd = [&](double x) { rres = std::max(rres, std::fabs(x)); };
  for (const Body& body : m.bodies)
    for (size_t i = 0; i < body.points.size(); ++i)
      for (size_t j = i + 1; j < body.points.size(); ++j) {
        const PointState2 &a = s.points[body.points[i]], &b = s.points[body.points[j]];
        const double L = (b.p - a.p).norm();
        if (L > 0) rupd((b.p - a.p).dot(b.v - a.v) / L);
      }
  for (const Joint& j : m.joints) {
    if (j.type == JointType::kGear) continue;
    const PointState2 &o = s.points[j.line[0]], &l = s.points[j.line[1]], &P = s.points[j.point];
    const Vec2 d = l.p - o.p;
    // d/dt [(l − o) × (P − o)] / |l − o|
    rupd((Cross2(l.v - o.v, P.p - o.p) + Cross2(d, P.v - o.v)) / d.norm());
  }
  for (size_t c = 0; c < m.coordinates.size(); ++c) {
    const Coordinate& co = m.coordinates[c];
    const PointState2 &a = s.points[co.vec[0]], &b = s.points[co.vec[1]];
    const Vec2 r = b.p - a.p, rd = b.v - a.v, rdd = b.a - a.a;
    if (co.type == CoordinateType::kDistance) rupd(r.dot(rd) / r.norm() - s.qd[c]);
    if (co.type != CoordinateType::kAngle) continue;
    double phv_d, phv_dd, phr, phr_d, phr_dd;
    DirectionRates(r, rd, rdd, phv_d, phv_dd);
    ref_dir(co, phr, phr_d, phr_dd);
    // The branch on which the position equation holds decides the sign of the rate.
    const double alpha = Angle(r) - phr;
    double best = INFINITY, sigma = 1;
    for (const FormBranch& fb : FormBranches(co.form)) {
      const double e = std::fabs(std::remainder(fb.sigma * (alpha - fb.c) - s.q[c], 2 * kPi));
      if (e < best - 1e-9) best = e, sigma = fb.sigma;
    }
    rupd(s.qd[c] - sigma * (phv_d - phr_d));
  }
  for (const Driver& d : m.drivers) {
    const Model::Slot& sl = m.q_layout[m.SlotIndex(d.coordinate)];
    if (sl.point >= 0) rupd(s.points[sl.point].v[sl.axis] - d.RateAt(t, t0));
  }
  for (const Coupling& cp : m.couplings) rupd(slot_value(cp.slots[1], 1) - cp.ratio * slot_value(cp.slots[0], 1));
  s.residual_rate = rres;
  return s;
}

void LinkageSolver::ToLayout(const LinkageState& s, Eigen::VectorXd& q, Eigen::VectorXd& qd, Eigen::VectorXd& qdd) const {
  const size_t n = m_.q_layout.size();
  q.resize(n), qd.resize(n), qdd.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const Model::Slot& sl = m_.q_layout[i];
    if (sl.point >= 0) {
      const PointState2& p = s.points[sl.point];
      q[i] = p.p[sl.axis], qd[i] = p.v[sl.axis], qdd[i] = p.a[sl.axis];
    } else {
      q[i] = s.q[sl.coordinate], qd[i] = s.qd[sl.coordinate], qdd[i] = s.qdd[sl.coordinate];
    }
  }
}

double LinkageSolver::SlideVelocity(const LinkageState& s, int joint) const {
  const Joint& j = m_.joints[joint];
  const PointState2 &o = s.points[j.line[0]], &P = s.points[j.point];
  const Vec2 e = Unit(Vec2(s.points[j.line[1]].p - o.p));
  // Velocity of P minus that of the body point under it (v_O + ω×OP).
  const Vec2 v_rel = P.v - (o.v + s.bodies[j.body].omega * Perp(P.p - o.p));
  return v_rel.dot(e);
}

}  // namespace mechbench::analytic
