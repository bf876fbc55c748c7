// The engines' spatial graph (spatial_graph.h) in Bullet, double precision, in both formulations:
//  - btMultiBody (reduced coordinates): the tree from ground as one fixed-base btMultiBody
//    (setupSpherical / setupRevolute links), each free body the floating base of one more (with
//    the part of the tree it carries), loop closures as btMultiBodyPoint2Point (a revolute
//    closure as two, on its axis, as the graph gives them), drivers as btMultiBodyJointMotor
//    velocity targets (the planar path's).
//  - btRigidBody (maximal coordinates): one body per graph body, btPoint2PointConstraint for a
//    ball, btHingeConstraint for a revolute (tree joint or closure alike: a revolute closure is one
//    hinge here), nothing for a free body; drivers as the hinge's motor.
// Bullet's link and rigid-body frames sit at the centre of mass with a diagonal inertia: each
// body's inertia tensor is diagonalised (SelfAdjointEigenSolver) and its Bullet frame turned onto
// the principal axes; the graph's body frame (origin at the first point, world axes at t0) is read
// back through that constant offset. Gravity by the world; constant forces, torques and
// spring–dampers applied before every step from the step's starting state (explicit, as the
// planar path does).
#include "bullet_internal.h"

#include "mechbench/errors.h"

#include <BulletDynamics/Featherstone/btMultiBody.h>
#include <BulletDynamics/Featherstone/btMultiBodyConstraintSolver.h>
#include <BulletDynamics/Featherstone/btMultiBodyDynamicsWorld.h>
#include <BulletDynamics/Featherstone/btMultiBodyJointMotor.h>
#include <BulletDynamics/Featherstone/btMultiBodyLinkCollider.h>
#include <BulletDynamics/Featherstone/btMultiBodyPoint2Point.h>
#include <btBulletDynamicsCommon.h>

#include <Eigen/Eigenvalues>

#include <cmath>
#include <numbers>

