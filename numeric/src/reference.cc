#include "mechbench/format.h"
#include "mechbench/numeric/reference.h"

#include "mechbench/numeric/dynamics_methods.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace mechbench::numeric {
namespace {

std::string FmtN(double v) { return Fmt(v, 3); }


bool IsAngle(const Model& model, int slot) {
  const Model::Slot& s = model.q_layout[slot];
  return s.point < 0 && model.coordinates[s.coordinate].type != CoordinateType::kDistance;
}

}  // namespace

PositionError ComparePositions(const Model& model, const std::vector<Sample>& ref, const std::vector<Sample>& other) {
  PositionError e;
  const size_t n = std::min(ref.size(), other.size());
  e.samples = static_cast<int>(n);
  if (ref.size() != other.size())
    e.problem = "different sample counts (" + std::to_string(ref.size()) + " vs " + std::to_string(other.size()) + ")";
  const int slots = static_cast<int>(model.q_layout.size());
  if (n == 0 || slots == 0) return e;
  // The motion's scale per kind: the largest range any slot of that kind covers in the reference.
  double range[2] = {0, 0};
  for (int i = 0; i < slots; ++i) {
    double lo = INFINITY, hi = -INFINITY;
    for (const Sample& s : ref)
      if (s.q.size() == slots) lo = std::min(lo, s.q[i]), hi = std::max(hi, s.q[i]);
    if (hi >= lo) range[IsAngle(model, i)] = std::max(range[IsAngle(model, i)], hi - lo);
  }
  // A scene that does not move at all is judged against 1 length unit / 1 rad.
  for (double& r : range)
    if (!(r > 0)) r = 1.0;
  for (size_t k = 0; k < n; ++k) {
    if (std::fabs(ref[k].t - other[k].t) > 1e-12 * (1 + std::fabs(ref[k].t))) {
      e.problem = "sample times differ at sample " + std::to_string(k);
      break;
    }
    if (ref[k].q.size() != slots || other[k].q.size() != slots) continue;
    for (int i = 0; i < slots; ++i) {
      const double d = std::fabs(ref[k].q[i] - other[k].q[i]) / range[IsAngle(model, i)];
      if (!(d <= e.value) || e.slot.empty()) {  // NaN counts as the worst
        e.value = std::isfinite(d) ? d : INFINITY;
        e.slot = model.q_layout[i].name;
        e.t = ref[k].t;
      }
    }
  }
  return e;
}

Reference ReferenceTrajectory(const Model& model, const ReferenceOptions& o) {
  Reference ref;
  ref.tolerance = o.agreement;
  BaumgarteOptions bg;
  bg.rtol = o.rtol;
  bg.atol = o.atol;
  ref.primary = MakeBaumgarteDopri5Method(bg)->Run(model);
  ref.primary.method = "reference (dyn-baumgarte-dopri5, rtol " + FmtN(o.rtol) + ")";
  if (!ref.primary.ok()) {
    ref.description = "no reference: " + ref.primary.reason;
    return ref;
  }
  ref.description = "index-1 + Baumgarte, DOPRI5 (rtol " + FmtN(o.rtol) + ")";
  PartitioningOptions cp;
  cp.rtol = o.rtol;
  cp.atol = o.atol;
  ref.confirmation = MakeCoordinatePartitioningMethod(cp)->Run(model);
  std::string by = "coordinate partitioning + DOPRI5";
  if (!ref.confirmation.ok()) {
    ref.description += "; coordinate partitioning stopped (" + ref.confirmation.reason + ")";
    Ali3pOptions al;
    al.h = o.ali3p_h;
    ref.confirmation = MakeAli3pMethod(al)->Run(model);
    by = "ALI3-P (h = " + FmtN(o.ali3p_h) + " s)";
  }
  ref.confirmation.method = "confirmation (" + by + ")";
  const PositionError e = ComparePositions(model, ref.primary.trajectory, ref.confirmation.trajectory);
  ref.agreement = e.value;
  ref.confirmed = ref.confirmation.ok() && e.problem.empty() && e.value <= o.agreement;
  if (ref.confirmed)
    ref.description += ", confirmed by " + by + " to " + FmtN(e.value) + " (stated " + FmtN(o.agreement) + ")";
  else if (!ref.confirmation.ok())
    ref.description += ", UNCONFIRMED: " + by + " " + ToString(ref.confirmation.status) + " " + ref.confirmation.reason;
  else
    ref.description += ", UNCONFIRMED: " + by + " differs by " + FmtN(e.value) + " at " + e.slot + ", t = " + FmtN(e.t) +
                       " s (stated " + FmtN(o.agreement) + ")";
  return ref;
}

}  // namespace mechbench::numeric
