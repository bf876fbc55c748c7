#include "mechbench/harness/registry.h"

#include "mechbench/analytic/analytic_method.h"
#include "mechbench/numeric/numeric_method.h"

namespace mechbench::harness {

std::vector<MethodPtr> AllMethods() {
  std::vector<MethodPtr> methods;
  methods.push_back(analytic::MakeAnalyticMethod());
  methods.push_back(numeric::MakeNumericMethod());
  return methods;
}

}  // namespace mechbench::harness