namespace mechbench::engines {
namespace bullet_spatial_detail {  // this file's own names (the library may build as one unity batch)
namespace {

using bullet_internal::kMaxImpulse;
using bullet_internal::Variant;
using bullet_internal::WorldParts;
using V3 = Eigen::Vector3d;
using M3 = Eigen::Matrix3d;

btVector3 Bt(const V3& v) { return btVector3(v.x(), v.y(), v.z()); }
V3 Ei(const btVector3& v) { return V3(v.x(), v.y(), v.z()); }
btMatrix3x3 BtMatrix(const M3& m) {
  btMatrix3x3 b;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) b[r][c] = m(r, c);
  return b;
}
btQuaternion Quat(const M3& m) {
  btQuaternion q;
  BtMatrix(m).getRotation(q);
  return q;
}

// A body's principal frame: the inertia tensor (body axes, about the centre of mass) = E diag(λ) Eᵀ,
// E a rotation (its columns the principal axes in body coordinates). Bullet's frame of the body is
// (com_B, E): world rotation R_B E, origin at the centre of mass.
struct Principal {
  M3 E = M3::Identity();
  V3 moments{1, 1, 1};
};
Principal PrincipalOf(const SpatialGraphBody& b) {
  const Eigen::SelfAdjointEigenSolver<M3> eig(0.5 * (b.inertia_B + b.inertia_B.transpose()));
  MB_ASSERT(eig.info() == Eigen::Success, "a graph body's inertia has no eigen-decomposition");
  Principal p;
  p.E = eig.eigenvectors();
  if (p.E.determinant() < 0) p.E.col(2) = -p.E.col(2);
  p.moments = eig.eigenvalues();
  return p;
}

// The world load on each body from the step's starting state: a force through the centre of mass
// and a torque about it (world axes), from constant point forces, body torques and spring–dampers.
struct Wrench {
  V3 f = V3::Zero(), torque = V3::Zero();
};
void Loads(const SpatialGraph& g, const std::vector<SpatialState>& st, std::vector<Wrench>& w) {
  w.assign(g.bodies.size(), Wrench{});
  auto add = [&](int b, const V3& at_B, const V3& f) {
    const V3 r = st[b].R * (at_B - g.bodies[b].com_B);
    w[b].f += f;
    w[b].torque += r.cross(f);
  };
  for (const SpatialGraphForce& f : g.forces) add(f.body, f.at_B, f.f_W);
  for (const SpatialGraphTorque& t : g.torques) w[t.body].torque += t.torque_W;
  for (const SpatialGraphSpring& sp : g.springs) {
    const auto pos = [&](int b, const V3& at) { return b < 0 ? at : st[b].PointPos(at); };
    const auto vel = [&](int b, const V3& at) { return b < 0 ? V3::Zero() : st[b].PointVel(at); };
    const V3 d = pos(sp.body_b, sp.at_b) - pos(sp.body_a, sp.at_a);
    const double L = d.norm();
    if (!(L > 0)) continue;  // no direction (graph.cc's SpringForceOnB does the same)
    const V3 e = d / L;
    const double L_dot = e.dot(vel(sp.body_b, sp.at_b) - vel(sp.body_a, sp.at_a));
    const V3 f_b = -(sp.stiffness * (L - sp.free_length) + sp.damping * L_dot + sp.preload) * e;
    if (sp.body_a >= 0) add(sp.body_a, sp.at_a, -f_b);
    if (sp.body_b >= 0) add(sp.body_b, sp.at_b, f_b);
  }
}

// A tree revolute's coordinate from the bodies' world states: the child's turn relative to the
// parent about the joint's axis (both frames have the world's axes at t0, where it is 0).
double HingeAngle(const SpatialGraphJoint& j, const std::vector<SpatialState>& st) {
  const M3 Rp = j.parent < 0 ? M3::Identity() : st[j.parent].R;
  const M3 rel = Rp.transpose() * st[j.child].R;
  const V3 u = j.axis_B.unitOrthogonal(), w = rel * u;
  return std::atan2(j.axis_B.dot(u.cross(w)), u.dot(w));
}

bool Finite(const std::vector<SpatialState>& st) {
  for (const SpatialState& s : st)
    if (!s.p.allFinite() || !s.R.allFinite() || !s.v.allFinite() || !s.omega.allFinite()) return false;
  return true;
}

class Scene {
 public:
  virtual ~Scene() = default;
  // Every graph body's world state (pose and velocities; accelerations left zero).
  virtual void Read(std::vector<SpatialState>& st) = 0;
  // One step of h from t, the drivers aimed at their law at t + h; `st` the state at t when
  // NeedsState(), else unused.
  virtual void Step(double t, double h, const std::vector<SpatialState>& st) = 0;
  virtual bool NeedsState() const = 0;
};

// The graph body's frame from its Bullet frame (centre of mass c, rotation R_L = R_B E) and the
// centre of mass's velocities (world).
SpatialState FromBulletFrame(const SpatialGraphBody& b, const Principal& pr, const M3& R_L, const V3& c, const V3& v_c,
                             const V3& omega) {
  SpatialState s;
  s.R = R_L * pr.E.transpose();
  const V3 r = s.R * b.com_B;
  s.p = c - r;
  s.omega = omega;
  s.v = v_c - omega.cross(r);
  return s;
}

// ---------------------------------------------------------------------------------------------
// btMultiBody: one per root of the graph's tree (ground, then each free body).

class MultiBodyScene final : public Scene {
 public:
  MultiBodyScene(const SpatialGraph& g, const Variant& v, Result& result) : g_(g) {
    solver_ = std::make_unique<btMultiBodyConstraintSolver>();
    world_ = std::make_unique<btMultiBodyDynamicsWorld>(parts_.dispatcher.get(), parts_.broadphase.get(), solver_.get(),
                                                        parts_.config.get());
    world_->setGravity(Bt(g.gravity));
    bullet_internal::ApplySolverSettings(world_->getSolverInfo(), v, result);
    for (const SpatialGraphBody& b : g.bodies) pr_.push_back(PrincipalOf(b));

    // Roots: ground (multibody 0, when a tree joint hangs from it) and every free joint's body.
    // Links in the graph's tree order (each parent's joint before its child's).
    const int nb = static_cast<int>(g.bodies.size());
    mb_of_.assign(nb, -1);
    link_of_.assign(nb, -1);
    std::vector<int> links;  // per multibody
    std::vector<int> root;   // per multibody: the free body, or -1 for ground
    for (const SpatialGraphJoint& j : g.joints) {
      if (!j.in_tree) continue;
      if (j.type == SpatialJointType::kFree) {
        mb_of_[j.child] = static_cast<int>(root.size());
        root.push_back(j.child);
        links.push_back(0);
        continue;
      }
      int m = j.parent < 0 ? -1 : mb_of_[j.parent];
      if (j.parent < 0) {
        if (ground_ < 0) {
          ground_ = static_cast<int>(root.size());
          root.push_back(-1);
          links.push_back(0);
        }
        m = ground_;
      }
      MB_ASSERT(m >= 0, "a tree joint before its parent's");
      mb_of_[j.child] = m;
      link_of_[j.child] = links[m]++;
    }
    // Closures to ground need ground's base even when no tree joint hangs from it (not reachable:
    // such a body is then in ground's tree), kept simple and checked.
    for (const SpatialGraphJoint& j : g.joints)
      MB_ASSERT(j.in_tree || j.parent >= 0 || ground_ >= 0, "a loop closure to ground without ground's multibody");

    for (size_t m = 0; m < root.size(); ++m) {
      std::unique_ptr<btMultiBody> mb;
      if (root[m] < 0) {
        mb = std::make_unique<btMultiBody>(links[m], 1.0, btVector3(1, 1, 1), /*fixedBase=*/true, /*canSleep=*/false);
        mb->setBaseWorldTransform(btTransform::getIdentity());
      } else {
        const SpatialGraphBody& b = g.bodies[root[m]];
        const Principal& p = pr_[root[m]];
        mb = std::make_unique<btMultiBody>(links[m], b.mass, Bt(p.moments), /*fixedBase=*/false, /*canSleep=*/false);
        // At t0 the body frame has the world's axes: the base's rotation is E, world → base Eᵀ.
        mb->setBasePos(Bt(b.initial.p + b.com_B));
        mb->setWorldToBaseRot(Quat(p.E.transpose()));  // its velocities after finalizeMultiDof (their buffer)
      }
      mbs_.push_back(std::move(mb));
    }
    int balls = 0, hinges = 0, sliders = 0;
    for (const SpatialGraphJoint& j : g.joints) {
      if (!j.in_tree || j.type == SpatialJointType::kFree) continue;
      btMultiBody& mb = *mbs_[mb_of_[j.child]];
      const SpatialGraphBody& c = g.bodies[j.child];
      const M3 Ep = j.parent < 0 ? M3::Identity() : pr_[j.parent].E, Ec = pr_[j.child].E;
      const V3 com_p = j.parent < 0 ? V3::Zero() : g.bodies[j.parent].com_B;
      const int parent_link = j.parent < 0 ? -1 : link_of_[j.parent];
      // Bullet's link frames at the centre of mass on the principal axes; parent → this at a zero
      // joint is Ecᵀ Ep (both body frames have the world's axes at t0).
      const btQuaternion parent_to_this = Quat(Ec.transpose() * Ep);
      const btVector3 parent_com_to_pivot = Bt(Ep.transpose() * (j.at_parent_B - com_p));
      const btVector3 pivot_to_com = Bt(Ec.transpose() * (c.com_B - j.at_child_B));
      const int i = link_of_[j.child];
      if (j.type == SpatialJointType::kRevolute) {
        mb.setupRevolute(i, c.mass, Bt(pr_[j.child].moments), parent_link, parent_to_this, Bt(Ec.transpose() * j.axis_B),
                         parent_com_to_pivot, pivot_to_com, true);
        ++hinges;
      } else if (j.type == SpatialJointType::kPrismatic) {
        mb.setupPrismatic(i, c.mass, Bt(pr_[j.child].moments), parent_link, parent_to_this, Bt(Ec.transpose() * j.axis_B),
                          parent_com_to_pivot, pivot_to_com, true);
        ++sliders;
      } else {
        mb.setupSpherical(i, c.mass, Bt(pr_[j.child].moments), parent_link, parent_to_this, parent_com_to_pivot,
                          pivot_to_com, true);
        ++balls;
      }
    }
    for (size_t m = 0; m < mbs_.size(); ++m) {
      btMultiBody& mb = *mbs_[m];
      mb.finalizeMultiDof();
      // Trap (as in the planar path): btMultiBody damps every link (0.04) and caps joint speeds at 100.
      mb.setLinearDamping(0);
      mb.setAngularDamping(0);
      mb.setMaxCoordinateVelocity(1e30);
      mb.setMaxAppliedImpulse(kMaxImpulse);
      mb.setCanSleep(false);
      world_->addMultiBody(&mb, 1, 0);
      // Trap: multibody constraints are dropped for links without a collider; mask 0 on each.
      for (int i = -1; i < mb.getNumLinks(); ++i) {
        auto col = std::make_unique<btMultiBodyLinkCollider>(&mb, i);
        col->setCollisionShape(parts_.shape.get());
        col->setActivationState(DISABLE_DEACTIVATION);
        world_->addCollisionObject(col.get(), 1, 0);
        if (i < 0)
          mb.setBaseCollider(col.get());
        else
          mb.getLink(i).m_collider = col.get();
        colliders_.push_back(std::move(col));
      }
    }
    for (size_t m = 0; m < root.size(); ++m)
      if (root[m] >= 0) {
        const SpatialGraphBody& b = g.bodies[root[m]];
        mbs_[m]->setBaseVel(Bt(b.initial.v + b.initial.omega.cross(b.com_B)));
        mbs_[m]->setBaseOmega(Bt(b.initial.omega));
      }
    // Joint rates at t0: a hinge's (ω_c − ω_p)·axis; a ball's ω_c − ω_p in the child's link frame.
    for (const SpatialGraphJoint& j : g.joints) {
      if (!j.in_tree || j.type == SpatialJointType::kFree) continue;
      btMultiBody& mb = *mbs_[mb_of_[j.child]];
      const V3 w_rel = g.bodies[j.child].initial.omega - (j.parent < 0 ? V3::Zero() : g.bodies[j.parent].initial.omega);
      if (j.type == SpatialJointType::kRevolute) {
        mb.setJointVel(link_of_[j.child], w_rel.dot(j.axis_B));
      } else if (j.type == SpatialJointType::kPrismatic) {  // the child's velocity along the axis, relative to the parent
        mb.setJointVel(link_of_[j.child], PrismaticRateAtT0(g, j));
      } else {
        const V3 w = pr_[j.child].E.transpose() * w_rel;
        btScalar qd[3] = {w.x(), w.y(), w.z()};
        mb.setJointVelMultiDof(link_of_[j.child], qd);
      }
    }
    for (auto& mb : mbs_) {
      btAlignedObjectArray<btQuaternion> q;
      btAlignedObjectArray<btVector3> o;
      mb->forwardKinematics(q, o);
      mb->updateCollisionObjectWorldTransforms(q, o);
    }

    // Loop closures: a ball as one btMultiBodyPoint2Point, a revolute as two on its axis.
    const double axis_length = SpatialGraphOptions{}.closure_axis_length * g.length_scale;
    int closures = 0, rows = 0;
    for (const SpatialGraphJoint& j : g.joints) {
      if (j.in_tree) continue;
      auto connect = [&](const V3& at_parent_B, const V3& at_child_B) {
        btMultiBody* a = j.parent < 0 ? mbs_[ground_].get() : mbs_[mb_of_[j.parent]].get();
        const int la = j.parent < 0 ? -1 : link_of_[j.parent];
        const V3 in_a = j.parent < 0 ? at_parent_B : V3(pr_[j.parent].E.transpose() * (at_parent_B - g.bodies[j.parent].com_B));
        const V3 in_b = pr_[j.child].E.transpose() * (at_child_B - g.bodies[j.child].com_B);
        auto c = std::make_unique<btMultiBodyPoint2Point>(a, la, mbs_[mb_of_[j.child]].get(), link_of_[j.child], Bt(in_a),
                                                          Bt(in_b));
        c->setMaxAppliedImpulse(kMaxImpulse);
        world_->addMultiBodyConstraint(c.get());
        constraints_.push_back(std::move(c));
        rows += 3;
      };
      connect(j.at_parent_B, j.at_child_B);
      if (j.type == SpatialJointType::kRevolute)
        connect(j.at_parent_B + axis_length * j.axis_B, j.at_child_B + axis_length * j.axis_B);
      ++closures;
    }
    for (const SpatialDriverMap& d : g.drivers) {
      const SpatialGraphJoint& j = g.joints[d.joint];
      auto m = std::make_unique<btMultiBodyJointMotor>(mbs_[mb_of_[j.child]].get(), link_of_[j.child], 0.0, kMaxImpulse);
      motors_.push_back(m.get());
      world_->addMultiBodyConstraint(m.get());
      constraints_.push_back(std::move(m));
    }
    int floating = 0;
    for (const int r : root) floating += r >= 0;
    result.settings["formulation"] =
        "btMultiBody (reduced coordinates, Featherstone): " +
        (ground_ >= 0 ? "the tree from ground as one fixed-base multibody of " +
                            std::to_string(mbs_[ground_]->getNumLinks()) + " links"
                      : std::string("no tree from ground")) +
        (floating ? ", " + std::to_string(floating) + " free bod" + (floating == 1 ? "y" : "ies") +
                        " as the floating base of a multibody of its own (with the links it carries)"
                  : std::string()) +
        "; " + std::to_string(balls) + " × setupSpherical, " + std::to_string(hinges) + " × setupRevolute" +
        (sliders ? ", " + std::to_string(sliders) + " × setupPrismatic" : std::string());
    result.settings["link_frames"] =
        "every link (and floating base) at its body's centre of mass on its principal axes: the graph's inertia "
        "tensor diagonalised (Eigen SelfAdjointEigenSolver), Bullet's diagonal inertia its principal moments";
    if (closures)
      result.settings["loop_closures"] = std::to_string(closures) + " × closure as btMultiBodyPoint2Point: a ball one, a "
                                         "revolute two on its axis " + Fmt(axis_length) + " apart (" + std::to_string(rows) +
                                         " rows; a revolute's six of rank five: the sequential-impulse solver takes the "
                                         "redundant one)";
    result.settings["multibody_damping"] = "linear 0, angular 0 (Bullet default 0.04 each: zeroed)";
    result.settings["multibody_max_coordinate_velocity"] = "1e30 (Bullet default 100: lifted)";
    result.settings["constraint_max_impulse"] = Fmt(kMaxImpulse) + " (btMultiBodyConstraint default 100: lifted)";
    result.settings["gyroscopic"] = "btMultiBody's gyroscopic term on (Bullet default)";
    result.settings["colliders"] = "btMultiBodyLinkCollider on every base and link, collision mask 0";
    if (!g.drivers.empty())
      result.settings["drivers"] = "btMultiBodyJointMotor on the driven hinge or prismatic link, velocity target (q_law(t+h) − q)/h, max impulse " +
                                   Fmt(kMaxImpulse);
  }

