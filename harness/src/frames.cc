#include "mechbench/harness/frames.h"

#include <cmath>

namespace mechbench::harness {

std::vector<Eigen::Vector2d> PointPositions(const Model& m, const Eigen::VectorXd& q) {
  std::vector<Eigen::Vector2d> p(m.points.size());
  for (size_t i = 0; i < m.points.size(); ++i) {
    p[i] = m.points[i].p_W;
    for (int axis = 0; axis < 2; ++axis)
      if (const int s = m.SlotOf(static_cast<int>(i), axis); s >= 0 && s < q.size()) p[i][axis] = q[s];
  }
  return p;
}

std::vector<Eigen::Vector3d> SpatialPointPositions(const Model& m, const Eigen::VectorXd& q) {
  const SpatialModel& sm = m.spatial;
  std::vector<Eigen::Vector3d> r(sm.entities.size());
  for (size_t e = 0; e < sm.entities.size(); ++e) r[e] = sm.entities[e].r_W;
  for (size_t s = 0; s < m.q_layout.size() && static_cast<Eigen::Index>(s) < q.size(); ++s) {
    const Model::Slot& slot = m.q_layout[s];
    if (slot.entity >= 0 && slot.axis >= 0 && slot.axis < 3) r[slot.entity][slot.axis] = q[static_cast<Eigen::Index>(s)];
  }
  std::vector<Eigen::Vector3d> p;
  for (size_t e = 0; e < sm.entities.size(); ++e)
    if (!sm.entities[e].vector) p.push_back(r[e]);
  return p;
}

std::vector<std::string> DrawnPointNames(const Model& m) {
  std::vector<std::string> n;
  if (m.kind == ScenarioKind::kSpatial) {
    for (const SpatialEntity& e : m.spatial.entities)
      if (!e.vector) n.push_back(e.name);
  } else {
    for (const Point& p : m.points) n.push_back(p.name);
  }
  return n;
}

std::vector<int> FrameSamples(const Model& m, int max_frames) {
  const int n = m.analysis.samples;
  std::vector<int> out;
  if (n < 2 || max_frames < 2) return out;
  const int f = std::min(n, max_frames);
  for (int j = 0; j < f; ++j) {
    const int k = static_cast<int>(std::lround(static_cast<double>(j) * (n - 1) / (f - 1)));
    if (out.empty() || k != out.back()) out.push_back(k);
  }
  return out;
}

namespace {
// 6 significant digits, as a number (a drawing needs no more; the file stays small).
double SixDigits(double v) {
  if (!std::isfinite(v) || v == 0) return v;
  const double scale = std::pow(10.0, 5 - static_cast<int>(std::floor(std::log10(std::fabs(v)))));
  return std::round(v * scale) / scale;
}
}  // namespace

nlohmann::json MotionFrames(const Model& m, const std::vector<Sample>& trajectory, int max_frames) {
  const bool spatial = m.kind == ScenarioKind::kSpatial;
  if ((m.kind != ScenarioKind::kLinkage && !spatial) || !m.analysis.HasMotion() || trajectory.size() < 2) return nullptr;
  nlohmann::json t = nlohmann::json::array(), p = nlohmann::json::array();
  const double tol = 1e-9 * std::max(1.0, std::fabs(m.analysis.t1 - m.analysis.t0));
  size_t from = 0;
  for (const int k : FrameSamples(m, max_frames)) {
    const double tk = m.analysis.TimeAt(k);
    // Samples are in time order; a trajectory with every sample holds sample k at index k.
    size_t i = static_cast<size_t>(k) < trajectory.size() && std::fabs(trajectory[k].t - tk) <= tol ? k : from;
    while (i < trajectory.size() && trajectory[i].t < tk - tol) ++i;
    if (i >= trajectory.size()) break;
    from = i;
    if (std::fabs(trajectory[i].t - tk) > tol || !trajectory[i].q.allFinite()) continue;
    nlohmann::json xy = nlohmann::json::array();
    if (spatial) {
      for (const Eigen::Vector3d& v : SpatialPointPositions(m, trajectory[i].q))
        for (int c = 0; c < 3; ++c) xy.push_back(SixDigits(v[c]));
    } else {
      for (const Eigen::Vector2d& v : PointPositions(m, trajectory[i].q)) xy.push_back(SixDigits(v.x())), xy.push_back(SixDigits(v.y()));
    }
    t.push_back(SixDigits(tk));
    p.push_back(std::move(xy));
  }
  if (t.size() < 2) return nullptr;
  if (spatial) return {{"dim", 3}, {"t", t}, {"p", p}};
  return {{"t", t}, {"p", p}};
}

}  // namespace mechbench::harness
