#include "mujoco_adapter.h"

#include "mechbench/errors.h"
#include "mechbench/numeric/reactions.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <memory>
#include <optional>
#include <sstream>
#include <utility>

namespace mechbench::engines {
namespace mujoco_adapter {

ModelPtr LoadMjcf(const std::string& xml, Result& result) {
  std::unique_ptr<mjVFS, VfsDeleter> vfs(new mjVFS);
  mj_defaultVFS(vfs.get());
  const char* file = "mechbench.xml";
  if (mj_makeEmptyFileVFS(vfs.get(), file, static_cast<int>(xml.size())) != 0) {
    result.status = Status::kFailed;
    result.reason = "MuJoCo: cannot make the in-memory MJCF file";
    return nullptr;
  }
  std::memcpy(vfs->filedata[mj_findFileVFS(vfs.get(), file)], xml.data(), xml.size());
  char error[1000] = "";
  ModelPtr m(mj_loadXML(file, vfs.get(), error, sizeof error));
  if (!m) {
    result.status = Status::kFailed;
    result.reason = std::string("MuJoCo rejected the generated MJCF: ") + error;
  }
  return m;
}

thread_local PassiveCallbackScope::Context PassiveCallbackScope::current_;

void SilenceWarnings() {
  static const bool silenced = [] {
    mju_user_warning = [](const char*) {};
    return true;
  }();
  (void)silenced;
}

}  // namespace mujoco_adapter

namespace {

using namespace mujoco_adapter;  // NOLINT: the adapter's own shared parts
// Whether the graph is mounted on its turning frame's platform (Graph::platform).
bool OnPlatform(const Graph& g) { return g.platform && !PlatformLoadsReason(g); }
const char* kPlatformBody = "platform";
const char* kPlatformJoint = "platform_hinge";

std::string BodyName(int b) { return "b" + std::to_string(b); }
std::string JointName(int j) { return "j" + std::to_string(j); }
std::string TendonName(int j) { return "w" + std::to_string(j); }

// Armature of a driven joint: `ratio` × the scene's inertia scale in that joint's units.
double DriverArmature(const Graph& g, const GraphJoint& j, double ratio) {
  double s = 0;
  for (const GraphBody& b : g.bodies)
    s += j.type == PairType::kPrismatic ? b.mass : b.mass * g.length_scale * g.length_scale + b.inertia_com;
  return ratio * s;
}

// The platform hinge's armature: as a driven hinge's, about the whole mechanism (its own inertia,
// 1 kg·length², is a stated placeholder: the hinge is prescribed).
double PlatformArmature(const Graph& g, double ratio) {
  GraphJoint hinge;
  hinge.type = PairType::kRevolute;
  return DriverArmature(g, hinge, ratio);
}

// A torsion (Graph::torsions) on a tree hinge between its two bodies becomes that hinge's own
// stiffness, damping and spring reference (MuJoCo's passive force, recomputed in every forward
// pass: at each RK4 stage, and Euler integrates joint damping implicitly). With the hinge's q zero
// at t0 and θ = θ(t0) + s q (s = ±σ, as the hinge's child is θ's vector or its reference), the
// generalized force on q, s T, is −k (q − q_ref) − c q̇ with q_ref = s (θ0 − θ(t0) + T0/k). A
// torsion with a preload and no stiffness (nothing to fold it into), or on bodies that no tree
// hinge joins, stays with StateLoads (explicit).
struct HingeTorsion {
  double stiffness = 0, damping = 0, springref = 0;
  int count = 0;
};
std::vector<HingeTorsion> HingeTorsions(const Graph& g, std::vector<bool>* on_hinge = nullptr) {
  std::vector<HingeTorsion> out(g.joints.size());
  if (on_hinge) on_hinge->assign(g.torsions.size(), false);
  std::vector<double> weighted(g.joints.size(), 0.0);
  for (size_t k = 0; k < g.torsions.size(); ++k) {
    const GraphTorsion& ts = g.torsions[k];
    if (ts.stiffness <= 0 && ts.preload != 0) continue;
    for (size_t ji = 0; ji < g.joints.size(); ++ji) {
      const GraphJoint& j = g.joints[ji];
      if (!j.in_tree || j.type != PairType::kRevolute) continue;
      double sign = 0;
      if (j.child == ts.body_vec && j.parent == ts.body_ref) sign = ts.sigma;
      if (j.child == ts.body_ref && j.parent == ts.body_vec) sign = -ts.sigma;
      if (sign == 0) continue;
      const double th_t0 = ts.offset + ts.sigma * (g.bodies[ts.body_vec].initial.angle -
                                                   (ts.body_ref < 0 ? 0.0 : g.bodies[ts.body_ref].initial.angle));
      const double ref = ts.stiffness > 0 ? sign * (ts.free_angle - th_t0 + ts.preload / ts.stiffness) : 0.0;
      out[ji].stiffness += ts.stiffness;
      out[ji].damping += ts.damping;
      weighted[ji] += ts.stiffness * ref;
      out[ji].count++;
      if (on_hinge) (*on_hinge)[k] = true;
      break;
    }
  }
  for (size_t ji = 0; ji < g.joints.size(); ++ji)
    if (out[ji].stiffness > 0) out[ji].springref = weighted[ji] / out[ji].stiffness;
  return out;
}

// The MJCF text of the graph.
std::string WriteMjcf(const Graph& g, const MujocoOptions& o) {
  const std::vector<HingeTorsion> hinge_torsion = HingeTorsions(g);
  std::ostringstream x;
  const std::string sref = Num(o.solref[0]) + " " + Num(o.solref[1]);
  std::string simp;
  for (int i = 0; i < 5; ++i) simp += (i ? " " : "") + Num(o.solimp[i]);
  x << "<mujoco model=\"mechbench\">\n"
    << "  <compiler angle=\"radian\" inertiafromgeom=\"false\"/>\n"
    << "  <option timestep=\"" << Num(o.step) << "\" integrator=\"" << o.integrator << "\" gravity=\""
    << (OnPlatform(g) ? Vec(g.platform->gravity_W) : Vec(g.gravity)) << "\" tolerance=\"" << Num(o.tolerance) << "\" iterations=\"" << o.iterations << "\">\n"
    << "    <flag contact=\"disable\"/>\n"
    << "  </option>\n"
    << "  <worldbody>\n";
  std::vector<bool> driven(g.joints.size(), false);
  for (const DriverMap& d : g.drivers) driven[d.joint] = true;
  // A spring's ends as sites on their bodies (body frame), or in the world for a fixed end.
  auto sites = [&](int body, const std::string& ind) {
    for (size_t k = 0; k < g.springs.size(); ++k) {
      const GraphSpring& sp = g.springs[k];
      for (int e = 0; e < 2; ++e)
        if ((e ? sp.body_b : sp.body_a) == body)
          x << ind << "<site name=\"" << SiteName(static_cast<int>(k), e) << "\" pos=\"" << Vec(e ? sp.at_b : sp.at_a)
            << "\"/>\n";
    }
  };
  sites(-1, "    ");
  // Nested bodies: each tree joint's child inside its parent, at the t0 pose relative to it.
  std::function<void(int, int)> emit = [&](int parent, int depth) {
    for (size_t ji = 0; ji < g.joints.size(); ++ji) {
      const GraphJoint& j = g.joints[ji];
      if (!j.in_tree || j.parent != parent) continue;
      const GraphBody& c = g.bodies[j.child];
      const PlanarState p = parent < 0 ? PlanarState{} : g.bodies[parent].initial;
      const Eigen::Vector2d pos = Rotate(-p.angle, c.initial.p - p.p);
      const double dth = c.initial.angle - p.angle;
      const std::string ind(2 * depth + 4, ' ');
      x << ind << "<body name=\"" << BodyName(j.child) << "\" pos=\"" << Vec(pos) << "\" quat=\"" << Num(std::cos(dth / 2))
        << " 0 0 " << Num(std::sin(dth / 2)) << "\">\n";
      x << ind << "  <joint name=\"" << JointName(static_cast<int>(ji)) << "\" ";
      if (j.type == PairType::kRevolute)
        x << "type=\"hinge\" pos=\"" << Vec(j.at_child_B) << "\" axis=\"0 0 1\"";
      else
        x << "type=\"slide\" pos=\"" << Vec(j.at_child_B) << "\" axis=\"" << Vec(Rotate(-j.angle0, j.axis_parent_B)) << "\"";
      if (driven[ji]) x << " armature=\"" << Num(DriverArmature(g, j, o.driver_armature)) << "\"";
      if (hinge_torsion[ji].count)
        x << " stiffness=\"" << Num(hinge_torsion[ji].stiffness) << "\" damping=\"" << Num(hinge_torsion[ji].damping)
          << "\" springref=\"" << Num(hinge_torsion[ji].springref) << "\"";
      x << "/>\n";
      const double I = c.inertia_com > 0 ? c.inertia_com : 1e-12;
      x << ind << "  <inertial pos=\"" << Vec(c.com_B) << "\" mass=\"" << Num(c.mass) << "\" diaginertia=\"" << Num(I / 2)
        << " " << Num(I / 2) << " " << Num(I) << "\"/>\n";
      sites(j.child, ind + "  ");
      emit(j.child, depth + 1);
      x << ind << "</body>\n";
    }
  };
  if (OnPlatform(g)) {
    // The turning frame's platform: a body whose frame is the plane's at t0, on a hinge about the
    // file's axis (in the platform's frame), driven as the drivers are; the mechanism inside it.
    const GraphPlatform& P = *g.platform;
    const Eigen::Quaterniond q(P.R0);
    x << "    <body name=\"" << kPlatformBody << "\" pos=\"" << Vec(P.origin) << "\" quat=\"" << Num(q.w()) << " "
      << Num(q.x()) << " " << Num(q.y()) << " " << Num(q.z()) << "\">\n"
      << "      <joint name=\"" << kPlatformJoint << "\" type=\"hinge\" pos=\""
      << Vec(Eigen::Vector3d(P.R0.transpose() * (P.axis_point - P.origin))) << "\" axis=\""
      << Vec(Eigen::Vector3d(P.R0.transpose() * P.axis)) << "\" armature=\"" << Num(PlatformArmature(g, o.driver_armature))
      << "\"/>\n"
      << "      <inertial pos=\"0 0 0\" mass=\"1\" diaginertia=\"1 1 1\"/>\n";
    emit(-1, 2);
    x << "    </body>\n";
  } else {
    emit(-1, 0);
  }
  x << "  </worldbody>\n";
  // A mesh on a carrier couples three joints: a fixed tendon L = q_a + (z_b/Z_a) q_b − (1 + z_b/Z_a) q_c
  // (Willis' relation Z_a (φ_a − φ_c) + z_b (φ_b − φ_c) = 0 divided by Z_a; every q zero at t0).
  bool tendons = false;
  // Spring–dampers: a spatial tendon through the two sites. Its rest length is set again on the
  // compiled model (MuJoCo replaces a negative springlength by the length at qpos0).
  for (size_t k = 0; k < g.springs.size(); ++k) {
    const GraphSpring& sp = g.springs[k];
    if (!tendons) x << "  <tendon>\n";
    tendons = true;
    WriteSpringTendon(x, sp, static_cast<int>(k));
  }
  for (size_t ji = 0; ji < g.joints.size(); ++ji) {
    const GraphJoint& j = g.joints[ji];
    if (j.type != PairType::kGear || j.carrier < 0) continue;
    if (!tendons) x << "  <tendon>\n";
    tendons = true;
    const double k = j.z_b / j.z_a;
    x << "    <fixed name=\"" << TendonName(static_cast<int>(ji)) << "\">"
      << "<joint joint=\"" << JointName(g.TreeJointOf(j.parent)) << "\" coef=\"1\"/>"
      << "<joint joint=\"" << JointName(g.TreeJointOf(j.child)) << "\" coef=\"" << Num(k) << "\"/>"
      << "<joint joint=\"" << JointName(g.TreeJointOf(j.carrier)) << "\" coef=\"" << Num(-(1 + k)) << "\"/></fixed>\n";
  }
  if (tendons) x << "  </tendon>\n";
  x << "  <equality>\n";
  for (const GraphJoint& j : g.joints) {
    if (j.in_tree) continue;
    if (j.type == PairType::kRevolute) {
      x << "    <connect body1=\"" << BodyName(j.child) << "\"";
      if (j.parent >= 0) x << " body2=\"" << BodyName(j.parent) << "\"";
      else if (OnPlatform(g)) x << " body2=\"" << kPlatformBody << "\"";
      x << " anchor=\"" << Vec(j.at_child_B) << "\"";
    } else if (j.type == PairType::kGear && j.carrier >= 0) {
      // The tendon's length held at its t0 value (0): tendon2 omitted, polycoef[0] = 0.
      x << "    <tendon tendon1=\"" << TendonName(static_cast<int>(&j - g.joints.data())) << "\" polycoef=\"0 0 0 0 0\"";
    } else if (j.type == PairType::kGear) {
      // q_a = −(z_b / Z_a) q_b, i.e. Z_a q_a + z_b q_b = 0 (both zero at t0).
      x << "    <joint joint1=\"" << JointName(g.TreeJointOf(j.parent)) << "\" joint2=\"" << JointName(g.TreeJointOf(j.child))
        << "\" polycoef=\"0 " << Num(-j.z_b / j.z_a) << " 0 0 0\"";
    } else {
      continue;  // prismatic closures are refused by EngineReason
    }
    x << " solref=\"" << sref << "\" solimp=\"" << simp << "\"/>\n";
  }
  // Couplings (a rack and pinion, a belt): q_b = ratio q_a on two tree joints, slide or hinge,
  // both zero at qpos0 (t0).
  for (const CouplingMap& c : g.couplings)
    x << "    <joint joint1=\"" << JointName(c.joint_b) << "\" joint2=\"" << JointName(c.joint_a) << "\" polycoef=\"0 "
      << Num(c.ratio) << " 0 0 0\" solref=\"" << sref << "\" solimp=\"" << simp << "\"/>\n";
  x << "  </equality>\n";
  WritePreloadMotors(x, g.springs);
  x << "</mujoco>\n";
  return x.str();
}

class StageLoads final : public PassiveLoads {
 public:
  // StateLoads keeps a pointer to its graph: explicit_, a member built before loads_, is `g` with
  // the torsions no hinge carries.
  StageLoads(const Graph& g, std::vector<int> body_id, const std::vector<bool>& on_hinge)
      : g_(g), body_id_(std::move(body_id)), explicit_(WithoutHingeTorsions(g, on_hinge)), loads_(explicit_),
        st_(g.bodies.size()) {}
  static Graph WithoutHingeTorsions(const Graph& g, const std::vector<bool>& on_hinge) {
    Graph out = g;
    out.torsions.clear();
    for (size_t k = 0; k < g.torsions.size(); ++k)
      if (!on_hinge[k]) out.torsions.push_back(g.torsions[k]);
    return out;
  }
  StageLoads(const StageLoads&) = delete;
  StageLoads& operator=(const StageLoads&) = delete;
  bool empty() const { return g_.forces.empty() && g_.torques.empty() && loads_.empty(); }
  // The world force on each MuJoCo body at the last evaluation [kg·length/s²] (reactions at t0).
  const std::vector<Eigen::Vector2d>& force_on_body() const { return force_on_body_; }

