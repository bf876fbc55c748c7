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
};

// The primary is index-1 + Baumgarte with DOPRI5 at rtol (it gets through singular positions).
// The confirmation is coordinate partitioning with DOPRI5 at rtol (independent coordinates, exact
// on the constraint manifold); where that stops at a singular position (Φ_q loses rank), ALI3-P
// (index-3 augmented Lagrangian, trapezoidal rule) at step ali3p_h confirms instead.
struct Reference {
  Result primary;       // dyn-baumgarte-dopri5 at rtol: the reference trajectory
  Result confirmation;  // dyn-coordinate-partitioning, or dyn-ali3p where partitioning stops
  double agreement = kNaN;  // measured, relative to the motion's scale
  double tolerance = kNaN;  // stated (ReferenceOptions::agreement)
  bool confirmed = false;   // both ran to the end and agree within `tolerance`
  std::string description;  // one line: what it is and how it was confirmed
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

}  // namespace mechbench::numeric