  ~MultiBodyScene() override {
    for (auto& c : constraints_) world_->removeMultiBodyConstraint(c.get());
    for (auto& c : colliders_) world_->removeCollisionObject(c.get());
    for (auto& mb : mbs_) world_->removeMultiBody(mb.get());
    world_.reset();
  }
  MultiBodyScene(const MultiBodyScene&) = delete;
  MultiBodyScene& operator=(const MultiBodyScene&) = delete;

  void Read(std::vector<SpatialState>& st) override {
    omega_.resize(mbs_.size());
    vel_.resize(mbs_.size());
    for (size_t m = 0; m < mbs_.size(); ++m) {
      omega_[m].resize(mbs_[m]->getNumLinks() + 1);
      vel_[m].resize(mbs_[m]->getNumLinks() + 1);
      mbs_[m]->compTreeLinkVelocities(omega_[m].data(), vel_[m].data());  // link-local frames, at the COM
    }
    st.resize(g_.bodies.size());
    for (size_t b = 0; b < g_.bodies.size(); ++b) {
      const btMultiBody& mb = *mbs_[mb_of_[b]];
      const int i = link_of_[b];
      M3 R_L;
      for (int k = 0; k < 3; ++k) R_L.col(k) = Ei(mb.localDirToWorld(i, btVector3(k == 0, k == 1, k == 2)));
      st[b] = FromBulletFrame(g_.bodies[b], pr_[b], R_L, Ei(mb.localPosToWorld(i, btVector3(0, 0, 0))),
                              Ei(mb.localDirToWorld(i, vel_[mb_of_[b]][i + 1])),
                              Ei(mb.localDirToWorld(i, omega_[mb_of_[b]][i + 1])));
    }
  }

