// The structure the registry's pendulum-like closed forms describe, found from the model's
// geometry and topology (never from names): parallel cranks of one length, each pinned to ground
// at one fixed point, whose tips are joined in a row by couplers that keep every crank at the
// same angle (parallelograms). One crank and no coupler is a compound pendulum; N + 1 cranks and
// N couplers is the N-four-bar (IFToMM A02). Its motion is a one-degree-of-freedom pendulum
//   J θ̈ = −g K cos θ,   J = Σ_cranks (I_com + m |d|²) + Σ_couplers m L²,
//                        K = Σ_cranks m (d · u) + Σ_couplers m L,
// θ the cranks' angle from +x, d a crank's centre of mass from its pivot, u its unit direction.
#pragma once

#include "mechbench/model.h"

#include <string>
#include <vector>

namespace mechbench::references {

struct ParallelCranks {
  // Per crank, in the order of the moving points along the row of couplers (the first crank is
  // the end of the row whose body comes first in the file).
  std::vector<int> ground;  // fixed point (pivot)
  std::vector<int> tip;     // moving point
  std::vector<int> x, y;    // q slots of the tip
  int couplers = 0;
  double L = 0;        // the cranks' length
  double J = 0, K = 0;  // of the reduced equation (above)
  double g = 0;        // gravity along −y [length/s²]
  double theta0 = 0;   // the cranks' angle at t0 [rad]
  double omega0 = 0;   // their rate at t0, from the initial condition [rad/s]
  // A pendulum written with the crank's angle as a coordinate (`type: angle` along the crank,
  // from the ground x axis): its q slot and its value at t0 (the branch the file draws; the
  // vector tip → pivot is the crank's angle + π). -1: no coordinate (the points' only).
  int angle_slot = -1;
  double angle0 = 0;
};

// The structure, or `why` it is not one (the first difference found, with the element it is about).
bool AnalyzeParallelCranks(const Model& model, ParallelCranks& out, std::string& why);

}  // namespace mechbench::references
