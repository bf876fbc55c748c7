#include "mechbench/format.h"
#include "mechbench/engines/simbody.h"

#include "mechbench/engines/engine_method.h"
#include "mechbench/numeric/reactions.h"
#include "simbody_spatial.h"

#include <Simbody.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>

namespace mechbench::engines {
namespace {

SimTK::Vec3 V3(const Eigen::Vector2d& p) { return SimTK::Vec3(p.x(), p.y(), 0); }

// The turning frame's platform hinge (Graph::platform): q(t) = Ω (t − t0), prescribed as the
// drivers are.
class PlatformLaw : public SimTK::Motion::Custom::Implementation {
 public:
  PlatformLaw(GraphPlatform p, double t0) : p_(std::move(p)), t0_(t0) {}
  Implementation* clone() const override { return new PlatformLaw(*this); }
  SimTK::Motion::Level getLevel(const SimTK::State&) const override { return SimTK::Motion::Position; }
  void calcPrescribedPosition(const SimTK::State& s, int nq, SimTK::Real* q) const override {
    if (nq == 1) q[0] = p_.Angle(s.getTime(), t0_);
  }
  void calcPrescribedPositionDot(const SimTK::State&, int nq, SimTK::Real* qd) const override {
    if (nq == 1) qd[0] = p_.omega;
  }
  void calcPrescribedPositionDotDot(const SimTK::State&, int nq, SimTK::Real* qdd) const override {
    if (nq == 1) qdd[0] = 0;
  }

 private:
  GraphPlatform p_;
  double t0_;
};

SimTK::Vec3 V3(const Eigen::Vector3d& p) { return SimTK::Vec3(p.x(), p.y(), p.z()); }
Eigen::Vector3d E3(const SimTK::Vec3& p) { return {p[0], p[1], p[2]}; }

// A mobilized body's world state (realized through Acceleration).
SpatialState WorldState(const SimTK::State& s, const SimTK::MobilizedBody& m) {
  SpatialState w;
  const SimTK::Rotation& R = m.getBodyRotation(s);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) w.R(i, j) = R[i][j];
  w.p = E3(m.getBodyOriginLocation(s));
  w.v = E3(m.getBodyOriginVelocity(s));
  w.omega = E3(m.getBodyAngularVelocity(s));
  w.a = E3(m.getBodyOriginAcceleration(s));
  w.alpha = E3(m.getBodyAngularAcceleration(s));
  return w;
}

// A torque law of t on one body, evaluated in Simbody's own force calculation at every stage's
// time (so not explicit: the error-controlled RK-Merson sees it like any other force).
class TorqueLaw : public SimTK::Force::Custom::Implementation {
 public:
  TorqueLaw(const SimTK::SimbodyMatterSubsystem& matter, SimTK::MobilizedBodyIndex body, GraphTorque t)
      : matter_(matter), body_(body), t_(std::move(t)) {}
  void calcForce(const SimTK::State& s, SimTK::Vector_<SimTK::SpatialVec>& body_forces, SimTK::Vector_<SimTK::Vec3>&,
                 SimTK::Vector&) const override {
    matter_.getMobilizedBody(body_).applyBodyTorque(s, SimTK::Vec3(0, 0, t_.At(s.getTime())), body_forces);
  }
  SimTK::Real calcPotentialEnergy(const SimTK::State&) const override { return 0; }