  bool NeedsState() const override {  // motors read the joint
    return !g_.forces.empty() || !g_.springs.empty() || !state_loads_.empty();
  }

  void Step(double t, double h, const std::vector<SpatialState>& st) override {
    for (size_t k = 0; k < g_.drivers.size(); ++k) {
      const SpatialDriverMap& d = g_.drivers[k];
      const int link = link_of_[g_.joints[d.joint].child];
      const btMultiBody& mb = *mbs_[mb_of_[g_.joints[d.joint].child]];
      motors_[k]->setVelocityTarget((d.Position(t + h, g_.t0) - mb.getJointPos(link)) / h);
    }
    if (!g_.forces.empty() || !g_.torques.empty() || !g_.springs.empty()) {
      if (g_.forces.empty() && g_.springs.empty()) {  // torques alone: no state needed
        loads_.assign(g_.bodies.size(), Wrench{});
        for (const SpatialGraphTorque& tq : g_.torques) loads_[tq.body].torque += tq.torque_W;
      } else {
        Loads(g_, st, loads_);
      }
      for (size_t b = 0; b < g_.bodies.size(); ++b) {
        btMultiBody& mb = *mbs_[mb_of_[b]];
        const int i = link_of_[b];
        if (i < 0) {
          mb.addBaseForce(Bt(loads_[b].f));
          mb.addBaseTorque(Bt(loads_[b].torque));
        } else {
          mb.addLinkForce(i, Bt(loads_[b].f));
          mb.addLinkTorque(i, Bt(loads_[b].torque));
        }
      }
    }
    if (!state_loads_.empty()) {  // torsions and load laws from the step's starting state (explicit)
      state_loads_.Evaluate(t, st, wrench_);
      for (size_t b = 0; b < g_.bodies.size(); ++b) {
        btMultiBody& mb = *mbs_[mb_of_[b]];
        const int i = link_of_[b];
        if (i < 0) {
          mb.addBaseForce(Bt(wrench_[b].force));
          mb.addBaseTorque(Bt(wrench_[b].torque));
        } else {
          mb.addLinkForce(i, Bt(wrench_[b].force));
          mb.addLinkTorque(i, Bt(wrench_[b].torque));
        }
      }
    }
    world_->stepSimulation(h, 0, h);
  }

