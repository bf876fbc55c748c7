// The MuJoCo adapter's spatial path: a spatial scene's graph (spatial_graph.h) as MJCF, stepped
// through the samples and observed back as world body states.
#include "mujoco_adapter.h"

#include "mechbench/errors.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <functional>
#include <optional>
#include <sstream>

namespace mechbench::engines::mujoco_adapter {
namespace {

// The spatial graph as MJCF: nested bodies at their t0 poses (every frame has the world's axes
// at t0, so each child is at its origin's offset with no rotation), ball, hinge and free joints,
// inertia by fullinertia, loop closures as connect equalities (a revolute closure: two, on its
// axis), spring–dampers as spatial tendons, constant point forces and body torques through
// mjcb_passive at every forward pass.
std::string SpatialBodyName(int b) { return "b" + std::to_string(b); }
std::string SpatialJointName(int j) { return "j" + std::to_string(j); }

// A driven spatial joint's armature: `ratio` × the scene's inertia scale Σ (m L² + tr I_G).
double SpatialDriverArmature(const SpatialGraph& g, double ratio) {
  double s = 0;
  for (const SpatialGraphBody& b : g.bodies) s += b.mass * g.length_scale * g.length_scale + b.inertia_B.trace();
  return ratio * s;
}
// A driven slide joint's armature: `ratio` × the scene's mass Σ m.
double SpatialDriverSlideArmature(const SpatialGraph& g, double ratio) {
  double s = 0;
  for (const SpatialGraphBody& b : g.bodies) s += b.mass;
  return ratio * s;
}

std::string WriteSpatialMjcf(const SpatialGraph& g, const MujocoOptions& o, double axis_length) {
  std::ostringstream x;
  const std::string sref = Num(o.solref[0]) + " " + Num(o.solref[1]);
  std::string simp;
  for (int i = 0; i < 5; ++i) simp += (i ? " " : "") + Num(o.solimp[i]);
  x << "<mujoco model=\"mechbench-spatial\">\n"
    << "  <compiler angle=\"radian\" inertiafromgeom=\"false\"/>\n"
    << "  <option timestep=\"" << Num(o.step) << "\" integrator=\"" << o.integrator << "\" gravity=\"" << Vec(g.gravity)
    << "\" tolerance=\"" << Num(o.tolerance) << "\" iterations=\"" << o.iterations << "\">\n"
    << "    <flag contact=\"disable\"/>\n"
    << "  </option>\n"
    << "  <worldbody>\n";
  auto sites = [&](int body, const std::string& ind) {
    for (size_t k = 0; k < g.springs.size(); ++k) {
      const SpatialGraphSpring& sp = g.springs[k];
      for (int e = 0; e < 2; ++e)
        if ((e ? sp.body_b : sp.body_a) == body)
          x << ind << "<site name=\"" << SiteName(static_cast<int>(k), e) << "\" pos=\"" << Vec(e ? sp.at_b : sp.at_a)
            << "\"/>\n";
    }
  };
  sites(-1, "    ");
  std::vector<bool> driven(g.joints.size(), false);
  for (const SpatialDriverMap& d : g.drivers) driven[d.joint] = true;
  std::function<void(int, int)> emit = [&](int parent, int depth) {
    for (size_t ji = 0; ji < g.joints.size(); ++ji) {
      const SpatialGraphJoint& j = g.joints[ji];
      if (!j.in_tree || j.parent != parent) continue;
      const SpatialGraphBody& c = g.bodies[j.child];
      const Eigen::Vector3d pos = c.initial.p - (parent < 0 ? Eigen::Vector3d::Zero() : g.bodies[parent].initial.p);
      const std::string ind(2 * depth + 4, ' ');
      x << ind << "<body name=\"" << SpatialBodyName(j.child) << "\" pos=\"" << Vec(pos) << "\">\n";
      const std::string jn = SpatialJointName(static_cast<int>(ji));
      if (j.type == SpatialJointType::kFree)
        x << ind << "  <freejoint name=\"" << jn << "\"/>\n";
      else if (j.type == SpatialJointType::kBall)
        x << ind << "  <joint name=\"" << jn << "\" type=\"ball\" pos=\"" << Vec(j.at_child_B) << "\"/>\n";
      else if (j.type == SpatialJointType::kPrismatic)
        x << ind << "  <joint name=\"" << jn << "\" type=\"slide\" pos=\"" << Vec(j.at_child_B) << "\" axis=\""
          << Vec(j.axis_B) << "\""
          << (driven[ji] ? " armature=\"" + Num(SpatialDriverSlideArmature(g, o.driver_armature)) + "\"" : std::string())
          << "/>\n";
      else
        x << ind << "  <joint name=\"" << jn << "\" type=\"hinge\" pos=\"" << Vec(j.at_child_B) << "\" axis=\""
          << Vec(j.axis_B) << "\""
          << (driven[ji] ? " armature=\"" + Num(SpatialDriverArmature(g, o.driver_armature)) + "\"" : std::string())
          << "/>\n";
      const Eigen::Matrix3d& I = c.inertia_B;
      x << ind << "  <inertial pos=\"" << Vec(c.com_B) << "\" mass=\"" << Num(c.mass) << "\" fullinertia=\"" << Num(I(0, 0))
        << " " << Num(I(1, 1)) << " " << Num(I(2, 2)) << " " << Num(I(0, 1)) << " " << Num(I(0, 2)) << " " << Num(I(1, 2))
        << "\"/>\n";
      sites(j.child, ind + "  ");
      emit(j.child, depth + 1);
      x << ind << "</body>\n";
    }
  };
  emit(-1, 0);
  x << "  </worldbody>\n";
  if (!g.springs.empty()) {
    x << "  <tendon>\n";
    for (size_t k = 0; k < g.springs.size(); ++k) {
      const SpatialGraphSpring& sp = g.springs[k];
      WriteSpringTendon(x, sp, static_cast<int>(k));
    }
    x << "  </tendon>\n";
  }
  if (g.Closures() > 0) {
    x << "  <equality>\n";
    for (const SpatialGraphJoint& j : g.joints) {
      if (j.in_tree) continue;
      auto connect = [&](const Eigen::Vector3d& anchor) {
        x << "    <connect body1=\"" << SpatialBodyName(j.child) << "\"";
        if (j.parent >= 0) x << " body2=\"" << SpatialBodyName(j.parent) << "\"";
        x << " anchor=\"" << Vec(anchor) << "\" solref=\"" << sref << "\" solimp=\"" << simp << "\"/>\n";
      };
      connect(j.at_child_B);
      if (j.type == SpatialJointType::kRevolute) connect(j.at_child_B + axis_length * j.axis_B);
    }
    x << "  </equality>\n";
  }
  WritePreloadMotors(x, g.springs);
  x << "</mujoco>\n";
  return x.str();
}

// Constant world point forces and body torques of a spatial graph into qfrc_passive at every
// forward pass (a force at a body point: its moment about the centre of mass turns with the body).
class SpatialStageLoads final : public PassiveLoads {
 public:
  SpatialStageLoads(const SpatialGraph& g, const std::vector<int>& body_id)
      : g_(g), body_id_(body_id), state_loads_(g), st_(g.bodies.size()) {}
  bool empty() const { return g_.forces.empty() && g_.torques.empty() && state_loads_.empty(); }
  void AddTo(const mjModel* m, mjData* d) override {
    const mjtNum zero[3] = {0, 0, 0};
    if (!state_loads_.empty()) {
      // Torsions and load laws from this pass's poses and velocities (mj_objectVelocity reads cvel,
      // computed before mj_passive: at the centre of mass, moved to the frame origin).
      for (size_t b = 0; b < g_.bodies.size(); ++b) {
        const int id = body_id_[b];
        SpatialState& w = st_[b];
        mjtNum vel[6];
        mj_objectVelocity(m, d, mjOBJ_BODY, id, vel, 0);
        for (int i = 0; i < 3; ++i) {
          w.p[i] = d->xpos[3 * id + i];
          for (int k = 0; k < 3; ++k) w.R(i, k) = d->xmat[9 * id + 3 * i + k];
        }
        w.omega = {vel[0], vel[1], vel[2]};
        const Eigen::Vector3d r = Eigen::Vector3d(d->xipos[3 * id], d->xipos[3 * id + 1], d->xipos[3 * id + 2]) - w.p;
        w.v = Eigen::Vector3d(vel[3], vel[4], vel[5]) - w.omega.cross(r);
      }
      state_loads_.Evaluate(d->time, st_, wrench_);
      for (size_t b = 0; b < g_.bodies.size(); ++b) {
        const int id = body_id_[b];
        const mjtNum force[3] = {wrench_[b].force.x(), wrench_[b].force.y(), wrench_[b].force.z()};
        const mjtNum torque[3] = {wrench_[b].torque.x(), wrench_[b].torque.y(), wrench_[b].torque.z()};
        mj_applyFT(m, d, force, torque, d->xipos + 3 * id, id, d->qfrc_passive);
      }
    }
    for (const SpatialGraphForce& f : g_.forces) {
      const int id = body_id_[f.body];
      Eigen::Matrix3d R;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) R(i, j) = d->xmat[9 * id + 3 * i + j];
      const Eigen::Vector3d p = Eigen::Vector3d(d->xpos[3 * id], d->xpos[3 * id + 1], d->xpos[3 * id + 2]) + R * f.at_B;
      const mjtNum point[3] = {p.x(), p.y(), p.z()}, force[3] = {f.f_W.x(), f.f_W.y(), f.f_W.z()};
      mj_applyFT(m, d, force, zero, point, id, d->qfrc_passive);
    }
    for (const SpatialGraphTorque& t : g_.torques) {
      const int id = body_id_[t.body];
      const mjtNum torque[3] = {t.torque_W.x(), t.torque_W.y(), t.torque_W.z()};
      mj_applyFT(m, d, zero, torque, d->xipos + 3 * id, id, d->qfrc_passive);
    }
  }