 private:
  const SimTK::SimbodyMatterSubsystem& matter_;
  SimTK::MobilizedBodyIndex body_;
  GraphTorque t_;
};

// Every graph body's pose and velocity (accelerations left zero) from a state realized through
// Velocity.
std::vector<PlanarState> BodyStates(const SimTK::State& s, const std::vector<SimTK::MobilizedBody>& mob) {
  std::vector<PlanarState> st(mob.size());
  for (size_t b = 0; b < mob.size(); ++b) {
    const SimTK::Vec3 p = mob[b].getBodyOriginLocation(s), v = mob[b].getBodyOriginVelocity(s);
    const SimTK::Rotation& R = mob[b].getBodyRotation(s);
    st[b].p = {p[0], p[1]};
    st[b].angle = std::atan2(R[1][0], R[0][0]);
    st[b].v = {v[0], v[1]};
    st[b].omega = mob[b].getBodyAngularVelocity(s)[2];
  }
  return st;
}

// Torsional spring–dampers, torque and point-force laws of the state (StateLoads) in Simbody's own
// force calculation: evaluated from each stage's positions and velocities, so inside RK-Merson's
// error control like Simbody's own elements (not held over a step).
class StateLoadForce : public SimTK::Force::Custom::Implementation {
 public:
  StateLoadForce(const Graph& g, const std::vector<SimTK::MobilizedBody>& mob)
      : loads_(std::make_shared<StateLoads>(g)), mob_(mob), g_(g) {}
  void calcForce(const SimTK::State& s, SimTK::Vector_<SimTK::SpatialVec>& body_forces, SimTK::Vector_<SimTK::Vec3>&,
                 SimTK::Vector&) const override {
    loads_->Evaluate(s.getTime(), BodyStates(s, mob_), torque_, force_);
    for (size_t b = 0; b < mob_.size(); ++b)
      if (torque_[b] != 0) mob_[b].applyBodyTorque(s, SimTK::Vec3(0, 0, torque_[b]), body_forces);
    for (size_t k = 0; k < g_.state_forces.size(); ++k) {
      const GraphForce& f = g_.state_forces[k];
      mob_[f.body].applyForceToBodyPoint(s, V3(f.at_B), V3(force_[k]), body_forces);
    }
  }
  // The torsions' springs: ½ k (θ − θ0)² − T0 (θ − θ0) (the laws have none).
  SimTK::Real calcPotentialEnergy(const SimTK::State& s) const override {
    const std::vector<PlanarState> st = BodyStates(s, mob_);
    double e = 0;
    for (size_t k = 0; k < g_.torsions.size(); ++k) {
      const GraphTorsion& ts = g_.torsions[k];
      const double d = loads_->TorsionAngle(k, st).first - ts.free_angle;
      e += 0.5 * ts.stiffness * d * d - ts.preload * d;
    }
    return e;
  }

 private:
  std::shared_ptr<StateLoads> loads_;
  const std::vector<SimTK::MobilizedBody>& mob_;
  const Graph& g_;
  mutable std::vector<double> torque_;
  mutable std::vector<Eigen::Vector2d> force_;  // per Graph::state_forces entry
};

// A point force given by a law of t or in its body's frame (GraphForce::Varies), evaluated in
// Simbody's own force calculation at every stage's time and pose (not explicit, as TorqueLaw).
class PointForceLaw : public SimTK::Force::Custom::Implementation {
 public:
  PointForceLaw(const SimTK::SimbodyMatterSubsystem& matter, SimTK::MobilizedBodyIndex body, GraphForce f)
      : matter_(matter), body_(body), f_(std::move(f)) {}
  void calcForce(const SimTK::State& s, SimTK::Vector_<SimTK::SpatialVec>& body_forces, SimTK::Vector_<SimTK::Vec3>&,
                 SimTK::Vector&) const override {
    const SimTK::MobilizedBody& b = matter_.getMobilizedBody(body_);
    const SimTK::Rotation& R = b.getBodyRotation(s);
    const Eigen::Vector2d f_W = f_.At(s.getTime(), std::atan2(R[1][0], R[0][0]));
    b.applyForceToBodyPoint(s, V3(f_.at_B), V3(f_W), body_forces);
  }
  SimTK::Real calcPotentialEnergy(const SimTK::State&) const override { return 0; }