 private:
  const SpatialGraph& g_;
  std::vector<Principal> pr_;
  WorldParts parts_;
  std::unique_ptr<btMultiBodyConstraintSolver> solver_;
  std::vector<std::unique_ptr<btMultiBody>> mbs_;
  std::vector<std::unique_ptr<btMultiBodyLinkCollider>> colliders_;
  std::vector<std::unique_ptr<btMultiBodyConstraint>> constraints_;
  std::unique_ptr<btMultiBodyDynamicsWorld> world_;  // reset first by the destructor
  std::vector<btMultiBodyJointMotor*> motors_;
  int ground_ = -1;                         // ground's multibody, when a tree joint hangs from it
  std::vector<int> mb_of_, link_of_;        // per graph body: its multibody, its link (-1: the base)
  std::vector<std::vector<btVector3>> omega_, vel_;
  std::vector<Wrench> loads_;
  SpatialStateLoads state_loads_{g_};
  std::vector<SpatialWrench> wrench_;
};

// ---------------------------------------------------------------------------------------------
// btRigidBody + typed constraints.

class RigidBodyScene final : public Scene {
 public:
  RigidBodyScene(const SpatialGraph& g, const Variant& v, Result& result) : g_(g) {
    solver_ = std::make_unique<btSequentialImpulseConstraintSolver>();
    world_ = std::make_unique<btDiscreteDynamicsWorld>(parts_.dispatcher.get(), parts_.broadphase.get(), solver_.get(),
                                                       parts_.config.get());
    world_->setGravity(Bt(g.gravity));
    bullet_internal::ApplySolverSettings(world_->getSolverInfo(), v, result);
    for (const SpatialGraphBody& b : g.bodies) {
      const Principal p = PrincipalOf(b);
      pr_.push_back(p);
      btRigidBody::btRigidBodyConstructionInfo info(b.mass, nullptr, parts_.shape.get(), Bt(p.moments));
      info.m_startWorldTransform = btTransform(BtMatrix(p.E), Bt(b.initial.p + b.com_B));  // R_B = 1 at t0
      info.m_linearDamping = 0;
      info.m_angularDamping = 0;
      auto body = std::make_unique<btRigidBody>(info);
      body->setLinearVelocity(Bt(b.initial.v + b.initial.omega.cross(b.com_B)));
      body->setAngularVelocity(Bt(b.initial.omega));
      body->setActivationState(DISABLE_DEACTIVATION);
      world_->addRigidBody(body.get(), 1, 0);
      bodies_.push_back(std::move(body));
    }
    // In a body's Bullet frame: a body point, a body direction.
    const auto at = [&](int b, const V3& p_B) { return Bt(pr_[b].E.transpose() * (p_B - g.bodies[b].com_B)); };
    const auto dir = [&](int b, const V3& d_B) { return Bt(pr_[b].E.transpose() * d_B); };
    joint_.assign(g.joints.size(), nullptr);
    int balls = 0, hinges = 0, closures = 0, sliders = 0;
    for (size_t ji = 0; ji < g.joints.size(); ++ji) {
      const SpatialGraphJoint& j = g.joints[ji];
      if (j.type == SpatialJointType::kFree) continue;
      btRigidBody& child = *bodies_[j.child];
      std::unique_ptr<btTypedConstraint> c;
      if (j.type == SpatialJointType::kBall) {
        if (j.parent < 0)
          c = std::make_unique<btPoint2PointConstraint>(child, at(j.child, j.at_child_B));
        else
          c = std::make_unique<btPoint2PointConstraint>(child, *bodies_[j.parent], at(j.child, j.at_child_B),
                                                        at(j.parent, j.at_parent_B));
        ++balls;
      } else if (j.type == SpatialJointType::kPrismatic) {
        // A = the parent (the world, or the line's body), B = the child: one frame at the joint point
        // with x along the axis (the same world frame at t0 in both bodies' Bullet frames);
        // btSliderConstraint's default angular limits (0, 0) hold the relative rotation, its linear
        // limits (lower 1 > upper −1) leave the travel free.
        const V3 a = j.axis_B.normalized(), e1 = a.unitOrthogonal();
        M3 W;
        W << a, e1, a.cross(e1);
        const btTransform in_child(BtMatrix(pr_[j.child].E.transpose() * W), at(j.child, j.at_child_B));
        if (j.parent < 0)
          c = std::make_unique<btSliderConstraint>(child, in_child, true);
        else
          c = std::make_unique<btSliderConstraint>(*bodies_[j.parent], child,
                                                   btTransform(BtMatrix(pr_[j.parent].E.transpose() * W),
                                                               at(j.parent, j.at_parent_B)),
                                                   in_child, true);
        ++sliders;
      } else {
        // A = child, B = parent (or the world): the motor drives the child's turn relative to the parent.
        if (j.parent < 0)
          c = std::make_unique<btHingeConstraint>(child, at(j.child, j.at_child_B), dir(j.child, j.axis_B));
        else
          c = std::make_unique<btHingeConstraint>(child, *bodies_[j.parent], at(j.child, j.at_child_B),
                                                  at(j.parent, j.at_parent_B), dir(j.child, j.axis_B),
                                                  dir(j.parent, j.axis_B));
        ++hinges;
      }
      closures += !j.in_tree;
      world_->addConstraint(c.get(), /*disableCollisionsBetweenLinkedBodies=*/true);
      joint_[ji] = c.get();
      constraints_.push_back(std::move(c));
    }
    for (const SpatialDriverMap& d : g.drivers) {
      if (g.joints[d.joint].type == SpatialJointType::kPrismatic) {
        auto* sl = static_cast<btSliderConstraint*>(joint_[d.joint]);
        sl->setPoweredLinMotor(true);
        sl->setMaxLinMotorForce(kMaxImpulse);
        sl->setTargetLinMotorVelocity(0);
        continue;
      }
      static_cast<btHingeConstraint*>(joint_[d.joint])->enableAngularMotor(true, 0, kMaxImpulse);
    }
    result.settings["formulation"] = "btRigidBody × " + std::to_string(g.bodies.size()) +
                                     " in btDiscreteDynamicsWorld (maximal coordinates), sequential-impulse solver";
    result.settings["joints"] = std::to_string(balls) + " × btPoint2PointConstraint (balls), " + std::to_string(hinges) +
                                " × btHingeConstraint (revolutes)" +
                                (sliders ? ", " + std::to_string(sliders) + " × btSliderConstraint (prismatic, from the world or the line's body; "
                                           "its rotation held by its angular limits)" : std::string()) +
                                (closures ? "; " + std::to_string(closures) +
                                                " of them the graph's loop closures (a revolute closure is one hinge here: "
                                                "five rows)"
                                          : std::string()) +
                                "; a free body has none";
    result.settings["body_frames"] =
        "every btRigidBody at its body's centre of mass on its principal axes: the graph's inertia tensor diagonalised "
        "(Eigen SelfAdjointEigenSolver), Bullet's diagonal local inertia its principal moments";
    result.settings["gyroscopic"] = "BT_ENABLE_GYROSCOPIC_FORCE_IMPLICIT_BODY (btRigidBody's default since 2.83)";
    result.settings["damping"] = "linear 0, angular 0, deactivation disabled, collision mask 0";
    if (!g.drivers.empty())
      result.settings["drivers"] = "hinge or slider motor (child relative to parent), target velocity (q_law(t+h) − q)/h with q "
                                   "read from the bodies' rotations, max impulse " + Fmt(kMaxImpulse);
  }

