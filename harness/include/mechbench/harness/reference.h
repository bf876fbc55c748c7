// The reference trajectory of a free scene (numeric::ReferenceTrajectory), computed on demand
// and cached on disk under a key made of the scenario file's text and the model's content, so
// that editing a scenario invalidates it.
//
// Cache folder: $MECHBENCH_REFERENCE_CACHE if set (the words "off", "0" or an empty value turn
// the cache off), else $XDG_CACHE_HOME/mechbench, else $HOME/.cache/mechbench.
#pragma once

#include "mechbench/method.h"
#include "mechbench/model.h"

#include <string>
#include <vector>

namespace mechbench::harness {

struct ReferenceRecord {
  std::vector<Sample> trajectory;  // at analysis.TimeAt(k); empty when it could not be computed
  std::string description;         // how it was computed and confirmed, or why it failed
  double agreement = kNaN;         // measured agreement of its two formulations (relative)
  double agreement_qd = kNaN, agreement_qdd = kNaN;  // the same for q̇ and q̈ (NaN: not measured)
  double tolerance = kNaN;         // the stated agreement
  bool confirmed = false;
  bool from_cache = false;
  std::string cache_file;          // where it was read or written ("" when not cached)
  double cpu_seconds = 0;          // to compute it (0 when read from the cache)
};

std::string ReferenceCacheDir();
// 16 hex digits: FNV-1a over the scenario file's text (when readable), the model's content and
// the reference's settings.
std::string ReferenceKey(const Model& model);
// `cpu_budget` [s] bounds each of the reference's two runs (NaN: no bound); a reference it stops
// is unconfirmed, with why, and not cached.
ReferenceRecord GetReference(const Model& model, double cpu_budget = kNaN);

}  // namespace mechbench::harness
