// ODE adapter (no ODE headers here): maximal coordinates, one dBody per graph body (origin at its
// centre of mass), dHinge/dSlider joints for every pin and slider (tree and loop closures alike),
// drivers as joint motors that track the prescribed coordinate. Semi-implicit Euler, fixed step.
// Gear meshes are dJointCreateTransmission joints between wheels laid out by LayOutGears (module
// 2 mm): parallel-axes mode for external meshes, chain-drive mode (same-direction wheels) for
// internal meshes on fixed axes (a carrier that its driver holds still counts as fixed); a planet
// is a body hinged to its carrier body. An internal mesh on a turning carrier is left out.
// Spatial scenes (kind: spatial) through the engines' spatial graph (src/ode_spatial.cc): a dBody
// per graph body at its centre of mass with its full inertia tensor, a dBall or dHinge per joint
// (tree and loop closure alike; a revolute closure is one dHinge), hinge motors for drivers.
#pragma once

#include "mechbench/method.h"

#include <string>
#include <vector>

namespace mechbench::engines {

struct OdeOptions {
  std::string name = "ode-worldstep-default";
  bool quick = false;    // dWorldQuickStep, else dWorldStep
  double step = 1e-3;    // largest step h [s] (shortened evenly to land on every sample time)
  double erp = -1;       // < 0: ODE's default (0.2)
  double cfm = -1;       // < 0: ODE's default (1e-10 in double precision)
  int iterations = -1;   // QuickStep iterations; < 0: ODE's default (20)
  // Gear scenes: every body turns by exactly ω·h per step (dBodySetFiniteRotationMode 1). False
  // keeps ODE's default infinitesimal quaternion update, which turns a body by 2·atan(ω·h/2).
  bool gear_finite_rotation = true;
};
MethodPtr MakeOdeMethod(const OdeOptions& options);

// "ode-worldstep-default", "ode-worldstep-tuned", "ode-quickstep-default", "ode-quickstep-tuned".
std::vector<MethodPtr> MakeOdeMethods();

}  // namespace mechbench::engines