 private:
  const SimTK::SimbodyMatterSubsystem& matter_;
  SimTK::MobilizedBodyIndex body_;
  GraphForce f_;
};

struct Variant {
  const char* suffix;
  double accuracy;  // <= 0: Simbody's default
  const char* what;
};

// Integrator::getAccuracyInUse() when no accuracy is set (SimTK::IntegratorRep's default).
constexpr double kSimbodyDefaultAccuracy = 1e-3;

class SimbodyMethod final : public EngineMethod {
 public:
  explicit SimbodyMethod(Variant v)
      : EngineMethod(std::string("simbody-rkmerson-") + v.suffix,
                     std::string("Simbody: MobilizedBody tree with loop constraints, RK-Merson (") + v.what + ")"),
        v_(v) {}
  // Swept by its accuracy (relative error per step, also the constraint tolerance when set).
  Control control() const override { return Control::kTolerance; }
  double default_control() const override { return v_.accuracy > 0 ? v_.accuracy : kSimbodyDefaultAccuracy; }

 protected:
  std::optional<std::string> PlatformReason(const Graph& g) const override { return PlatformLoadsReason(g); }

  // Simulate's only variant-dependent setting is the accuracy (RunAccuracy).
  std::string EngineComputation(const ControlValue& control) const override {
    const double acc = RunAccuracy(control);
    return "Simbody RK-Merson, " + (acc > 0 ? "accuracy and constraint tolerance set to " + FullPrecision(acc)
                                            : std::string("Simbody's default accuracy and constraint tolerance (left unset)"));
  }
  // The variant's accuracy (<= 0: Simbody's default, left unset) or a RunOptions override, which
  // is set as the tuned variant sets its own: accuracy and constraint tolerance alike.
  double RunAccuracy(const ControlValue& control) const { return control.overridden ? control.value : v_.accuracy; }

  // Spatial scenes: simbody_spatial.cc, at the same accuracy as a planar run.
  bool SimulatesSpatial() const override { return true; }
  void SimulateSpatial(const SpatialGraph& g, const std::vector<double>& times, const ControlValue& control,
                       const SpatialRecorder& record, const RunOptions& options, Result& result) const override {
    SimulateSimbodySpatial(g, times, RunAccuracy(control), control, record, options, result);
  }

  std::optional<std::string> EngineReason(const Model&, const Graph& g) const override {
    for (const GraphJoint& j : g.joints)
      if (!j.in_tree && j.type == PairType::kPrismatic)
        return "joint " + j.name + ": a prismatic loop closure is not wired in the Simbody adapter";
    return std::nullopt;
  }

