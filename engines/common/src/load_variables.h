// The load laws' variables [t, q, q̇] (model.h: LoadVarQ) from an observed sample, as the planar
// StateLoads and the SpatialStateLoads evaluate them from an engine's body states.
#pragma once

#include "mechbench/method.h"
#include "mechbench/model.h"

#include <vector>

namespace mechbench::engines {

inline void SetLoadVariables(double t, const Sample& s, std::vector<double>& x) {
  const int n = static_cast<int>(s.q.size());
  x[kLoadVarTime] = t;
  for (int i = 0; i < n; ++i) x[LoadVarQ(i)] = s.q[i], x[LoadVarQd(i, n)] = s.qd[i];
}

}  // namespace mechbench::engines
