// What the MuJoCo adapter's planar path (mujoco_method.cc) and spatial path (mujoco_spatial.cc)
// share: MJCF text formatting, the model's owners, spring-tendon conventions, loads added at every
// forward pass (mjcb_passive), loading the generated MJCF and the stepping through the samples.
// Internal to engines/mujoco.
#pragma once

#include "mechbench/engines/engine_method.h"
#include "mechbench/engines/mujoco.h"
#include "mechbench/engines/spatial_graph.h"
#include "mechbench/format.h"
#include "mechbench/method.h"

#include <mujoco/mujoco.h>

#include <algorithm>
#include <cstdio>
#include <ostream>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace mechbench::engines::mujoco_adapter {

// Full precision for the MJCF text.
inline std::string Num(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}
inline std::string Vec(const Eigen::Vector2d& p) { return Num(p.x()) + " " + Num(p.y()) + " 0"; }
inline std::string Vec(const Eigen::Vector3d& p) { return Num(p.x()) + " " + Num(p.y()) + " " + Num(p.z()); }
inline std::string Join(const double* v, int n) {
  std::string s;
  for (int i = 0; i < n; ++i) s += (i ? " " : "") + Fmt(v[i]);
  return s;
}

struct ModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};
struct DataDeleter {
  void operator()(mjData* d) const { mj_deleteData(d); }
};
struct VfsDeleter {
  void operator()(mjVFS* v) const {
    mj_deleteVFS(v);
    delete v;
  }
};
using ModelPtr = std::unique_ptr<mjModel, ModelDeleter>;
using DataPtr = std::unique_ptr<mjData, DataDeleter>;

inline std::string SpringName(int k) { return "sp" + std::to_string(k); }
inline std::string SiteName(int k, int end) { return SpringName(k) + (end ? "b" : "a"); }
// A spring–damper's tension k (L − L0) + c L̇ + F0 is MuJoCo's tendon spring with its rest length
// moved by the preload, L0 − F0/k, when k > 0; without stiffness the preload is a motor on the
// tendon at a constant control (an actuator's positive force lengthens its tendon: ctrl = −F0).
// (GraphSpring, SpatialGraphSpring.)
template <class Spring>
bool PreloadByMotor(const Spring& s) {
  return !(s.stiffness > 0) && s.preload != 0;
}
template <class Spring>
double RestLength(const Spring& s) {
  return s.stiffness > 0 ? s.free_length - s.preload / s.stiffness : s.free_length;
}
// Spring–damper k as a spatial tendon between its two sites (inside <tendon>).
template <class Spring>
void WriteSpringTendon(std::ostream& x, const Spring& sp, int k) {
  x << "    <spatial name=\"" << SpringName(k) << "\" stiffness=\"" << Num(sp.stiffness) << "\" damping=\""
    << Num(sp.damping) << "\" springlength=\"" << Num(std::max(0.0, RestLength(sp))) << "\"><site site=\""
    << SiteName(k, 0) << "\"/><site site=\"" << SiteName(k, 1) << "\"/></spatial>\n";
}
// The <actuator> block of the preloads without stiffness (PreloadByMotor), if any.
template <class Spring>
void WritePreloadMotors(std::ostream& x, const std::vector<Spring>& springs) {
  bool motors = false;
  for (size_t k = 0; k < springs.size(); ++k) {
    if (!PreloadByMotor(springs[k])) continue;
    if (!motors) x << "  <actuator>\n";
    motors = true;
    x << "    <motor name=\"pre" << k << "\" tendon=\"" << SpringName(static_cast<int>(k)) << "\" gear=\"1\" ctrllimited=\"false\"/>\n";
  }
  if (motors) x << "  </actuator>\n";
}

// The scene's loads other than the hinges' own torsions and the tendons: point forces (constant,
// laws of t, body frames), torque laws of t, and StateLoads (torsions no hinge carries, torque and
// force laws of the state), evaluated at every forward pass from that pass's d->time, qpos and qvel
// and added to qfrc_passive with mj_applyFT. MuJoCo calls mjcb_passive inside mj_passive, from
// mj_fwdVelocity, after mj_fwdPosition (mj_kinematics, mj_comPos: xpos, xmat, xipos, subtree_com)
// and mj_comVel (cvel) of the same pass (MuJoCo 2.2 engine_forward.c / engine_core_smooth.c), and
// mj_RungeKutta sets each stage's qpos, qvel and time before its mj_forwardSkip: so RK4 sees the
// loads at its four stages, Euler at the step's start (as before, when they were in xfrc_applied).
// Loads added to qfrc_passive at every forward pass (mjcb_passive, PassiveCallbackScope).
class PassiveLoads {
 public:
  virtual ~PassiveLoads() = default;
  virtual void AddTo(const mjModel* m, mjData* d) = 0;
};