  void Simulate(const Graph& g, const std::vector<double>& times, const ControlValue& control, const Recorder& record,
                const RunOptions& options, Result& result) const override {
    using namespace SimTK;
    MultibodySystem system;
    SimbodyMatterSubsystem matter(system);
    GeneralForceSubsystem forces(system);
    const bool on_platform = g.platform && !PlatformReason(g);
    Force::UniformGravity gravity(forces, matter, on_platform ? V3(g.platform->gravity_W) : V3(g.gravity));
    (void)gravity;
    std::vector<MobilizedBody> mob(g.bodies.size());
    auto body_info = [&](const GraphBody& b) {
      // Planar lamina about the centre of mass: Izz = I, Ixx = Iyy = I/2 (only Izz acts).
      const double I = b.inertia_com > 0 ? b.inertia_com : 1e-12;
      const Inertia central(I / 2, I / 2, I);
      const Vec3 com = V3(b.com_B);
      return SimTK::Body::Rigid(MassProperties(b.mass, com, central.shiftFromMassCenter(-com, b.mass)));
    };
    // The turning frame's platform (Graph::platform): a Pin from Ground about the file's axis, its
    // body frame the plane's at t0 (X_GB(0) = X_GF X_BM⁻¹, so X_BM = X_GB(0)⁻¹ X_GF), prescribed
    // q = Ω (t − t0). The mechanism's ground (body −1) is the platform.
    MobilizedBody platform;
    if (on_platform) {
      const GraphPlatform& P = *g.platform;
      const Transform X_GF(Rotation(UnitVec3(V3(P.axis)), ZAxis), V3(P.axis_point));
      Mat33 R0;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) R0[i][j] = P.R0(i, j);
      const Transform X_GB0(Rotation(R0, true), V3(P.origin));
      platform = MobilizedBody::Pin(matter.updGround(), X_GF,
                                    SimTK::Body::Rigid(MassProperties(1, Vec3(0), UnitInertia(1))), ~X_GB0 * X_GF);
      Motion::Custom(platform, new PlatformLaw(P, g.t0));
    }
    auto mob_of = [&](int b) -> MobilizedBody& { return b < 0 ? (on_platform ? platform : matter.updGround()) : mob[b]; };
    std::vector<std::pair<int, int>> coord_of_body(g.bodies.size(), {-1, -1});  // tree joint per body
    for (size_t ji = 0; ji < g.joints.size(); ++ji) {
      const GraphJoint& j = g.joints[ji];
      if (!j.in_tree) continue;
      MobilizedBody& parent = mob_of(j.parent);
      const SimTK::Body::Rigid info = body_info(g.bodies[j.child]);
      if (j.type == PairType::kRevolute) {
        mob[j.child] = MobilizedBody::Pin(parent, Transform(Rotation(), V3(j.at_parent_B)), info,
                                          Transform(Rotation(-j.angle0, ZAxis), V3(j.at_child_B)));
      } else {
        const double phi = std::atan2(j.axis_parent_B.y(), j.axis_parent_B.x());
        mob[j.child] = MobilizedBody::Slider(parent, Transform(Rotation(phi, ZAxis), V3(j.at_parent_B)), info,
                                             Transform(Rotation(phi - j.angle0, ZAxis), V3(j.at_child_B)));
      }
    }
    int closures = 0, gears = 0;
    std::vector<std::optional<Constraint>> closure(g.joints.size());  // per revolute loop closure
    for (const GraphJoint& j : g.joints) {
      if (j.in_tree) continue;
      if (j.type == PairType::kRevolute) {
        closure[&j - g.joints.data()] = Constraint::PointOnLine(mob_of(j.parent), UnitVec3(ZAxis), V3(j.at_parent_B),
                                                                mob_of(j.child), V3(j.at_child_B));
        ++closures;
      } else if (j.type == PairType::kGear) {
        // Z_a q_a + z_b q_b − (Z_a + z_b) q_c = 0 on the ground-pin angles (zero at t0).
        std::vector<MobilizedBodyIndex> bodies{mob[j.parent].getMobilizedBodyIndex(), mob[j.child].getMobilizedBodyIndex()};
        std::vector<double> c{j.z_a, j.z_b};
        if (j.carrier >= 0) {
          bodies.push_back(mob[j.carrier].getMobilizedBodyIndex());
          c.push_back(-(j.z_a + j.z_b));
        }
        Vector coef(static_cast<int>(c.size()) + 1, 0.0);
        for (size_t k = 0; k < c.size(); ++k) coef[static_cast<int>(k)] = c[k];
        std::vector<MobilizerQIndex> qi(bodies.size(), MobilizerQIndex(0));
        Constraint::CoordinateCoupler(matter, new Function::Linear(coef), bodies, qi);
        ++gears;
      }
    }
    // Couplings (a rack and pinion, a belt): ratio q_a − q_b = 0 on the two tree mobilizers' q (zero at t0).
    for (const CouplingMap& c : g.couplings) {
      const std::vector<MobilizedBodyIndex> bodies{mob[g.joints[c.joint_a].child].getMobilizedBodyIndex(),
                                                   mob[g.joints[c.joint_b].child].getMobilizedBodyIndex()};
      Vector coef(3, 0.0);
      coef[0] = c.ratio;
      coef[1] = -1;
      Constraint::CoordinateCoupler(matter, new Function::Linear(coef), bodies,
                                    std::vector<MobilizerQIndex>(2, MobilizerQIndex(0)));
    }
    for (const DriverMap& d : g.drivers)
      Motion::Custom(mob[g.joints[d.joint].child], new PrescribedLaw<DriverMap>(d, g.t0));
    for (const GraphForce& f : g.forces) {
      if (f.Varies()) Force::Custom(forces, new PointForceLaw(matter, mob[f.body].getMobilizedBodyIndex(), f));
      else Force::ConstantForce(forces, mob[f.body], V3(f.at_B), V3(f.f_W));
    }
    // Spring–dampers as Simbody's own two-point elements (each is zero when its coefficient is):
    // TwoPointLinearSpring f = k (x − x0) pulling together, TwoPointLinearDamper c ẋ, and the
    // preload as a TwoPointConstantForce, whose positive value separates the points (so −F0).
    for (const GraphSpring& sp : g.springs) {
      const MobilizedBody &a = mob_of(sp.body_a), &b = mob_of(sp.body_b);
      if (sp.stiffness > 0) Force::TwoPointLinearSpring(forces, a, V3(sp.at_a), b, V3(sp.at_b), sp.stiffness, sp.free_length);
      if (sp.damping > 0) Force::TwoPointLinearDamper(forces, a, V3(sp.at_a), b, V3(sp.at_b), sp.damping);
      if (sp.preload != 0) Force::TwoPointConstantForce(forces, a, V3(sp.at_a), b, V3(sp.at_b), -sp.preload);
    }
    for (const GraphTorque& t : g.torques) {
      if (t.law) Force::Custom(forces, new TorqueLaw(matter, mob[t.body].getMobilizedBodyIndex(), t));
      else Force::ConstantTorque(forces, mob[t.body], Vec3(0, 0, t.torque));
    }
    if (!g.torsions.empty() || !g.state_torques.empty() || !g.state_forces.empty())
      Force::Custom(forces, new StateLoadForce(g, mob));

