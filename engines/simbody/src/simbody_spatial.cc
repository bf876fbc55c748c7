#include "simbody_spatial.h"

#include "mechbench/format.h"

#include <Simbody.h>

#include <cmath>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace mechbench::engines {
namespace simbody_spatial {  // apart from simbody_method.cc's names (the library builds in unity batches)
namespace {

SimTK::Vec3 Vec(const Eigen::Vector3d& p) { return SimTK::Vec3(p.x(), p.y(), p.z()); }
Eigen::Vector3d Eig(const SimTK::Vec3& p) { return {p[0], p[1], p[2]}; }

// A mobilized body's world state, realized through Acceleration: its frame is the graph body's
// (origin at the body's first entity, the world's axes at t0).
SpatialState World(const SimTK::State& s, const SimTK::MobilizedBody& m) {
  SpatialState w;
  const SimTK::Rotation& R = m.getBodyRotation(s);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) w.R(i, j) = R[i][j];
  w.p = Eig(m.getBodyOriginLocation(s));
  w.v = Eig(m.getBodyOriginVelocity(s));
  w.omega = Eig(m.getBodyAngularVelocity(s));
  w.a = Eig(m.getBodyOriginAcceleration(s));
  w.alpha = Eig(m.getBodyAngularAcceleration(s));
  return w;
}

bool Finite(const SpatialState& w) {
  return w.p.allFinite() && w.R.allFinite() && w.v.allFinite() && w.omega.allFinite() && w.a.allFinite() &&
         w.alpha.allFinite();
}

// Two unit vectors perpendicular to `a` and to each other.
std::pair<Eigen::Vector3d, Eigen::Vector3d> Perpendiculars(const Eigen::Vector3d& a) {
  const Eigen::Vector3d n = a.normalized();
  const Eigen::Vector3d seed = std::fabs(n.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d e1 = n.cross(seed).normalized();
  return {e1, n.cross(e1)};
}

// Torsions and load laws (SpatialStateLoads) in Simbody's own force calculation: from each
// stage's positions and velocities, so inside RK-Merson's error control like Simbody's own
// elements; each body's wrench at its centre of mass.
class StateLoadForce : public SimTK::Force::Custom::Implementation {
 public:
  StateLoadForce(const SpatialGraph& g, const std::vector<SimTK::MobilizedBody>& mob)
      : loads_(std::make_shared<SpatialStateLoads>(g)), mob_(mob), g_(g) {}
  void calcForce(const SimTK::State& s, SimTK::Vector_<SimTK::SpatialVec>& body_forces, SimTK::Vector_<SimTK::Vec3>&,
                 SimTK::Vector&) const override {
    st_.resize(mob_.size());
    for (size_t b = 0; b < mob_.size(); ++b) {  // realized through Velocity here: no accelerations
      SpatialState& w = st_[b];
      const SimTK::Rotation& R = mob_[b].getBodyRotation(s);
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) w.R(i, j) = R[i][j];
      w.p = Eig(mob_[b].getBodyOriginLocation(s));
      w.v = Eig(mob_[b].getBodyOriginVelocity(s));
      w.omega = Eig(mob_[b].getBodyAngularVelocity(s));
    }
    loads_->Evaluate(s.getTime(), st_, wrench_);
    for (size_t b = 0; b < mob_.size(); ++b) {
      mob_[b].applyForceToBodyPoint(s, Vec(g_.bodies[b].com_B), Vec(wrench_[b].force), body_forces);
      mob_[b].applyBodyTorque(s, Vec(wrench_[b].torque), body_forces);
    }
  }
  SimTK::Real calcPotentialEnergy(const SimTK::State&) const override { return 0; }  // not reported

 private:
  std::shared_ptr<SpatialStateLoads> loads_;
  const std::vector<SimTK::MobilizedBody>& mob_;
  const SpatialGraph& g_;
  mutable std::vector<SpatialState> st_;
  mutable std::vector<SpatialWrench> wrench_;
};

}  // namespace
}  // namespace simbody_spatial

