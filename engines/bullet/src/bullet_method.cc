#include "mechbench/engines/bullet.h"
#include "bullet_internal.h"
#include "mechbench/format.h"

#include "mechbench/engines/engine_method.h"
#include "mechbench/errors.h"
#include "mechbench/numeric/reactions.h"

#include <BulletDynamics/ConstraintSolver/btGearConstraint.h>
#include <BulletDynamics/Featherstone/btMultiBody.h>
#include <BulletDynamics/Featherstone/btMultiBodyConstraintSolver.h>
#include <BulletDynamics/Featherstone/btMultiBodyDynamicsWorld.h>
#include <BulletDynamics/Featherstone/btMultiBodyGearConstraint.h>
#include <BulletDynamics/Featherstone/btMultiBodyJointFeedback.h>
#include <BulletDynamics/Featherstone/btMultiBodyJointMotor.h>
#include <BulletDynamics/Featherstone/btMultiBodyLinkCollider.h>
#include <BulletDynamics/Featherstone/btMultiBodyPoint2Point.h>
#include <btBulletDynamicsCommon.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <numbers>
#include <optional>

#ifndef BT_USE_DOUBLE_PRECISION
#error "mechbench needs Bullet in double precision (pkg-config bullet-float64 defines BT_USE_DOUBLE_PRECISION)"
#endif
static_assert(sizeof(btScalar) == sizeof(double), "btScalar must be double");

