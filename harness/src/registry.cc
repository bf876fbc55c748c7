#include "mechbench/harness/registry.h"

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

}  // namespace mechbench::harness