 private:
  const SpatialGraph& g_;
  std::vector<int> body_id_;
  SpatialStateLoads state_loads_;
  std::vector<SpatialState> st_;
  std::vector<SpatialWrench> wrench_;
};

}  // namespace

// A spatial graph's free motion, stepped and recorded as the planar Simulate does (mj_step split
// at its forward pass, the step shortened evenly to land on every sample, warnings as divergence).
void SimulateSpatialGraph(const SpatialGraph& g, const std::vector<double>& times, const MujocoOptions& o,
                          const ControlValue& control, const SpatialRecorder& record, const RunOptions& options,
                          Result& result) {
  const double axis_length = SpatialGraphOptions{}.closure_axis_length * g.length_scale;
  const std::string xml = WriteSpatialMjcf(g, o, axis_length);
  ModelPtr m = LoadMjcf(xml, result);
  if (!m) return;
  DataPtr d(mj_makeData(m.get()));
  for (size_t k = 0, motor = 0; k < g.springs.size(); ++k) {
    const SpatialGraphSpring& sp = g.springs[k];
    m->tendon_lengthspring[mj_name2id(m.get(), mjOBJ_TENDON, SpringName(static_cast<int>(k)).c_str())] = RestLength(sp);
    if (PreloadByMotor(sp)) d->ctrl[motor++] = -sp.preload;
  }
  std::vector<int> body_id(g.bodies.size());
  for (size_t b = 0; b < g.bodies.size(); ++b)
    body_id[b] = mj_name2id(m.get(), mjOBJ_BODY, SpatialBodyName(static_cast<int>(b)).c_str());
  // Joint rates at t0 from the assembled body velocities. Every frame has the world's axes at t0,
  // so a ball's and a free joint's local angular velocity is the world one.
  for (size_t ji = 0; ji < g.joints.size(); ++ji) {
    const SpatialGraphJoint& j = g.joints[ji];
    if (!j.in_tree) continue;
    const int id = mj_name2id(m.get(), mjOBJ_JOINT, SpatialJointName(static_cast<int>(ji)).c_str());
    mjtNum* qv = d->qvel + m->jnt_dofadr[id];
    const SpatialState& c = g.bodies[j.child].initial;
    const Eigen::Vector3d w_rel = c.omega - (j.parent < 0 ? Eigen::Vector3d::Zero() : g.bodies[j.parent].initial.omega);
    if (j.type == SpatialJointType::kRevolute) {
      qv[0] = w_rel.dot(j.axis_B);
    } else if (j.type == SpatialJointType::kPrismatic) {  // the child's velocity along the axis, relative to the parent
      qv[0] = PrismaticRateAtT0(g, j);
    } else if (j.type == SpatialJointType::kBall) {
      for (int i = 0; i < 3; ++i) qv[i] = w_rel[i];
    } else {
      for (int i = 0; i < 3; ++i) qv[i] = c.v[i], qv[3 + i] = c.omega[i];
    }
  }
  d->time = g.t0;
  bool at_rest = !g.driven;
  for (const SpatialGraphBody& gb : g.bodies) at_rest = at_rest && gb.initial.v.norm() == 0 && gb.initial.omega.norm() == 0;
  // Drivers as in the planar path: the joint's qpos/qvel set to the law before every step, and
  // armature·q̈_law as its applied force.
  std::vector<int> drv_q(g.drivers.size()), drv_v(g.drivers.size());
  for (size_t k = 0; k < g.drivers.size(); ++k) {
    const int id = mj_name2id(m.get(), mjOBJ_JOINT, SpatialJointName(g.drivers[k].joint).c_str());
    drv_q[k] = m->jnt_qposadr[id];
    drv_v[k] = m->jnt_dofadr[id];
  }
  auto prescribe = [&](double t) {
    for (size_t k = 0; k < g.drivers.size(); ++k) {
      const SpatialDriverMap& dm = g.drivers[k];
      d->qpos[drv_q[k]] = dm.Position(t, g.t0);
      d->qvel[drv_v[k]] = dm.Rate(t, g.t0);
      d->qfrc_applied[drv_v[k]] = m->dof_armature[drv_v[k]] * dm.Acceleration(t, g.t0);
    }
  };
  if (!g.drivers.empty())
    result.settings["drivers"] = "prescribed: armature " + Fmt(o.driver_armature) +
                                 " × the scene's inertia Σ (m L² + tr I) on a driven hinge (× Σ m on a driven slide), qfrc_applied = armature·q̈_law, "
                                 "qpos/qvel set to the law before every step";
  const int closures = g.Closures();
  // As in the planar path: connect rows hold J q̈ to a reference acceleration without −J̇ q̇, so a
  // moving loop has no accelerations at t0; a tree alone (no equality) or a loop at rest has them.
  const bool acc_at_t0 = at_rest || closures == 0;

  result.settings["format"] = "MJCF written in memory (mjVFS), mj_loadXML; MuJoCo " + std::to_string(mj_version()) +
                              "; the spatial graph (" + Describe(g) + ")";
  result.settings["integrator"] = o.integrator;
  result.settings["step"] = "h ≤ " + ControlText(control, " s") +
                            " (mjOption.timestep), shortened evenly to end on every sample time";
  result.settings["precision"] = "double (mjtNum)";
  result.settings["solver"] = "Newton, tolerance " + Fmt(m->opt.tolerance) + ", " + std::to_string(m->opt.iterations) + " iterations";
  result.settings["joints"] = "ball, hinge, slide and free joints of the spatial graph's tree; inertia by fullinertia in each body's frame";
  if (closures > 0) {
    result.settings["solref"] = Join(o.solref.data(), 2) + " (equalities; MuJoCo default 0.02 1)";
    if (o.solref[0] > 0 && o.solref[0] < 2 * o.step && !(m->opt.disableflags & mjDSBL_REFSAFE))
      result.settings["solref"] += "; its time constant " + Fmt(o.solref[0]) + " s is below 2 h = " + Fmt(2 * o.step) +
                                   " s: MuJoCo's refsafe raises it to twice the step taken";
    result.settings["solimp"] = Join(o.solimp.data(), 5) + " (equalities; MuJoCo default 0.9 0.95 0.001 0.5 2)";
    result.settings["loop_closures"] = std::to_string(closures) + " × closure: a ball as one connect equality, a revolute " +
                                       "as two on its axis " + Fmt(axis_length) + " apart (soft; 6 rows of rank 5)";
  }
  const std::string per_pass = o.integrator == "RK4" ? "at each of RK4's four stages" : "at each Euler step's start (explicit)";
  if (!g.springs.empty())
    result.settings["spring_dampers"] = std::to_string(g.springs.size()) +
                                        " × spatial tendon between two sites, stiffness k, damping c, springlength "
                                        "L0 − F0/k (without stiffness: the preload as a tendon motor): passive forces";
  if (!g.forces.empty())
    result.settings["forces"] = std::to_string(g.forces.size()) + " × constant world force, mjcb_passive: mj_applyFT at "
                                "the body point into qfrc_passive, " + per_pass;
  if (!g.torques.empty())
    result.settings["torques"] = std::to_string(g.torques.size()) + " × constant world torque, mjcb_passive: mj_applyFT "
                                 "into qfrc_passive, " + per_pass;
  if (!g.torsions.empty() || !g.law_loads.empty())
    result.settings["state_loads"] = std::to_string(g.torsions.size()) + " torsion(s) and " +
                                     std::to_string(g.law_loads.size()) +
                                     " load law(s) (SpatialStateLoads: q, q̇ observed from the bodies), mjcb_passive: "
                                     "mj_applyFT of a wrench at each body's centre of mass into qfrc_passive, " + per_pass;
  result.settings["accelerations"] =
      std::string("at each sample from the forward pass that starts the next step, with mj_rnePostConstraint "
                  "(mj_objectAcceleration, gravity offset removed)") +
      (acc_at_t0 ? "" : "; none at t0: the loop starts moving, and MuJoCo's equality rows at t0 leave out J̇ q̇");
  result.settings["reactions"] = "not reported for spatial scenes yet";

  SpatialStageLoads loads(g, body_id);
  std::optional<PassiveCallbackScope> passive_scope;
  if (!loads.empty()) passive_scope.emplace(m.get(), &loads);
  MB_ASSERT(m->opt.integrator == mjINT_EULER || m->opt.integrator == mjINT_RK4,
            "the MuJoCo adapter advances Euler and RK4 only");
  auto forward = [&] {
    mj_checkPos(m.get(), d.get());
    mj_checkVel(m.get(), d.get());
    mj_forward(m.get(), d.get());
    mj_checkAcc(m.get(), d.get());
  };
  auto advance = [&] {
    if (m->opt.integrator == mjINT_RK4)
      mj_RungeKutta(m.get(), d.get(), 4);
    else
      mj_Euler(m.get(), d.get());
  };
  bool first_sample = true;
  auto observe = [&]() -> bool {
    mj_rnePostConstraint(m.get(), d.get());
    std::vector<SpatialState> st(g.bodies.size());
    for (size_t b = 0; b < g.bodies.size(); ++b) {
      const int id = body_id[b];
      SpatialState& w = st[b];
      mjtNum vel[6], acc[6];
      mj_objectVelocity(m.get(), d.get(), mjOBJ_BODY, id, vel, 0);
      mj_objectAcceleration(m.get(), d.get(), mjOBJ_BODY, id, acc, 0);
      for (int i = 0; i < 3; ++i) {
        w.p[i] = d->xpos[3 * id + i];
        for (int k = 0; k < 3; ++k) w.R(i, k) = d->xmat[9 * id + 3 * i + k];
      }
      // At the centre of mass (xipos), cacc with −gravity: moved to the frame origin, gravity added back.
      w.omega = {vel[0], vel[1], vel[2]};
      w.alpha = {acc[0], acc[1], acc[2]};
      const Eigen::Vector3d r = Eigen::Vector3d(d->xipos[3 * id], d->xipos[3 * id + 1], d->xipos[3 * id + 2]) - w.p;
      w.v = Eigen::Vector3d(vel[3], vel[4], vel[5]) - w.omega.cross(r);
      w.a = Eigen::Vector3d(acc[3], acc[4], acc[5]) + g.gravity - w.alpha.cross(r) - w.omega.cross(w.omega.cross(r));
      if (!w.p.allFinite() || !w.R.allFinite() || !w.v.allFinite() || !w.omega.allFinite() || !w.a.allFinite()) return false;
    }
    record(st, !first_sample || acc_at_t0);
    first_sample = false;
    return true;
  };
  EnterPhase(options, Phase::kObservation);
  prescribe(g.t0);
  forward();
  if (!observe()) {
    result.status = Status::kDiverged;
    result.reason = "MuJoCo: non-finite state at t0";
    return;
  }
  StepThroughSamples(m.get(), d.get(), times, o.step, options, prescribe, forward, advance, observe, result);
}

}  // namespace mechbench::engines::mujoco_adapter
