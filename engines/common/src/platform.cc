// The turning frame's platform (Graph::platform): its exact motion, world states at t0, states
// relative to it, and the absolute quantities observed from an engine's world states.
#include "mechbench/engines/graph.h"

#include <Eigen/Geometry>

#include <cmath>

namespace mechbench::engines {

SpatialState GraphPlatform::At(double t, double t0) const {
  SpatialState s;
  const Eigen::Matrix3d Rt = Eigen::AngleAxisd(Angle(t, t0), axis).toRotationMatrix();
  s.R = Rt * R0;
  s.p = axis_point + Rt * (origin - axis_point);
  s.omega = omega * axis;
  s.v = s.omega.cross(s.p - axis_point);
  s.a = s.omega.cross(s.v);
  return s;
}

SpatialState GraphPlatform::LiftAtT0(const PlanarState& ps) const {
  SpatialState s;
  const Eigen::Matrix3d Rz = Eigen::AngleAxisd(ps.angle, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  s.R = R0 * Rz;
  s.p = PointAtT0(ps.p);
  const Eigen::Vector3d w = omega * axis;
  s.omega = w + R0.col(2) * ps.omega;
  s.v = w.cross(s.p - axis_point) + DirectionAtT0(ps.v);
  return s;
}

std::vector<PlanarState> RelativeToPlatform(const SpatialState& P, const std::vector<SpatialState>& bodies) {
  std::vector<PlanarState> out(bodies.size());
  const Eigen::Matrix3d Rt = P.R.transpose();
  for (size_t b = 0; b < bodies.size(); ++b) {
    const SpatialState& s = bodies[b];
    const Eigen::Vector3d d = s.p - P.p;
    const Eigen::Vector3d v_rel_W = s.v - P.v - P.omega.cross(d);
    const Eigen::Vector3d a_rel_W =
        s.a - P.a - P.alpha.cross(d) - P.omega.cross(P.omega.cross(d)) - 2 * P.omega.cross(v_rel_W);
    const Eigen::Vector3d r = Rt * d, v = Rt * v_rel_W, a = Rt * a_rel_W;
    const Eigen::Matrix3d Rrel = Rt * s.R;
    PlanarState& o = out[b];
    o.p = {r.x(), r.y()};
    o.angle = std::atan2(Rrel(1, 0), Rrel(0, 0));
    o.v = {v.x(), v.y()};
    o.a = {a.x(), a.y()};
    o.omega = (Rt * (s.omega - P.omega)).z();
    o.alpha = (Rt * (s.alpha - P.alpha - P.omega.cross(s.omega))).z();
  }
  return out;
}

std::optional<std::string> PlatformLoadsReason(const Graph& g) {
  if (!g.forces.empty() || !g.torques.empty() || !g.springs.empty() || !g.torsions.empty() ||
      !g.state_torques.empty() || !g.state_forces.empty())
    return "the scene's loads (forces, torques, springs) are not mapped onto a turning frame yet";
  for (const GraphBody& b : g.bodies)
    if (b.kind == BodyKind::kGearMember) return "a gear train on a turning frame is not built yet";
  return std::nullopt;
}

Quantities Observer::AbsoluteQuantities(const SpatialState& platform, const std::vector<SpatialState>& st,
                                        bool with_acc) const {
  const Model& m = *model_;
  Quantities out;
  const char* ax[3] = {".x", ".y", ".z"};
  auto put = [&](const std::string& prefix, const Eigen::Vector3d& x) {
    for (int k = 0; k < 3; ++k) out[prefix + ax[k]] = x[k];
  };
  if (m.kind == ScenarioKind::kLinkage)
    for (size_t P = 0; P < m.points.size(); ++P) {
      const PointRef& pr = points_[P];
      const SpatialState& s = pr.body < 0 ? platform : st[pr.body];
      const Eigen::Vector2d x = pr.body < 0 ? pr.fixed : pr.p_B;
      const Eigen::Vector3d x_B(x.x(), x.y(), 0);
      const std::string& name = m.points[P].name;
      put("vabs." + name, s.PointVel(x_B));
      if (with_acc) put("aabs." + name, s.PointAcc(x_B));
    }
  for (size_t b = 0; b < graph_->bodies.size(); ++b)
    if (graph_->bodies[b].model_body >= 0) put("omegaabs." + graph_->bodies[b].name, st[b].omega);
  return out;
}

}  // namespace mechbench::engines
