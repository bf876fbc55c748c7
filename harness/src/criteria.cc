#include "mechbench/harness/criteria.h"

#include "mechbench/errors.h"
#include "mechbench/format.h"

#include <algorithm>
#include <cmath>

namespace mechbench::harness {

double CriteriaDistance(const Model& model, const Sample& reference, const Sample& run) {
  MB_ASSERT(model.criteria.has_value(), "CriteriaDistance needs a scene with criteria");
  double d2 = 0;
  for (int s : CriteriaSlots(model)) {
    const double d = run.q[s] - reference.q[s];
    d2 += d * d;
  }
  return std::sqrt(d2);
}

std::vector<int> CriteriaSlots(const Model& model) {
  MB_ASSERT(model.criteria.has_value(), "CriteriaSlots needs a scene with criteria");
  const int p = model.criteria->point;
  std::vector<int> slots;
  if (model.kind == ScenarioKind::kSpatial) {
    for (size_t s = 0; s < model.q_layout.size(); ++s)
      if (model.q_layout[s].entity == p) slots.push_back(static_cast<int>(s));
  } else {
    for (int axis = 0; axis < 2; ++axis)
      if (const int s = model.SlotOf(p, axis); s >= 0) slots.push_back(s);
  }
  return slots;
}

CriteriaVerdict JudgeCriteria(const Model& model, const std::vector<Sample>& reference, const std::vector<Sample>& run) {
  MB_ASSERT(model.criteria.has_value(), "JudgeCriteria needs a scene with criteria");
  const Criteria& c = *model.criteria;
  CriteriaVerdict v;
  const size_t n = std::min(reference.size(), run.size());
  v.error = 0;
  for (size_t k = 0; k < n; ++k) {
    const double d = CriteriaDistance(model, reference[k], run[k]);
    if (!(d <= v.error)) v.error = d, v.t = run[k].t;  // NaN counts as the worst
    ++v.samples;
  }
  v.complete = v.samples == c.output_steps + 1;
  for (double level : c.levels) v.met.push_back(v.complete && v.error <= level);
  return v;
}

std::string CriteriaVerdict::Verdict(const Criteria& c) const {
  if (!complete)
    return "not judged: the run reached " + std::to_string(samples) + " of the " + std::to_string(c.output_steps + 1) +
           " samples (output steps + 1)";
  std::string met_list, not_list;
  for (size_t i = 0; i < c.levels.size(); ++i) (met[i] ? met_list : not_list) += (i ? ", " : "") + Fmt(c.levels[i], 3);
  if (met_list.empty()) return "meets neither level (" + not_list + ")";
  const auto trim = [](std::string s) { return s.rfind(", ", 0) == 0 ? s.substr(2) : s; };
  return "meets " + trim(met_list) + (not_list.empty() ? "" : ", not " + trim(not_list));
}

}  // namespace mechbench::harness