namespace mechbench::engines {
namespace {

using namespace bullet_internal;

constexpr double kPi = std::numbers::pi;
// The turning frame's platform link (its hinge is driven, so these only set how hard the motor
// works): ODE's platform body's.
constexpr double kPlatformMass = 1, kPlatformInertia = 1;

Eigen::Vector2d Perp(const Eigen::Vector2d& a) { return {-a.y(), a.x()}; }
btVector3 V3(const Eigen::Vector2d& p) { return btVector3(p.x(), p.y(), 0); }
btQuaternion RotZ(double th) { return btQuaternion(btVector3(0, 0, 1), th); }
// The centre-of-mass transform of a body frame in the world state `s` (R, origin).
btTransform WorldTransform(const SpatialState& s, const Eigen::Vector2d& com_B) {
  btMatrix3x3 B;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) B[r][c] = s.R(r, c);
  const Eigen::Vector3d c = s.p + s.R * Eigen::Vector3d(com_B.x(), com_B.y(), 0);
  return btTransform(B, btVector3(c.x(), c.y(), c.z()));
}
// Lamina about its centre of mass: Izz = I, Ixx = Iyy = I/2 (only Izz acts in a planar motion).
btVector3 LaminaInertia(const GraphBody& b) {
  const double I = b.inertia_com > 0 ? b.inertia_com : 1e-12;
  return btVector3(I / 2, I / 2, I);
}

// The state of a body frame from its centre of mass (position, angle, velocities): origin = COM − R com_B.
PlanarState FromCom(const GraphBody& gb, const Eigen::Vector2d& c, double angle, const Eigen::Vector2d& vc, double omega) {
  PlanarState s;
  s.angle = angle;
  s.omega = omega;
  const Eigen::Vector2d r = Rotate(angle, gb.com_B);
  s.p = c - r;
  s.v = vc - omega * Perp(r);
  return s;
}

// Graph joint coordinate measured from body states (zero at t0).
double JointCoordinate(const GraphJoint& j, const std::vector<PlanarState>& st) {
  const PlanarState c = st[j.child];
  const PlanarState p = j.parent < 0 ? PlanarState{} : st[j.parent];
  if (j.type == PairType::kRevolute) return c.angle - p.angle - j.angle0;
  return (c.PointPos(j.at_child_B) - p.PointPos(j.at_parent_B)).dot(Rotate(p.angle, j.axis_parent_B));
}


// How far the bodies left the platform's plane: the largest distance of a body frame's origin from
// it and angle of a body's z axis from its normal.
void TrackDrift(const SpatialState& platform, const std::vector<SpatialState>& bodies, double& length, double& angle) {
  const Eigen::Vector3d n = platform.R.col(2);
  for (const SpatialState& s : bodies) {
    length = std::max(length, std::fabs(n.dot(s.p - platform.p)));
    angle = std::max(angle, std::atan2(n.cross(s.R.col(2)).norm(), n.dot(s.R.col(2))));
  }
}

// The module of the gear layout when a planet must ride on its carrier [m] (the scene gives tooth
// counts only; the angles do not depend on it, only where the planet's mass orbits).
constexpr double kGearModule = 2e-3;

bool HasCarrierMesh(const Graph& g) {
  for (const GraphJoint& j : g.joints)
    if (j.type == PairType::kGear && j.carrier >= 0) return true;
  return false;
}
GearLayoutOrReason Layout(const Graph& g) { return LayOutGears(g, kGearModule / g.meters_per_unit); }

// One engine scene: built from the graph, stepped, read back as planar body-frame states.
// A force on a moving body for one step: F [world], r from the body's centre of mass to where it acts.
struct BodyLoad {
  int body = -1;
  Eigen::Vector2d f{0, 0}, r{0, 0};
};
// The spring–dampers' forces on their moving ends from the step's starting state (explicit).
std::vector<BodyLoad> SpringLoads(const Graph& g, const std::vector<PlanarState>& st) {
  std::vector<BodyLoad> out;
  for (const GraphSpring& sp : g.springs) {
    const Eigen::Vector2d p_a = Graph::EndPos(st, sp.body_a, sp.at_a), p_b = Graph::EndPos(st, sp.body_b, sp.at_b);
    const Eigen::Vector2d f_b =
        SpringForceOnB(sp, p_a, Graph::EndVel(st, sp.body_a, sp.at_a), p_b, Graph::EndVel(st, sp.body_b, sp.at_b));
    if (sp.body_a >= 0) out.push_back({sp.body_a, -f_b, p_a - st[sp.body_a].PointPos(g.bodies[sp.body_a].com_B)});
    if (sp.body_b >= 0) out.push_back({sp.body_b, f_b, p_b - st[sp.body_b].PointPos(g.bodies[sp.body_b].com_B)});
  }
  return out;
}

class Scene {
 public:
  virtual ~Scene() = default;
  virtual void Read(std::vector<PlanarState>& st) = 0;
  // On the turning frame's platform (Graph::platform): the platform's and every graph body's
  // world state (pose and velocities; accelerations left zero).
  virtual void ReadWorld(SpatialState& platform, std::vector<SpatialState>& bodies) {
    (void)platform;
    (void)bodies;
    MB_ASSERT(false, "this Bullet scene does not build the platform");
  }
  // One step of h from t, the drivers aimed at their law at t + h; `st` is the current state
  // when NeedsState(), else unused (and not read between the steps of a sample interval).
  virtual void Step(double t, double h, const std::vector<PlanarState>& st) = 0;
  virtual bool NeedsState() const = 0;
  // Joint reactions (numeric/reactions.h): EnableReactions before the first step; after a step of
  // h, every non-gear graph joint with the force [N, world] its child received from its parent in
  // that step, and in `how` where the forces come from.
  virtual void EnableReactions() = 0;
  virtual std::vector<numeric::EngineJointForce> Reactions(double h, std::string& how) const = 0;
};

// ---------------------------------------------------------------------------------------------
// btMultiBody over the spanning tree.

class MultiBodyScene final : public Scene {
 public:
  // `on_platform`: mount the mechanism on the turning frame's platform (Graph::platform), the
  // multibody's first link: a revolute about the frame's axis from the fixed base (the world),
  // driven by a btMultiBodyJointMotor as the drivers are; the graph's ground is that link.
  MultiBodyScene(const Graph& g, const Variant& v, bool on_platform, Result& result)
      : g_(g), state_loads_(g), base_(on_platform ? 1 : 0) {
    solver_ = std::make_unique<btMultiBodyConstraintSolver>();
    world_ = std::make_unique<btMultiBodyDynamicsWorld>(parts_.dispatcher.get(), parts_.broadphase.get(), solver_.get(),
                                                        parts_.config.get());
    if (on_platform) {
      const Eigen::Vector3d gw = g.platform->gravity_W;
      world_->setGravity(btVector3(gw.x(), gw.y(), gw.z()));
    } else {
      world_->setGravity(btVector3(g.gravity.x(), g.gravity.y(), 0));
    }
    ApplySolverSettings(world_->getSolverInfo(), v, result);

    // A planetary train: every planet becomes a link under its carrier's (its joint coordinate is
    // then relative to the carrier), its pivot at the planet's axis of the gear layout.
    if (HasCarrierMesh(g)) {
      layout_ = Layout(g).layout;
      MB_ASSERT(layout_.has_value(), "gear layout refused after Applicability accepted it");
    }
    auto planet = [&](const GraphJoint& j) { return layout_ && j.parent < 0 && layout_->IsPlanet(j.child); };
    // Links in tree order (each tree joint's parent precedes its child; planets after the rest).
    link_of_body_.assign(g.bodies.size(), -1);
    std::vector<int> tree;
    for (int pass = 0; pass < 2; ++pass)
      for (size_t ji = 0; ji < g.joints.size(); ++ji)
        if (g.joints[ji].in_tree && planet(g.joints[ji]) == (pass == 1)) {
          link_of_body_[g.joints[ji].child] = base_ + static_cast<int>(tree.size());
          tree.push_back(static_cast<int>(ji));
        }
    const int n = base_ + static_cast<int>(tree.size());
    tree_ = tree;
    mb_ = std::make_unique<btMultiBody>(n, 1.0, btVector3(1, 1, 1), /*fixedBase=*/true, /*canSleep=*/false);
    mb_->setBaseWorldTransform(btTransform::getIdentity());
    auto com = [&](int b) { return b < 0 ? Eigen::Vector2d(0, 0) : g.bodies[b].com_B; };
    // The graph's ground: the platform's link (its frame the platform's, centred at its origin), or the base.
    const int ground_link = on_platform ? 0 : -1;
    std::vector<double> rate(n);
    if (on_platform) SetUpPlatform(*g.platform, result);
    for (int i = base_; i < n; ++i) {
      const GraphJoint& j = g.joints[tree[i - base_]];
      const GraphBody& c = g.bodies[j.child];
      int parent_link = j.parent < 0 ? ground_link : link_of_body_[j.parent];
      // Link frames are centred at the centre of mass with the body frame's orientation.
      btVector3 parent_com_to_pivot = V3(j.at_parent_B - com(j.parent));  // parent frame
      btVector3 pivot_to_com = V3(c.com_B - j.at_child_B);                 // child frame
      btQuaternion parent_to_this = RotZ(-j.angle0);  // rotates parent-frame vectors into this frame
      rate[i] = InitialJointRate(g, j);
      if (layout_) {  // gear members at their axes; a planet's pivot on its carrier
        pivot_to_com = V3(c.com_B);
        parent_com_to_pivot = V3(layout_->axis[j.child]);
        if (planet(j)) {
          const int carrier = layout_->carrier_of[j.child];
          const PlanarState& cs = g.bodies[carrier].initial;
          parent_link = link_of_body_[carrier];
          parent_com_to_pivot = V3(Rotate(-cs.angle, layout_->axis[j.child] - layout_->axis[carrier]) - com(carrier));
          parent_to_this = RotZ(-(c.initial.angle - cs.angle));
          rate[i] = c.initial.omega - cs.omega;
          ++planets_;
        }
      }
      if (j.type == PairType::kRevolute) {
        mb_->setupRevolute(i, c.mass, LaminaInertia(c), parent_link, parent_to_this, btVector3(0, 0, 1),
                           parent_com_to_pivot, pivot_to_com, true);
      } else {
        const Eigen::Vector2d axis_child = Rotate(-j.angle0, j.axis_parent_B);
        mb_->setupPrismatic(i, c.mass, LaminaInertia(c), parent_link, parent_to_this, V3(axis_child),
                            parent_com_to_pivot, pivot_to_com, true);
      }
    }
    mb_->finalizeMultiDof();
    // Trap: btMultiBody damps every link (linear and angular damping 0.04) and carries a joint
    // speed cap of 100; zero and lift them.
    mb_->setLinearDamping(0);
    mb_->setAngularDamping(0);
    mb_->setMaxCoordinateVelocity(1e30);
    mb_->setMaxAppliedImpulse(kMaxImpulse);
    mb_->setCanSleep(false);
    world_->addMultiBody(mb_.get(), 1, 0);
    // Trap: multibody constraints are silently dropped for links without a collider (they have no
    // island); every link and the base get one, with collision mask 0.
    for (int i = -1; i < n; ++i) {
      auto col = std::make_unique<btMultiBodyLinkCollider>(mb_.get(), i);
      col->setCollisionShape(parts_.shape.get());
      col->setActivationState(DISABLE_DEACTIVATION);
      world_->addCollisionObject(col.get(), 1, 0);
      if (i < 0)
        mb_->setBaseCollider(col.get());
      else
        mb_->getLink(i).m_collider = col.get();
      colliders_.push_back(std::move(col));
    }
    if (on_platform) mb_->setJointVel(0, g.platform->omega);
    for (int i = base_; i < n; ++i) mb_->setJointVel(i, rate[i]);
    UpdateKinematics();

    // Loop closures and gears.
    int closures = 0, gears = 0;
    for (const GraphJoint& j : g.joints) {
      if (j.in_tree) continue;
      const int la = j.parent < 0 ? ground_link : link_of_body_[j.parent];
      const int lb = link_of_body_[j.child];
      if (j.type == PairType::kRevolute) {
        auto c = std::make_unique<btMultiBodyPoint2Point>(mb_.get(), la, mb_.get(), lb, V3(j.at_parent_B - com(j.parent)),
                                                          V3(j.at_child_B - com(j.child)));
        c->setMaxAppliedImpulse(kMaxImpulse);
        world_->addMultiBodyConstraint(c.get());
        closure_of_joint_[static_cast<int>(&j - g.joints.data())] = c.get();
        constraints_.push_back(std::move(c));
        ++closures;
      } else if (j.type == PairType::kGear) {
        // q̇_a + r q̇_b = 0 with r = z_b / Z_a (Z_a ω_a + z_b ω_b = 0); its ERP 1 hands the position
        // error to the world's ERP (both links on the one multibody, as the constraint assumes).
        int link_a = la, link_b = lb;
        double ratio = j.z_b / j.z_a;
        const GearMeshLayout* m = j.carrier >= 0 ? layout_->MeshOf(static_cast<int>(&j - g.joints.data())) : nullptr;
        if (m) {
          // On a carrier c, with A the central member (absolute coordinate q_A) and B the planet
          // (coordinate relative to c): κ_A (φ_A − φ_c) + κ_B ψ_B = 0, i.e. q̇_A + (κ_B/κ_A) q̇_B = q̇_c:
          // the carrier is the constraint's auxiliary link, whose rate at the step's start is the
          // row's target velocity. Bullet 3.24 also subtracts the auxiliary link's position in the
          // row's position error (q_A − q_c + r q_B), so the relative position target stays 0
          // (every joint coordinate is zero at t0). A Bullet that did not would show at once: the
          // planetary scenes' residual is checked to 1e-13 (engines_bullet_test, BulletGear).
          const double k_central = m->central == j.parent ? j.z_a : j.z_b;
          const double k_planet = m->planet == j.parent ? j.z_a : j.z_b;
          link_a = link_of_body_[m->central];
          link_b = link_of_body_[m->planet];
          ratio = k_planet / k_central;
        }
        auto c = std::make_unique<btMultiBodyGearConstraint>(mb_.get(), link_a, mb_.get(), link_b, btVector3(0, 0, 0),
                                                             btVector3(0, 0, 0), btMatrix3x3::getIdentity(),
                                                             btMatrix3x3::getIdentity());
        c->setGearRatio(ratio);
        c->setErp(1);
        c->setMaxAppliedImpulse(kMaxImpulse);
        if (m) {
          c->setGearAuxLink(link_of_body_[j.carrier]);
          c->setRelativePositionTarget(0);
          ++carrier_gears_;
        }
        world_->addMultiBodyConstraint(c.get());
        constraints_.push_back(std::move(c));
        ++gears;
      }
    }
    // Couplings (a rack and pinion, a belt): q_b = ratio q_a as btMultiBodyGearConstraint's
    // q̇_A + r q̇_B = 0 with A = b, B = a, r = −ratio (a prismatic link is allowed); ERP 1 as for the
    // gears, its position error q_A + r q_B read on the one multibody (both links are on it).
    for (const CouplingMap& cm : g.couplings) {
      auto c = std::make_unique<btMultiBodyGearConstraint>(mb_.get(), link_of_body_[g.joints[cm.joint_b].child], mb_.get(),
                                                           link_of_body_[g.joints[cm.joint_a].child], btVector3(0, 0, 0),
                                                           btVector3(0, 0, 0), btMatrix3x3::getIdentity(),
                                                           btMatrix3x3::getIdentity());
      c->setGearRatio(-cm.ratio);
      c->setErp(1);
      c->setMaxAppliedImpulse(kMaxImpulse);
      world_->addMultiBodyConstraint(c.get());
      constraints_.push_back(std::move(c));
    }
    if (!g.couplings.empty())
      result.settings["couplings"] = std::to_string(g.couplings.size()) +
                                     " × btMultiBodyGearConstraint on the two joints (q̇_b − ratio q̇_a = 0, ERP 1: the "
                                     "position error corrected each step)";
    for (const DriverMap& d : g.drivers) {
      auto m = std::make_unique<btMultiBodyJointMotor>(mb_.get(), link_of_body_[g.joints[d.joint].child], 0.0, kMaxImpulse);
      motors_.push_back(m.get());
      world_->addMultiBodyConstraint(m.get());
      constraints_.push_back(std::move(m));
    }
    if (on_platform) {
      auto m = std::make_unique<btMultiBodyJointMotor>(mb_.get(), 0, g.platform->omega, kMaxImpulse);
      platform_motor_ = m.get();
      world_->addMultiBodyConstraint(m.get());
      constraints_.push_back(std::move(m));
    }
    result.settings["formulation"] =
        on_platform ? "btMultiBody (reduced coordinates, Featherstone), fixed base = the world, link 0 = the turning "
                      "frame's platform, " + std::to_string(n - 1) + " links over the spanning tree on it"
                    : "btMultiBody (reduced coordinates, Featherstone), fixed base = ground, " + std::to_string(n) +
                          " links over the spanning tree";
    result.settings["loop_closures"] = std::to_string(closures) + " × btMultiBodyPoint2Point";
    if (gears) result.settings["gears"] = std::to_string(gears) + " × btMultiBodyGearConstraint (ERP via the world's)";
    if (carrier_gears_) {
      result.settings["gears"] += "; " + std::to_string(carrier_gears_) +
                                  " of them on a carrier: central member (absolute joint) and planet (joint relative to "
                                  "the carrier), the carrier as the gear's auxiliary link (q̇_central + r q̇_planet = "
                                  "q̇_carrier at the step's start; position error q_central − q_carrier + r q_planet)";
      result.settings["planets"] = std::to_string(planets_) + " × link under the carrier's link, pivot at the planet's axis";
      result.settings["gear_layout"] = (layout_->from_file ? std::string()
                                                           : "module " + Fmt(kGearModule * 1e3) +
                                                                 " mm chosen (only the planets' orbits depend on it): ") +
                                       layout_->Describe(g);
    }
    result.settings["multibody_damping"] = "linear 0, angular 0 (Bullet default 0.04 each: zeroed)";
    result.settings["multibody_max_coordinate_velocity"] = "1e30 (Bullet default 100: lifted)";
    result.settings["constraint_max_impulse"] = Fmt(kMaxImpulse) + " (btMultiBodyConstraint default 100: lifted)";
    result.settings["colliders"] = "btMultiBodyLinkCollider on the base and every link, collision mask 0";
    result.settings["planarity"] =
        on_platform ? "by construction: revolute links about the platform's normal, prismatic links along its plane"
                    : "by construction: revolute links about z, prismatic links along in-plane axes";
    result.settings["drivers"] = "btMultiBodyJointMotor, velocity target (q_law(t+h) − q)/h, max impulse " + Fmt(kMaxImpulse);
  }