  // Adds the loads at d's stage to d->qfrc_passive.
  void AddTo(const mjModel* m, mjData* d) override {
    const double t = d->time;
    force_on_body_.assign(m->nbody, Eigen::Vector2d::Zero());
    const mjtNum zero[3] = {0, 0, 0};
    auto angle_of = [&](int b) {
      const mjtNum* R = d->xmat + 9 * body_id_[b];
      return std::atan2(R[3], R[0]);
    };
    auto torque = [&](int b, double T) {
      if (T == 0) return;
      const mjtNum tz[3] = {0, 0, T};
      mj_applyFT(m, d, zero, tz, d->xipos + 3 * body_id_[b], body_id_[b], d->qfrc_passive);
    };
    auto force = [&](int b, const Eigen::Vector2d& at_B, double angle, const Eigen::Vector2d& f_W) {
      const int id = body_id_[b];
      const Eigen::Vector2d r = Rotate(angle, at_B);
      const mjtNum point[3] = {d->xpos[3 * id] + r.x(), d->xpos[3 * id + 1] + r.y(), d->xpos[3 * id + 2]};
      const mjtNum f[3] = {f_W.x(), f_W.y(), 0};
      mj_applyFT(m, d, f, zero, point, id, d->qfrc_passive);
      force_on_body_[id] += f_W;
    };
    for (const GraphForce& f : g_.forces) {
      const double th = angle_of(f.body);
      force(f.body, f.at_B, th, f.At(t, th));
    }
    for (const GraphTorque& tq : g_.torques) torque(tq.body, tq.At(t));
    if (loads_.empty()) return;
    // The bodies' poses and frame-origin velocities from this pass (mj_objectVelocity reads cvel:
    // at the centre of mass, moved to the origin).
    for (size_t b = 0; b < g_.bodies.size(); ++b) {
      const int id = body_id_[b];
      mjtNum vel[6];
      mj_objectVelocity(m, d, mjOBJ_BODY, id, vel, 0);
      PlanarState& ps = st_[b];
      ps.p = {d->xpos[3 * id], d->xpos[3 * id + 1]};
      ps.angle = angle_of(static_cast<int>(b));
      ps.omega = vel[2];
      const Eigen::Vector2d r = Rotate(ps.angle, g_.bodies[b].com_B);
      ps.v = Eigen::Vector2d(vel[3], vel[4]) - ps.omega * Eigen::Vector2d(-r.y(), r.x());
    }
    loads_.Evaluate(t, st_, load_torque_, load_force_);
    for (size_t b = 0; b < g_.bodies.size(); ++b) torque(static_cast<int>(b), load_torque_[b]);
    for (size_t k = 0; k < g_.state_forces.size(); ++k) {
      const GraphForce& f = g_.state_forces[k];
      force(f.body, f.at_B, st_[f.body].angle, load_force_[k]);
    }
  }

