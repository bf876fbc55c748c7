#include "mechbench/format.h"
#include "mechbench/engines/ode.h"

#include "mechbench/engines/engine_method.h"
#include "mechbench/errors.h"
#include "mechbench/numeric/reactions.h"
#include "ode_internal.h"

#include <ode/ode.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <numbers>

#ifndef dDOUBLE
#error "mechbench needs ODE built in double precision"
#endif

namespace mechbench::engines {
namespace {

using ode_internal::SetWorldState;
using ode_internal::WorldAcceleration;
using ode_internal::WorldState;

constexpr double kPi = std::numbers::pi;

Eigen::Vector2d Perp(const Eigen::Vector2d& a) { return {-a.y(), a.x()}; }

// RAII: the library (dInitODE2/dCloseODE, reference-counted by ODE) and a world, which owns every
// body and every joint created outside a joint group.
class OdeLibrary {
 public:
  OdeLibrary() { dInitODE2(0); }
  ~OdeLibrary() { dCloseODE(); }
  OdeLibrary(const OdeLibrary&) = delete;
  OdeLibrary& operator=(const OdeLibrary&) = delete;
};
class OdeWorld {
 public:
  OdeWorld() : id_(dWorldCreate()) {}
  ~OdeWorld() { dWorldDestroy(id_); }
  OdeWorld(const OdeWorld&) = delete;
  OdeWorld& operator=(const OdeWorld&) = delete;
  dWorldID get() const { return id_; }

 private:
  dWorldID id_;
};

struct Variant {
  std::string name;
  bool quick;         // dWorldQuickStep, else dWorldStep
  double h;           // largest step [s]
  double erp, cfm;    // <0: ODE's default
  int iterations;     // QuickStep; <0: default
  bool gear_finite_rotation = true;
};

// The module of the gear layout (the scene gives tooth counts only) [m].
constexpr double kGearModule = 2e-3;

bool HasGears(const Graph& g) {
  for (const GraphJoint& j : g.joints)
    if (j.type == PairType::kGear) return true;
  return false;
}

// A carrier whose driver holds it still (velocity and acceleration zero): its planets' axes stay put.
bool HeldByItsDriver(const Graph& g, int body) {
  for (const DriverMap& d : g.drivers)
    if (g.joints[d.joint].child == body && g.joints[d.joint].parent < 0 && d.law.IsStill())
      return true;
  return false;
}

GearLayoutOrReason Layout(const Graph& g) { return LayOutGears(g, kGearModule / g.meters_per_unit); }

class OdeMethod final : public EngineMethod {
 public:
  explicit OdeMethod(Variant v)
      : EngineMethod(v.name, std::string("ODE ") + (v.quick ? "dWorldQuickStep" : "dWorldStep") +
                                 ": maximal coordinates, hinge/slider joints, motor drivers, fixed step " + Fmt(v.h) + " s"),
        v_(v) {}
  Control control() const override { return Control::kStep; }
  double default_control() const override { return v_.h; }

 protected:
  std::optional<std::string> PlatformReason(const Graph& g) const override { return PlatformLoadsReason(g); }