  ~MultiBodyScene() override {
    for (auto& c : constraints_) world_->removeMultiBodyConstraint(c.get());
    for (auto& c : colliders_) world_->removeCollisionObject(c.get());
    world_->removeMultiBody(mb_.get());
    world_.reset();
  }
  MultiBodyScene(const MultiBodyScene&) = delete;
  MultiBodyScene& operator=(const MultiBodyScene&) = delete;

  void Read(std::vector<PlanarState>& st) override {
    if (base_ > 0) {  // relative to the platform
      ReadWorld(platform_state_, world_states_);
      st = RelativeToPlatform(platform_state_, world_states_);
      return;
    }
    const int n = mb_->getNumLinks();
    omega_.resize(n + 1);
    vel_.resize(n + 1);
    mb_->compTreeLinkVelocities(omega_.data(), vel_.data());  // link-local frames, at the COM
    st.resize(g_.bodies.size());
    for (size_t b = 0; b < g_.bodies.size(); ++b) {
      const int i = link_of_body_[b];
      const btVector3 c = mb_->localPosToWorld(i, btVector3(0, 0, 0));
      const btVector3 x = mb_->localDirToWorld(i, btVector3(1, 0, 0));
      const btVector3 w = mb_->localDirToWorld(i, omega_[i + 1]);
      const btVector3 v = mb_->localDirToWorld(i, vel_[i + 1]);
      st[b] = FromCom(g_.bodies[b], {c.x(), c.y()}, std::atan2(x.y(), x.x()), {v.x(), v.y()}, w.z());
    }
  }

  void ReadWorld(SpatialState& platform, std::vector<SpatialState>& bodies) override {
    MB_ASSERT(base_ > 0, "world states read from a scene without the platform");
    const int n = mb_->getNumLinks();
    omega_.resize(n + 1);
    vel_.resize(n + 1);
    mb_->compTreeLinkVelocities(omega_.data(), vel_.data());  // link-local frames, at the COM
    // A link's world state: the body frame's origin = COM − R com_B, its velocity v_c − ω × R com_B.
    const auto world = [&](int i, const Eigen::Vector2d& com_B) {
      SpatialState s;
      for (int k = 0; k < 3; ++k) {
        const btVector3 e = mb_->localDirToWorld(i, btVector3(k == 0 ? 1 : 0, k == 1 ? 1 : 0, k == 2 ? 1 : 0));
        s.R.col(k) = Eigen::Vector3d(e.x(), e.y(), e.z());
      }
      const btVector3 c = mb_->localPosToWorld(i, btVector3(0, 0, 0));
      const btVector3 w = mb_->localDirToWorld(i, omega_[i + 1]);
      const btVector3 v = mb_->localDirToWorld(i, vel_[i + 1]);
      const Eigen::Vector3d r = s.R * Eigen::Vector3d(com_B.x(), com_B.y(), 0);
      s.omega = {w.x(), w.y(), w.z()};
      s.p = Eigen::Vector3d(c.x(), c.y(), c.z()) - r;
      s.v = Eigen::Vector3d(v.x(), v.y(), v.z()) - s.omega.cross(r);
      return s;
    };
    platform = world(0, Eigen::Vector2d(0, 0));
    bodies.resize(g_.bodies.size());
    for (size_t b = 0; b < g_.bodies.size(); ++b) bodies[b] = world(link_of_body_[b], g_.bodies[b].com_B);
  }

