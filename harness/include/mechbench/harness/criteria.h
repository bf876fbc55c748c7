// A published benchmark's own precision criteria (Model::criteria, `criteria:` in the file): the
// largest distance of one point from its reference position over the benchmark's output steps
// (the scene's samples), judged at each level (IFToMM: 1e-3 m high, 1e-1 m low precision).
#pragma once

#include "mechbench/method.h"
#include "mechbench/model.h"

#include <string>
#include <vector>

namespace mechbench::harness {

struct CriteriaVerdict {
  double error = kNaN;  // max |p − p_ref| of the criteria's point over the samples compared [length]
  double t = kNaN;      // where [s]
  int samples = 0;      // compared
  bool complete = false;  // every output step compared (a run stopped early is not judged)
  std::vector<bool> met;  // per level of Criteria::levels
  // "meets 1e-3 (and 1e-1)", "meets 1e-1, not 1e-3", "meets neither", "not judged: …"
  std::string Verdict(const Criteria& criteria) const;
};

// The criteria's distance at one sample: |p − p_ref| of its point between `run` and `reference`
// at the same time (pre: the model has criteria). NaN where the run's value is not finite.
double CriteriaDistance(const Model& model, const Sample& reference, const Sample& run);

// The q slots of the criteria's point (x, y; a spatial scene's x, y, z), those that move.
std::vector<int> CriteriaSlots(const Model& model);

// `run` against `reference` at the same samples (pre: the model has criteria).
CriteriaVerdict JudgeCriteria(const Model& model, const std::vector<Sample>& reference, const std::vector<Sample>& run);

}  // namespace mechbench::harness
