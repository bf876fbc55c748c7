#include "mechbench/motion_error.h"

#include <algorithm>
#include <cmath>

namespace mechbench {

int SlotKind(const Model& model, int slot) {
  const Model::Slot& s = model.q_layout[slot];
  if (s.point >= 0) return 0;
  // Spatial: points and `along` distances are lengths; a unit vector's components are turns
  // (an error δ in one is an angle of about δ rad), compared with the angles.
  if (s.entity >= 0) return model.spatial.entities[s.entity].vector ? 1 : 0;
  if (s.spatial_coordinate >= 0) return model.spatial.coordinates[s.spatial_coordinate].IsAngle() ? 1 : 0;
  const CoordinateType t = model.coordinates[s.coordinate].type;
  return t != CoordinateType::kDistance && t != CoordinateType::kTravel ? 1 : 0;
}

namespace {

using Get = const Eigen::VectorXd& (*)(const Sample&);
const Eigen::VectorXd& GetQ(const Sample& s) { return s.q; }
const Eigen::VectorXd& GetQd(const Sample& s) { return s.qd; }
const Eigen::VectorXd& GetQdd(const Sample& s) { return s.qdd; }

// The largest |x| of each kind over the samples that carry x (0 where none does).
std::array<double, 2> Largest(const Model& model, const std::vector<Sample>& traj, Get get) {
  const int slots = static_cast<int>(model.q_layout.size());
  std::array<double, 2> out{0, 0};
  for (const Sample& s : traj) {
    const Eigen::VectorXd& x = get(s);
    if (x.size() != slots) continue;
    for (int i = 0; i < slots; ++i)
      if (std::isfinite(x[i])) out[SlotKind(model, i)] = std::max(out[SlotKind(model, i)], std::fabs(x[i]));
  }
  return out;
}

KindError CompareKind(const Model& model, const std::array<double, 2>& scale, const std::vector<Sample>& a,
                      const std::vector<Sample>& b, size_t n, Get get, std::vector<double>* per_sample) {
  const int slots = static_cast<int>(model.q_layout.size());
  KindError e;
  double sum_sq = 0;
  long count = 0;
  bool any = false;
  for (size_t k = 0; k < n; ++k) {
    const Eigen::VectorXd& x = get(a[k]);
    const Eigen::VectorXd& y = get(b[k]);
    const bool both = x.size() == slots && y.size() == slots;
    if (per_sample) per_sample->push_back(0.0);
    if (!both) continue;  // not given on one side (an engine's q̈ at t0)
    if (!any) e.max = 0;
    any = true;
    for (int i = 0; i < slots; ++i) {
      double d = std::fabs(x[i] - y[i]) / scale[SlotKind(model, i)];
      if (!std::isfinite(d)) d = INFINITY;  // NaN counts as the worst
      sum_sq += d * d;
      ++count;
      if (per_sample) per_sample->back() = std::max(per_sample->back(), d);
      if (d > e.max || e.slot.empty()) {
        e.max = d;
        e.slot = model.q_layout[i].name;
        e.t = a[k].t;
      }
    }
  }
  if (any) e.rms = std::sqrt(sum_sq / static_cast<double>(std::max(count, 1L)));
  return e;
}

}  // namespace

MotionScale ScaleOfMotion(const Model& model, const std::vector<Sample>& ref) {
  const int slots = static_cast<int>(model.q_layout.size());
  MotionScale sc;
  std::array<double, 2> range{0, 0};
  for (int i = 0; i < slots; ++i) {
    double lo = INFINITY, hi = -INFINITY;
    for (const Sample& s : ref)
      if (s.q.size() == slots && std::isfinite(s.q[i])) lo = std::min(lo, s.q[i]), hi = std::max(hi, s.q[i]);
    if (hi >= lo) range[SlotKind(model, i)] = std::max(range[SlotKind(model, i)], hi - lo);
  }
  const std::array<double, 2> size{model.LengthScale(), 1.0};
  const double T = model.analysis.HasMotion() && model.analysis.t1 > model.analysis.t0 ? model.analysis.t1 - model.analysis.t0 : 1.0;
  const std::array<double, 2> qd = Largest(model, ref, GetQd), qdd = Largest(model, ref, GetQdd);
  for (int c = 0; c < 2; ++c) {
    sc.q[c] = std::max(range[c], kScaleFloor * size[c]);
    sc.qd[c] = std::max(qd[c], sc.q[c] / T);
    sc.qdd[c] = std::max(qdd[c], sc.qd[c] / T);
  }
  return sc;
}

MotionError CompareMotion(const Model& model, const std::vector<Sample>& ref, const std::vector<Sample>& other) {
  return CompareMotion(model, ScaleOfMotion(model, ref), ref, other);
}

MotionError CompareMotion(const Model& model, const MotionScale& scale, const std::vector<Sample>& ref,
                          const std::vector<Sample>& other) {
  MotionError e;
  e.scale = scale;
  size_t n = std::min(ref.size(), other.size());
  if (ref.size() != other.size())
    e.problem = "different sample counts (" + std::to_string(ref.size()) + " vs " + std::to_string(other.size()) + ")";
  for (size_t k = 0; k < n; ++k)
    if (!(std::fabs(ref[k].t - other[k].t) <= 1e-12 * (1 + std::fabs(ref[k].t)))) {
      e.problem = "sample times differ at sample " + std::to_string(k) + " (t = " + std::to_string(ref[k].t) + " vs " +
                  std::to_string(other[k].t) + " s)";
      n = k;  // compared up to there
      break;
    }
  e.samples = static_cast<int>(n);
  if (model.q_layout.empty()) return e;
  e.q = CompareKind(model, scale.q, ref, other, n, GetQ, &e.q_per_sample);
  e.qd = CompareKind(model, scale.qd, ref, other, n, GetQd, nullptr);
  e.qdd = CompareKind(model, scale.qdd, ref, other, n, GetQdd, nullptr);
  return e;
}

}  // namespace mechbench