  // Tree joints: each link's btMultiBodyJointFeedback, world frame (solver info
  // m_jointFeedbackInWorldSpace): the spatial force the articulated-body pass carries across the
  // link's joint, I^A a + p^A, with the loop closures' and gears' forces added by the constraint
  // pass, i.e. the force the child link receives from its parent. That second pass evaluates the
  // velocity-product terms again, at the step's unconstrained velocities v0 + h a (O(h) from rest):
  // an O(h²) error, whatever the iterations (tests/reactions_test.cc). Loop closures: the
  // btMultiBodyPoint2Point's applied impulses along the world x, y, z rows, on B (the child) as
  // +impulse/h (the solver adds contactNormal2·impulse/h, contactNormal2 = +axis, to link B).
  void EnableReactions() override {
    world_->getSolverInfo().m_jointFeedbackInWorldSpace = true;
    world_->getSolverInfo().m_jointFeedbackInJointFrame = false;
    for (int i = base_; i < mb_->getNumLinks(); ++i) {
      feedback_.push_back(std::make_unique<btMultiBodyJointFeedback>());
      mb_->getLink(i).m_jointFeedback = feedback_.back().get();
    }
  }
  std::vector<numeric::EngineJointForce> Reactions(double h, std::string& how) const override {
    how = "btMultiBodyJointFeedback of each link (world frame) for tree joints, btMultiBodyPoint2Point applied "
          "impulses / h for loop closures (the feedback's constraint pass adds velocity-product terms at the step's "
          "unconstrained velocities, O(h) from rest: an O(h²) error)";
    std::vector<numeric::EngineJointForce> out;
    for (size_t ji = 0; ji < g_.joints.size(); ++ji) {
      const GraphJoint& j = g_.joints[ji];
      if (j.type == PairType::kGear) continue;
      Eigen::Vector2d f(kNaN, kNaN);
      if (j.in_tree) {
        const int link = link_of_body_[j.child];
        MB_ASSERT(link >= base_ && tree_[link - base_] == static_cast<int>(ji), "tree joint without its link");
        const btVector3 F = mb_->getLink(link).m_jointFeedback->m_reactionForces.getLinear();
        f = {F.x(), F.y()};
      } else if (const auto it = closure_of_joint_.find(static_cast<int>(ji)); it != closure_of_joint_.end()) {
        f = Eigen::Vector2d(it->second->getAppliedImpulse(0), it->second->getAppliedImpulse(1)) / h;
      }
      out.push_back(PinForce(g_, j, f * g_.meters_per_unit));
    }
    return out;
  }

  bool NeedsState() const override { return !g_.forces.empty() || !g_.springs.empty() || !state_loads_.empty(); }  // motors read the joint itself
  void Step(double t, double h, const std::vector<PlanarState>& st) override {
    if (platform_motor_)  // as a driver: the hinge's angle onto Ω (t + h − t0) at the step's end
      platform_motor_->setVelocityTarget((g_.platform->Angle(t + h, g_.t0) - mb_->getJointPos(0)) / h);
    for (size_t k = 0; k < g_.drivers.size(); ++k) {
      const DriverMap& d = g_.drivers[k];
      const int link = link_of_body_[g_.joints[d.joint].child];
      motors_[k]->setVelocityTarget((d.Position(t + h, g_.t0) - mb_->getJointPos(link)) / h);
    }
    for (const GraphForce& f : g_.forces) {
      const int i = link_of_body_[f.body];
      const Eigen::Vector2d r = Rotate(st[f.body].angle, f.at_B - g_.bodies[f.body].com_B);
      const Eigen::Vector2d f_W = f.At(t, st[f.body].angle);  // a law or a body frame: at the step's start
      mb_->addLinkForce(i, V3(f_W));
      mb_->addLinkTorque(i, btVector3(0, 0, r.x() * f_W.y() - r.y() * f_W.x()));
    }
    for (const BodyLoad& l : SpringLoads(g_, st)) {
      const int i = link_of_body_[l.body];
      mb_->addLinkForce(i, V3(l.f));
      mb_->addLinkTorque(i, btVector3(0, 0, l.r.x() * l.f.y() - l.r.y() * l.f.x()));
    }
    for (const GraphTorque& tq : g_.torques) mb_->addLinkTorque(link_of_body_[tq.body], btVector3(0, 0, tq.At(t)));
    if (!state_loads_.empty()) {  // torsions and laws of the state, from the step's start: explicit
      state_loads_.Evaluate(t, st, load_torque_, load_force_);
      for (size_t b = 0; b < g_.bodies.size(); ++b)
        if (load_torque_[b] != 0) mb_->addLinkTorque(link_of_body_[b], btVector3(0, 0, load_torque_[b]));
      for (size_t k = 0; k < g_.state_forces.size(); ++k) {
        const GraphForce& f = g_.state_forces[k];
        const int i = link_of_body_[f.body];
        const Eigen::Vector2d r = Rotate(st[f.body].angle, f.at_B - g_.bodies[f.body].com_B), f_W = load_force_[k];
        mb_->addLinkForce(i, V3(f_W));
        mb_->addLinkTorque(i, btVector3(0, 0, r.x() * f_W.y() - r.y() * f_W.x()));
      }
    }
    world_->stepSimulation(h, 0, h);
  }

 private:
  // The platform as link 0 under the fixed base (the world, identity): a revolute about the
  // frame's axis through axis_point, its frame the plane's at t0 (origin, u, v, n) centred at
  // the origin (its centre of mass), so the graph's ground coordinates are its link's own. Bullet's
  // link rotation is world → link, R0ᵀ at a zero joint angle; the joint axis is in the link's frame.
  void SetUpPlatform(const GraphPlatform& P, Result& result) {
    const Eigen::Matrix3d Rt = P.R0.transpose();
    btMatrix3x3 world_to_link;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) world_to_link[r][c] = Rt(r, c);
    btQuaternion q;
    world_to_link.getRotation(q);
    const Eigen::Vector3d axis_L = Rt * P.axis, pivot_to_com = Rt * (P.origin - P.axis_point);
    mb_->setupRevolute(0, kPlatformMass, btVector3(kPlatformInertia, kPlatformInertia, kPlatformInertia), -1, q,
                       btVector3(axis_L.x(), axis_L.y(), axis_L.z()),
                       btVector3(P.axis_point.x(), P.axis_point.y(), P.axis_point.z()),
                       btVector3(pivot_to_com.x(), pivot_to_com.y(), pivot_to_com.z()), true);
    result.settings["platform"] =
        "link 0 of the btMultiBody (" + Fmt(kPlatformMass) + " kg, inertia " + Fmt(kPlatformInertia) +
        " about each axis: its hinge is driven), a revolute from the fixed base about the frame's axis, driven by a "
        "btMultiBodyJointMotor as the drivers are (velocity target (Ω (t+h − t0) − angle)/h, max impulse " +
        Fmt(kMaxImpulse) + "); the mechanism's ground joints and loop closures attach to it, in its frame";
  }

  void UpdateKinematics() {
    btAlignedObjectArray<btQuaternion> q;
    btAlignedObjectArray<btVector3> o;
    mb_->forwardKinematics(q, o);
    mb_->updateCollisionObjectWorldTransforms(q, o);
  }