    State state = system.realizeTopology();
    state.setTime(g.t0);
    // Joint coordinates are zero at t0 by construction; speeds from the graph's t0 velocities.
    for (const GraphJoint& j : g.joints) {
      if (!j.in_tree) continue;
      const PlanarState& c = g.bodies[j.child].initial;
      PlanarState p;
      if (j.parent >= 0) p = g.bodies[j.parent].initial;
      double u;
      if (j.type == PairType::kRevolute) {
        u = c.omega - p.omega;
      } else {
        // Slider speed: velocity of the child's point relative to the parent's material point
        // there, along the axis, in the parent frame's rotating coordinates.
        const ::Eigen::Vector2d rel = c.PointVel(j.at_child_B) - p.PointVel(j.at_parent_B);
        const double ph = p.angle;
        const ::Eigen::Vector2d axis_W(std::cos(ph) * j.axis_parent_B.x() - std::sin(ph) * j.axis_parent_B.y(),
                                     std::sin(ph) * j.axis_parent_B.x() + std::cos(ph) * j.axis_parent_B.y());
        u = rel.dot(axis_W);
      }
      mob[j.child].setOneU(state, MobilizerUIndex(0), u);
    }
    const double acc = RunAccuracy(control);
    RungeKuttaMersonIntegrator integ(system);
    if (acc > 0) {
      integ.setAccuracy(acc);
      integ.setConstraintTolerance(acc);
    }
    integ.setAllowInterpolation(false);  // stop exactly at every sample time
    // Control back after every internal step, so that the CPU budget bounds a run whose steps
    // shrink without end between two samples (RunOptions::cpu_budget); the steps are the same.
    integ.setReturnEveryInternalStep(true);
    system.prescribe(state);
    system.project(state, acc > 0 ? acc / 10 : -1);
    integ.initialize(state);
    result.settings["integrator"] = "RK-Merson (error-controlled, 4th order)";
    // What Simbody actually uses (control.value unless kSimbodyDefaultAccuracy is out of date,
    // which the engine suite checks through default_control()).
    result.settings["control_value"] = FullPrecision(integ.getAccuracyInUse());
    result.settings["accuracy"] =
        control.overridden ? ControlText(control, "") + " (set)"
                           : Fmt(integ.getAccuracyInUse()) + (acc > 0 ? " (set)" : " (Simbody default)");
    result.settings["constraint_tolerance"] = Fmt(integ.getConstraintToleranceInUse());
    result.settings["interpolation"] = "off: steps end at every sample time";
    result.settings["loop_closures"] = std::to_string(closures) + " × Constraint::PointOnLine (z line: planar coincidence)";
    if (gears) result.settings["gears"] = std::to_string(gears) + " × Constraint::CoordinateCoupler (linear)";
    if (!g.couplings.empty())
      result.settings["couplings"] = std::to_string(g.couplings.size()) +
                                     " × Constraint::CoordinateCoupler (Function::Linear: ratio q_a − q_b on a pin's "
                                     "angle and a slider's travel, holonomic)";
    result.settings["drivers"] = "Motion::Custom, prescribed position q(t), q̇(t), q̈(t)";
    if (!g.springs.empty())
      result.settings["spring_dampers"] =
          std::to_string(g.springs.size()) +
          " × Force::TwoPointLinearSpring + TwoPointLinearDamper + TwoPointConstantForce (preload): part of the "
          "system's right-hand side, evaluated at every RK-Merson stage (explicit, error-controlled: a stiff "
          "spring shortens the steps)";
    if (HasVaryingForces(g))
      result.settings["varying_forces"] = "a point force given by a law of t or in its body's frame: Force::Custom "
                                          "(applyForceToBodyPoint at every stage's time and pose)";
    if (!g.torques.empty())
      result.settings["torques"] = std::to_string(g.torques.size()) + " × Force::ConstantTorque, or Force::Custom for a torque law of t (on the body alone, "
                                   "no reaction on its parent; in the right-hand side, at every stage's time)";
    if (!g.torsions.empty())
      result.settings["torsions"] = std::to_string(g.torsions.size()) +
                                    " × Force::Custom: T = −k (θ − θ0) − c θ̇ + T0 from the bodies' relative rotation and "
                                    "rate at every RK-Merson stage (in the right-hand side, error-controlled; equal and "
                                    "opposite couples on the two bodies)";
    if (!g.state_torques.empty())
      result.settings["state_torques"] = std::to_string(g.state_torques.size()) +
                                         " × Force::Custom: the law of q., qd. from the scene's coordinates observed at "
                                         "every RK-Merson stage (in the right-hand side, error-controlled)";
    if (!g.state_springs.empty())
      result.settings["state_springs"] =
          std::to_string(g.state_springs.size()) + " × spring–damper with laws: Force::Custom, tension k (L − L0) + "
          "c L̇ + F0 with the laws of t, q., qd. at every RK-Merson stage, applyForceToBodyPoint on each moving end "
          "(in the right-hand side, error-controlled)";
    if (StateForceLaws(g) > 0)
      result.settings["state_forces"] = std::to_string(StateForceLaws(g)) +
                                        " × Force::Custom: the law of q., qd. from the scene's coordinates observed at "
                                        "every RK-Merson stage, applyForceToBodyPoint at that stage's pose (in the "
                                        "right-hand side, error-controlled)";

