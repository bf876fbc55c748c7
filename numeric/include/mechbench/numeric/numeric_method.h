// The "numeric" method: natural coordinates with Newton–Raphson position and linear velocity and
// acceleration problems (book Part II), plus M and Q (Part III) when the scene has mass.
#pragma once

#include "mechbench/method.h"
#include "mechbench/numeric/solver.h"

#include <memory>
#include <optional>
#include <string>

namespace mechbench::numeric {

class NumericMethod final : public Method {
 public:
  explicit NumericMethod(NewtonOptions options = {});
  std::optional<std::string> Applicability(const Model& model) const override;

 protected:
  void DoRun(const Model& model, const RunOptions& options, Result& result) const override;

 private:
  NewtonOptions newton_;
};

std::unique_ptr<Method> MakeNumericMethod();

}  // namespace mechbench::numeric
