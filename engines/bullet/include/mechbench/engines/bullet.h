// Bullet adapter (no Bullet headers here), double precision only (pkg-config bullet-float64, which
// defines BT_USE_DOUBLE_PRECISION). Two formulations, each a separate method:
//  - bullet-multibody: one btMultiBody with a fixed base (ground) over the graph's spanning tree
//    (revolute links about z, prismatic links along in-plane axes: planar by construction), loop
//    closures as btMultiBodyPoint2Point, gears as btMultiBodyGearConstraint, drivers as
//    btMultiBodyJointMotor velocity targets. A planet (LayOutGears) is a link under its carrier's;
//    its meshes couple it with the central member through the carrier as the gear's auxiliary link.
//  - bullet-rigidbody: one btRigidBody per graph body in a btDiscreteDynamicsWorld, every pin a
//    btHingeConstraint about z and every slider a btSliderConstraint (tree and loop joints alike),
//    gears as btGearConstraint (no carrier: it couples two absolute angular velocities), drivers
//    as the hinge/slider motors; out-of-plane motion is removed
//    by each body's linear factor (1, 1, 0) and angular factor (0, 0, 1).
// Both step semi-implicit Euler with the sequential-impulse (PGS) solver at a fixed step.
#pragma once

#include "mechbench/method.h"

#include <string>
#include <vector>

namespace mechbench::engines {

struct BulletOptions {
  std::string name = "bullet-multibody-default";
  bool multibody = true;  // btMultiBody, else btRigidBody + typed constraints
  double step = 1e-3;     // largest step h [s] (shortened evenly to land on every sample time)
  int iterations = -1;    // solver iterations; < 0: Bullet's default (10)
  double erp = -1;        // < 0: Bullet's default (0.2)
  double cfm = -1;        // global CFM; < 0: Bullet's default (0)
};
MethodPtr MakeBulletMethod(const BulletOptions& options);

// "bullet-multibody-default", "bullet-multibody-tuned", "bullet-rigidbody-default",
// "bullet-rigidbody-tuned".
std::vector<MethodPtr> MakeBulletMethods();

}  // namespace mechbench::engines
