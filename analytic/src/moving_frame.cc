#include "mechbench/analytic/moving_frame.h"

namespace mechbench::analytic {

Vec3 EmbedVector(const Embedding& e, const Vec2& r) { return e.u * r.x() + e.v * r.y(); }

PointState3 EmbedPoint(const Embedding& e, const PointState2& s) {
  return {e.origin + EmbedVector(e, s.p), EmbedVector(e, s.v), EmbedVector(e, s.a)};
}

PointState3 AbsoluteInTurningFrame(const FrameRotation& f, const PointState3& rel) {
  // The frame's origin is taken on the axis: it is at rest, and Ω is constant (α_frame = 0).
  PointState3 origin;
  origin.p = f.axis_point;
  const Vec3 Omega = f.omega * f.axis;
  return MovingFramePoint(origin, Omega, Vec3::Zero(), rel.p, rel.v, rel.a);
}

BodyChainResult AbsoluteByBodyChain(const Model& m, const LinkageState& s) {
  const Embedding& e = m.embedding;
  const Vec3 n = e.Normal();
  const Vec3 Omega = m.frame ? Vec3(m.frame->omega * m.frame->axis) : Vec3::Zero();
  const Vec3 axis_point = m.frame ? m.frame->axis_point : Vec3::Zero();
  BodyChainResult r;
  r.omega_abs.assign(m.bodies.size(), Vec3::Constant(kNaN));
  r.alpha_abs = r.omega_abs;
  r.points.assign(m.points.size(), {});
  r.reached.assign(m.points.size(), false);
  for (size_t b = 0; b < m.bodies.size(); ++b) {
    const BodyState2& bs = s.bodies[b];
    if (!(bs.omega == bs.omega)) continue;
    r.omega_abs[b] = bs.omega * n + Omega;                              // eq. 2.8, sum of rotations
    r.alpha_abs[b] = bs.alpha * n + Cross(Omega, Vec3(bs.omega * n));  // n turns with the frame
  }
  // Points at rest in the frame turn with it about the axis (a point of the axis as the origin).
  PointState3 axis;
  axis.p = axis_point;
  for (size_t i = 0; i < m.points.size(); ++i)
    if (m.points[i].fixed) {
      r.points[i] = RigidBodyPoint(axis, Omega, Vec3::Zero(), EmbedPoint(e, s.points[i]).p);
      r.reached[i] = true;
    }
  for (bool progress = true; progress;) {
    progress = false;
    for (size_t b = 0; b < m.bodies.size(); ++b) {
      if (!r.omega_abs[b].allFinite()) continue;
      int from = -1;
      for (int p : m.bodies[b].points)
        if (r.reached[p]) from = p;
      if (from < 0) continue;
      for (int p : m.bodies[b].points) {
        if (r.reached[p]) continue;
        r.points[p] = RigidBodyPoint(r.points[from], r.omega_abs[b], r.alpha_abs[b], EmbedPoint(e, s.points[p]).p);
        r.reached[p] = true;
        progress = true;
      }
    }
  }
  return r;
}

}  // namespace mechbench::analytic
