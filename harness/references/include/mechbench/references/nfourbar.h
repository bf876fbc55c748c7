// The IFToMM multibody benchmark A02, the N-four-bar mechanism: N four-bars in a row sharing
// their vertical bars. 2N + 1 uniform bars of 1 m and 1 kg: ground points G0 … GN at x = 0 … N on
// y = 0, coupler points P0 … PN at y = 1; bars Gi–Pi (vertical) and P(i−1)–Pi (coupler); gravity
// −9.81 m/s² along y; P0 starts at 1 m/s along +x (every coupler point then moves alike); 20 s.
// Whenever the vertical bars pass through the horizontal, all bars are collinear: Φ_q loses N
// ranks and the mechanism may bifurcate, which is what the benchmark tests.
#pragma once

#include "mechbench/method.h"
#include "mechbench/model.h"

#include <string>
#include <vector>

namespace mechbench::references {

struct NFourBarOptions {
  int n = 1;              // number of four-bars (1 … 1000 for scaling; 40 in the benchmark)
  double t1 = 20.0;       // end of the motion [s]
  int samples = 201;      // output samples over [0, t1]
  // The benchmark's precision criteria (A02: P0's position — the specification's B0 — within
  // 1e-3 m and 1e-1 m over the output steps, which are the samples less one; the specification
  // asks for 400, i.e. samples = 401).
  bool criteria = false;
};

// The scenario file text (see scenarios/FORMAT.md), and the model loaded from it. The file names
// its exact solution, `reference: {exact: nfourbar}` (the registry, registry.h).
std::string NFourBarYaml(const NFourBarOptions& options);
Model NFourBar(const NFourBarOptions& options);

// The q slots of xPi, yPi and the point index of Gi, i = 0 … n_bars, of a generated N-four-bar (O(N)).
struct NFourBarSlots {
  std::vector<int> x, y, ground;
};
NFourBarSlots NFourBarSlotsOf(const Model& model, int n_bars);

// The N-four-bar's motion on its parallelogram branch, from its physics: every crank turns alike
// (θ_i = θ, the couplers translate), so the mechanism is a one-degree-of-freedom pendulum
//   J θ̈ = −g K cos θ,   J = Σ_cranks (I_G) + Σ_couplers m L²,   K = Σ_cranks m x_com + Σ_couplers m L,
// θ(0) = 90°, θ̇(0) = −v0 / L (P0 moving at v0 along +x), with Pi = (i + L cos θ, L sin θ). The
// smooth solution through the singular horizontal positions, where velocities are continuous
// and the constraint forces bounded: a branch switch there would need an impulse. This is the
// benchmark's own reference (IFToMM A02). Integrated by DOPRI5 on (θ, θ̇) at `rtol` (atol rtol/100
// rad), landing on every sample, every extra time and points 1 ms apart; states in the model's q
// layout, with q̇ and q̈. Requires the structure (cranks.h) with N ≥ 1 couplers; the mechanism
// need not be the generator's (any masses, lengths, pivots in a row, initial state).
struct NFourBarSolution {
  std::vector<Sample> trajectory;  // at the model's samples
  std::vector<Sample> extra;       // at `extra_times`, in their order
  double energy_drift = 0;        // max |E − E0| of the reduced equation over the samples [J]
  double energy = 0;              // E0 [J]
  long steps = 0;
  std::vector<double> crossings;  // times of the singular (horizontal) positions [s]
};
// `budget`: its cpu_deadline, when set, bounds the integration (BudgetExceeded, as in a method's
// stepping loop): a long motion has 1000 stops a second.
NFourBarSolution NFourBarExact(const Model& model, double rtol = 1e-13, const std::vector<double>& extra_times = {},
                               const RunOptions& budget = {});

}  // namespace mechbench::references
