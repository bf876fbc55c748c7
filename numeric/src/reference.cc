#include "mechbench/format.h"
#include "mechbench/numeric/reference.h"

#include "mechbench/numeric/dynamics_methods.h"
#include "mechbench/numeric/forward_dynamics.h"
#include "mechbench/numeric/natural_model.h"
#include "mechbench/numeric/nfourbar.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <numbers>

namespace mechbench::numeric {
namespace {

std::string FmtN(double v) { return Fmt(v, 3); }


bool IsAngle(const Model& model, int slot) {
  const Model::Slot& s = model.q_layout[slot];
  return s.point < 0 && model.coordinates[s.coordinate].type != CoordinateType::kDistance;
}

double CpuSeconds() { return static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }

// The largest spread of the crank angles atan2(yPi, xPi − i) over a trajectory [rad] (0 on the
// N-four-bar's parallelogram branch).
double CrankSpread(const Model& model, int n, const std::vector<Sample>& traj) {
  std::vector<int> xs(n + 1), ys(n + 1);
  for (int i = 0; i <= n; ++i) xs[i] = model.SlotIndex("xP" + std::to_string(i)), ys[i] = model.SlotIndex("yP" + std::to_string(i));
  double worst = 0;
  for (const Sample& s : traj) {
    double lo = INFINITY, hi = -INFINITY;
    const double th0 = std::atan2(s.q[ys[0]], s.q[xs[0]]);
    for (int i = 0; i <= n; ++i) {
      // Relative to crank 0, wrapped, so that ±π does not read as a spread of 2π.
      const double d = std::remainder(std::atan2(s.q[ys[i]], s.q[xs[i]] - i) - th0, 2 * std::numbers::pi);
      lo = std::min(lo, d), hi = std::max(hi, d);
    }
    worst = std::max(worst, hi - lo);
  }
  return worst;
}

Reference NFourBarReference(const Model& model, int n_bars, const ReferenceOptions& o) {
  Reference ref;
  ref.tolerance = o.agreement;
  const Analysis& a = model.analysis;
  // Pass 1 finds the singular positions; pass 2 also gives the states where the segments start.
  double cpu = CpuSeconds();
  const std::vector<double> crossings = NFourBarExact(model, o.nfourbar_rtol).crossings;
  struct Segment {
    double t0, t1;
  };
  std::vector<Segment> segments;
  std::vector<double> starts;
  double begin = a.t0;
  for (size_t k = 0; k <= crossings.size(); ++k) {
    const double end = k < crossings.size() ? crossings[k] - o.segment_margin : a.t1;
    if (end > begin) {
      segments.push_back({begin, end});
      if (begin > a.t0) starts.push_back(begin);
    }
    if (k < crossings.size()) begin = std::min(a.t1, crossings[k] + o.segment_margin);
  }
  const NFourBarSolution exact = NFourBarExact(model, o.nfourbar_rtol, starts);
  Result& p = ref.primary;
  p.method = "reference (N-four-bar reduced to its crank angle, DOPRI5 rtol " + FmtN(o.nfourbar_rtol) + ")";
  p.trajectory = exact.trajectory;
  p.quantities["energy"] = exact.energy;
  p.quantities["energy_drift"] = exact.energy_drift;
  p.quantities["steps"] = static_cast<double>(exact.steps);
  p.settings["formulation"] = "every crank alike (the couplers translate): J θ̈ = −g K cos θ, a 1-DOF pendulum";
  p.cpu_seconds = CpuSeconds() - cpu;
  ref.singular_positions = static_cast<int>(crossings.size());

  // Confirmation: index-1 DOPRI5 on the full model, one segment at a time from the reference state.
  cpu = CpuSeconds();
  Result& c = ref.confirmation;
  c.method = "confirmation (dyn-baumgarte-dopri5 rtol " + FmtN(o.segment_rtol) + " between the singular positions)";
  const NaturalModel nm = Compile(model);
  DynamicsSystem sys(nm);
  const int nq = nm.n;
  BaumgarteOptions bg;
  Eigen::VectorXd qdd, lambda, y(2 * nq);
  const OdeRhs f = [&](double, const Eigen::VectorXd& yy, Eigen::VectorXd& dy, std::string& why) {
    if (!sys.Accelerations(yy.head(nq), yy.tail(nq), bg.alpha, bg.beta, qdd, lambda, &why)) return false;
    dy.resize(2 * nq);
    dy << yy.tail(nq), qdd;
    return true;
  };
  std::vector<Sample> ref_subset;
  size_t next_start = 0;
  for (const Segment& seg : segments) {
    const Sample& s0 = seg.t0 == a.t0 ? exact.trajectory[0] : exact.extra[next_start++];
    if (seg.t0 == a.t0) sys.ChooseRows(s0.q);
    y << s0.q, s0.qd;
    Dopri5Options dop;
    dop.rtol = o.segment_rtol;
    dop.atol = Eigen::VectorXd(2 * nq);
    dop.atol << o.segment_rtol * 1e-2 * nm.q_scale, o.segment_rtol * 1e-2 * nm.q_scale;
    Dopri5 dopri(dop);
    double t = seg.t0;
    std::string why;
    for (int k = 0; k < a.samples; ++k) {
      const double tk = a.TimeAt(k);
      if (tk < seg.t0 || tk > seg.t1) continue;
      if (tk > t && !dopri.Advance(f, {}, t, tk, y, why)) {
        c.status = Status::kDiverged;
        c.reason = "at t = " + Fmt(t) + " s (segment " + Fmt(seg.t0) + " … " + Fmt(seg.t1) + " s): " + why;
        break;
      }
      if (!sys.Accelerations(y.head(nq), y.tail(nq), bg.alpha, bg.beta, qdd, lambda, &why)) qdd.setConstant(nq, kNaN);
      c.trajectory.push_back(Sample{tk, y.head(nq), y.tail(nq), qdd, 0.0});
      ref_subset.push_back(exact.trajectory[k]);
    }
    if (!c.ok()) break;
  }
  c.cpu_seconds = CpuSeconds() - cpu;
  ref.compared_samples = static_cast<int>(c.trajectory.size());
  const PositionError e = ComparePositionsScaled(model, exact.trajectory, ref_subset, c.trajectory);
  ref.agreement = e.value;

  // Across the singular positions: ALI3-P over the whole run (informative).
  Ali3pOptions al;
  const Result whole = MakeAli3pMethod(al)->Run(model, {.step = o.whole_run_h});
  c.cpu_seconds += whole.cpu_seconds;
  if (whole.ok()) {
    ref.whole_run_error = ComparePositions(model, exact.trajectory, whole.trajectory).value;
    ref.whole_run_spread = CrankSpread(model, n_bars, whole.trajectory);
  }

  ref.confirmed = c.ok() && e.problem.empty() && e.value <= o.agreement && ref.compared_samples > 0;
  ref.description = "N-four-bar (N = " + std::to_string(n_bars) + "): its reduced equation, every crank alike " +
                    "(a 1-DOF pendulum through the " + std::to_string(crossings.size()) +
                    " singular positions), DOPRI5 rtol " + FmtN(o.nfourbar_rtol) + " (energy kept to " +
                    FmtN(exact.energy_drift) + " J)";
  const std::string by = "index-1 DOPRI5 (rtol " + FmtN(o.segment_rtol) + ") on the full " + std::to_string(nq) +
                         "-coordinate model between the singular positions (restarted " + FmtN(o.segment_margin) +
                         " s after each, " + std::to_string(ref.compared_samples) + " of " + std::to_string(a.samples) +
                         " samples)";
  if (ref.confirmed)
    ref.description += ", confirmed by " + by + " to " + FmtN(e.value) + " (stated " + FmtN(o.agreement) + ")";
  else if (!c.ok())
    ref.description += ", UNCONFIRMED: " + by + " " + ToString(c.status) + " " + c.reason;
  else
    ref.description += ", UNCONFIRMED: " + by + " differs by " + FmtN(e.value) + " at " + e.slot + ", t = " + FmtN(e.t) +
                       " s (stated " + FmtN(o.agreement) + ")";
  if (whole.ok())
    ref.description += "; across them ALI3-P (h = " + FmtN(o.whole_run_h) + " s) follows it to " +
                       FmtN(ref.whole_run_error) + " with every crank within " + FmtN(ref.whole_run_spread) + " rad";
  else
    ref.description += "; ALI3-P (h = " + FmtN(o.whole_run_h) + " s) across them: " + whole.reason;
  return ref;
}

}  // namespace

PositionError ComparePositions(const Model& model, const std::vector<Sample>& ref, const std::vector<Sample>& other) {
  return ComparePositionsScaled(model, ref, ref, other);
}

PositionError ComparePositionsScaled(const Model& model, const std::vector<Sample>& scale_from, const std::vector<Sample>& ref,
                                     const std::vector<Sample>& other) {
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
    for (const Sample& s : scale_from)
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
  if (!DynamicsApplicability(model)) {
    if (const std::optional<NFourBarOptions> nfb = RecognizeNFourBar(model)) return NFourBarReference(model, nfb->n, o);
  }
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
