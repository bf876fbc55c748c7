// What the Bullet adapter's planar path (bullet_method.cc) and its spatial path (bullet_spatial.cc,
// the engines' spatial graph) share: the variant's settings, the world's parts and solver
// settings, the impulse limit, and the world acceleration of a body from one step.
#pragma once

#include "mechbench/engines/engine_method.h"
#include "mechbench/engines/spatial_graph.h"
#include "mechbench/format.h"
#include "mechbench/method.h"
#include "mechbench/run_control.h"

#include <btBulletDynamicsCommon.h>

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace mechbench::engines::bullet_internal {

// Motor and constraint impulse limits: large enough never to bind (Bullet's defaults are 100 for
// btMultiBodyConstraint, which a driven linkage exceeds).
inline constexpr double kMaxImpulse = 1e10;

struct Variant {
  std::string name;
  bool multibody;
  double h;
  int iterations;  // <0: default
  double erp, cfm; // <0: default
};

// A body's world acceleration from the step ending now: its centre of mass's (v_{n+1} − v_n)/h
// and (ω_{n+1} − ω_n)/h, moved to the body frame's origin (as for the planar states).
inline void WorldAcceleration(SpatialState& now, const SpatialState& before, const Eigen::Vector3d& com_B, double h) {
  const Eigen::Vector3d r1 = now.R * com_B, r0 = before.R * com_B;
  const Eigen::Vector3d ac = ((now.v + now.omega.cross(r1)) - (before.v + before.omega.cross(r0))) / h;
  now.alpha = (now.omega - before.omega) / h;
  now.a = ac - now.alpha.cross(r1) - now.omega.cross(now.omega.cross(r1));
}

// The parts every Bullet world needs; the world itself is owned by the derived scene, which must
// destroy it (and remove its objects) before these go.
struct WorldParts {
  std::unique_ptr<btDefaultCollisionConfiguration> config = std::make_unique<btDefaultCollisionConfiguration>();
  std::unique_ptr<btCollisionDispatcher> dispatcher = std::make_unique<btCollisionDispatcher>(config.get());
  std::unique_ptr<btDbvtBroadphase> broadphase = std::make_unique<btDbvtBroadphase>();
  // Every body needs a shape; no pair ever collides (collision mask 0 on every object).
  std::unique_ptr<btSphereShape> shape = std::make_unique<btSphereShape>(btScalar(0.01));
};

inline void ApplySolverSettings(btContactSolverInfo& info, const Variant& v, Result& result) {
  if (v.iterations > 0) info.m_numIterations = v.iterations;
  if (v.erp >= 0) info.m_erp = info.m_erp2 = v.erp;
  if (v.cfm >= 0) info.m_globalCfm = v.cfm;
  result.settings["solver_iterations"] = std::to_string(info.m_numIterations) + (v.iterations > 0 ? " (set)" : " (Bullet default)");
  result.settings["erp"] = Fmt(info.m_erp) + (v.erp >= 0 ? " (set)" : " (Bullet default)");
  result.settings["cfm"] = Fmt(info.m_globalCfm) + (v.cfm >= 0 ? " (set)" : " (Bullet default)");
}

// The spatial graph in Bullet (bullet_spatial.cc): what the variant cannot express, or nullopt;
// and the run, as EngineMethod::SimulateSpatial describes it.
std::optional<std::string> SpatialReason(const SpatialGraph& g, const Variant& v);
void SimulateSpatial(const SpatialGraph& g, const Variant& v, const std::vector<double>& times,
                     const ControlValue& control, const SpatialRecorder& record, const RunOptions& options,
                     Result& result);

}  // namespace mechbench::engines::bullet_internal