  // The variant's world settings (an unset one stays ODE's default).
  void ConfigureWorld(dWorldID w) const {
    if (v_.erp >= 0) dWorldSetERP(w, v_.erp);
    if (v_.cfm >= 0) dWorldSetCFM(w, v_.cfm);
    if (v_.quick && v_.iterations > 0) dWorldSetQuickStepNumIterations(w, v_.iterations);
  }
  // The stepper's settings of a run in `w` (configured by ConfigureWorld).
  void WorldSettings(dWorldID w, const ControlValue& control, Result& result) const {
    result.settings["stepper"] = v_.quick ? "dWorldQuickStep (iterative)" : "dWorldStep (direct LCP)";
    result.settings["precision"] = "double (dDOUBLE)";
    result.settings["erp"] = Fmt(dWorldGetERP(w)) + (v_.erp >= 0 ? " (set)" : " (ODE default)");
    result.settings["cfm"] = Fmt(dWorldGetCFM(w)) + (v_.cfm >= 0 ? " (set)" : " (ODE default)");
    if (v_.quick)
      result.settings["quickstep_iterations"] = std::to_string(dWorldGetQuickStepNumIterations(w)) +
                                                (v_.iterations > 0 ? " (set)" : " (ODE default)") +
                                                ", SOR w " + Fmt(dWorldGetQuickStepW(w)) +
                                                ", row order randomised from seed 0 every run";
    result.settings["step"] = "h ≤ " + ControlText(control, " s") + ", shortened evenly to end on every sample time";
  }
  // Spatial scenes (ode_spatial.cc): every joint of the spatial graph is an ODE ball or hinge, so
  // nothing the graph maps is refused here (no SpatialEngineReason).
  bool SimulatesSpatial() const override { return true; }
  void SimulateSpatial(const SpatialGraph& g, const std::vector<double>& times, const ControlValue& control,
                       const SpatialRecorder& record, const RunOptions& options, Result& result) const override {
    OdeLibrary lib;
    dRandSetSeed(0);  // QuickStep's row order: the same run gives the same numbers (as Simulate)
    OdeWorld world;
    ConfigureWorld(world.get());
    WorldSettings(world.get(), control, result);
    ode_internal::SimulateSpatialGraph(world.get(), v_.quick, g, times, control, record, options, result);
  }
  // What Simulate depends on besides the graph: the stepper, the step, the world's settings as ODE
  // holds them (defaults read back from a world configured like the run's) and the gear mode.
  std::string EngineComputation(const ControlValue& control) const override {
    OdeLibrary lib;
    OdeWorld world;
    const dWorldID w = world.get();
    ConfigureWorld(w);
    std::string out = std::string(v_.quick ? "ODE dWorldQuickStep" : "ODE dWorldStep") + ", h " + FullPrecision(control.value) +
                      ", ERP " + FullPrecision(dWorldGetERP(w)) + ", CFM " + FullPrecision(dWorldGetCFM(w));
    if (v_.quick)
      out += ", " + std::to_string(dWorldGetQuickStepNumIterations(w)) + " iterations, SOR w " + FullPrecision(dWorldGetQuickStepW(w));
    return out + (v_.gear_finite_rotation ? ", finite rotation on gears" : ", infinitesimal rotation on gears");
  }

  std::optional<std::string> EngineReason(const Model&, const Graph& g) const override {
    for (const CouplingMap& c : g.couplings) {
      if (g.joints[c.joint_a].type == PairType::kRevolute && g.joints[c.joint_b].type == PairType::kRevolute)
        return c.name + ": a coupling of two hinges (a belt) is not wired in the ODE adapter — "
               "dJointCreateTransmission would need the wheels' radii and anchors, which the scene does not give";
      return c.name + ": ODE has no joint that couples a slider's travel to a hinge's angle — "
             "dJointCreateTransmission couples two wheels' rotations (parallel, bevel or chain modes), so no rack; an "
             "emulation by a motor whose target speed is reset each step would be a lagging velocity coupling, not ODE's";
    }
    if (!HasGears(g)) return std::nullopt;
    const GearLayoutOrReason lay = Layout(g);
    if (!lay.layout) return "gear meshes: no wheel layout for dJointCreateTransmission: " + lay.reason;
    const GearLayout& L = *lay.layout;
    for (const DriverMap& d : g.drivers)
      if (L.IsPlanet(g.joints[d.joint].child))
        return "driver " + d.coordinate + " turns a planet, whose hinge is on its carrier: a hinge motor there sets "
               "its rate relative to the carrier, not the absolute rotation the driver prescribes";
    for (const GearMeshLayout& m : L.meshes) {
      // The file's axes may put an internal mesh's baseline anywhere; chain-drive needs it along x.
      const Eigen::Vector2d base = L.axis[g.joints[m.joint].child] - L.axis[g.joints[m.joint].parent];
      if (m.internal && std::fabs(base.y()) > 1e-12 * base.norm())
        return g.joints[m.joint].name + ": the file puts this internal mesh's axes on a line at " +
               Fmt(std::atan2(base.y(), base.x()) * 180 / 3.14159265358979323846, 4) +
               " deg to the world x axis, and dJointCreateTransmission's chain-drive mode (the one for internal meshes) "
               "computes its contact points in the plane only for a baseline along x";
    }
    for (const GearMeshLayout& m : L.meshes)
      if (m.internal && m.planet >= 0 && !HeldByItsDriver(g, L.carrier_of[m.planet]))
        return g.joints[m.joint].name + ": an internal mesh whose planet orbits (a turning carrier) has no "
               "dJointCreateTransmission mode: parallel-axes puts the contact between the two axes (external meshes "
               "only; ODE asserts ratio > 0), and chain-drive (same-direction wheels, used for internal meshes on fixed "
               "axes) computes its contact points in the plane only for a baseline along the world x axis, and its "
               "phase error then pulls the wheels off the ratio";
    return std::nullopt;
  }

