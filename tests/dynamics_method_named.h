// What the spatial dynamics suites share: the dynamics formulation a parameterized test names
// ("rk4", "dopri5", "ali3p", "partitioning": index-1 + Baumgarte with RK4 or DOPRI5, ALI3-P,
// coordinate partitioning).
#pragma once

#include "mechbench/numeric/dynamics_methods.h"

#include <memory>
#include <string>

namespace mechbench::numeric::test {

inline std::unique_ptr<Method> DynamicsMethodNamed(const std::string& name) {
  if (name == "rk4") return MakeBaumgarteRk4Method();
  if (name == "dopri5") return MakeBaumgarteDopri5Method();
  if (name == "ali3p") return MakeAli3pMethod();
  return MakeCoordinatePartitioningMethod();
}

}  // namespace mechbench::numeric::test
