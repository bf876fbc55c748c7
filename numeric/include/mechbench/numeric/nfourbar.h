// The IFToMM multibody benchmark A02, the N-four-bar mechanism: N four-bars in a row sharing
// their vertical bars. 2N + 1 uniform bars of 1 m and 1 kg: ground points G0 … GN at x = 0 … N on
// y = 0, coupler points P0 … PN at y = 1; bars Gi–Pi (vertical) and P(i−1)–Pi (coupler); gravity
// −9.81 m/s² along y; P0 starts at 1 m/s along +x (every coupler point then moves alike); 20 s.
// Whenever the vertical bars pass through the horizontal, all bars are collinear: Φ_q loses N
// ranks and the mechanism may bifurcate, which is what the benchmark tests.
#pragma once

#include "mechbench/model.h"

#include <string>

namespace mechbench::numeric {

struct NFourBarOptions {
  int n = 1;              // number of four-bars (1 … 1000 for scaling; 40 in the benchmark)
  double t1 = 20.0;       // end of the motion [s]
  int samples = 201;      // output samples over [0, t1]
};

// The scenario file text (see scenarios/FORMAT.md), and the model loaded from it.
std::string NFourBarYaml(const NFourBarOptions& options);
Model NFourBar(const NFourBarOptions& options);

}  // namespace mechbench::numeric