    if (on_platform)
      result.settings["platform"] = "MobilizedBody::Pin from Ground about the frame's axis, Motion::Custom q = Ω (t − t0); "
                                    "world states from the bodies' Ground-frame kinematics at the Acceleration stage";
    auto observe = [&](const State& s) {
      system.realize(s, Stage::Acceleration);
      if (on_platform) {
        std::vector<SpatialState> st(g.bodies.size());
        for (size_t b = 0; b < g.bodies.size(); ++b) st[b] = WorldState(s, mob[b]);
        record(WorldState(s, platform), st, true);
        return;
      }
      std::vector<PlanarState> st(g.bodies.size());
      for (size_t b = 0; b < g.bodies.size(); ++b) {
        const MobilizedBody& m = mob[b];
        const Vec3 p = m.getBodyOriginLocation(s);
        const Rotation& R = m.getBodyRotation(s);
        st[b].p = {p[0], p[1]};
        st[b].angle = std::atan2(R[1][0], R[0][0]);
        const Vec3 v = m.getBodyOriginVelocity(s), a = m.getBodyOriginAcceleration(s);
        st[b].v = {v[0], v[1]};
        st[b].a = {a[0], a[1]};
        st[b].omega = m.getBodyAngularVelocity(s)[2];
        st[b].alpha = m.getBodyAngularAcceleration(s)[2];
      }
      record(st, true);
    };
    EnterPhase(options, Phase::kObservation);
    observe(integ.getState());
    // Joint reactions at t0 (numeric/reactions.h) of a free scene (the scenes whose natural-coordinate
    // formulations give them too), after the first sample's quantities: the state is realized through
    // Acceleration by observe(). A tree pin's is its mobilizer's reaction on the child (force part,
    // Ground frame; the point it is shifted to changes only the moment); a loop closure's is the
    // negated constrained-body force on the child (Simbody's constraint forces carry the opposite
    // sign of applied forces). Lengths are the scene's, so forces are in kg·length/s²: × meters_per_unit.
    if (!g.driven) {
      const State& s0 = integ.getState();
      std::vector<numeric::EngineJointForce> pins;
      std::string why;
      for (size_t ji = 0; ji < g.joints.size() && why.empty(); ++ji) {
        const GraphJoint& j = g.joints[ji];
        if (j.type == PairType::kGear) continue;
        ::Eigen::Vector2d f(kNaN, kNaN);
        if (j.in_tree) {
          const Vec3 F = mob[j.child].findMobilizerReactionOnBodyAtMInGround(s0)[1];
          f = {F[0], F[1]};
        } else if (closure[ji]) {
          const Constraint& c = *closure[ji];
          const Vector_<SpatialVec> body_forces = c.getConstrainedBodyForcesAsVector(s0);
          for (ConstrainedBodyIndex k(0); k < c.getNumConstrainedBodies(); ++k)
            if (c.getMobilizedBodyFromConstrainedBody(k).getMobilizedBodyIndex() == mob[j.child].getMobilizedBodyIndex())
              f = {-body_forces[k][1][0], -body_forces[k][1][1]};
        } else if (j.type == PairType::kRevolute) {
          why = "joint " + j.name + " has no Simbody element";
        }
        pins.push_back(PinForce(g, j, f * g.meters_per_unit));
      }
      const numeric::EngineReactions r = numeric::EngineReactionQuantities(pins);
      if (why.empty()) result.quantities.insert(r.quantities.begin(), r.quantities.end());
      std::string text = why.empty() ? "at t0 (Acceleration stage): tree pins from "
                                       "MobilizedBody::findMobilizerReactionOnBodyAtMInGround, loop closures from "
                                       "Constraint::getConstrainedBodyForcesAsVector (negated)"
                                     : "none: " + why;
      for (const std::string& n : r.notes) text += "; left out: " + n;
      result.settings["reactions"] = text;
    }
    for (size_t k = 1; k < times.size(); ++k) {
      EnterPhase(options, Phase::kIntegration);
      while (integ.getTime() < times[k] - 1e-14 * (1 + std::fabs(times[k]))) {
        const Integrator::SuccessfulStepStatus status = integ.stepTo(times[k]);
        if (status == Integrator::EndOfSimulation || integ.isSimulationOver()) {
          result.status = Status::kDiverged;
          result.reason = "Simbody stopped at t = " + Fmt(integ.getTime()) + " s: " +
                          Integrator::getTerminationReasonString(integ.getTerminationReason());
          return;
        }
        CheckBudget(options, times[k - 1]);
      }
      EnterPhase(options, Phase::kObservation);
      observe(integ.getState());
    }
    result.settings["steps_taken"] = std::to_string(integ.getNumStepsTaken());
    result.steps = integ.getNumStepsTaken();
  }

 private:
  Variant v_;
};

}  // namespace

std::vector<MethodPtr> MakeSimbodyMethods() {
  std::vector<MethodPtr> out;
  out.push_back(std::make_unique<SimbodyMethod>(Variant{"default", -1, "Simbody's default accuracy"}));
  out.push_back(std::make_unique<SimbodyMethod>(Variant{"tuned", 1e-10, "accuracy 1e-10"}));
  return out;
}

}  // namespace mechbench::engines