  void Simulate(const Graph& g, const std::vector<double>& times, const ControlValue& control, const Recorder& record,
                const RunOptions& options, Result& result) const override {
    const double h_max = control.value;  // the variant's step or the RunOptions override
    OdeLibrary lib;
    // dWorldQuickStep reorders its constraint rows with ODE's global random generator: seeded per
    // run, so that the same run gives the same numbers bit for bit (a sweep or a bisection on
    // the step compares runs).
    dRandSetSeed(0);
    OdeWorld world;
    const dWorldID w = world.get();
    // The turning frame's platform (Graph::platform): every pose, joint and velocity below is the
    // planar graph's carried into the world by the platform's frame at t0 (lift*), and the graph's
    // ground is the platform body, on a motor hinge about the frame's axis.
    const bool on_platform = g.platform && !PlatformReason(g);
    const GraphPlatform P = on_platform ? *g.platform : GraphPlatform{};
    const Eigen::Vector3d gravity = on_platform ? P.gravity_W : Eigen::Vector3d(g.gravity.x(), g.gravity.y(), 0);
    dWorldSetGravity(w, gravity.x(), gravity.y(), gravity.z());
    ConfigureWorld(w);
    WorldSettings(w, control, result);
    // QuickStep's iterations do not hold a joint on a link this light in rotation: the
    // substitute's promised lag is not what it gives (IFToMM A01, a known failure in
    // harness/tolerances.yaml, diverges in the first swing at 1e-13 … 1e-6 of m L²).
    if (v_.quick)
      for (const GraphBody& b : g.bodies)
        if (b.mass_source.find(") for 0") != std::string::npos)
          result.messages.push_back(
              "dWorldQuickStep does not hold the joints of link " + b.name +
              " with its substitute inertia: its iterations diverge within the first swing on a lumped pendulum "
              "(IFToMM A01: a known failure in harness/tolerances.yaml), so the substitute's lag above is not "
              "this solver's error; dWorldStep (ode-worldstep-*) holds them, or give the link its inertia");
    if (!g.springs.empty())
      result.settings["spring_dampers"] =
          std::to_string(g.springs.size()) +
          " × tension k (L − L0) + c L̇ + F0 from the step's starting positions and velocities, dBodyAddForceAtPos on "
          "each moving end before every step: explicit (ODE has no spring element; a stiff one is stable only "
          "while h ω stays small)";
    if (HasVaryingForces(g))
      result.settings["varying_forces"] = "a point force given by a law of t or in its body's frame: dBodyAddForceAtPos "
                                          "with its value and direction at the step's start (explicit)";
    if (!g.torques.empty())
      result.settings["torques"] = std::to_string(g.torques.size()) + " × dBodyAddTorque before every step (a torque law of t taken at the step's start: explicit)";
    if (!g.torsions.empty())
      result.settings["torsions"] = std::to_string(g.torsions.size()) +
                                    " × T = −k (θ − θ0) − c θ̇ + T0 from the bodies' relative rotation and rate at the "
                                    "step's start, dBodyAddTorque (±) on both bodies before every step: explicit (a stiff "
                                    "one is stable only while h √(k/I) stays small)";
    if (!g.state_torques.empty())
      result.settings["state_torques"] = std::to_string(g.state_torques.size()) +
                                         " × dBodyAddTorque before every step, the law of q., qd. from the scene's "
                                         "coordinates observed at the step's start: explicit";
    if (!g.state_springs.empty())
      result.settings["state_springs"] =
          std::to_string(g.state_springs.size()) + " × spring–damper with laws: tension k (L − L0) + c L̇ + F0 with the "
          "laws of t, q., qd. at the step's start, dBodyAddForceAtPos on each moving end before every step: explicit";
    if (StateForceLaws(g) > 0)
      result.settings["state_forces"] = std::to_string(StateForceLaws(g)) +
                                        " × dBodyAddForceAtPos before every step, the law of q., qd. from the scene's "
                                        "coordinates observed at the step's start (direction too, in a body frame): explicit";

    // Gear scenes: the wheels' axes from the layout (a planet's on its carrier, orbiting with it).
    std::vector<PlanarState> initial;
    for (const GraphBody& gb : g.bodies) initial.push_back(gb.initial);
    std::optional<GearLayout> layout;
    if (HasGears(g)) {
      layout = Layout(g).layout;
      MB_ASSERT(layout.has_value(), "gear layout refused after Applicability accepted it");
      for (size_t b = 0; b < g.bodies.size(); ++b) {
        initial[b].p = layout->axis[b];
        const int c = layout->carrier_of[b];
        if (c >= 0) initial[b].v = g.bodies[c].initial.omega * Perp(layout->axis[b] - layout->axis[c]);
      }
    }
    // Bodies at their centres of mass.
    std::vector<dBodyID> body(g.bodies.size());
    for (size_t b = 0; b < g.bodies.size(); ++b) {
      const GraphBody& gb = g.bodies[b];
      body[b] = dBodyCreate(w);
      dMass m;
      const double I = gb.inertia_com > 0 ? gb.inertia_com : 1e-12;
      dMassSetParameters(&m, gb.mass, 0, 0, 0, I / 2, I / 2, I, 0, 0, 0);
      dBodySetMass(body[b], &m);
      if (layout && v_.gear_finite_rotation) dBodySetFiniteRotationMode(body[b], 1);  // axis 0: the whole rotation
      const PlanarState& s = initial[b];
      if (on_platform) {
        const SpatialState ws = P.LiftAtT0(s);
        SetWorldState(body[b], ws, Eigen::Vector3d(gb.com_B.x(), gb.com_B.y(), 0));
        continue;
      }
      const Eigen::Vector2d r = Rotate(s.angle, gb.com_B);
      const Eigen::Vector2d c = s.p + r, vc = s.v + s.omega * Perp(r);
      dBodySetPosition(body[b], c.x(), c.y(), 0);
      dMatrix3 R;
      dRFromAxisAndAngle(R, 0, 0, 1, s.angle);
      dBodySetRotation(body[b], R);
      dBodySetLinearVel(body[b], vc.x(), vc.y(), 0);
      dBodySetAngularVel(body[b], 0, 0, s.omega);
    }
    dBodyID platform = nullptr;
    dJointID platform_hinge = nullptr;
    const double fmax = 1e10;
    if (on_platform) {
      platform = dBodyCreate(w);
      dMass m;
      dMassSetParameters(&m, 1, 0, 0, 0, 1, 1, 1, 0, 0, 0);
      dBodySetMass(platform, &m);
      SetWorldState(platform, P.At(g.t0, g.t0), Eigen::Vector3d::Zero());
      platform_hinge = dJointCreateHinge(w, nullptr);
      dJointAttach(platform_hinge, platform, nullptr);
      dJointSetHingeAnchor(platform_hinge, P.axis_point.x(), P.axis_point.y(), P.axis_point.z());
      dJointSetHingeAxis(platform_hinge, P.axis.x(), P.axis.y(), P.axis.z());
      dJointSetHingeParam(platform_hinge, dParamFMax, fmax);
      result.settings["platform"] = "a body (1 kg, unit inertia: its hinge is driven) on a dHinge to the world about the "
                                    "frame's axis, a motor as the drivers' (target speed (Ω (t+h − t0) − angle)/h); the "
                                    "mechanism's ground joints attach to it, in the world through its frame at t0";
    }
    const auto lift_point = [&](const Eigen::Vector2d& x) -> Eigen::Vector3d {
      return on_platform ? P.PointAtT0(x) : Eigen::Vector3d(x.x(), x.y(), 0);
    };
    const auto lift_direction = [&](const Eigen::Vector2d& x) -> Eigen::Vector3d {
      return on_platform ? P.DirectionAtT0(x) : Eigen::Vector3d(x.x(), x.y(), 0);
    };
    auto id = [&](int b) -> dBodyID { return b < 0 ? platform : body[b]; };
    auto state_of = [&](int b) { return b < 0 ? PlanarState{} : initial[b]; };
    // Every pin and slider is a joint: ODE needs no tree. A gear member's pin is on its axis; a
    // planet's is on its carrier (the graph's ground pin of the planet becomes a planet-carrier hinge).
    std::vector<dJointID> joint(g.joints.size(), nullptr);
    int transmissions = 0, chains = 0, planets = 0;
    for (size_t ji = 0; ji < g.joints.size(); ++ji) {
      const GraphJoint& j = g.joints[ji];
      const PlanarState p = state_of(j.parent);
      if (j.type == PairType::kRevolute) {
        joint[ji] = dJointCreateHinge(w, nullptr);
        const int carrier = layout && j.parent < 0 ? layout->carrier_of[j.child] : -1;
        planets += carrier >= 0;
        dJointAttach(joint[ji], id(j.child), id(carrier >= 0 ? carrier : j.parent));  // rate = ω_child − ω_parent about +z
        const Eigen::Vector3d a = lift_point(layout ? layout->axis[j.child] : p.PointPos(j.at_parent_B));
        const Eigen::Vector3d n = on_platform ? Eigen::Vector3d(P.R0.col(2)) : Eigen::Vector3d::UnitZ();
        dJointSetHingeAnchor(joint[ji], a.x(), a.y(), a.z());
        dJointSetHingeAxis(joint[ji], n.x(), n.y(), n.z());
      } else if (j.type == PairType::kPrismatic) {
        joint[ji] = dJointCreateSlider(w, nullptr);
        dJointAttach(joint[ji], id(j.child), id(j.parent));
        const Eigen::Vector3d u = lift_direction(Rotate(p.angle, j.axis_parent_B));
        dJointSetSliderAxis(joint[ji], u.x(), u.y(), u.z());
      } else {
        // The wheels' contact point moves with their anchors (a planet's orbits); the row keeps the
        // contact's tangential velocities equal, its phase error fed back at the joint's ERP.
        const GearMeshLayout& m = *layout->MeshOf(static_cast<int>(ji));
        joint[ji] = dJointCreateTransmission(w, nullptr);
        dJointAttach(joint[ji], body[j.parent], body[j.child]);
        dJointSetTransmissionMode(joint[ji], m.internal ? dTransmissionChainDrive : dTransmissionParallelAxes);
        dJointSetTransmissionAxis(joint[ji], 0, 0, 1);
        const Eigen::Vector2d a = layout->axis[j.parent], b = layout->axis[j.child];
        dJointSetTransmissionAnchor1(joint[ji], a.x(), a.y(), 0);
        dJointSetTransmissionAnchor2(joint[ji], b.x(), b.y(), 0);
        if (m.internal) {
          dJointSetTransmissionRadius1(joint[ji], m.r_a);
          dJointSetTransmissionRadius2(joint[ji], m.r_b);
          ++chains;
        } else {
          dJointSetTransmissionRatio(joint[ji], m.r_a / m.r_b);  // the contact divides the centre distance r_a : r_b
        }
        dJointSetTransmissionBacklash(joint[ji], 0);
        ++transmissions;
      }
    }
    if (layout) {
      const dJointID any = joint[layout->meshes.front().joint];
      result.settings["gears"] =
          std::to_string(transmissions) + " × dJointCreateTransmission (" + std::to_string(transmissions - chains) +
          " parallel-axes for external meshes, " + std::to_string(chains) +
          " chain-drive for internal meshes on fixed axes or a carrier its driver holds), backlash 0, ERP " +
          Fmt(dJointGetTransmissionParam(any, dParamERP)) + " and CFM " + Fmt(dJointGetTransmissionParam(any, dParamCFM)) +
          " (the world's when created): a velocity-level row on the contact's tangential velocities, its phase error "
          "r_a φ_a ± r_b φ_b fed back at ERP/h";
      result.settings["gear_layout"] = (layout->from_file ? std::string()
                                                          : "module " + Fmt(kGearModule * 1e3) +
                                                                " mm chosen (the scene gives tooth counts only), fixed axes "
                                                                "along the world x axis: ") +
                                       layout->Describe(g);
      if (planets)
        result.settings["planets"] = std::to_string(planets) + " × dHinge on the carrier at the planet's axis (its orbit simulated)";
      result.settings["rotation_update"] =
          v_.gear_finite_rotation
              ? "finite (dBodySetFiniteRotationMode 1): a body turns by exactly ω·h per step (ODE's default "
                "infinitesimal update turns it by 2·atan(ω·h/2), which puts a fast train off its ratio)"
              : "infinitesimal (ODE default): a body turns by 2·atan(ω·h/2) per step";
    }
    // Drivers: a motor on the joint whose target speed brings the joint coordinate onto the law at
    // the end of the step: v = (q_law(t + h) − q_now) / h.
    result.settings["drivers"] = "joint motor, target speed (q_law(t+h) − q)/h, FMax " + Fmt(fmax);
    for (const DriverMap& d : g.drivers) {
      const dJointID j = joint[d.joint];
      if (g.joints[d.joint].type == PairType::kRevolute)
        dJointSetHingeParam(j, dParamFMax, fmax);
      else
        dJointSetSliderParam(j, dParamFMax, fmax);
    }

    // On the platform: the world states of the body frames and the platform's (wst, pst; their
    // accelerations from the step, as below), and the planar states relative to the platform.
    std::vector<SpatialState> wst, wprev;
    SpatialState pst, pprev;
    // Planar states of the body frames (origin = COM − R com_B).
    auto read = [&](std::vector<PlanarState>& st) {
      if (on_platform) {
        wst.resize(g.bodies.size());
        for (size_t b = 0; b < g.bodies.size(); ++b)
          wst[b] = WorldState(body[b], Eigen::Vector3d(g.bodies[b].com_B.x(), g.bodies[b].com_B.y(), 0));
        pst = WorldState(platform, Eigen::Vector3d::Zero());
        st = RelativeToPlatform(pst, wst);
        return;
      }
      st.resize(g.bodies.size());
      for (size_t b = 0; b < g.bodies.size(); ++b) {
        const dReal* c = dBodyGetPosition(body[b]);
        const dReal* R = dBodyGetRotation(body[b]);  // 3×4 row-major
        const dReal* v = dBodyGetLinearVel(body[b]);
        const dReal* om = dBodyGetAngularVel(body[b]);
        PlanarState s;
        s.angle = std::atan2(R[4], R[0]);
        s.omega = om[2];
        const Eigen::Vector2d r = Rotate(s.angle, g.bodies[b].com_B);
        s.p = Eigen::Vector2d(c[0], c[1]) - r;
        s.v = Eigen::Vector2d(v[0], v[1]) - s.omega * Perp(r);
        st[b] = s;
      }
    };
    // Accelerations: the step's own (v_{n+1} − v_n)/h of the centre of mass, moved to the origin.
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
    auto joint_coordinate = [&](const GraphJoint& j, const std::vector<PlanarState>& st) {
      const PlanarState c = st[j.child];
      const PlanarState p = j.parent < 0 ? PlanarState{} : st[j.parent];
      if (j.type == PairType::kRevolute) return c.angle - p.angle - j.angle0;
      return (c.PointPos(j.at_child_B) - p.PointPos(j.at_parent_B)).dot(Rotate(p.angle, j.axis_parent_B));
    };
    StateLoads state_loads(g);
    std::vector<double> load_torque;
    std::vector<Eigen::Vector2d> load_force;  // per Graph::state_forces entry
    auto step = [&](double t, double h, const std::vector<PlanarState>& st) {
      if (on_platform) {
        const double target = P.Angle(t + h, g.t0);
        double now = dJointGetHingeAngle(platform_hinge);
        now += 2 * kPi * std::round((target - now) / (2 * kPi));
        dJointSetHingeParam(platform_hinge, dParamVel, (target - now) / h);
      }
      for (const DriverMap& d : g.drivers) {
        const GraphJoint& j = g.joints[d.joint];
        const double target = d.Position(t + h, g.t0);
        double now = joint_coordinate(j, st);
        if (j.type == PairType::kRevolute) now += 2 * kPi * std::round((target - now) / (2 * kPi));
        const double vel = (target - now) / h;
        if (j.type == PairType::kRevolute)
          dJointSetHingeParam(joint[d.joint], dParamVel, vel);
        else
          dJointSetSliderParam(joint[d.joint], dParamVel, vel);
      }
      for (const GraphForce& f : g.forces) {
        const Eigen::Vector2d at = st[f.body].PointPos(f.at_B);
        const Eigen::Vector2d f_W = f.At(t, st[f.body].angle);  // a law or a body frame: at the step's start
        dBodyAddForceAtPos(body[f.body], f_W.x(), f_W.y(), 0, at.x(), at.y(), 0);
      }
      // Spring–dampers from the step's starting positions and velocities (explicit), a fixed end
      // taking nothing; ODE clears its accumulators after every step, so they are added each time.
      for (const GraphSpring& sp : g.springs) {
        const Eigen::Vector2d p_a = Graph::EndPos(st, sp.body_a, sp.at_a), p_b = Graph::EndPos(st, sp.body_b, sp.at_b);
        const Eigen::Vector2d f_b =
            SpringForceOnB(sp, p_a, Graph::EndVel(st, sp.body_a, sp.at_a), p_b, Graph::EndVel(st, sp.body_b, sp.at_b));
        if (sp.body_b >= 0) dBodyAddForceAtPos(body[sp.body_b], f_b.x(), f_b.y(), 0, p_b.x(), p_b.y(), 0);
        if (sp.body_a >= 0) dBodyAddForceAtPos(body[sp.body_a], -f_b.x(), -f_b.y(), 0, p_a.x(), p_a.y(), 0);
      }
      for (const GraphTorque& tq : g.torques) dBodyAddTorque(body[tq.body], 0, 0, tq.At(t));
      // Torsions, torque and force laws of the state from the step's starting state (explicit).
      if (!state_loads.empty()) {
        state_loads.Evaluate(t, st, load_torque, load_force);
        for (size_t b = 0; b < g.bodies.size(); ++b)
          if (load_torque[b] != 0) dBodyAddTorque(body[b], 0, 0, load_torque[b]);
        for (size_t k = 0; k < g.state_forces.size(); ++k) {
          const GraphForce& f = g.state_forces[k];
          const Eigen::Vector2d at = st[f.body].PointPos(f.at_B);
          dBodyAddForceAtPos(body[f.body], load_force[k].x(), load_force[k].y(), 0, at.x(), at.y(), 0);
        }
      }
      const int ok = v_.quick ? dWorldQuickStep(w, h) : dWorldStep(w, h);
      return ok != 0;
    };

    // Joint reactions (numeric/reactions.h) of a free scene: every joint's dJointFeedback; f1 is
    // the force on body 1, the child (dJointAttach(child, parent)). ODE has no force at an instant:
    // they are those of the first step from t0, whose velocity-level rows J v_1 = 0 (plus ERP × the
    // assembly residual) give the t0 multipliers when the scene starts at rest (J̇ v_0 = 0); from a
    // moving start they lack the J̇ q̇ part of the constraint forces (the centripetal pulls: 8 % on
    // the N-four-bar started at 1 m/s, tests/reactions_test.cc). CFM softens the rows, (J M⁻¹ Jᵀ + CFM/h) λ: a relative error
    // of about CFM/h (1e-6 on the free four-bar at ODE's 1e-10 and 1 ms, tests/reactions_test.cc).
    // Without a motion, one step is taken for them alone.
    std::vector<dJointFeedback> feedback(g.joints.size());
    if (!g.driven)
      for (size_t ji = 0; ji < g.joints.size(); ++ji)
        if (g.joints[ji].type != PairType::kGear) dJointSetFeedback(joint[ji], &feedback[ji]);
    const auto report_reactions = [&](double h, bool extra_step) {
      std::vector<numeric::EngineJointForce> pins;
      for (size_t ji = 0; ji < g.joints.size(); ++ji) {
        const GraphJoint& j = g.joints[ji];
        if (j.type == PairType::kGear) continue;
        pins.push_back(PinForce(g, j, Eigen::Vector2d(feedback[ji].f1[0], feedback[ji].f1[1]) * g.meters_per_unit));
      }
      const numeric::EngineReactions r = numeric::EngineReactionQuantities(pins);
      result.quantities.insert(r.quantities.begin(), r.quantities.end());
      std::string text = "dJointFeedback f1 (force on the child) of the first step, h = " + Fmt(h) +
                         " s, from t0: the t0 force when the scene starts at rest (J̇ q̇ = 0), up to the rows' CFM (about "
                         "CFM/h); from a moving start the velocity-level rows leave out the J̇ q̇ part";
      bool at_rest = true;
      for (const GraphBody& gb : g.bodies) at_rest = at_rest && gb.initial.v.norm() == 0 && gb.initial.omega == 0;
      text += at_rest ? " (this scene starts at rest)" : " (this scene does not start at rest)";
      if (extra_step) text += "; no motion was asked for: that step was taken for the reactions alone";
      for (const std::string& n : r.notes) text += "; left out: " + n;
      result.settings["reactions"] = text;
    };

    long steps = 0;
    double t = g.t0;
    std::vector<PlanarState> st, prev;
    EnterPhase(options, Phase::kObservation);
    read(st);
    // ODE has no acceleration of its own: q̈ of a sample is the last step's (v_{n+1} − v_n)/h, and
    // t0 has none (the first step's velocity-level constraints lack the J̇v term, so its
    // (v_1 − v_0)/h is a start-up transient, not the acceleration at t0).
    result.settings["accelerations"] = "(v_{n+1} − v_n)/h of the step ending at the sample; none at t0";
    const auto record_sample = [&](bool has_acc) {
      if (on_platform) record(pst, wst, has_acc);
      else record(st, has_acc);
    };
    record_sample(false);
    if (!g.driven && times.size() == 1) {
      if (!step(t, h_max, st)) {
        result.status = Status::kDiverged;
        result.reason = "ODE step failed at t = " + Fmt(t) + " (the step taken for the reactions at t0)";
        return;
      }
      report_reactions(h_max, true);
    }
    // The state is read between steps only when the next step needs it (a driver's motor is aimed
    // from the current joint coordinate, a force placed at the current pose); otherwise before the
    // last step of each sample interval (for its (v_{n+1} − v_n)/h) and at the sample.
    const bool each_step = !g.drivers.empty() || !g.forces.empty() || !g.springs.empty() || !state_loads.empty();
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
        if (!step(t, h, st)) {
          result.status = Status::kDiverged;
          result.reason = "ODE step failed at t = " + Fmt(t);
          return;
        }
        if (each_step) read(st);
        t += h;
        if (steps == 0 && !g.driven) report_reactions(h, false);
        ++steps;
      }
      EnterPhase(options, Phase::kObservation);
      t = times[k];
      if (!each_step) read(st);
      with_acc(st, prev, h);
      if (on_platform) {
        for (size_t b = 0; b < g.bodies.size(); ++b)
          WorldAcceleration(wst[b], wprev[b], Eigen::Vector3d(g.bodies[b].com_B.x(), g.bodies[b].com_B.y(), 0), h);
        WorldAcceleration(pst, pprev, Eigen::Vector3d::Zero(), h);
      }
      record_sample(true);
    }
    result.settings["steps_taken"] = std::to_string(steps);
    result.steps = steps;
  }

 private:
  Variant v_;
};

}  // namespace

MethodPtr MakeOdeMethod(const OdeOptions& o) {
  return std::make_unique<OdeMethod>(Variant{o.name, o.quick, o.step, o.erp, o.cfm, o.iterations, o.gear_finite_rotation});
}

std::vector<MethodPtr> MakeOdeMethods() {
  std::vector<MethodPtr> out;
  // Defaults: ODE's ERP 0.2, CFM 1e-10 (double precision), 20 QuickStep iterations; a 1 ms step
  // (ODE has no default step). Tuned: 0.1 ms and, for QuickStep, 200 iterations.
  out.push_back(std::make_unique<OdeMethod>(Variant{"ode-worldstep-default", false, 1e-3, -1, -1, -1}));
  out.push_back(std::make_unique<OdeMethod>(Variant{"ode-worldstep-tuned", false, 1e-4, 0.2, 1e-10, -1}));
  out.push_back(std::make_unique<OdeMethod>(Variant{"ode-quickstep-default", true, 1e-3, -1, -1, -1}));
  out.push_back(std::make_unique<OdeMethod>(Variant{"ode-quickstep-tuned", true, 1e-4, 0.2, 1e-10, 200}));
  return out;
}

}  // namespace mechbench::engines