  const Graph& g_;
  StateLoads state_loads_;
  const int base_;  // links before the mechanism's: 1 with the platform (link 0), else 0
  std::vector<double> load_torque_;
  std::vector<Eigen::Vector2d> load_force_;  // per Graph::state_forces entry
  WorldParts parts_;
  std::unique_ptr<btMultiBodyConstraintSolver> solver_;
  std::unique_ptr<btMultiBody> mb_;
  std::vector<std::unique_ptr<btMultiBodyLinkCollider>> colliders_;
  std::vector<std::unique_ptr<btMultiBodyConstraint>> constraints_;
  std::unique_ptr<btMultiBodyDynamicsWorld> world_;  // reset first by the destructor
  std::vector<btMultiBodyJointMotor*> motors_;
  btMultiBodyJointMotor* platform_motor_ = nullptr;
  SpatialState platform_state_;              // Read's world states on the platform
  std::vector<SpatialState> world_states_;
  std::vector<int> link_of_body_;
  std::vector<int> tree_;  // graph joint of each link after the platform's
  std::map<int, btMultiBodyPoint2Point*> closure_of_joint_;  // graph joint → its loop closure
  std::vector<std::unique_ptr<btMultiBodyJointFeedback>> feedback_;  // per link, once enabled
  std::vector<btVector3> omega_, vel_;
  std::optional<GearLayout> layout_;  // planetary trains only
  int carrier_gears_ = 0;  // meshes on a carrier
  int planets_ = 0;
};

// ---------------------------------------------------------------------------------------------
// btRigidBody + typed constraints.

class RigidBodyScene final : public Scene {
 public:
  // `on_platform`: every body free in 3-D (no linear or angular factors), in the world through the
  // platform's frame at t0; the graph's ground is a platform body on a btHingeConstraint to the
  // world about the frame's axis, its motor driven as the drivers' are. The joints' frames are the
  // planar scene's, in the bodies' own frames (the platform's for the ground's side).
  RigidBodyScene(const Graph& g, const Variant& v, bool on_platform, Result& result) : g_(g), state_loads_(g) {
    solver_ = std::make_unique<btSequentialImpulseConstraintSolver>();
    world_ = std::make_unique<btDiscreteDynamicsWorld>(parts_.dispatcher.get(), parts_.broadphase.get(), solver_.get(),
                                                       parts_.config.get());
    if (on_platform) {
      const Eigen::Vector3d gw = g.platform->gravity_W;
      world_->setGravity(btVector3(gw.x(), gw.y(), gw.z()));
    } else {
      world_->setGravity(btVector3(g.gravity.x(), g.gravity.y(), 0));
    }
    ApplySolverSettings(world_->getSolverInfo(), v, result);

    for (const GraphBody& gb : g.bodies) {
      const PlanarState& s = gb.initial;
      const Eigen::Vector2d r = Rotate(s.angle, gb.com_B);
      const Eigen::Vector2d c = s.p + r, vc = s.v + s.omega * Perp(r);
      btRigidBody::btRigidBodyConstructionInfo info(gb.mass, nullptr, parts_.shape.get(), LaminaInertia(gb));
      info.m_startWorldTransform = btTransform(RotZ(s.angle), V3(c));
      SpatialState ws;
      if (on_platform) {
        ws = g.platform->LiftAtT0(s);
        info.m_startWorldTransform = WorldTransform(ws, gb.com_B);
      }
      info.m_linearDamping = 0;
      info.m_angularDamping = 0;
      auto body = std::make_unique<btRigidBody>(info);
      if (on_platform) {
        const Eigen::Vector3d rw = ws.R * Eigen::Vector3d(gb.com_B.x(), gb.com_B.y(), 0), vw = ws.v + ws.omega.cross(rw);
        body->setLinearVelocity(btVector3(vw.x(), vw.y(), vw.z()));
        body->setAngularVelocity(btVector3(ws.omega.x(), ws.omega.y(), ws.omega.z()));
      } else {
        body->setLinearVelocity(V3(vc));
        body->setAngularVelocity(btVector3(0, 0, s.omega));
        body->setLinearFactor(btVector3(1, 1, 0));
        body->setAngularFactor(btVector3(0, 0, 1));
      }
      body->setActivationState(DISABLE_DEACTIVATION);
      world_->addRigidBody(body.get(), 1, 0);
      bodies_.push_back(std::move(body));
    }
    if (on_platform) {
      const GraphPlatform& P = *g.platform;
      const SpatialState ps = P.At(g.t0, g.t0);
      btRigidBody::btRigidBodyConstructionInfo info(kPlatformMass, nullptr, parts_.shape.get(),
                                                    btVector3(kPlatformInertia, kPlatformInertia, kPlatformInertia));
      info.m_startWorldTransform = WorldTransform(ps, Eigen::Vector2d(0, 0));
      info.m_linearDamping = 0;
      info.m_angularDamping = 0;
      platform_ = std::make_unique<btRigidBody>(info);
      platform_->setLinearVelocity(btVector3(ps.v.x(), ps.v.y(), ps.v.z()));
      platform_->setAngularVelocity(btVector3(ps.omega.x(), ps.omega.y(), ps.omega.z()));
      platform_->setActivationState(DISABLE_DEACTIVATION);
      world_->addRigidBody(platform_.get(), 1, 0);
      const Eigen::Vector3d pivot = P.R0.transpose() * (P.axis_point - P.origin), axis = P.R0.transpose() * P.axis;
      auto h = std::make_unique<btHingeConstraint>(*platform_, btVector3(pivot.x(), pivot.y(), pivot.z()),
                                                   btVector3(axis.x(), axis.y(), axis.z()));
      h->enableAngularMotor(true, P.omega, kMaxImpulse);
      platform_hinge_ = h.get();
      world_->addConstraint(h.get(), true);
      constraints_.push_back(std::move(h));
      result.settings["platform"] = "a btRigidBody (" + Fmt(kPlatformMass) + " kg, inertia " + Fmt(kPlatformInertia) +
                                    ") on a btHingeConstraint to the world about the frame's axis, its motor as the "
                                    "drivers' (target (Ω (t+h − t0) − angle)/h); every body free in 3-D";
    }
    auto com = [&](int b) { return b < 0 ? Eigen::Vector2d(0, 0) : g.bodies[b].com_B; };
    joint_.assign(g.joints.size(), nullptr);
    int hinges = 0, sliders = 0, gears = 0;
    for (size_t ji = 0; ji < g.joints.size(); ++ji) {
      const GraphJoint& j = g.joints[ji];
      btRigidBody& child = *bodies_[j.child];
      std::unique_ptr<btTypedConstraint> c;
      if (j.type == PairType::kRevolute) {
        // A = child, B = parent: the motor drives ω_child − ω_parent about +z.
        const btVector3 z(0, 0, 1);
        if (j.parent < 0 && platform_)
          c = std::make_unique<btHingeConstraint>(child, *platform_, V3(j.at_child_B - com(j.child)), V3(j.at_parent_B), z, z);
        else if (j.parent < 0)
          c = std::make_unique<btHingeConstraint>(child, V3(j.at_child_B - com(j.child)), z);
        else
          c = std::make_unique<btHingeConstraint>(child, *bodies_[j.parent], V3(j.at_child_B - com(j.child)),
                                                  V3(j.at_parent_B - com(j.parent)), z, z);
        ++hinges;
      } else if (j.type == PairType::kPrismatic) {
        // Frames: x along the axis. A = parent (or the world), B = child, linear reference frame A:
        // the slider coordinate is the child's displacement along the parent's axis, as the graph's.
        const double phi = std::atan2(j.axis_parent_B.y(), j.axis_parent_B.x());
        const btTransform in_child(RotZ(phi - j.angle0), V3(j.at_child_B - com(j.child)));
        std::unique_ptr<btSliderConstraint> s;
        if (j.parent < 0 && !platform_) {
          s = std::make_unique<btSliderConstraint>(child, in_child, true);
        } else {
          const btTransform in_parent(RotZ(phi), V3(j.at_parent_B - com(j.parent)));
          s = std::make_unique<btSliderConstraint>(j.parent < 0 ? *platform_ : *bodies_[j.parent], child, in_parent,
                                                   in_child, true);
        }
        c = std::move(s);
        ++sliders;
      } else {
        // ω_a + r ω_b = 0 about z, r = z_b / Z_a (velocity level only: btGearConstraint has no
        // position term, the angles stay coupled as far as each step's velocities are).
        c = std::make_unique<btGearConstraint>(*bodies_[j.parent], child, btVector3(0, 0, 1), btVector3(0, 0, 1),
                                               j.z_b / j.z_a);
        ++gears;
      }
      world_->addConstraint(c.get(), /*disableCollisionsBetweenLinkedBodies=*/true);
      joint_[ji] = c.get();
      constraints_.push_back(std::move(c));
    }
    for (const DriverMap& d : g.drivers) {
      btTypedConstraint* c = joint_[d.joint];
      if (g.joints[d.joint].type == PairType::kRevolute) {
        static_cast<btHingeConstraint*>(c)->enableAngularMotor(true, 0, kMaxImpulse);
      } else {
        auto* s = static_cast<btSliderConstraint*>(c);
        s->setPoweredLinMotor(true);
        s->setMaxLinMotorForce(kMaxImpulse);
        s->setTargetLinMotorVelocity(0);
      }
    }
    result.settings["formulation"] = "btRigidBody × " + std::to_string(g.bodies.size()) +
                                     " in btDiscreteDynamicsWorld (maximal coordinates), sequential-impulse solver";
    result.settings["joints"] = std::to_string(hinges) + " × btHingeConstraint (axis z), " + std::to_string(sliders) +
                                " × btSliderConstraint" + (gears ? ", " + std::to_string(gears) + " × btGearConstraint (velocity level)" : "");
    result.settings["planarity"] = platform_ ? "none imposed: every body free in 3-D, held in the platform's plane by "
                                               "the hinges and sliders alone (see platform_drift)"
                                             : "every body: linear factor (1, 1, 0), angular factor (0, 0, 1)";
    result.settings["damping"] = "linear 0, angular 0 (Bullet default), deactivation disabled, collision mask 0";
    result.settings["drivers"] = "hinge/slider motor, target velocity (q_law(t+h) − q)/h, max impulse/force " + Fmt(kMaxImpulse);
  }

