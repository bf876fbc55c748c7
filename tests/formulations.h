// What the numeric suites share: a fixture scene by file name, and every natural-coordinate
// dynamics formulation, dense and sparse where it has both, to run a scene through.
#pragma once

#include "mechbench/loader.h"
#include "mechbench/numeric/dynamics_methods.h"

#include <Eigen/Core>

#include <cmath>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace mechbench::numeric::test {

// tests/data/scenes/<file>.
inline Model Scene(const std::string& file) {
  return LoadScenario(std::string(MECHBENCH_TEST_DATA) + "/scenes/" + file);
}

// A consistent state off the file's (for Q and its tangents at t = 0.9 s): the scene's block
// (slot xB) or bar (xA, yA, theta): the block at x = 0.3 m moving at 0.7 m/s; the
// bar at θ = 0.7 rad turning at 1.3 rad/s.
inline void OffState(const Model& model, Eigen::VectorXd& q, Eigen::VectorXd& qd) {
  q = model.GuessQ();
  qd = Eigen::VectorXd::Zero(q.size());
  if (const int x = model.SlotIndex("xB"); x >= 0) {
    q[x] = 0.3, qd[x] = 0.7;
    return;
  }
  const double a = 0.7;
  q[model.SlotIndex("xA")] = std::cos(a), q[model.SlotIndex("yA")] = std::sin(a), q[model.SlotIndex("theta")] = a;
  qd[model.SlotIndex("xA")] = -1.3 * std::sin(a), qd[model.SlotIndex("yA")] = 1.3 * std::cos(a);
  qd[model.SlotIndex("theta")] = 1.3;
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