  ~RigidBodyScene() override {
    for (auto& c : constraints_) world_->removeConstraint(c.get());
    for (auto& b : bodies_) world_->removeRigidBody(b.get());
    world_.reset();
  }
  RigidBodyScene(const RigidBodyScene&) = delete;
  RigidBodyScene& operator=(const RigidBodyScene&) = delete;

  void Read(std::vector<SpatialState>& st) override {
    st.resize(g_.bodies.size());
    for (size_t b = 0; b < g_.bodies.size(); ++b) {
      const btRigidBody& rb = *bodies_[b];
      const btTransform& T = rb.getCenterOfMassTransform();
      M3 R_L;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) R_L(r, c) = T.getBasis()[r][c];
      st[b] = FromBulletFrame(g_.bodies[b], pr_[b], R_L, Ei(T.getOrigin()), Ei(rb.getLinearVelocity()),
                              Ei(rb.getAngularVelocity()));
    }
  }

  bool NeedsState() const override {
    return !g_.forces.empty() || !g_.springs.empty() || !g_.drivers.empty() || !state_loads_.empty();
  }

  void Step(double t, double h, const std::vector<SpatialState>& st) override {
    for (const SpatialDriverMap& d : g_.drivers) {
      const double target = d.Position(t + h, g_.t0);
      const SpatialGraphJoint& j = g_.joints[d.joint];
      if (j.type == SpatialJointType::kPrismatic) {  // the travel from t0 along the axis, relative to the parent
        const double x = PrismaticTravel(j, j.parent < 0 ? SpatialState{} : st[j.parent], st[j.child]);
        static_cast<btSliderConstraint*>(joint_[d.joint])->setTargetLinMotorVelocity((target - x) / h);
        continue;
      }
      double now = HingeAngle(g_.joints[d.joint], st);
      now += 2 * std::numbers::pi * std::round((target - now) / (2 * std::numbers::pi));
      static_cast<btHingeConstraint*>(joint_[d.joint])->enableAngularMotor(true, (target - now) / h, kMaxImpulse);
    }
    if (!g_.forces.empty() || !g_.torques.empty() || !g_.springs.empty()) {
      if (g_.forces.empty() && g_.springs.empty()) {
        loads_.assign(g_.bodies.size(), Wrench{});
        for (const SpatialGraphTorque& tq : g_.torques) loads_[tq.body].torque += tq.torque_W;
      } else {
        Loads(g_, st, loads_);
      }
      for (size_t b = 0; b < g_.bodies.size(); ++b) {
        bodies_[b]->applyCentralForce(Bt(loads_[b].f));
        bodies_[b]->applyTorque(Bt(loads_[b].torque));
      }
    }
    if (!state_loads_.empty()) {  // torsions and load laws from the step's starting state (explicit)
      state_loads_.Evaluate(t, st, wrench_);
      for (size_t b = 0; b < g_.bodies.size(); ++b) {
        bodies_[b]->applyCentralForce(Bt(wrench_[b].force));
        bodies_[b]->applyTorque(Bt(wrench_[b].torque));
      }
    }
    world_->stepSimulation(h, 0, h);
  }