void SimulateSimbodySpatial(const SpatialGraph& g, const std::vector<double>& times, double accuracy,
                            const ControlValue& control, const SpatialRecorder& record, const RunOptions& options,
                            Result& result) {
  using namespace SimTK;
  using simbody_spatial::Vec;
  MultibodySystem system;
  SimbodyMatterSubsystem matter(system);
  GeneralForceSubsystem forces(system);
  Force::UniformGravity gravity(forces, matter, Vec(g.gravity));
  (void)gravity;
  // Mass properties: Simbody takes the inertia about the body origin, the graph gives it about the
  // centre of mass (both in the body frame): shifted by −com (from the centre of mass to the origin).
  auto body_info = [&](const SpatialGraphBody& b) {
    const ::Eigen::Matrix3d& I = b.inertia_B;
    const Inertia central(Vec3(I(0, 0), I(1, 1), I(2, 2)), Vec3(I(0, 1), I(0, 2), I(1, 2)));
    const Vec3 com = Vec(b.com_B);
    return SimTK::Body::Rigid(MassProperties(b.mass, com, central.shiftFromMassCenter(-com, b.mass)));
  };
  std::vector<MobilizedBody> mob(g.bodies.size());
  auto mob_of = [&](int b) -> MobilizedBody& { return b < 0 ? matter.updGround() : mob[b]; };
  // The tree (parents first). Every graph frame has the world's axes at t0, so at q = 0 (identity
  // rotation, zero angle or translation) the mobilizer frames F (on the parent, at the shared
  // point) and M (on the child, at the same point) coincide and the child is at its t0 pose.
  // A Pin turns about its frames' Z: both are given the rotation taking Z to the graph's axis_B.
  for (const SpatialGraphJoint& j : g.joints) {
    if (!j.in_tree) continue;
    const SimTK::Body::Rigid info = body_info(g.bodies[j.child]);
    MobilizedBody& parent = mob_of(j.parent);
    switch (j.type) {
      case SpatialJointType::kBall:
        mob[j.child] = MobilizedBody::Ball(parent, Transform(Vec(j.at_parent_B)), info, Transform(Vec(j.at_child_B)));
        break;
      case SpatialJointType::kRevolute: {
        const Rotation z_to_axis(UnitVec3(Vec(j.axis_B)), ZAxis);
        mob[j.child] = MobilizedBody::Pin(parent, Transform(z_to_axis, Vec(j.at_parent_B)), info,
                                          Transform(z_to_axis, Vec(j.at_child_B)));
        break;
      }
      case SpatialJointType::kPrismatic: {  // a Slider translates along its frames' X
        const Rotation x_to_axis(UnitVec3(Vec(j.axis_B)), XAxis);
        mob[j.child] = MobilizedBody::Slider(parent, Transform(x_to_axis, Vec(j.at_parent_B)), info,
                                             Transform(x_to_axis, Vec(j.at_child_B)));
        break;
      }
      case SpatialJointType::kFree:
        mob[j.child] = MobilizedBody::Free(parent, Transform(Vec(g.bodies[j.child].initial.p)), info, Transform());
        break;
    }
  }
  // Loop closures: a ball as Constraint::Ball (three rows); a revolute as Constraint::Ball at its
  // point and two Constraint::ConstantAngle at 90° between the parent's axis and two directions
  // across the child's (five rows of rank five, Simbody's own recipe for aligned axes), rather than
  // the graph's two balls on the axis (six rows of rank five).
  int ball_closures = 0, revolute_closures = 0;
  for (const SpatialGraphJoint& j : g.joints) {
    if (j.in_tree) continue;
    MobilizedBody &parent = mob_of(j.parent), &child = mob_of(j.child);
    Constraint::Ball(parent, Vec(j.at_parent_B), child, Vec(j.at_child_B));
    if (j.type == SpatialJointType::kRevolute) {
      const auto [e1, e2] = simbody_spatial::Perpendiculars(j.axis_B);
      Constraint::ConstantAngle(parent, UnitVec3(Vec(j.axis_B)), child, UnitVec3(Vec(e1)), Pi / 2);
      Constraint::ConstantAngle(parent, UnitVec3(Vec(j.axis_B)), child, UnitVec3(Vec(e2)), Pi / 2);
      ++revolute_closures;
    } else {
      ++ball_closures;
    }
  }
  for (const SpatialDriverMap& d : g.drivers)
    Motion::Custom(mob[g.joints[d.joint].child], new PrescribedLaw<SpatialDriverMap>(d, g.t0));
  for (const SpatialGraphForce& f : g.forces) Force::ConstantForce(forces, mob[f.body], Vec(f.at_B), Vec(f.f_W));
  for (const SpatialGraphTorque& t : g.torques) Force::ConstantTorque(forces, mob[t.body], Vec(t.torque_W));
  if (!g.torsions.empty() || !g.law_loads.empty()) Force::Custom(forces, new simbody_spatial::StateLoadForce(g, mob));
  // Spring–dampers as in the planar path: TwoPointLinearSpring k (L − L0) pulling together,
  // TwoPointLinearDamper c L̇, and the preload F0 as a TwoPointConstantForce (whose positive value
  // separates the points, so −F0).
  for (const SpatialGraphSpring& sp : g.springs) {
    MobilizedBody &a = mob_of(sp.body_a), &b = mob_of(sp.body_b);
    if (sp.stiffness > 0) Force::TwoPointLinearSpring(forces, a, Vec(sp.at_a), b, Vec(sp.at_b), sp.stiffness, sp.free_length);
    if (sp.damping > 0) Force::TwoPointLinearDamper(forces, a, Vec(sp.at_a), b, Vec(sp.at_b), sp.damping);
    if (sp.preload != 0) Force::TwoPointConstantForce(forces, a, Vec(sp.at_a), b, Vec(sp.at_b), -sp.preload);
  }

  State state = system.realizeTopology();
  state.setTime(g.t0);
  // Joint rates at t0 from the assembled body velocities (q is zero there by construction). Every
  // frame has the world's axes at t0, so a ball's u (ω_FM in F) is the world relative angular
  // velocity; a free body's u is its world ω and its origin's velocity.
  for (const SpatialGraphJoint& j : g.joints) {
    if (!j.in_tree) continue;
    const SpatialState& c = g.bodies[j.child].initial;
    const ::Eigen::Vector3d w_rel = c.omega - (j.parent < 0 ? ::Eigen::Vector3d::Zero() : g.bodies[j.parent].initial.omega);
    MobilizedBody& m = mob[j.child];
    if (j.type == SpatialJointType::kRevolute) {
      m.setOneU(state, MobilizerUIndex(0), w_rel.dot(j.axis_B.normalized()));
    } else if (j.type == SpatialJointType::kPrismatic) {  // the child's velocity along the axis, relative to the parent
      m.setOneU(state, MobilizerUIndex(0), PrismaticRateAtT0(g, j));
    } else {
      for (int i = 0; i < 3; ++i) m.setOneU(state, MobilizerUIndex(i), w_rel[i]);
      if (j.type == SpatialJointType::kFree)
        for (int i = 0; i < 3; ++i) m.setOneU(state, MobilizerUIndex(3 + i), c.v[i]);
    }
  }
  RungeKuttaMersonIntegrator integ(system);
  if (accuracy > 0) {
    integ.setAccuracy(accuracy);
    integ.setConstraintTolerance(accuracy);
  }
  integ.setAllowInterpolation(false);  // stop exactly at every sample time
  // Control back after every internal step, so that the CPU budget bounds a run whose steps shrink
  // without end between two samples (RunOptions::cpu_budget); the steps are the same.
  integ.setReturnEveryInternalStep(true);
  system.prescribe(state);
  system.project(state, accuracy > 0 ? accuracy / 10 : -1);
  integ.initialize(state);

  result.settings["model"] = "MobilizedBody tree of the spatial graph (" + Describe(g) + ")";
  result.settings["joints"] = "MobilizedBody::Ball (quaternion), MobilizedBody::Pin (its mobilizer frames' Z turned to "
                              "the graph's axis), MobilizedBody::Slider (its frames' X turned to the axis), MobilizedBody::Free; mass properties with the inertia shifted from "
                              "the centre of mass to the body origin";
  result.settings["integrator"] = "RK-Merson (error-controlled, 4th order)";
  result.settings["control_value"] = FullPrecision(integ.getAccuracyInUse());
  result.settings["accuracy"] = control.overridden ? ControlText(control, "") + " (set)"
                                                   : Fmt(integ.getAccuracyInUse()) +
                                                         (accuracy > 0 ? " (set)" : " (Simbody default)");
  result.settings["constraint_tolerance"] = Fmt(integ.getConstraintToleranceInUse());
  result.settings["interpolation"] = "off: steps end at every sample time";
  if (ball_closures + revolute_closures > 0)
    result.settings["loop_closures"] =
        std::to_string(ball_closures) + " ball × Constraint::Ball, " + std::to_string(revolute_closures) +
        " revolute × Constraint::Ball + 2 Constraint::ConstantAngle (90°, the parent's axis across two "
        "directions normal to the child's: five rows of rank five); Simbody's projection and its "
        "multipliers take what redundancy the mechanism has (Bricard)";
  if (!g.drivers.empty()) result.settings["drivers"] = "Motion::Custom on the pin or slider, prescribed position q(t), q̇(t), q̈(t)";
  if (!g.forces.empty())
    result.settings["forces"] = std::to_string(g.forces.size()) + " × Force::ConstantForce (world force at a body point)";
  if (!g.torques.empty())
    result.settings["torques"] = std::to_string(g.torques.size()) + " × Force::ConstantTorque (world torque on the body)";
  if (!g.torsions.empty() || !g.law_loads.empty())
    result.settings["state_loads"] =
        std::to_string(g.torsions.size()) + " torsion(s) and " + std::to_string(g.law_loads.size()) +
        " load law(s) (SpatialStateLoads: q, q̇ observed from the bodies) in one Force::Custom, a wrench at each "
        "body's centre of mass at every RK-Merson stage";
  if (!g.springs.empty())
    result.settings["spring_dampers"] =
        std::to_string(g.springs.size()) +
        " × Force::TwoPointLinearSpring + TwoPointLinearDamper + TwoPointConstantForce (preload): in the "
        "right-hand side at every RK-Merson stage (explicit, error-controlled)";
  result.settings["accelerations"] = "the bodies' own at every sample (Stage::Acceleration), t0 included";
  result.settings["reactions"] = "not reported for spatial scenes yet";

  auto observe = [&](const State& s) -> bool {
    system.realize(s, Stage::Acceleration);
    std::vector<SpatialState> st(g.bodies.size());
    for (size_t b = 0; b < g.bodies.size(); ++b) {
      st[b] = simbody_spatial::World(s, mob[b]);
      if (!simbody_spatial::Finite(st[b])) return false;
    }
    record(st, true);
    return true;
  };
  EnterPhase(options, Phase::kObservation);
  if (!observe(integ.getState())) {
    result.status = Status::kDiverged;
    result.reason = "Simbody: non-finite state at t0";
    return;
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
    if (!observe(integ.getState())) {
      result.status = Status::kDiverged;
      result.reason = "Simbody: non-finite state at t = " + Fmt(times[k]);
      return;
    }
  }
  result.settings["steps_taken"] = std::to_string(integ.getNumStepsTaken());
  result.steps = integ.getNumStepsTaken();
}

}  // namespace mechbench::engines