  // The platform's angle about the frame's axis since t0 from its world rotation.
  double PlatformAngle(const Eigen::Matrix3d& R) const {
    const GraphPlatform& P = *g_.platform;
    const Eigen::Vector3d w0 = P.axis.unitOrthogonal(), w = R * P.R0.transpose() * w0;
    return std::atan2(P.axis.dot(w0.cross(w)), w0.dot(w));
  }

  ~RigidBodyScene() override {
    for (auto& c : constraints_) world_->removeConstraint(c.get());
    for (auto& b : bodies_) world_->removeRigidBody(b.get());
    if (platform_) world_->removeRigidBody(platform_.get());
    world_.reset();
  }
  RigidBodyScene(const RigidBodyScene&) = delete;
  RigidBodyScene& operator=(const RigidBodyScene&) = delete;

  void ReadWorld(SpatialState& platform, std::vector<SpatialState>& bodies) override {
    MB_ASSERT(platform_ != nullptr, "world states read from a scene without the platform");
    const auto world = [](const btRigidBody& rb, const Eigen::Vector2d& com_B) {
      SpatialState s;
      const btTransform& T = rb.getCenterOfMassTransform();
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) s.R(r, c) = T.getBasis()[r][c];
      const btVector3 c = T.getOrigin(), v = rb.getLinearVelocity(), w = rb.getAngularVelocity();
      const Eigen::Vector3d r = s.R * Eigen::Vector3d(com_B.x(), com_B.y(), 0);
      s.omega = {w.x(), w.y(), w.z()};
      s.p = Eigen::Vector3d(c.x(), c.y(), c.z()) - r;
      s.v = Eigen::Vector3d(v.x(), v.y(), v.z()) - s.omega.cross(r);
      return s;
    };
    platform = world(*platform_, Eigen::Vector2d(0, 0));
    bodies.resize(g_.bodies.size());
    for (size_t b = 0; b < g_.bodies.size(); ++b) bodies[b] = world(*bodies_[b], g_.bodies[b].com_B);
    platform_angle_ = PlatformAngle(platform.R);
  }

  void Read(std::vector<PlanarState>& st) override {
    st.resize(g_.bodies.size());
    for (size_t b = 0; b < g_.bodies.size(); ++b) {
      const btRigidBody& rb = *bodies_[b];
      const btTransform& T = rb.getCenterOfMassTransform();
      const btVector3 c = T.getOrigin(), x = T.getBasis().getColumn(0);
      const btVector3 v = rb.getLinearVelocity(), w = rb.getAngularVelocity();
      st[b] = FromCom(g_.bodies[b], {c.x(), c.y()}, std::atan2(x.y(), x.x()), {v.x(), v.y()}, w.z());
    }
  }

  // Every hinge's btJointFeedback: A is the child (see the constructor), and the solver writes
  // m_appliedForceBodyA = its rows' impulses / h (× the linear factor) each step.
  void EnableReactions() override {
    for (size_t ji = 0; ji < g_.joints.size(); ++ji) {
      if (g_.joints[ji].type != PairType::kRevolute) continue;
      feedback_.push_back(std::make_unique<btJointFeedback>());
      joint_[ji]->enableFeedback(true);
      joint_[ji]->setJointFeedback(feedback_.back().get());
    }
  }
  std::vector<numeric::EngineJointForce> Reactions(double, std::string& how) const override {
    how = "btJointFeedback m_appliedForceBodyA of every btHingeConstraint (A = the child)";
    std::vector<numeric::EngineJointForce> out;
    for (size_t ji = 0; ji < g_.joints.size(); ++ji) {
      const GraphJoint& j = g_.joints[ji];
      if (j.type == PairType::kGear) continue;
      Eigen::Vector2d f(kNaN, kNaN);
      if (const btJointFeedback* fb = joint_[ji]->getJointFeedback(); fb && j.type == PairType::kRevolute)
        f = {fb->m_appliedForceBodyA.x(), fb->m_appliedForceBodyA.y()};
      out.push_back(PinForce(g_, j, f * g_.meters_per_unit));
    }
    return out;
  }

  bool NeedsState() const override {
    return platform_ || !g_.forces.empty() || !g_.drivers.empty() || !g_.springs.empty() || !state_loads_.empty();
  }
  void Step(double t, double h, const std::vector<PlanarState>& st) override {
    if (platform_hinge_) {  // from the angle read with the step's starting state (NeedsState)
      const double target = g_.platform->Angle(t + h, g_.t0);
      const double now = platform_angle_ + 2 * kPi * std::round((target - platform_angle_) / (2 * kPi));
      platform_hinge_->enableAngularMotor(true, (target - now) / h, kMaxImpulse);
    }
    for (const DriverMap& d : g_.drivers) {
      const GraphJoint& j = g_.joints[d.joint];
      const double target = d.Position(t + h, g_.t0);
      double now = JointCoordinate(j, st);
      if (j.type == PairType::kRevolute) now += 2 * kPi * std::round((target - now) / (2 * kPi));
      const double vel = (target - now) / h;
      if (j.type == PairType::kRevolute)
        static_cast<btHingeConstraint*>(joint_[d.joint])->enableAngularMotor(true, vel, kMaxImpulse);
      else
        static_cast<btSliderConstraint*>(joint_[d.joint])->setTargetLinMotorVelocity(vel);
    }
    for (const GraphForce& f : g_.forces) {
      const Eigen::Vector2d r = Rotate(st[f.body].angle, f.at_B - g_.bodies[f.body].com_B);
      bodies_[f.body]->applyForce(V3(f.At(t, st[f.body].angle)), V3(r));  // a law or a body frame: explicit
    }
    for (const BodyLoad& l : SpringLoads(g_, st)) bodies_[l.body]->applyForce(V3(l.f), V3(l.r));
    for (const GraphTorque& tq : g_.torques) bodies_[tq.body]->applyTorque(btVector3(0, 0, tq.At(t)));
    if (!state_loads_.empty()) {  // torsions and laws of the state, from the step's start: explicit
      state_loads_.Evaluate(t, st, load_torque_, load_force_);
      for (size_t b = 0; b < g_.bodies.size(); ++b)
        if (load_torque_[b] != 0) bodies_[b]->applyTorque(btVector3(0, 0, load_torque_[b]));
      for (size_t k = 0; k < g_.state_forces.size(); ++k) {
        const GraphForce& f = g_.state_forces[k];
        const Eigen::Vector2d r = Rotate(st[f.body].angle, f.at_B - g_.bodies[f.body].com_B);
        bodies_[f.body]->applyForce(V3(load_force_[k]), V3(r));
      }
    }
    world_->stepSimulation(h, 0, h);
  }

 private:
  const Graph& g_;
  StateLoads state_loads_;
  std::vector<double> load_torque_;
  std::vector<Eigen::Vector2d> load_force_;  // per Graph::state_forces entry
  WorldParts parts_;
  std::unique_ptr<btSequentialImpulseConstraintSolver> solver_;
  std::vector<std::unique_ptr<btRigidBody>> bodies_;
  std::vector<std::unique_ptr<btTypedConstraint>> constraints_;
  std::unique_ptr<btRigidBody> platform_;  // the turning frame's, when built
  btHingeConstraint* platform_hinge_ = nullptr;
  double platform_angle_ = 0;  // its angle about the axis since t0, at the last ReadWorld [rad]
  std::unique_ptr<btDiscreteDynamicsWorld> world_;  // reset first by the destructor
  std::vector<btTypedConstraint*> joint_;
  std::vector<std::unique_ptr<btJointFeedback>> feedback_;  // per hinge, once enabled
};

