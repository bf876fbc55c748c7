// ODE on a spatial scene (issue 13): the engines' spatial graph (spatial_graph.h) as ODE bodies
// and joints. Maximal coordinates: every graph body is a dBody at its centre of mass, every joint of
// the graph — tree or closure — a joint between two bodies (or a body and the world): a ball a
// dBall, a revolute a dHinge; a free joint is no joint. Loads are added before every step, drivers
// are hinge motors aimed at the law, as in the planar path (ode_method.cc).
#include "ode_internal.h"

#include "mechbench/errors.h"
#include "mechbench/format.h"

#include <cmath>
#include <cstdlib>
#include <numbers>

namespace mechbench::engines::ode_internal {
namespace {

using V3 = Eigen::Vector3d;
constexpr double kPi = std::numbers::pi;

// A hinge motor's force limit: far above any load of a scene in the file's units, so the motor
// holds the law (as the planar path's drivers).
constexpr double kMotorFMax = 1e10;

// The angle of body c relative to body p about `axis_B` (the joint's axis in both frames at t0,
// when both have the world's axes): R_rel = R_pᵀ R_c turns a unit u ⊥ axis by θ about it.
double HingeAngle(const SpatialState& p, const SpatialState& c, const V3& axis_B) {
  const Eigen::Matrix3d R_rel = p.R.transpose() * c.R;
  const V3 u = axis_B.unitOrthogonal(), ru = R_rel * u;
  return std::atan2(axis_B.dot(u.cross(ru)), u.dot(ru));
}

bool Finite(const SpatialState& s) {
  return s.p.allFinite() && s.R.allFinite() && s.v.allFinite() && s.omega.allFinite();
}

// A body that turns more than 100 rad or moves more than 100 length scales in one step of h: no
// motion the harness compares does (it is an instability growing by a factor per step).
bool BlownUp(const std::vector<SpatialState>& st, double h, double length_scale) {
  for (const SpatialState& s : st)
    if (s.omega.norm() * h > 100 || s.v.norm() * h > 100 * length_scale) return true;
  return false;
}

}  // namespace

void SimulateSpatialGraph(dWorldID w, bool quick, const SpatialGraph& g, const std::vector<double>& times,
                          const ControlValue& control, const SpatialRecorder& record, const RunOptions& options,
                          Result& result) {
  const double h_max = control.value;
  dWorldSetGravity(w, g.gravity.x(), g.gravity.y(), g.gravity.z());
  const size_t nb = g.bodies.size();

  // Bodies at their centres of mass (ODE puts a body's origin there: dMassSetParameters with a
  // centre ≠ 0 is refused for a body), with the full inertia tensor about it in the body's axes.
  std::vector<dBodyID> body(nb);
  for (size_t b = 0; b < nb; ++b) {
    const SpatialGraphBody& gb = g.bodies[b];
    body[b] = dBodyCreate(w);
    const Eigen::Matrix3d& I = gb.inertia_B;
    dMass m;
    dMassSetParameters(&m, gb.mass, 0, 0, 0, I(0, 0), I(1, 1), I(2, 2), I(0, 1), I(0, 2), I(1, 2));
    dBodySetMass(body[b], &m);
    SetWorldState(body[b], gb.initial, gb.com_B);
  }
  auto id = [&](int b) -> dBodyID { return b < 0 ? nullptr : body[b]; };

  // Joints: every one between its two bodies (body 1 the child, body 2 the parent or the world),
  // anchored at the shared point in the world at t0 (the child's frame has the world's axes then).
  std::vector<dJointID> joint(g.joints.size(), nullptr);
  int balls = 0, hinges = 0, ball_closures = 0, hinge_closures = 0, sliders = 0;
  for (size_t ji = 0; ji < g.joints.size(); ++ji) {
    const SpatialGraphJoint& j = g.joints[ji];
    if (j.type == SpatialJointType::kFree) continue;
    const SpatialState& c = g.bodies[j.child].initial;
    const V3 anchor = c.PointPos(j.at_child_B);
    if (j.type == SpatialJointType::kBall) {
      joint[ji] = dJointCreateBall(w, nullptr);
      dJointAttach(joint[ji], id(j.child), id(j.parent));
      dJointSetBallAnchor(joint[ji], anchor.x(), anchor.y(), anchor.z());
      ++balls;
      ball_closures += !j.in_tree;
    } else if (j.type == SpatialJointType::kPrismatic) {  // from the world or the line's body; a dSlider holds the relative rotation too
      joint[ji] = dJointCreateSlider(w, nullptr);
      dJointAttach(joint[ji], id(j.child), id(j.parent));
      dJointSetSliderAxis(joint[ji], j.axis_B.x(), j.axis_B.y(), j.axis_B.z());
      ++sliders;
    } else {
      const V3 axis = c.R * j.axis_B;
      joint[ji] = dJointCreateHinge(w, nullptr);
      dJointAttach(joint[ji], id(j.child), id(j.parent));  // its rate: (ω_child − ω_parent)·axis
      dJointSetHingeAnchor(joint[ji], anchor.x(), anchor.y(), anchor.z());
      dJointSetHingeAxis(joint[ji], axis.x(), axis.y(), axis.z());
      ++hinges;
      hinge_closures += !j.in_tree;
    }
  }
  for (const SpatialDriverMap& d : g.drivers) {
    MB_ASSERT(joint[d.joint] != nullptr, "a spatial driver on no ODE joint");
    if (g.joints[d.joint].type == SpatialJointType::kPrismatic) {
      dJointSetSliderParam(joint[d.joint], dParamFMax, kMotorFMax);
      continue;
    }
    MB_ASSERT(g.joints[d.joint].type == SpatialJointType::kRevolute, "a spatial driver on a joint that is not a hinge");
    dJointSetHingeParam(joint[d.joint], dParamFMax, kMotorFMax);
  }

  result.settings["model"] = "the spatial graph (" + Describe(g) + ")";
  result.settings["bodies"] = std::to_string(nb) +
                              " × dBody at the graph body's centre of mass (ODE's body origin), dMassSetParameters "
                              "with the full inertia tensor about it in the body's axes; the graph body's frame read "
                              "back as p = c − R com_B";
  result.settings["joints"] = std::to_string(balls) + " × dBall, " + std::to_string(hinges) +
                              " × dHinge" + (sliders > 0 ? ", " + std::to_string(sliders) + " × dSlider (prismatic, from the world or the line's body)" : std::string()) +
                              ": tree joints and loop closures alike (maximal coordinates: ODE has no tree); "
                              "a free joint is no joint";
  if (ball_closures + hinge_closures > 0) {
    std::string text = std::to_string(ball_closures) + " ball closure(s) as dBall (3 rows)";
    if (hinge_closures > 0)
      text += ", " + std::to_string(hinge_closures) +
              " revolute closure(s) as one dHinge (5 rows: the hinge's own constraints, none redundant by itself), not "
              "the two balls on the axis that graph.closures describes (6 rows of rank 5: one redundant row more for "
              "the solver)";
    result.settings["loop_closures"] = text;
  }
  result.settings["rotation_update"] =
      "ODE's defaults: infinitesimal (quaternion) orientation update, gyroscopic term on";
  if (!g.drivers.empty())
    result.settings["drivers"] = "hinge (or slider) motor, target speed (q_law(t+h) − q)/h from the joint angle (or "
                                 "travel) at the step's start, FMax " + Fmt(kMotorFMax);
  if (!g.springs.empty())
    result.settings["spring_dampers"] =
        std::to_string(g.springs.size()) +
        " × tension k (L − L0) + c L̇ + F0 from the step's starting positions and velocities, dBodyAddForceAtPos on "
        "each moving end before every step: explicit (ODE has no spring element)";
  if (!g.forces.empty())
    result.settings["forces"] = std::to_string(g.forces.size()) +
                                " × constant world force, dBodyAddForceAtPos at the body point's position at the "
                                "step's start, before every step";
  if (!g.torques.empty())
    result.settings["torques"] = std::to_string(g.torques.size()) + " × constant world torque, dBodyAddTorque before every step";
  if (!g.torsions.empty() || !g.law_loads.empty())
    result.settings["state_loads"] = std::to_string(g.torsions.size()) + " torsion(s) and " +
                                     std::to_string(g.law_loads.size()) +
                                     " load law(s) (SpatialStateLoads: q, q̇ observed from the bodies) from the step's "
                                     "starting state, dBodyAddForce + dBodyAddTorque at each centre of mass before every "
                                     "step: explicit";
  result.settings["accelerations"] = "(v_{n+1} − v_n)/h of the step ending at the sample; none at t0";
  result.settings["reactions"] = "not reported for spatial scenes yet";
  if (quick && g.Closures() > 0)
    result.messages.push_back("dWorldQuickStep on a loop: its iterations (a fixed number of SOR sweeps) leave a "
                              "closure's rows unconverged; the drift is fed back at ERP/h each step");

  std::vector<SpatialState> st(nb), prev(nb);
  SpatialStateLoads state_loads(g);
  std::vector<SpatialWrench> wrench;
  bool finite = true;
  auto read = [&] {
    for (size_t b = 0; b < nb; ++b) {
      st[b] = WorldState(body[b], g.bodies[b].com_B);
      finite = finite && Finite(st[b]);
    }
  };
  auto step = [&](double t, double h) {
    for (const SpatialDriverMap& d : g.drivers) {
      const SpatialGraphJoint& j = g.joints[d.joint];
      const double target = d.Position(t + h, g.t0);
      if (j.type == SpatialJointType::kPrismatic) {  // the travel from t0 along the axis, relative to the parent
        const double x = PrismaticTravel(j, j.parent < 0 ? SpatialState{} : st[j.parent], st[j.child]);
        dJointSetSliderParam(joint[d.joint], dParamVel, (target - x) / h);
        continue;
      }
      double now = HingeAngle(j.parent < 0 ? SpatialState{} : st[j.parent], st[j.child], j.axis_B);
      now += 2 * kPi * std::round((target - now) / (2 * kPi));
      dJointSetHingeParam(joint[d.joint], dParamVel, (target - now) / h);
    }
    for (const SpatialGraphForce& f : g.forces) {
      const V3 at = st[f.body].PointPos(f.at_B);
      dBodyAddForceAtPos(body[f.body], f.f_W.x(), f.f_W.y(), f.f_W.z(), at.x(), at.y(), at.z());
    }
    for (const SpatialGraphTorque& tq : g.torques)
      dBodyAddTorque(body[tq.body], tq.torque_W.x(), tq.torque_W.y(), tq.torque_W.z());
    // Torsions and load laws (SpatialStateLoads) from the step's starting state: explicit, as the springs.
    if (!state_loads.empty()) {
      state_loads.Evaluate(t, st, wrench);
      for (size_t b = 0; b < nb; ++b) {
        dBodyAddForce(body[b], wrench[b].force.x(), wrench[b].force.y(), wrench[b].force.z());
        dBodyAddTorque(body[b], wrench[b].torque.x(), wrench[b].torque.y(), wrench[b].torque.z());
      }
    }
    // Spring–dampers from the step's starting state (explicit); a fixed end takes nothing. ODE
    // clears its force accumulators after every step, so every load is added each time.
    for (const SpatialGraphSpring& sp : g.springs) {
      const V3 p_a = sp.body_a < 0 ? sp.at_a : st[sp.body_a].PointPos(sp.at_a);
      const V3 p_b = sp.body_b < 0 ? sp.at_b : st[sp.body_b].PointPos(sp.at_b);
      const V3 v_a = sp.body_a < 0 ? V3::Zero() : st[sp.body_a].PointVel(sp.at_a);
      const V3 v_b = sp.body_b < 0 ? V3::Zero() : st[sp.body_b].PointVel(sp.at_b);
      const V3 d = p_b - p_a;
      const double L = d.norm();
      if (!(L > 0)) continue;
      const V3 e = d / L;
      const V3 f_b = -(sp.stiffness * (L - sp.free_length) + sp.damping * e.dot(v_b - v_a) + sp.preload) * e;
      if (sp.body_b >= 0) dBodyAddForceAtPos(body[sp.body_b], f_b.x(), f_b.y(), f_b.z(), p_b.x(), p_b.y(), p_b.z());
      if (sp.body_a >= 0) dBodyAddForceAtPos(body[sp.body_a], -f_b.x(), -f_b.y(), -f_b.z(), p_a.x(), p_a.y(), p_a.z());
    }
    return (quick ? dWorldQuickStep(w, h) : dWorldStep(w, h)) != 0;
  };
  auto diverged = [&](const std::string& why) {
    result.status = Status::kDiverged;
    result.reason = why;
  };

  EnterPhase(options, Phase::kObservation);
  read();
  if (!finite) return diverged("ODE: non-finite state at t0");
  record(st, false);
  // The state is read between steps only when the next step needs it (a motor aimed from the
  // current angle, a force or a spring end at the current pose); otherwise before the last step of
  // each sample interval (for its (v_{n+1} − v_n)/h) and at the sample.
  const bool each_step = !g.drivers.empty() || !g.forces.empty() || !g.springs.empty() || !state_loads.empty();
  long steps = 0;
  double t = g.t0;
  for (size_t k = 1; k < times.size(); ++k) {
    EnterPhase(options, Phase::kIntegration);
    const auto [n, h] = StepsTo(t, times[k], h_max);
    for (long i = 0; i < n; ++i) {
      CheckBudgetInStep(options, i, times[k - 1]);
      if (i + 1 == n) {
        if (!each_step) read();
        prev = st;
      }
      if (!step(t, h)) return diverged("ODE step failed at t = " + Fmt(t));
      if (each_step) {
        read();
        // A state that blows up (an explicit force past its stability limit: A05's stiff dampers
        // at 1 ms) stops here as diverged, before its forces overflow and ODE's own assertion on
        // the orientation's normalization aborts the process.
        if (!finite || BlownUp(st, h, g.length_scale))
          return diverged("ODE: the state blew up by t = " + Fmt(t + h) + " s (h = " + Fmt(h) +
                          " s: a body turns or moves more than 100 rad or 100 length scales per step; explicit "
                          "forces past their stability limit, e.g. a stiff spring–damper's c/m · h ≫ 1)");
      }
      t += h;
      ++steps;
    }
    EnterPhase(options, Phase::kObservation);
    t = times[k];
    if (!each_step) read();
    if (!finite) return diverged("ODE: non-finite state by t = " + Fmt(t) + " s (h = " + Fmt(h) + " s)");
    for (size_t b = 0; b < nb; ++b) WorldAcceleration(st[b], prev[b], g.bodies[b].com_B, h);
    record(st, true);
  }
  result.settings["steps_taken"] = std::to_string(steps);
  result.steps = steps;
}

}  // namespace mechbench::engines::ode_internal
