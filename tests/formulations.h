// What the numeric suites share: a fixture scene by file name, and every natural-coordinate
// dynamics formulation, dense and sparse where it has both, to run a scene through.
#pragma once

#include "mechbench/loader.h"
#include "mechbench/numeric/dynamics_methods.h"

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace mechbench::numeric::test {

// tests/data/scenes/<file>.
inline Model Scene(const std::string& file) {
  return LoadScenario(std::string(MECHBENCH_TEST_DATA) + "/scenes/" + file);
}

struct Formulation {
  std::string name;
  std::function<std::unique_ptr<Method>()> make;
};

inline std::vector<Formulation> Formulations() {
  const auto rk4 = [](LinearAlgebra la) { BaumgarteOptions o; o.linear_algebra = la; return MakeBaumgarteRk4Method(o); };
  const auto dopri = [](LinearAlgebra la) { BaumgarteOptions o; o.linear_algebra = la; return MakeBaumgarteDopri5Method(o); };
  const auto ali = [](LinearAlgebra la) { Ali3pOptions o; o.linear_algebra = la; return MakeAli3pMethod(o); };
  return {{"rk4 dense", [=] { return rk4(LinearAlgebra::kDense); }},
          {"rk4 sparse", [=] { return rk4(LinearAlgebra::kSparse); }},
          {"dopri5 dense", [=] { return dopri(LinearAlgebra::kDense); }},
          {"dopri5 sparse", [=] { return dopri(LinearAlgebra::kSparse); }},
          {"ali3p dense", [=] { return ali(LinearAlgebra::kDense); }},
          {"ali3p sparse", [=] { return ali(LinearAlgebra::kSparse); }},
          {"coordinate partitioning", [] { return MakeCoordinatePartitioningMethod(); }}};
}

}  // namespace mechbench::numeric::test