// ---------------------------------------------------------------------------------------------

class BulletMethod final : public EngineMethod {
 public:
  explicit BulletMethod(Variant v)
      : EngineMethod(v.name, std::string("Bullet ") + (v.multibody ? "btMultiBody (reduced coordinates)" : "btRigidBody + typed constraints") +
                                 ", double precision, sequential impulse, motor drivers, fixed step " + Fmt(v.h) + " s"),
        v_(std::move(v)) {}
  Control control() const override { return Control::kStep; }
  double default_control() const override { return v_.h; }

 protected:
  // The turning frame's platform: btMultiBody's first link (MultiBodyScene::SetUpPlatform), or a
  // btRigidBody on a motor hinge with every body free in 3-D (the planar scenes' linear and
  // angular factors would hold the bodies to the world's XY plane). Unlocked, the hinges and
  // sliders hold the mechanism in the platform's plane to the order of their in-plane closure
  // (result setting platform_drift; README "The turning frame in the engines").
  std::optional<std::string> PlatformReason(const Graph& g) const override { return PlatformLoadsReason(g); }

  // Spatial scenes through the engines' spatial graph (bullet_spatial.cc).
  bool SimulatesSpatial() const override { return true; }
  std::optional<std::string> SpatialEngineReason(const Model&, const SpatialGraph& g) const override {
    return SpatialReason(g, v_);
  }
  void SimulateSpatial(const SpatialGraph& g, const std::vector<double>& times, const ControlValue& control,
                       const SpatialRecorder& record, const RunOptions& options, Result& result) const override {
    bullet_internal::SimulateSpatial(g, v_, times, control, record, options, result);
  }

  std::optional<std::string> EngineReason(const Model&, const Graph& g) const override {
    for (const GraphJoint& j : g.joints) {
      if (j.type == PairType::kGear && j.carrier >= 0 && !v_.multibody)
        return j.name + ": a mesh on a moving carrier couples three members (Willis' relation); btGearConstraint "
                        "couples two rigid bodies' absolute angular velocities and has no carrier term";
      if (!j.in_tree && j.type == PairType::kPrismatic && v_.multibody)
        return "joint " + j.name + ": a prismatic loop closure is not wired in the btMultiBody adapter";
    }
    if (!v_.multibody && !g.couplings.empty())
      return g.couplings.front().name + ": btRigidBody constraints have no coupling of two joint coordinates — "
             "btGearConstraint relates two bodies' absolute angular velocities only (no slider's travel, so no rack; "
             "a belt between two hinges would drift, velocity level only) and is not wired for couplings; the "
             "btMultiBody variants use btMultiBodyGearConstraint";
    if (v_.multibody && HasCarrierMesh(g)) {
      const GearLayoutOrReason lay = Layout(g);
      if (!lay.layout) return "gear meshes on a carrier: no planet layout for btMultiBody: " + lay.reason;
      for (const DriverMap& d : g.drivers)
        if (lay.layout->IsPlanet(g.joints[d.joint].child))
          return "driver " + d.coordinate + " turns a planet, whose btMultiBody joint is relative to its carrier: a "
                 "joint motor there sets the rate relative to the carrier, not the absolute rotation the driver prescribes";
    }
    return std::nullopt;
  }

