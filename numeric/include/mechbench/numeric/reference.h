// A trusted reference trajectory for a free scene: one formulation at tight tolerance, confirmed
// by a second, independent one. Computed on demand; the harness caches it by scenario content.
#pragma once

#include "mechbench/method.h"
#include "mechbench/model.h"

#include <string>
#include <vector>

namespace mechbench::numeric {

struct ReferenceOptions {
  double rtol = 1e-12;      // DOPRI5 relative tolerance of the primary and of coordinate partitioning
  double atol = 1e-14;      // × coordinate scale
  double ali3p_h = 1e-4;    // step of the ALI3-P confirmation [s] (second order: error ~ h²)
  double agreement = 1e-8;  // stated: max position difference of the two runs, relative to the motion's scale
  // The N-four-bar (RecognizeNFourBar): the primary is its reduced equation at nfourbar_rtol; the
  // confirmation is index-1 DOPRI5 at segment_rtol on the full natural-coordinate model, restarted
  // from the reference state segment_margin after every singular position and stopped
  // segment_margin before the next (no index-1 integration crosses one); ALI3-P at whole_run_h
  // over the whole run shows what a formulation that crosses them reaches (informative).
  double nfourbar_rtol = 1e-13;
  double segment_rtol = 1e-12;
  double segment_margin = 0.02;  // [s]
  double whole_run_h = 5e-4;     // [s]
};

// The primary is index-1 + Baumgarte with DOPRI5 at rtol (it gets through singular positions).
// The confirmation is coordinate partitioning with DOPRI5 at rtol (independent coordinates, exact
// on the constraint manifold); where that stops at a singular position (Φ_q loses rank), ALI3-P
// (index-3 augmented Lagrangian, trapezoidal rule) at step ali3p_h confirms instead.
// The N-four-bar instead: the primary is NFourBarExact (its physics: every crank alike, a 1-DOF
// pendulum, the smooth continuation through the singular positions), confirmed segment by segment
// between them (see ReferenceOptions); `agreement` is over the samples of the segments.
struct Reference {
  Result primary;       // dyn-baumgarte-dopri5 at rtol (N-four-bar: its reduced equation): the reference trajectory
  Result confirmation;  // dyn-coordinate-partitioning, or dyn-ali3p where partitioning stops (N-four-bar:
                        // the segments' samples only)
  double agreement = kNaN;  // measured, relative to the motion's scale
  double tolerance = kNaN;  // stated (ReferenceOptions::agreement)
  bool confirmed = false;   // both ran to the end and agree within `tolerance`
  std::string description;  // one line: what it is and how it was confirmed
  // N-four-bar: samples compared (inside the segments) of all, the singular positions, and the
  // whole-run ALI3-P check (position error against the reference, largest spread of the crank
  // angles [rad]).
  int compared_samples = 0, singular_positions = 0;
  double whole_run_error = kNaN, whole_run_spread = kNaN;
  const std::vector<Sample>& trajectory() const { return primary.trajectory; }
};

// Applies to free scenes with mass (DynamicsApplicability); otherwise primary.status says why.
Reference ReferenceTrajectory(const Model& model, const ReferenceOptions& options = {});

// The largest position difference between two trajectories over their common samples, each slot
// divided by the motion's scale of its kind in `reference`: the largest range (max − min) reached
// by any length slot, or by any angle slot. Slots that hardly move do not make the scale vanish.
struct PositionError {
  double value = 0;     // relative
  std::string slot;     // where it is largest
  double t = 0;         // when [s]
  int samples = 0;      // compared
  std::string problem;  // e.g. sample times differ
};
PositionError ComparePositions(const Model& model, const std::vector<Sample>& reference,
                               const std::vector<Sample>& other);
// The same with the motion's scale taken from `scale_from` (e.g. a whole run) while comparing
// `reference` and `other` (e.g. some of its samples).
PositionError ComparePositionsScaled(const Model& model, const std::vector<Sample>& scale_from,
                                     const std::vector<Sample>& reference, const std::vector<Sample>& other);

}  // namespace mechbench::numeric