// mjcb_passive is one process-wide pointer: while a run lasts, it points at Passive, which adds the
// run's StageLoads for the run's mjModel (kept per thread) and hands any other model to the
// callback that was installed before; the scope puts that callback (and the thread's previous
// run, if nested) back when it ends, so other MuJoCo users in the process are unaffected.
class PassiveCallbackScope {
 public:
  PassiveCallbackScope(const mjModel* m, PassiveLoads* loads) : saved_(current_) {
    current_ = {m, loads, mjcb_passive == &Passive ? saved_.previous : mjcb_passive};
    mjcb_passive = &Passive;
  }
  ~PassiveCallbackScope() {
    mjcb_passive = saved_.loads ? &Passive : current_.previous;
    current_ = saved_;
  }
  PassiveCallbackScope(const PassiveCallbackScope&) = delete;
  PassiveCallbackScope& operator=(const PassiveCallbackScope&) = delete;

 private:
  struct Context {
    const mjModel* model = nullptr;
    PassiveLoads* loads = nullptr;
    mjfGeneric previous = nullptr;  // the callback before the first scope
  };
  static void Passive(const mjModel* m, mjData* d) {
    if (current_.loads && current_.model == m)
      current_.loads->AddTo(m, d);
    else if (current_.previous)
      current_.previous(m, d);
  }
  static thread_local Context current_;  // defined in mujoco_method.cc
  Context saved_;
};

// The generated MJCF loaded from memory; null with result's status and reason set on failure.
ModelPtr LoadMjcf(const std::string& xml, Result& result);

// MuJoCo's default warning handler prints and appends to MUJOCO_LOG.TXT in the working directory;
// the adapter reads mjData::warning itself and reports every warning in the result (a blow-up as
// Status::kDiverged), so the handler is silenced once per process.
void SilenceWarnings();

// The stepping both paths share, from the state at times[0] (forward-passed and observed): to each
// sample in steps shortened evenly to land on it (StepsTo), the drivers prescribed and the forward
// pass redone before every step but the interval's first, MuJoCo's bad-state warnings ending the
// run as diverged, then the sample's own forward pass and its observation.
template <class Prescribe, class Forward, class Advance, class Observe>
void StepThroughSamples(mjModel* m, mjData* d, const std::vector<double>& times, double step, const RunOptions& options,
                        Prescribe&& prescribe, Forward&& forward, Advance&& advance, Observe&& observe,
                        Result& result) {
  long steps = 0;
  for (size_t k = 1; k < times.size(); ++k) {
    EnterPhase(options, Phase::kIntegration);
    const double t_start = d->time;
    const auto [n, h] = StepsTo(t_start, times[k], step);
    m->opt.timestep = h;
    for (long i = 0; i < n; ++i) {
      CheckBudgetInStep(options, i, times[k - 1]);
      if (i > 0) {  // the interval's first step starts from the sample's own forward pass
        prescribe(t_start + static_cast<double>(i) * m->opt.timestep);
        forward();
      }
      advance();
      ++steps;
      // MuJoCo does not stop on a NaN, Inf or huge (> mjMAXVAL) value in qpos/qvel/qacc: it
      // warns, resets mjData to the reference pose and carries on, which would pass for a
      // finite run (a step too large for the scene does this). End the run as diverged.
      for (const auto& [w, what] : {std::pair{mjWARN_BADQPOS, "qpos"}, std::pair{mjWARN_BADQVEL, "qvel"},
                                    std::pair{mjWARN_BADQACC, "qacc"}})
        if (d->warning[w].number > 0) {
          result.status = Status::kDiverged;
          result.reason = std::string("MuJoCo: NaN, Inf or a huge value in ") + what + " in the step from t = " +
                          Fmt(t_start + i * m->opt.timestep) + " s (h = " + Fmt(m->opt.timestep) +
                          " s); MuJoCo reset the simulation (unstable at this step)";
          return;
        }
    }
    // The forward pass at the sample is the next step's (integration); after the last sample it
    // serves the observation alone.
    EnterPhase(options, k + 1 < times.size() ? Phase::kIntegration : Phase::kObservation);
    d->time = times[k];
    prescribe(times[k]);
    forward();
    EnterPhase(options, Phase::kObservation);
    if (!observe()) {
      result.status = Status::kDiverged;
      result.reason = "MuJoCo: non-finite state at t = " + Fmt(times[k]);
      return;
    }
  }
  for (int w = 0; w < mjNWARNING; ++w)
    if (d->warning[w].number > 0)
      result.messages.push_back("MuJoCo warning " + std::to_string(w) + " raised " + std::to_string(d->warning[w].number) + " times");
  result.settings["steps_taken"] = std::to_string(steps);
  result.steps = steps;
}

// A spatial graph's free motion, stepped and recorded as the planar Simulate does (mj_step split
// at its forward pass, the step shortened evenly to land on every sample, warnings as divergence).
void SimulateSpatialGraph(const SpatialGraph& g, const std::vector<double>& times, const MujocoOptions& o,
                          const ControlValue& control, const SpatialRecorder& record, const RunOptions& options,
                          Result& result);

}  // namespace mechbench::engines::mujoco_adapter
