// What the ODE adapter's planar path (ode_method.cc) and spatial path (ode_spatial.cc) share:
// a body's frame state set on and read from an ODE body (whose origin is its centre of mass), and
// the spatial path's entry point. Internal to engines/ode/src.
#pragma once

#include "mechbench/engines/engine_method.h"
#include "mechbench/engines/spatial_graph.h"

#include <ode/ode.h>

#include <vector>

namespace mechbench::engines::ode_internal {

// A body's frame state (origin, not the centre of mass, which sits at R com_B from it) set on, and
// read from, the ODE body; accelerations of a step as (v_{n+1} − v_n)/h of the centre of mass.
inline void SetWorldState(dBodyID b, const SpatialState& s, const Eigen::Vector3d& com_B) {
  const Eigen::Vector3d r = s.R * com_B, c = s.p + r, vc = s.v + s.omega.cross(r);
  dBodySetPosition(b, c.x(), c.y(), c.z());
  dMatrix3 R;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) R[4 * i + j] = s.R(i, j);
    R[4 * i + 3] = 0;
  }
  dBodySetRotation(b, R);
  dBodySetLinearVel(b, vc.x(), vc.y(), vc.z());
  dBodySetAngularVel(b, s.omega.x(), s.omega.y(), s.omega.z());
}
inline SpatialState WorldState(dBodyID b, const Eigen::Vector3d& com_B) {
  SpatialState s;
  const dReal* c = dBodyGetPosition(b);
  const dReal* R = dBodyGetRotation(b);  // 3×4 row-major
  const dReal* v = dBodyGetLinearVel(b);
  const dReal* om = dBodyGetAngularVel(b);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) s.R(i, j) = R[4 * i + j];
  s.omega = {om[0], om[1], om[2]};
  const Eigen::Vector3d r = s.R * com_B;
  s.p = Eigen::Vector3d(c[0], c[1], c[2]) - r;
  s.v = Eigen::Vector3d(v[0], v[1], v[2]) - s.omega.cross(r);
  return s;
}
inline void WorldAcceleration(SpatialState& now, const SpatialState& before, const Eigen::Vector3d& com_B, double h) {
  const Eigen::Vector3d r1 = now.R * com_B, r0 = before.R * com_B;
  const Eigen::Vector3d ac = ((now.v + now.omega.cross(r1)) - (before.v + before.omega.cross(r0))) / h;
  now.alpha = (now.omega - before.omega) / h;
  now.a = ac - now.alpha.cross(r1) - now.omega.cross(now.omega.cross(r1));
}

// A spatial graph's motion in the world `w` (created, seeded and configured by the caller, its
// stepper's settings already in result.settings): bodies, joints, loads and drivers built from the
// graph, stepped with dWorldQuickStep (`quick`) or dWorldStep at h ≤ control.value, landing on
// every sample, each sample recorded as the graph bodies' world states.
void SimulateSpatialGraph(dWorldID w, bool quick, const SpatialGraph& g, const std::vector<double>& times,
                          const ControlValue& control, const SpatialRecorder& record, const RunOptions& options,
                          Result& result);

}  // namespace mechbench::engines::ode_internal