  void Simulate(const Graph& g, const std::vector<double>& times, const ControlValue& control, const Recorder& record,
                const RunOptions& options, Result& result) const override {
    const double h_max = control.value;  // the variant's step or the RunOptions override
    result.settings["precision"] = "double (bullet-float64, BT_USE_DOUBLE_PRECISION)";
    result.settings["integrator"] = "semi-implicit Euler (Bullet's only one), stepSimulation(h, 0): one step of h per call";
    result.settings["step"] = "h ≤ " + ControlText(control, " s") + ", shortened evenly to end on every sample time";
    if (!g.springs.empty())
      result.settings["spring_dampers"] =
          std::to_string(g.springs.size()) + " × tension k (L − L0) + c L̇ + F0 from the step's starting positions and "
          "velocities, " + (v_.multibody ? "addLinkForce + addLinkTorque (r × F)" : "btRigidBody::applyForce") +
          " on each moving end before every step: explicit (btGeneric6DofSpring2's solver springs act along frame "
          "axes, not between two points; a stiff spring is stable only while h ω stays small)";
    if (HasVaryingForces(g))
      result.settings["varying_forces"] = std::string("a point force given by a law of t or in its body's frame: ") +
                                          (v_.multibody ? "addLinkForce + addLinkTorque (r × F)" : "btRigidBody::applyForce") +
                                          " with its value and direction at the step's start (explicit)";
    if (!g.torques.empty())
      result.settings["torques"] = std::to_string(g.torques.size()) + " × " +
                                   (v_.multibody ? "addLinkTorque" : "btRigidBody::applyTorque") +
                                   " before every step (a torque law of t taken at the step's start: explicit)";
    if (!g.torsions.empty())
      result.settings["torsions"] = std::to_string(g.torsions.size()) +
                                    " × T = −k (θ − θ0) − c θ̇ + T0 from the bodies' relative rotation and rate at the "
                                    "step's start, " + (v_.multibody ? "addLinkTorque" : "btRigidBody::applyTorque") +
                                    " (±) on both bodies before every step: explicit (a stiff one is stable only while "
                                    "h √(k/I) stays small)";
    if (!g.state_torques.empty())
      result.settings["state_torques"] = std::to_string(g.state_torques.size()) + " × " +
                                         (v_.multibody ? "addLinkTorque" : "btRigidBody::applyTorque") +
                                         " before every step, the law of q., qd. from the scene's coordinates observed "
                                         "at the step's start: explicit";
    if (!g.state_springs.empty())
      result.settings["state_springs"] =
          std::to_string(g.state_springs.size()) + " × spring–damper with laws: tension k (L − L0) + c L̇ + F0 with the "
          "laws of t, q., qd. at the step's start, " +
          (v_.multibody ? "addLinkForce + addLinkTorque (r × F)" : "btRigidBody::applyForce") +
          " on each moving end before every step: explicit";
    if (StateForceLaws(g) > 0)
      result.settings["state_forces"] = std::to_string(StateForceLaws(g)) + " × " +
                                        (v_.multibody ? "addLinkForce + addLinkTorque (r × F)" : "btRigidBody::applyForce") +
                                        " before every step, the law of q., qd. from the scene's coordinates observed "
                                        "at the step's start (direction too, in a body frame): explicit";
    // The turning frame's platform (Graph::platform): world states recorded, the planar ones
    // relative to the platform (MultiBodyScene::Read) for the drivers and the loads.
    const bool on_platform = g.platform && !PlatformReason(g);
    std::unique_ptr<Scene> scene;
    if (v_.multibody)
      scene = std::make_unique<MultiBodyScene>(g, v_, on_platform, result);
    else
      scene = std::make_unique<RigidBodyScene>(g, v_, on_platform, result);
    auto with_acc = [&](std::vector<PlanarState>& now, const std::vector<PlanarState>& before, double h) {
      for (size_t b = 0; b < g.bodies.size(); ++b) {
        const Eigen::Vector2d r1 = Rotate(now[b].angle, g.bodies[b].com_B), r0 = Rotate(before[b].angle, g.bodies[b].com_B);
        const Eigen::Vector2d vc1 = now[b].v + now[b].omega * Perp(r1), vc0 = before[b].v + before[b].omega * Perp(r0);
        const Eigen::Vector2d ac = (vc1 - vc0) / h;
        const double al = (now[b].omega - before[b].omega) / h;
        now[b].alpha = al;
        now[b].a = ac - al * Perp(r1) + now[b].omega * now[b].omega * r1;
      }
    };
    auto finite = [](const std::vector<PlanarState>& st) {
      for (const PlanarState& s : st)
        if (!std::isfinite(s.p.x()) || !std::isfinite(s.p.y()) || !std::isfinite(s.angle) || !std::isfinite(s.v.x()) ||
            !std::isfinite(s.v.y()) || !std::isfinite(s.omega))
          return false;
      return true;
    };
    result.settings["accelerations"] = "(v_{n+1} − v_n)/h of the step ending at the sample; none at t0";
    // Joint reactions (numeric/reactions.h) of a free scene: the forces of the first step from t0,
    // Bullet having none at an instant. Its velocity-level rows (J v_1 = 0 plus ERP × the assembly
    // residual) give the t0 multipliers when the scene starts at rest (J̇ v_0 = 0) and the
    // iterative solver converges; from a moving start they lack the J̇ q̇ part of the constraint
    // forces. Without a motion, one step is taken for them alone.
    if (!g.driven) scene->EnableReactions();
    const auto report_reactions = [&](double h, bool extra_step) {
      std::string how;
      const numeric::EngineReactions r = numeric::EngineReactionQuantities(scene->Reactions(h, how));
      result.quantities.insert(r.quantities.begin(), r.quantities.end());
      bool at_rest = true;
      for (const GraphBody& gb : g.bodies) at_rest = at_rest && gb.initial.v.norm() == 0 && gb.initial.omega == 0;
      std::string text = how + ", of the first step from t0 (h = " + Fmt(h) + " s): the t0 force when the scene starts " +
                         "at rest (J̇ q̇ = 0) and the sequential-impulse iterations converge; from a moving start the " +
                         "velocity-level rows leave out the J̇ q̇ part" +
                         (at_rest ? " (this scene starts at rest)" : " (this scene does not start at rest)");
      if (extra_step) text += "; no motion was asked for: that step was taken for the reactions alone";
      for (const std::string& n : r.notes) text += "; left out: " + n;
      result.settings["reactions"] = text;
    };
    // On the platform: world states (wst, pst) beside the planar ones, read at the same moments,
    // their accelerations the step's own (v_{n+1} − v_n)/h as the planar ones'.
    std::vector<PlanarState> st, prev;
    double drift_length = 0, drift_angle = 0;  // out of the platform's plane, largest at a sample
    std::vector<SpatialState> wst, wprev;
    SpatialState pst, pprev;
    const auto read = [&](std::vector<PlanarState>& now) {
      if (!on_platform) return scene->Read(now);
      scene->ReadWorld(pst, wst);
      now = RelativeToPlatform(pst, wst);
    };
    const auto record_sample = [&](bool has_acc) {
      if (on_platform)
        record(pst, wst, has_acc);
      else
        record(st, has_acc);
    };
    long steps = 0;
    double t = g.t0;
    EnterPhase(options, Phase::kObservation);
    read(st);
    record_sample(false);
    if (!g.driven && times.size() == 1) {
      scene->Step(t, h_max, st);
      report_reactions(h_max, true);
    }
    // The state is read between steps only when the next step needs it (drivers aimed from the
    // current joint coordinate, forces placed at the current pose); otherwise before the last step
    // of each sample interval (for its (v_{n+1} − v_n)/h) and at the sample.
    const bool each_step = scene->NeedsState();
    for (size_t k = 1; k < times.size(); ++k) {
      EnterPhase(options, Phase::kIntegration);
      const auto [n, h] = StepsTo(t, times[k], h_max);
      for (long i = 0; i < n; ++i) {
        CheckBudgetInStep(options, i, times[k - 1]);
        if (i + 1 == n) {
          if (!each_step) read(st);
          prev = st;
          wprev = wst;
          pprev = pst;
        }
        scene->Step(t, h, st);
        if (each_step) {
          read(st);
          if (!finite(st)) {
            result.status = Status::kDiverged;
            result.reason = "Bullet's state is not finite after the step at t = " + Fmt(t);
            return;
          }
        }
        t += h;
        if (steps == 0 && !g.driven) report_reactions(h, false);
        ++steps;
      }
      EnterPhase(options, Phase::kObservation);
      t = times[k];
      if (!each_step) read(st);
      if (!finite(st)) {
        result.status = Status::kDiverged;
        result.reason = "Bullet's state is not finite at the sample t = " + Fmt(t);
        return;
      }
      with_acc(st, prev, h);
      if (on_platform) {
        TrackDrift(pst, wst, drift_length, drift_angle);
        for (size_t b = 0; b < g.bodies.size(); ++b)
          WorldAcceleration(wst[b], wprev[b], Eigen::Vector3d(g.bodies[b].com_B.x(), g.bodies[b].com_B.y(), 0), h);
        WorldAcceleration(pst, pprev, Eigen::Vector3d::Zero(), h);
      }
      record_sample(true);
    }
    result.settings["steps_taken"] = std::to_string(steps);
    result.steps = steps;
    if (on_platform)
      result.settings["platform_drift"] =
          "largest at a sample: a body frame's origin " + Fmt(drift_length / g.length_scale) +
          " of the scene's length scale off the platform's plane, its z axis " + Fmt(drift_angle) +
          " rad off the platform's normal" + (v_.multibody ? " (none by construction: revolute links about the normal)" : "");
  }

 private:
  Variant v_;
};

}  // namespace

MethodPtr MakeBulletMethod(const BulletOptions& o) {
  return std::make_unique<BulletMethod>(Variant{o.name, o.multibody, o.step, o.iterations, o.erp, o.cfm});
}

std::vector<MethodPtr> MakeBulletMethods() {
  std::vector<MethodPtr> out;
  // Defaults: Bullet's solver settings (10 iterations, ERP 0.2, CFM 0) at a 1 ms step (Bullet's
  // own 1/60 s is meant for games, not for sampling a mechanism). Tuned: 0.1 ms, 100 iterations.
  out.push_back(MakeBulletMethod({"bullet-multibody-default", true, 1e-3, -1, -1, -1}));
  out.push_back(MakeBulletMethod({"bullet-multibody-tuned", true, 1e-4, 100, 0.2, 0}));
  out.push_back(MakeBulletMethod({"bullet-rigidbody-default", false, 1e-3, -1, -1, -1}));
  out.push_back(MakeBulletMethod({"bullet-rigidbody-tuned", false, 1e-4, 100, 0.2, 0}));
  return out;
}

}  // namespace mechbench::engines