 private:
  const Graph& g_;
  std::vector<int> body_id_;  // graph body → MuJoCo body
  Graph explicit_;
  StateLoads loads_;
  std::vector<PlanarState> st_;
  std::vector<double> load_torque_;
  std::vector<Eigen::Vector2d> load_force_;
  std::vector<Eigen::Vector2d> force_on_body_;
};

class MujocoMethod final : public EngineMethod {
 public:
  explicit MujocoMethod(MujocoOptions o)
      : EngineMethod(o.name, "MuJoCo " + std::to_string(mj_version()) + ": MJCF tree, connect/joint equalities (soft), " +
                                 o.integrator + ", step " + Fmt(o.step) + " s"),
        o_(std::move(o)) {}
  Control control() const override { return Control::kStep; }
  double default_control() const override { return o_.step; }

 protected:
  std::optional<std::string> PlatformReason(const Graph& g) const override { return PlatformLoadsReason(g); }

  bool SimulatesSpatial() const override { return true; }
  void SimulateSpatial(const SpatialGraph& g, const std::vector<double>& times, const ControlValue& control,
                       const SpatialRecorder& record, const RunOptions& options, Result& result) const override {
    SilenceWarnings();
    MujocoOptions o = o_;
    o.step = control.value;
    SimulateSpatialGraph(g, times, o, control, record, options, result);
  }

