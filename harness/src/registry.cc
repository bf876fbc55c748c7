#include "mechbench/harness/registry.h"

#include <algorithm>

#include "mechbench/analytic/analytic_method.h"
#include "mechbench/numeric/dynamics_methods.h"
#include "mechbench/numeric/numeric_method.h"
#ifdef MECHBENCH_WITH_SIMBODY
#include "mechbench/engines/simbody.h"
#endif
#ifdef MECHBENCH_WITH_ODE
#include "mechbench/engines/ode.h"
#endif
#ifdef MECHBENCH_WITH_BULLET
#include "mechbench/engines/bullet.h"
#endif
#ifdef MECHBENCH_WITH_MUJOCO
#include "mechbench/engines/mujoco.h"
#endif

namespace mechbench::harness {

std::vector<MethodPtr> EngineMethods() {
  std::vector<MethodPtr> methods;
  auto append = [&](std::vector<MethodPtr> more) {
    for (MethodPtr& m : more) methods.push_back(std::move(m));
  };
#ifdef MECHBENCH_WITH_SIMBODY
  append(engines::MakeSimbodyMethods());
#endif
#ifdef MECHBENCH_WITH_ODE
  append(engines::MakeOdeMethods());
#endif
#ifdef MECHBENCH_WITH_BULLET
  append(engines::MakeBulletMethods());
#endif
#ifdef MECHBENCH_WITH_MUJOCO
  append(engines::MakeMujocoMethods());
#endif
  (void)append;
  return methods;
}

std::vector<MethodPtr> AllMethods() {
  std::vector<MethodPtr> methods;
  methods.push_back(analytic::MakeAnalyticMethod());
  methods.push_back(numeric::MakeNumericMethod());
  // Forward dynamics of free scenes in natural coordinates, one method per formulation.
  methods.push_back(numeric::MakeBaumgarteRk4Method());
  methods.push_back(numeric::MakeBaumgarteDopri5Method());
  methods.push_back(numeric::MakeAli3pMethod());
  methods.push_back(numeric::MakeCoordinatePartitioningMethod());
  for (MethodPtr& m : EngineMethods()) methods.push_back(std::move(m));
  return methods;
}

bool KnownMethodName(const std::string& name) {
  static const std::vector<std::string> built = [] {
    std::vector<std::string> names;
    for (const MethodPtr& m : AllMethods()) names.push_back(m->name());
    return names;
  }();
  if (std::find(built.begin(), built.end(), name) != built.end()) return true;
  std::vector<std::string> absent;  // engines left out of this build
#ifndef MECHBENCH_WITH_SIMBODY
  absent.push_back("simbody-");
#endif
#ifndef MECHBENCH_WITH_ODE
  absent.push_back("ode-");
#endif
#ifndef MECHBENCH_WITH_BULLET
  absent.push_back("bullet-");
#endif
#ifndef MECHBENCH_WITH_MUJOCO
  absent.push_back("mujoco-");
#endif
  return std::any_of(absent.begin(), absent.end(), [&](const std::string& p) { return name.rfind(p, 0) == 0; });
}

}  // namespace mechbench::harness
