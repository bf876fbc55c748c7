// The compound pendulum's exact motion through Jacobi's elliptic functions (IFToMM A01 is the
// point-mass case): one crank pinned to ground under gravity (cranks.h, no couplers),
//   J θ̈ = −g K cos θ;  with φ = θ + π/2 (from the downward vertical), ω0² = g K / J:
//   sin(φ/2) = k sn(ω0 t + u0 | k),  cos(φ/2) = dn(…),  φ̇ = 2 k ω0 cn(…),
//   k² = sin²(φ0/2) + (φ̇0 / 2ω0)²  (k < 1: it swings; at k ≥ 1 it turns over, not described here).
// K(k) and sn, cn, dn are computed here by the arithmetic–geometric mean (descending Landen
// transformation, Abramowitz & Stegun 16.4 and 17.6), not taken from a library.
#pragma once

#include "mechbench/model.h"
#include "mechbench/numeric/reference.h"

#include <string>
#include <vector>

namespace mechbench::references {

// K(k), the complete elliptic integral of the first kind of modulus k (0 ≤ k < 1): π / (2 AGM(1, k')).
double EllipticK(double k);

struct Jacobi {
  double sn, cn, dn;
};
// sn, cn, dn of u for modulus k (0 ≤ k < 1); u is first reduced by the period 4K(k).
Jacobi JacobiElliptic(double u, double k);

// The motion of `model` (AnalyzeParallelCranks with no coupler) at its samples and at
// `extra_times`; `why` and an empty trajectory when it turns over.
numeric::ExactSolution PendulumExact(const Model& model, const std::vector<double>& extra_times, std::string& why);

}  // namespace mechbench::references