  std::optional<std::string> EngineReason(const Model&, const Graph& g) const override {
    for (const GraphJoint& j : g.joints) {
      if (!j.in_tree && j.type == PairType::kPrismatic)
        return "joint " + j.name + ": a prismatic loop closure has no MuJoCo equality (weld fixes all six)";
    }
    return std::nullopt;
  }

  void Simulate(const Graph& g, const std::vector<double>& times, const ControlValue& control, const Recorder& record,
                const RunOptions& options, Result& result) const override {
    SilenceWarnings();
    // The run's options: the variant's own with its step (mjOption.timestep in the MJCF) replaced
    // by the run's, the variant's or a RunOptions override. Everything else stays the variant's.
    MujocoOptions o = o_;
    o.step = control.value;
    const std::string xml = WriteMjcf(g, o);
    std::vector<bool> on_hinge;  // per torsion: built as its hinge's stiffness and damping
    (void)HingeTorsions(g, &on_hinge);
    ModelPtr m = LoadMjcf(xml, result);
    if (!m) return;
    DataPtr d(mj_makeData(m.get()));
    for (size_t k = 0, motor = 0; k < g.springs.size(); ++k) {
      const GraphSpring& sp = g.springs[k];
      m->tendon_lengthspring[mj_name2id(m.get(), mjOBJ_TENDON, SpringName(static_cast<int>(k)).c_str())] = RestLength(sp);
      if (PreloadByMotor(sp)) d->ctrl[motor++] = -sp.preload;
    }
    // MuJoCo's equality rows hold J q̈ to the reference acceleration −b J q̇ − k r (solref), which
    // is 0 on a state that satisfies the constraints, without the −J̇ q̇ a rigid closure needs: at
    // t0 the forward pass's q̈ is that of a loop whose velocity-product terms are missing (a
    // drag-link's coupler gets α ≈ 0 against 0.78 rad/s²), a start-up transient that the motion's
    // own accelerations do not have once the rows have a velocity error to act on. Where J̇ q̇ ≠ 0
    // at t0 (a driven scene, or a free one that starts moving), t0 has no accelerations (as ODE and
    // Bullet); a free scene at rest keeps MuJoCo's own, softened by solimp as its constraint forces are.
    bool at_rest = !g.driven;
    for (const GraphBody& gb : g.bodies) at_rest = at_rest && gb.initial.v.norm() == 0 && gb.initial.omega == 0;

    std::vector<int> body_id(g.bodies.size());
    for (size_t b = 0; b < g.bodies.size(); ++b) body_id[b] = mj_name2id(m.get(), mjOBJ_BODY, BodyName(static_cast<int>(b)).c_str());
    std::vector<int> qadr(g.joints.size(), -1), dadr(g.joints.size(), -1);
    for (size_t ji = 0; ji < g.joints.size(); ++ji) {
      if (!g.joints[ji].in_tree) continue;
      const int id = mj_name2id(m.get(), mjOBJ_JOINT, JointName(static_cast<int>(ji)).c_str());
      qadr[ji] = m->jnt_qposadr[id];
      dadr[ji] = m->jnt_dofadr[id];
      d->qvel[dadr[ji]] = InitialJointRate(g, g.joints[ji]);
    }
    d->time = g.t0;

    int closures = 0, gears = 0, willis = 0;
    for (const GraphJoint& j : g.joints)
      if (!j.in_tree) (j.type == PairType::kGear ? (j.carrier >= 0 ? willis : gears) : closures)++;
    result.settings["format"] = "MJCF written in memory (mjVFS), mj_loadXML; MuJoCo " + std::to_string(mj_version());
    result.settings["integrator"] = o.integrator;
    result.settings["step"] = "h ≤ " + ControlText(control, " s") +
                              " (mjOption.timestep), shortened evenly to end on every sample time";
    result.settings["precision"] = "double (mjtNum)";
    result.settings["solref"] = Join(o.solref.data(), 2) + " (equalities; MuJoCo default 0.02 1)";
    // MuJoCo's integrator safety (mjDSBL_REFSAFE not set) raises a time constant below 2 h to 2 h.
    if (o.solref[0] > 0 && o.solref[0] < 2 * o.step && !(m->opt.disableflags & mjDSBL_REFSAFE))
      result.settings["solref"] += "; its time constant " + Fmt(o.solref[0]) + " s is below 2 h = " + Fmt(2 * o.step) +
                                   " s: MuJoCo's refsafe raises it to twice the step taken";
    result.settings["solimp"] = Join(o.solimp.data(), 5) + " (equalities; MuJoCo default 0.9 0.95 0.001 0.5 2)";
    result.settings["solver"] = "Newton, tolerance " + Fmt(m->opt.tolerance) + ", " + std::to_string(m->opt.iterations) + " iterations";
    result.settings["loop_closures"] = std::to_string(closures) + " × connect equality (soft)";
    if (gears || willis) {
      std::string text;
      if (gears) text = std::to_string(gears) + " × joint equality, polycoef (soft)";
      if (willis)
        text += (gears ? "; " : "") + std::to_string(willis) +
                " × fixed tendon q_a + (z_b/Z_a) q_b − (1 + z_b/Z_a) q_carrier (Willis' relation over the three "
                "members' absolute rotations) held at its t0 length by a tendon equality (soft)";
      result.settings["gears"] = text;
    }
    if (!g.couplings.empty()) {
      // Each coupling's own ratio (its polycoef "0 ratio 0 0 0"), not the template.
      std::string ratios;
      for (const CouplingMap& c : g.couplings)
        ratios += (ratios.empty() ? "" : ", ") + c.name + ": ratio " + Fmt(c.ratio, 10);
      result.settings["couplings"] = std::to_string(g.couplings.size()) +
                                     " × joint equality joint1 = ratio · joint2 (" + ratios +
                                     "; a slide–hinge pair for a rack; soft, with the equalities' solref/solimp)";
    }
    result.settings["planarity"] = "by construction: hinge joints about z, slide joints along in-plane axes";
    result.settings["drivers"] = "prescribed: armature " + Fmt(o.driver_armature) +
                                 " × the scene's inertia on the driven joint, qfrc_applied = armature·q̈_law, qpos/qvel set to "
                                 "the law before every step";
    // Where StageLoads' loads are evaluated: every forward pass, i.e. each of RK4's stages.
    const std::string per_pass = o.integrator == "RK4" ? "at each of RK4's four stages (its time, qpos and qvel)"
                                                       : "at each Euler step's start (explicit)";
    if (!g.forces.empty())
      result.settings["forces"] = "mjcb_passive: mj_applyFT at the point into qfrc_passive, " + per_pass +
                                  (HasVaryingForces(g) ? "; a law of t or a body frame: value and direction there too" : "");
    if (!g.springs.empty()) {
      int motors = 0;
      for (const GraphSpring& sp : g.springs) motors += PreloadByMotor(sp);
      result.settings["spring_dampers"] =
          std::to_string(g.springs.size()) +
          " × spatial tendon between two sites, stiffness k, damping c, springlength L0 − F0/k (the preload folded "
          "into the rest length)" +
          (motors ? "; " + std::to_string(motors) + " without stiffness: the preload as a tendon motor at ctrl = −F0" : "") +
          ": passive forces (qfrc_passive), explicit in " + o.integrator +
          " (MuJoCo treats stiffness explicitly always, and its Euler makes joint damping implicit, not tendon damping)";
    }
    if (!g.torques.empty())
      result.settings["torques"] = std::to_string(g.torques.size()) + " × mjcb_passive: mj_applyFT torque (z) into qfrc_passive, " + per_pass;
    if (!g.torsions.empty()) {
      const size_t n_hinge = static_cast<size_t>(std::count(on_hinge.begin(), on_hinge.end(), true));
      std::string text;
      if (n_hinge)
        text = std::to_string(n_hinge) + " × the hinge's own stiffness k, damping c and springref (θ0 + T0/k on the "
               "hinge's angle): passive force, recomputed at every " + o.integrator + " stage" +
               (o.integrator == "Euler" ? " with the damping implicit" : "");
      if (n_hinge < g.torsions.size())
        text += (text.empty() ? "" : "; ") + std::to_string(g.torsions.size() - n_hinge) +
                " × T = −k (θ − θ0) − c θ̇ + T0 from the bodies' relative rotation and rate, mjcb_passive: mj_applyFT "
                "torque (z, ±) on both bodies into qfrc_passive, " + per_pass + " (no tree hinge joins them, or a "
                "preload without stiffness)";
      result.settings["torsions"] = text;
    }
    if (!g.state_torques.empty())
      result.settings["state_torques"] = std::to_string(g.state_torques.size()) +
                                         " × mjcb_passive: mj_applyFT torque (z) into qfrc_passive, the law of q., qd. "
                                         "from the scene's coordinates observed " + per_pass;
    if (!g.state_springs.empty())
      result.settings["state_springs"] =
          std::to_string(g.state_springs.size()) + " × spring–damper with laws (no tendon: its stiffness and rest "
          "length are constants): mjcb_passive, tension k (L − L0) + c L̇ + F0 with the laws of t, q., qd. from the "
          "scene's coordinates observed " + per_pass + ", mj_applyFT on each moving end into qfrc_passive";
    if (StateForceLaws(g) > 0)
      result.settings["state_forces"] = std::to_string(StateForceLaws(g)) +
                                        " × mjcb_passive: mj_applyFT at the point into qfrc_passive, the law of q., qd. "
                                        "from the scene's coordinates observed " + per_pass +
                                        " (direction too, in a body frame)";
    result.settings["accelerations"] =
        std::string("at each sample from the forward pass that starts the next step, with mj_rnePostConstraint "
                    "(mj_objectAcceleration, gravity offset removed)") +
        (at_rest ? "" : "; none at t0: the scene starts moving, and MuJoCo's equality rows at t0 leave out J̇ q̇");
    result.settings["stepping"] = "mj_step's sequence (mj_checkPos, mj_checkVel, mj_forward, mj_checkAcc, then " +
                                  std::string(m->opt.integrator == mjINT_RK4 ? "mj_RungeKutta" : "mj_Euler") +
                                  "), split so that the forward pass at a sample is shared by its observation and the next step";

    std::vector<double> armature(g.drivers.size());
    for (size_t k = 0; k < g.drivers.size(); ++k) armature[k] = m->dof_armature[dadr[g.drivers[k].joint]];
    // The platform's hinge (Graph::platform), prescribed like a driver: q = Ω (t − t0), q̇ = Ω, q̈ = 0.
    const bool on_platform = OnPlatform(g);
    int platform_id = -1, platform_q = -1, platform_d = -1;
    if (on_platform) {
      platform_id = mj_name2id(m.get(), mjOBJ_BODY, kPlatformBody);
      const int jid = mj_name2id(m.get(), mjOBJ_JOINT, kPlatformJoint);
      platform_q = m->jnt_qposadr[jid];
      platform_d = m->jnt_dofadr[jid];
      result.settings["platform"] = "a body around the mechanism on a hinge about the frame's axis, prescribed as the "
                                    "drivers are (qpos/qvel set to Ω (t − t0), Ω before every step, armature " +
                                    Fmt(m->dof_armature[platform_d]) + "); world states from xpos, xmat, "
                                    "mj_objectVelocity and mj_objectAcceleration";
    }
    auto prescribe = [&](double t) {
      if (on_platform) {
        d->qpos[platform_q] = g.platform->Angle(t, g.t0);
        d->qvel[platform_d] = g.platform->omega;
      }
      for (size_t k = 0; k < g.drivers.size(); ++k) {
        const DriverMap& dm = g.drivers[k];
        d->qpos[qadr[dm.joint]] = dm.Position(t, g.t0);
        d->qvel[dadr[dm.joint]] = dm.Rate(t, g.t0);
        d->qfrc_applied[dadr[dm.joint]] = armature[k] * dm.Acceleration(t, g.t0);
      }
    };
    // Every load but the hinges' torsions and the tendons, at every forward pass (StageLoads).
    StageLoads stage_loads(g, body_id, on_hinge);
    std::optional<PassiveCallbackScope> passive_scope;
    if (!stage_loads.empty()) passive_scope.emplace(m.get(), &stage_loads);
    // mj_step split at its forward pass, in MuJoCo's own order (mj_checkPos, mj_checkVel,
    // mj_forward, mj_checkAcc, then the integrator): the forward pass at a sample's state serves
    // both the sample's observation and the next step, so a sample costs no second pass.
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
    // Reads the sample from the forward pass just made at its state.
    // A body's world state: mj_objectVelocity/Acceleration are at its centre of mass (xipos), cacc
    // carries −gravity (added back); moved to the frame origin.
    auto world_state = [&](int id) {
      SpatialState w;
      mjtNum vel[6], acc[6];
      mj_objectVelocity(m.get(), d.get(), mjOBJ_BODY, id, vel, 0);
      mj_objectAcceleration(m.get(), d.get(), mjOBJ_BODY, id, acc, 0);
      for (int i = 0; i < 3; ++i) {
        w.p[i] = d->xpos[3 * id + i];
        for (int j = 0; j < 3; ++j) w.R(i, j) = d->xmat[9 * id + 3 * i + j];
      }
      w.omega = {vel[0], vel[1], vel[2]};
      w.alpha = {acc[0], acc[1], acc[2]};
      const Eigen::Vector3d r = Eigen::Vector3d(d->xipos[3 * id], d->xipos[3 * id + 1], d->xipos[3 * id + 2]) - w.p;
      w.v = Eigen::Vector3d(vel[3], vel[4], vel[5]) - w.omega.cross(r);
      w.a = Eigen::Vector3d(acc[3], acc[4], acc[5]) + g.platform->gravity_W - w.alpha.cross(r) -
            w.omega.cross(w.omega.cross(r));
      return w;
    };
    auto observe = [&]() -> bool {
      mj_rnePostConstraint(m.get(), d.get());
      if (on_platform) {
        std::vector<SpatialState> st(g.bodies.size());
        for (size_t b = 0; b < g.bodies.size(); ++b) {
          st[b] = world_state(body_id[b]);
          if (!st[b].p.allFinite() || !st[b].v.allFinite() || !st[b].omega.allFinite() || !st[b].a.allFinite()) return false;
        }
        record(world_state(platform_id), st, !first_sample || at_rest);
        first_sample = false;
        return true;
      }
      std::vector<PlanarState> st(g.bodies.size());
      for (size_t b = 0; b < g.bodies.size(); ++b) {
        const int id = body_id[b];
        mjtNum vel[6], acc[6];
        mj_objectVelocity(m.get(), d.get(), mjOBJ_BODY, id, vel, 0);
        mj_objectAcceleration(m.get(), d.get(), mjOBJ_BODY, id, acc, 0);
        const mjtNum* p = d->xpos + 3 * id;
        const mjtNum* R = d->xmat + 9 * id;
        PlanarState& s = st[b];
        s.p = {p[0], p[1]};
        s.angle = std::atan2(R[3], R[0]);
        s.omega = vel[2];
        s.alpha = acc[2];
        // mj_objectVelocity/Acceleration of a body are at its centre of mass (xipos); cacc carries
        // −gravity (MuJoCo's accelerometer convention), added back. Moved to the frame origin.
        const Eigen::Vector2d r = Rotate(s.angle, g.bodies[b].com_B);
        const Eigen::Vector2d perp(-r.y(), r.x());
        s.v = Eigen::Vector2d(vel[3], vel[4]) - s.omega * perp;
        s.a = Eigen::Vector2d(acc[3], acc[4]) + g.gravity - s.alpha * perp + s.omega * s.omega * r;
        if (!std::isfinite(s.p.x()) || !std::isfinite(s.angle) || !std::isfinite(s.omega) || !std::isfinite(s.a.x()))
          return false;
      }
      record(st, !first_sample || at_rest);
      first_sample = false;
      return true;
    };

    // The scene's loads act at t0 too (the sample's q̈ and the reactions below include them).
    EnterPhase(options, Phase::kObservation);
    prescribe(g.t0);
    forward();
    if (!observe()) {
      result.status = Status::kDiverged;
      result.reason = "MuJoCo: non-finite state at t0";
      return;
    }
    if (!g.driven) {
      // Joint reactions at t0 (numeric/reactions.h) of a free scene, from observe()'s mj_forward and
      // mj_rnePostConstraint. A loop closure (connect equality, body1 = the child): its three
      // efc_force rows are the force on body1 at the anchor (efc_J = J_body1 − J_body2 there). A
      // tree joint: cfrc_int of the child's body is Σ over its subtree of m (a − g) − cfrc_ext,
      // and cfrc_ext holds xfrc_applied and contacts (MuJoCo 2.2: not the equality forces; later
      // versions add connect forces), so the force from the parent is cfrc_int + Σ_subtree
      // (cfrc_ext − xfrc_applied − connect forces). Forces only (com-based: the reference point
      // changes only the moment). × meters_per_unit: kg·length/s² to N.
      std::vector<Eigen::Vector2d> connect(m->nbody, Eigen::Vector2d::Zero());
      std::vector<int> efc_row(m->neq, -1);  // first efc row of each equality
      for (int i = 0; i < d->nefc; ++i)
        if (d->efc_type[i] == mjCNSTR_EQUALITY && efc_row[d->efc_id[i]] < 0) efc_row[d->efc_id[i]] = i;
      std::vector<Eigen::Vector2d> closure_on_child(g.joints.size(), Eigen::Vector2d(kNaN, kNaN));
      int eq = 0;  // equalities are written in graph order, one per non-tree revolute or gear
      for (size_t ji = 0; ji < g.joints.size(); ++ji) {
        const GraphJoint& j = g.joints[ji];
        if (j.in_tree || j.type == PairType::kPrismatic) continue;
        const int e = eq++;
        if (j.type != PairType::kRevolute || m->eq_type[e] != mjEQ_CONNECT || efc_row[e] < 0) continue;
        const Eigen::Vector2d f(d->efc_force[efc_row[e]], d->efc_force[efc_row[e] + 1]);
        closure_on_child[ji] = f;
        connect[m->eq_obj1id[e]] += f;
        connect[m->eq_obj2id[e]] -= f;
      }
      std::vector<Eigen::Vector2d> correction(m->nbody, Eigen::Vector2d::Zero());
      // A tendon's force is passive, in neither cfrc_ext nor xfrc_applied: taken off as well.
      std::vector<PlanarState> st0(g.bodies.size());
      for (size_t b = 0; b < g.bodies.size(); ++b) st0[b] = g.bodies[b].initial;
      for (const GraphSpring& sp : g.springs) {
        const Eigen::Vector2d f_b =
            SpringForceOnB(sp, Graph::EndPos(st0, sp.body_a, sp.at_a), Graph::EndVel(st0, sp.body_a, sp.at_a),
                           Graph::EndPos(st0, sp.body_b, sp.at_b), Graph::EndVel(st0, sp.body_b, sp.at_b));
        if (sp.body_a >= 0) correction[body_id[sp.body_a]] += f_b;
        if (sp.body_b >= 0) correction[body_id[sp.body_b]] -= f_b;
      }
      // So are the loads StageLoads adds to qfrc_passive (at t0: the last forward pass's).
      if (!stage_loads.empty())
        for (int b = 1; b < m->nbody; ++b) correction[b] -= stage_loads.force_on_body()[b];
      for (int b = m->nbody - 1; b > 0; --b) {
        correction[b] += Eigen::Vector2d(d->cfrc_ext[6 * b + 3], d->cfrc_ext[6 * b + 4]) -
                         Eigen::Vector2d(d->xfrc_applied[6 * b], d->xfrc_applied[6 * b + 1]) - connect[b];
        if (m->body_parentid[b] > 0) correction[m->body_parentid[b]] += correction[b];
      }
      std::vector<numeric::EngineJointForce> pins;
      for (size_t ji = 0; ji < g.joints.size(); ++ji) {
        const GraphJoint& j = g.joints[ji];
        if (j.type == PairType::kGear) continue;
        Eigen::Vector2d f = closure_on_child[ji];
        if (j.in_tree) {
          const int b = body_id[j.child];
          f = Eigen::Vector2d(d->cfrc_int[6 * b + 3], d->cfrc_int[6 * b + 4]) + correction[b];
        }
        pins.push_back(PinForce(g, j, f * g.meters_per_unit));
      }
      const numeric::EngineReactions r = numeric::EngineReactionQuantities(pins);
      result.quantities.insert(r.quantities.begin(), r.quantities.end());
      std::string text = "at t0 (mj_forward, mj_rnePostConstraint): tree joints from cfrc_int corrected by the subtree's "
                         "cfrc_ext − xfrc_applied − connect forces, loop closures from the connect equalities' efc_force; "
                         "the equalities are soft (solref/solimp), so the closure forces are the softened ones";
      for (const std::string& n : r.notes) text += "; left out: " + n;
      result.settings["reactions"] = text;
    }
    StepThroughSamples(m.get(), d.get(), times, o.step, options, prescribe, forward, advance, observe, result);
  }

 private:
  MujocoOptions o_;
};

}  // namespace

MethodPtr MakeMujocoMethod(const MujocoOptions& o) { return std::make_unique<MujocoMethod>(o); }

std::vector<MethodPtr> MakeMujocoMethods() {
  std::vector<MethodPtr> out;
  out.push_back(MakeMujocoMethod(MujocoOptions{}));  // MuJoCo's defaults: Euler, 2 ms, solref 0.02 1
  MujocoOptions t;
  t.name = "mujoco-rk4-tuned";
  t.integrator = "RK4";
  t.step = 1e-4;
  t.solref = {2e-4, 1.0};  // the stiffest MuJoCo allows at this step (time constant ≥ 2 h)
  t.solimp = {0.9999, 0.9999, 0.001, 0.5, 2.0};
  t.tolerance = 1e-12;
  out.push_back(MakeMujocoMethod(t));
  return out;
}

}  // namespace mechbench::engines
