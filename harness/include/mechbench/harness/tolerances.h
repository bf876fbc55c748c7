// Tolerances as data: harness/tolerances.yaml.
#pragma once

#include <string>

namespace mechbench::harness {

struct Tolerances {
  double q = 1e-9, qd = 1e-9, qdd = 1e-9;  // relative agreement between methods
  double instant = 1e-9;                   // every named quantity both methods give at t0
  double residual = 1e-10;                 // scaled ‖Φ‖ along a motion
};

// The tolerances for `scenario` (its file stem), from the default file or `path`.
Tolerances LoadTolerances(const std::string& scenario, const std::string& path = "");
std::string DefaultTolerancesFile();

}  // namespace mechbench::harness
