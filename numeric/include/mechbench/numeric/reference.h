// A trusted reference trajectory for a free scene: one formulation at tight tolerance, confirmed
// by a second, independent one. Computed on demand; the harness caches it by scenario content.
#pragma once

#include "mechbench/method.h"
#include "mechbench/model.h"

#include <functional>
#include <map>
#include <string>
#include <vector>

namespace mechbench::numeric {

struct ReferenceOptions {
  double rtol = 1e-12;      // DOPRI5 relative tolerance of the primary and of coordinate partitioning
  double atol = 1e-14;      // × coordinate scale
  double ali3p_h = 1e-4;    // step of the ALI3-P confirmation [s] (second order: error ~ h²)
  // Stated: max position difference of the two runs, relative to the motion's scale
  // (CompareMotion), for a motion of agreement_horizon seconds; a longer one is allowed
  // proportionally more (both runs' errors are mostly phase, which accumulates linearly).
  double agreement = 1e-8;
  double agreement_horizon = 1.0;  // [s]
  // A scene whose exact motion is known (ReferenceFromExact, from the registry in
  // harness/references): the primary is its closed form or reduced equation (at exact_rtol where
  // it is integrated), confirmed on the full natural-coordinate model by index-1 DOPRI5, never by
  // the exact motion itself; with singular positions (the N-four-bar) twice:
  //  - between the singular positions at segment_rtol, restarted from the reference state
  //    segment_margin after every singular position and stopped segment_margin before the next
  //    (no integration in real time crosses one); within `agreement` over those samples;
  //  - across them, one run over the whole motion from the model's initial state at
  //    whole_run_rtol along t + i·detour in complex time (see Reference); within
  //    whole_run_agreement over all samples. Its error is DOPRI5's, not extrapolated, and the same
  //    whatever the detour (analytic continuation): on A02 (N = 40, 20 s) 2.8e-9 at rtol 1e-12,
  //    2.3e-10 at 1e-13; 1.9e-9 at N = 1 over its 21 singular positions.
  double exact_rtol = 1e-13;
  double segment_rtol = 1e-12;
  double segment_margin = 0.02;       // [s]
  double whole_run_rtol = 1e-12;
  double detour = 0.02;               // the path's imaginary time [s]: how far it passes each singular position
  double whole_run_agreement = 1e-8;  // stated, relative to the motion's scale as `agreement`
  // [s] CPU for each of the two formulations' runs (NaN: none). A run its budget stops leaves the
  // reference unconfirmed, with why, instead of holding the command up (a free scene followed for
  // 1e9 s would take days).
  double cpu_budget = kNaN;
};

// The primary is index-1 + Baumgarte with DOPRI5 at rtol (it gets through singular positions).
// The confirmation is coordinate partitioning with DOPRI5 at rtol (independent coordinates, exact
// on the constraint manifold); where that stops at a singular position (Φ_q loses rank), ALI3-P
// (index-3 augmented Lagrangian, trapezoidal rule) at step ali3p_h confirms instead.
// Generic: no scene is recognised here. A scene that names its exact motion goes through
// ReferenceFromExact instead (the harness's reference builder asks the registry).
// (declared below)

// A motion known exactly, from outside the solver (the reference registry, harness/references):
// a closed form, or a mechanism's own reduced equation; numeric only confirms it.
struct ExactSolution {
  std::vector<Sample> trajectory;  // at the model's samples, in its q layout, with q̇ and q̈
  std::vector<Sample> extra;       // at the extra times asked for, in their order
  std::vector<double> singular;    // times where the full model's Φ_q loses rank [s]
  std::map<std::string, double> quantities;  // the primary's figures (energy, energy_drift, steps, …)
};
struct ExactMotion {
  std::string method;       // the primary's name in the results
  std::string formulation;  // its settings["formulation"]
  std::string budget_note;  // appended to an over-budget reason (why it takes long)
  // The motion at the model's samples and at `extra_times` (sorted or not); may throw
  // BudgetExceeded against budget.cpu_deadline.
  std::function<ExactSolution(const std::vector<double>& extra_times, const RunOptions& budget)> solve;
  // The description's first part (what it is), from the solution.
  std::function<std::string(const ExactSolution&)> describe;
  // The confirmation's plan: index-1 DOPRI5 segments end here (a long horizon confirmed over part
  // of it); with whole_run, also one run across the singular positions in complex time, whose
  // branch_spread (optional) is reported as Reference::whole_run_spread.
  double confirm_until = INFINITY;
  bool whole_run = false;
  std::function<double(const std::vector<Sample>&)> branch_spread;
};

// The exact motion as the primary, confirmed by its plan: index-1 DOPRI5 on the full model,
// restarted from the exact state segment_margin after each singular position, segment by
// segment; with whole_run, across them by the whole run in complex time: the motion is
// real-analytic in t, so the full model's equations also hold along its continuation to complex
// t, where Φ_q keeps its rank; a run along t + i·detour passes every singular position at a
// distance, and a leg down to the real axis at each sample gives the motion there, the analytic
// continuation, i.e. the smooth passage (a branch switch is not analytic). ALI3-P, which crosses
// them in real time, does not converge tightly enough to confirm: on A02 (N = 40, default
// options) it is 4.1e-4 / 2.2e-4 / 5.4e-4 / 1.1e-3 off at h = 1 / 0.5 / 0.25 / 0.125 ms (not
// ~h², already before the first singular position), so its Richardson extrapolation is no better.
// Without singular positions (the pendulum): one segment from t0 to confirm_until.
// (declared below)

struct Reference {
  Result primary;       // dyn-baumgarte-dopri5 at rtol (N-four-bar: its reduced equation): the reference trajectory
  Result confirmation;  // dyn-coordinate-partitioning, or dyn-ali3p where partitioning stops (N-four-bar:
                        // the segments' samples only; cpu_seconds includes whole_run's)
  // Measured, relative to the motion's scale (N-four-bar: the worse of segment_agreement and
  // whole_run_agreement, so that one figure says how far the two formulations are apart).
  double agreement = kNaN;
  // The same for q̇ and q̈ (relative to their scales, CompareMotion), measured where the two
  // formulations are compared sample by sample (NaN for the N-four-bar); not part of `confirmed`.
  double agreement_qd = kNaN, agreement_qdd = kNaN;
  double tolerance = kNaN;  // stated (ReferenceOptions::agreement; N-four-bar: the wider of its two)
  bool confirmed = false;   // both ran to the end and agree within `tolerance` (N-four-bar: each
                            // confirmation within its own stated tolerance)
  std::string description;  // one line: what it is and how it was confirmed
  // N-four-bar: samples compared inside the segments, of all; the singular positions.
  int compared_samples = 0, singular_positions = 0;
  double segment_agreement = kNaN;  // measured over the segments' samples
  // N-four-bar across the singular positions: the run in complex time at every sample (real parts;
  // quantities: steps, evaluations, and "imaginary", the largest |Im q_j| / coordinate scale left
  // at the samples), its agreement over all samples (measured; stated whole_run_tolerance), and
  // the largest spread of its crank angles [rad] (0 on the parallelogram branch).
  Result whole_run;
  double whole_run_agreement = kNaN, whole_run_tolerance = kNaN, whole_run_spread = kNaN;
  const std::vector<Sample>& trajectory() const { return primary.trajectory; }
};


Reference ReferenceTrajectory(const Model& model, const ReferenceOptions& options = {});
Reference ReferenceFromExact(const Model& model, const ExactMotion& exact, const ReferenceOptions& options = {});

}  // namespace mechbench::numeric
