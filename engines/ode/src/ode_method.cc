#include "mechbench/format.h"
#include "mechbench/engines/ode.h"

#include "mechbench/engines/engine_method.h"

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
};

class OdeMethod final : public EngineMethod {
 public:
  explicit OdeMethod(Variant v)
      : EngineMethod(v.name, std::string("ODE ") + (v.quick ? "dWorldQuickStep" : "dWorldStep") +
                                 ": maximal coordinates, hinge/slider joints, motor drivers, fixed step " + Fmt(v.h) + " s"),
        v_(v) {}
  Control control() const override { return Control::kStep; }
  double default_control() const override { return v_.h; }

 protected:
  std::optional<std::string> EngineReason(const Model&, const Graph& g) const override {
    for (const GraphJoint& j : g.joints)
      if (j.type == PairType::kGear)
        return "gear meshes: dJointCreateTransmission is not wired in the ODE adapter yet (it needs gear "
               "centres and pitch radii the scene does not give, and a carrier mesh couples three bodies)";
    return std::nullopt;
  }

  void Simulate(const Graph& g, const std::vector<double>& times, const ControlValue& control, const Recorder& record,
                Result& result) const override {
    const double h_max = control.value;  // the variant's step or the RunOptions override
    OdeLibrary lib;
    // dWorldQuickStep reorders its constraint rows with ODE's global random generator: seeded per
    // run, so that the same run gives the same numbers bit for bit (a sweep or a bisection on
    // the step compares runs).
    dRandSetSeed(0);
    OdeWorld world;
    const dWorldID w = world.get();
    dWorldSetGravity(w, g.gravity.x(), g.gravity.y(), 0);
    if (v_.erp >= 0) dWorldSetERP(w, v_.erp);
    if (v_.cfm >= 0) dWorldSetCFM(w, v_.cfm);
    if (v_.quick && v_.iterations > 0) dWorldSetQuickStepNumIterations(w, v_.iterations);
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

    // Bodies at their centres of mass.
    std::vector<dBodyID> body(g.bodies.size());
    for (size_t b = 0; b < g.bodies.size(); ++b) {
      const GraphBody& gb = g.bodies[b];
      body[b] = dBodyCreate(w);
      dMass m;
      const double I = gb.inertia_com > 0 ? gb.inertia_com : 1e-12;
      dMassSetParameters(&m, gb.mass, 0, 0, 0, I / 2, I / 2, I, 0, 0, 0);
      dBodySetMass(body[b], &m);
      const PlanarState& s = gb.initial;
      const Eigen::Vector2d r = Rotate(s.angle, gb.com_B);
      const Eigen::Vector2d c = s.p + r, vc = s.v + s.omega * Perp(r);
      dBodySetPosition(body[b], c.x(), c.y(), 0);
      dMatrix3 R;
      dRFromAxisAndAngle(R, 0, 0, 1, s.angle);
      dBodySetRotation(body[b], R);
      dBodySetLinearVel(body[b], vc.x(), vc.y(), 0);
      dBodySetAngularVel(body[b], 0, 0, s.omega);
    }
    auto id = [&](int b) -> dBodyID { return b < 0 ? nullptr : body[b]; };
    auto state_of = [&](int b) { return b < 0 ? PlanarState{} : g.bodies[b].initial; };
    // Every pin and slider is a joint: ODE needs no tree.
    std::vector<dJointID> joint(g.joints.size(), nullptr);
    for (size_t ji = 0; ji < g.joints.size(); ++ji) {
      const GraphJoint& j = g.joints[ji];
      const PlanarState p = state_of(j.parent);
      if (j.type == PairType::kRevolute) {
        joint[ji] = dJointCreateHinge(w, nullptr);
        dJointAttach(joint[ji], id(j.child), id(j.parent));  // rate = ω_child − ω_parent about +z
        const Eigen::Vector2d a = p.PointPos(j.at_parent_B);
        dJointSetHingeAnchor(joint[ji], a.x(), a.y(), 0);
        dJointSetHingeAxis(joint[ji], 0, 0, 1);
      } else if (j.type == PairType::kPrismatic) {
        joint[ji] = dJointCreateSlider(w, nullptr);
        dJointAttach(joint[ji], id(j.child), id(j.parent));
        const Eigen::Vector2d u = Rotate(p.angle, j.axis_parent_B);
        dJointSetSliderAxis(joint[ji], u.x(), u.y(), 0);
      }
    }
    // Drivers: a motor on the joint whose target speed brings the joint coordinate onto the law at
    // the end of the step: v = (q_law(t + h) − q_now) / h.
    const double fmax = 1e10;
    result.settings["drivers"] = "joint motor, target speed (q_law(t+h) − q)/h, FMax " + Fmt(fmax);
    for (const DriverMap& d : g.drivers) {
      const dJointID j = joint[d.joint];
      if (g.joints[d.joint].type == PairType::kRevolute)
        dJointSetHingeParam(j, dParamFMax, fmax);
      else
        dJointSetSliderParam(j, dParamFMax, fmax);
    }

    // Planar states of the body frames (origin = COM − R com_B).
    auto read = [&](std::vector<PlanarState>& st) {
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
    auto step = [&](double t, double h, const std::vector<PlanarState>& st) {
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
        dBodyAddForceAtPos(body[f.body], f.f_W.x(), f.f_W.y(), 0, at.x(), at.y(), 0);
      }
      const int ok = v_.quick ? dWorldQuickStep(w, h) : dWorldStep(w, h);
      return ok != 0;
    };

    long steps = 0;
    double t = g.t0;
    std::vector<PlanarState> st, prev;
    read(st);
    // ODE has no acceleration of its own: q̈ of a sample is the last step's (v_{n+1} − v_n)/h, and
    // t0 has none (the first step's velocity-level constraints lack the J̇v term, so its
    // (v_1 − v_0)/h is a start-up transient, not the acceleration at t0).
    result.settings["accelerations"] = "(v_{n+1} − v_n)/h of the step ending at the sample; none at t0";
    record(st, false);
    for (size_t k = 1; k < times.size(); ++k) {
      const double span = times[k] - t;
      const long n = std::max(1L, static_cast<long>(std::ceil(span / h_max - 1e-9)));
      const double h = span / static_cast<double>(n);
      for (long i = 0; i < n; ++i) {
        prev = st;
        if (!step(t, h, st)) {
          result.status = Status::kDiverged;
          result.reason = "ODE step failed at t = " + Fmt(t);
          return;
        }
        read(st);
        with_acc(st, prev, h);
        t += h;
        ++steps;
      }
      t = times[k];
      record(st, true);
    }
    result.settings["steps_taken"] = std::to_string(steps);
  }

 private:
  Variant v_;
};

}  // namespace

MethodPtr MakeOdeMethod(const OdeOptions& o) {
  return std::make_unique<OdeMethod>(Variant{o.name, o.quick, o.step, o.erp, o.cfm, o.iterations});
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
