#include "mechbench/numeric/derived.h"

#include "planar.h"

#include <Eigen/Geometry>

#include <cmath>

namespace mechbench::numeric {
namespace {

using V2 = Eigen::Vector2d;
using planar::Cross;
using planar::Perp;

Eigen::Matrix3d Skew(const Eigen::Vector3d& w) {
  Eigen::Matrix3d S;
  S << 0, -w.z(), w.y(),
       w.z(), 0, -w.x(),
       -w.y(), w.x(), 0;
  return S;
}

}  // namespace

std::optional<BodyRates> BodyAngularRates(const NaturalModel& model, const NaturalData& data, int body) {
  const Body& b = model.model.bodies[body];
  if (b.points.size() >= 2) {
    const int p0 = b.points[0], p1 = b.points[1];
    const V2 r = data.r[p1] - data.r[p0];
    const V2 rd = data.rd[p1] - data.rd[p0];
    const V2 rdd = data.rdd[p1] - data.rdd[p0];
    const double r2 = r.squaredNorm();
    if (!(r2 > 0)) return std::nullopt;
    return BodyRates{Cross(r, rd) / r2, Cross(r, rdd) / r2};
  }
  const int s = model.member_slot[body];
  if (s < 0) return std::nullopt;
  return BodyRates{data.qd[s], data.qdd[s]};
}

std::optional<SlideRates> SliderRates(const NaturalModel& model, const NaturalData& data, int joint) {
  const Joint& j = model.model.joints[joint];
  if (j.type != JointType::kPointOnBody) return std::nullopt;
  const Body& b = model.model.bodies[j.body];
  const int p0 = b.points[0], p1 = b.points[1];
  const V2 e = data.r[p1] - data.r[p0];
  const double L2 = e.squaredNorm();
  if (!(L2 > 0)) return std::nullopt;
  // Body-frame coordinates of the material point under P, divided by |e|: r_M = r0 + α e + β Perp(e).
  const V2 d = data.r[j.point] - data.r[p0];
  const double alpha = d.dot(e) / L2, beta = Cross(e, d) / L2;
  const auto material = [&](const std::vector<V2>& x) {
    const V2 ex = x[p1] - x[p0];
    return V2(x[p0] + alpha * ex + beta * Perp(ex));
  };
  const V2 u = e / std::sqrt(L2);
  return SlideRates{(data.rd[j.point] - material(data.rd)).dot(u), (data.rdd[j.point] - material(data.rdd)).dot(u)};
}

WorldPoint PointInWorld(const NaturalModel& model, const NaturalData& data, int point) {
  const Embedding& E = model.model.embedding;
  const auto lift = [&](const V2& x) -> Eigen::Vector3d { return E.u * x.x() + E.v * x.y(); };
  return WorldPoint{E.origin + lift(data.r[point]), lift(data.rd[point]), lift(data.rdd[point])};
}

std::optional<WorldPoint> MemberCentreInWorld(const NaturalModel& model, const NaturalData& data, int body) {
  const Model& m = model.model;
  if (body < 0 || static_cast<size_t>(body) >= m.gear_axes.size() || !m.gear_axes[body].Known()) return std::nullopt;
  const GearAxis& g = m.gear_axes[body];
  V2 p = g.centre, v(0, 0), a(0, 0);
  if (g.carrier >= 0) {
    const int s = model.member_slot[g.carrier];
    if (s < 0) return std::nullopt;
    const double phi = data.q[s], phid = data.qd[s], phidd = data.qdd.size() > s ? data.qdd[s] : kNaN;
    Eigen::Matrix2d A, dA;
    A << std::cos(phi), -std::sin(phi), std::sin(phi), std::cos(phi);
    dA << -std::sin(phi), -std::cos(phi), std::cos(phi), -std::sin(phi);
    const V2 arm(g.arm, 0);
    p = g.centre + A * arm;
    v = phid * (dA * arm);
    a = phidd * (dA * arm) - phid * phid * (A * arm);
  }
  const Embedding& E = m.embedding;
  const auto lift = [&](const V2& x) -> Eigen::Vector3d { return E.u * x.x() + E.v * x.y(); };
  return WorldPoint{E.origin + lift(p), lift(v), lift(a)};
}

WorldPoint AbsolutePoint(const FrameRotation& frame, const WorldPoint& rel) {
  // R(t0) = I; with constant ω about the unit axis: Ṙ = [ω]×, R̈ = Ṙ² (matrix form on purpose,
  // independent of the analytic method's cross-product / Coriolis form).
  const Eigen::Matrix3d Rd = Skew(frame.omega * frame.axis.normalized());
  const Eigen::Matrix3d Rdd = Rd * Rd;
  const Eigen::Vector3d x = rel.p - frame.axis_point;
  return WorldPoint{rel.p, Rd * x + rel.v, Rdd * x + 2.0 * Rd * rel.v + rel.a};
}

}  // namespace mechbench::numeric