 private:
  const SpatialGraph& g_;
  std::vector<Principal> pr_;
  WorldParts parts_;
  std::unique_ptr<btSequentialImpulseConstraintSolver> solver_;
  std::vector<std::unique_ptr<btRigidBody>> bodies_;
  std::vector<std::unique_ptr<btTypedConstraint>> constraints_;
  std::unique_ptr<btDiscreteDynamicsWorld> world_;  // reset first by the destructor
  std::vector<btTypedConstraint*> joint_;           // per graph joint (null for a free one)
  std::vector<Wrench> loads_;
  SpatialStateLoads state_loads_{g_};
  std::vector<SpatialWrench> wrench_;
};

}  // namespace
}  // namespace bullet_spatial_detail

namespace bullet_internal {

std::optional<std::string> SpatialReason(const SpatialGraph& g, const Variant&) {
  // Bullet reads a zero component of a diagonal inertia as an infinite one (btRigidBody's inverse
  // inertia is 0 there; btMultiBody divides by it): a wrong model, so a reason.
  for (const SpatialGraphBody& b : g.bodies) {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(b.inertia_B);
    if (!(eig.eigenvalues().minCoeff() > 0) || !(b.mass > 0))
      return "body " + b.name + ": a principal moment of inertia (or the mass) is zero; Bullet takes a zero diagonal "
             "inertia as infinite (btRigidBody) or divides by it (btMultiBody)";
  }
  return std::nullopt;
}

void SimulateSpatial(const SpatialGraph& g, const Variant& v, const std::vector<double>& times,
                     const ControlValue& control, const SpatialRecorder& record, const RunOptions& options,
                     Result& result) {
  namespace d = bullet_spatial_detail;
  const double h_max = control.value;
  result.settings["format"] = "the spatial graph (" + Describe(g) + ")";
  result.settings["precision"] = "double (bullet-float64, BT_USE_DOUBLE_PRECISION)";
  result.settings["integrator"] = "semi-implicit Euler (Bullet's only one), stepSimulation(h, 0): one step of h per call";
  result.settings["step"] = "h ≤ " + ControlText(control, " s") + ", shortened evenly to end on every sample time";
  const std::string how = v.multibody ? "addLinkForce + addLinkTorque (addBaseForce/-Torque on a floating base)"
                                      : "btRigidBody::applyCentralForce + applyTorque";
  if (!g.forces.empty())
    result.settings["forces"] = std::to_string(g.forces.size()) + " × constant world force at a body point: " + how +
                                " (its moment about the centre of mass from the step's starting pose) before every "
                                "step: explicit";
  if (!g.torques.empty())
    result.settings["torques"] = std::to_string(g.torques.size()) + " × constant world torque, " + how + " before every step";
  if (!g.torsions.empty() || !g.law_loads.empty())
    result.settings["state_loads"] = std::to_string(g.torsions.size()) + " torsion(s) and " +
                                     std::to_string(g.law_loads.size()) +
                                     " load law(s) (SpatialStateLoads: q, q̇ observed from the bodies) from the step's "
                                     "starting state, a wrench at each centre of mass: " + how + " before every step (explicit)";
  if (!g.springs.empty())
    result.settings["spring_dampers"] =
        std::to_string(g.springs.size()) + " × tension k (L − L0) + c L̇ + F0 from the step's starting positions and "
        "velocities, " + how + " on each moving end before every step: explicit (a stiff spring is stable only while "
        "h ω stays small)";
  result.settings["accelerations"] = "(v_{n+1} − v_n)/h of the step ending at the sample; none at t0";
  result.settings["reactions"] = "not reported for spatial scenes yet";
  std::unique_ptr<d::Scene> scene;
  if (v.multibody)
    scene = std::make_unique<d::MultiBodyScene>(g, v, result);
  else
    scene = std::make_unique<d::RigidBodyScene>(g, v, result);
  std::vector<SpatialState> st, prev;
  long steps = 0;
  double t = g.t0;
  EnterPhase(options, Phase::kObservation);
  scene->Read(st);
  // The model as built holds the assembled t0 (a frame or an offset gone wrong would show here).
  for (size_t b = 0; b < g.bodies.size(); ++b)
    MB_ASSERT((st[b].p - g.bodies[b].initial.p).norm() <= 1e-9 * g.length_scale &&
                  (st[b].R - Eigen::Matrix3d::Identity()).norm() <= 1e-9 &&
                  (st[b].omega - g.bodies[b].initial.omega).norm() <= 1e-9 * (1 + g.bodies[b].initial.omega.norm()),
              "Bullet's t0 pose or rate of a body is not the graph's");
  record(st, false);
  const bool each_step = scene->NeedsState();
  for (size_t k = 1; k < times.size(); ++k) {
    EnterPhase(options, Phase::kIntegration);
    const auto [n, h] = StepsTo(t, times[k], h_max);
    for (long i = 0; i < n; ++i) {
      CheckBudgetInStep(options, i, times[k - 1]);
      if (i + 1 == n) {
        if (!each_step) scene->Read(st);
        prev = st;
      }
      scene->Step(t, h, st);
      if (each_step) {
        scene->Read(st);
        if (!d::Finite(st)) {
          result.status = Status::kDiverged;
          result.reason = "Bullet's state is not finite after the step at t = " + Fmt(t);
          return;
        }
      }
      t += h;
      ++steps;
    }
    EnterPhase(options, Phase::kObservation);
    t = times[k];
    if (!each_step) scene->Read(st);
    if (!d::Finite(st)) {
      result.status = Status::kDiverged;
      result.reason = "Bullet's state is not finite at the sample t = " + Fmt(t);
      return;
    }
    for (size_t b = 0; b < g.bodies.size(); ++b) WorldAcceleration(st[b], prev[b], g.bodies[b].com_B, h);
    record(st, true);
  }
  result.settings["steps_taken"] = std::to_string(steps);
  result.steps = steps;
}

}  // namespace bullet_internal
}  // namespace mechbench::engines
