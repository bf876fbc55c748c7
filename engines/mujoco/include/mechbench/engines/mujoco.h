// MuJoCo adapter (no MuJoCo headers here): the scene written as MJCF in memory (a virtual file
// system, no temporary file) and loaded with mj_loadXML. The graph's spanning tree becomes nested
// bodies (hinge joints about z, slide joints along in-plane axes: planar by construction), loop
// closures `connect` equalities, gear meshes `joint` equalities with `polycoef`, and a mesh on a
// carrier (Willis' relation over three members) a fixed tendon over the three joints held at its
// t0 length by a `tendon` equality (every member on its own hinge, as the graph has it). MuJoCo's
// equality constraints are soft: their solref/solimp are recorded with every result. A driver is
// prescribed motion: its joint carries a large armature, is pushed by armature·q̈_law, and has its
// qpos/qvel set to the law before every step (MuJoCo 2.2 has no kinematic joints).
#pragma once

#include "mechbench/method.h"

#include <array>
#include <string>
#include <vector>

namespace mechbench::engines {

struct MujocoOptions {
  std::string name = "mujoco-euler-default";
  double step = 2e-3;                // largest step h [s] (MuJoCo's default timestep is 2 ms)
  std::string integrator = "Euler";  // "Euler" | "RK4" | "implicit"
  // Equality-constraint softness; MuJoCo's defaults (0.02, 1) and (0.9, 0.95, 0.001, 0.5, 2).
  std::array<double, 2> solref{0.02, 1.0};
  std::array<double, 5> solimp{0.9, 0.95, 0.001, 0.5, 2.0};
  double tolerance = 1e-8;  // main solver tolerance (MuJoCo default 1e-8)
  int iterations = 100;     // main solver iterations (MuJoCo default 100)
  double driver_armature = 1e6;  // driven joint's armature ÷ the scene's inertia scale
};
MethodPtr MakeMujocoMethod(const MujocoOptions& options);

// "mujoco-euler-default" (MuJoCo's defaults) and "mujoco-rk4-tuned".
std::vector<MethodPtr> MakeMujocoMethods();

}  // namespace mechbench::engines
