// One interface for every method (analytic, numeric, each engine variant).
//
// Non-virtual interface (as Drake does): Method::Run() checks applicability, times the run,
// turns exceptions into a status, and packs the common Result; a method implements only
// Applicability() and DoRun(). A method that cannot do a scene says why, and that reason is
// shown by every output (tests GTEST_SKIP() with it).
#pragma once

#include "mechbench/model.h"

#include <Eigen/Core>

#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace mechbench {

enum class Status {
  kOk,
  kNotApplicable,   // the method cannot do this scene; `reason` says why
  kInvalidScenario, // the scene itself is impossible: cannot assemble, singular, wrong DOF
  kDiverged,        // the run produced NaN/Inf or its iteration did not converge
  kFailed,          // anything else (an exception inside the method)
  kOverBudget,      // stopped when its CPU budget (RunOptions::cpu_budget) ran out; the samples so far are kept
  kCrashed,         // its process died (an engine's abort or segfault), run in isolation (harness/process.h)
  kTimedOut,        // its process was killed at the time limit, run in isolation
  kStopped,         // stopped by its caller's watch on the motion (RunOptions::watch); the samples so far are kept
};
const char* ToString(Status s);

// One sample of the motion, in the model's q layout (Model::q_layout).
struct Sample {
  double t = 0.0;          // [s]
  Eigen::VectorXd q, qd, qdd;
  double residual = 0.0;   // ‖Φ(q, t)‖ measured by the method that produced it (0 if n/a)
};

// Quantity names used in `Result::quantities` and in the book checks:
//   q.<slot> qd.<slot> qdd.<slot>        coordinate value / rate / acceleration at the instant
//   omega.<body> alpha.<body>           planar angular velocity [rad/s] / acceleration [rad/s²]
//   p.<point>.<x|y|z> v.<point>.<x|y|z> a.<point>.<x|y|z>   3-D world values (via the embedding)
//   p.<member>.<x|y|z> v.… a.…          a gear-train member's axis centre (a planet's on its carrier's
//                                         arm) when the file gives the train's geometry (Model::gear_axes)
//   vabs.<point>.<c> aabs.<point>.<c>    absolute values when the frame rotates (Model::frame)
//   omegaabs.<body>.<c>                   absolute angular velocity when the frame rotates
//   Phi_q[i,j]  Phidot_q[i,j]  Phidot_q_qd[i]  M[i,j]  Q[i]   numeric matrices (0-based)
//   newton.<k>.<slot>                     k-th Newton–Raphson iterate (1 = after the first step)
//   dof  rank  rows  n                    degrees of freedom, rank of Φ_q, rows of Φ, size of q
//   residual.guess                        scaled ‖Φ‖ of the file's own positions and guesses at t0 (numeric):
//                                         whether a state written out in full closes the loop
//   reaction.<point>.<body>.<x|y>         force [N, world] <body> gets at pin <point> at t0 (numeric/reactions.h)
// Methods add other named quantities freely (e.g. "v_rel.1", "ratio"); a check whose quantity a
// method does not produce shows that method as "n/a".
using Quantities = std::map<std::string, double>;

// Where a run's CPU time goes. `setup`: building the method's own model from the scene (compiling
// natural coordinates, writing and compiling MJCF, creating an engine's world) and the start
// state; `integration`: the method's own work over the motion (stepping, or solving each
// kinematic sample); `observation`: reading states back into q, q̇, q̈ and derived quantities.
// The three add up to `total`, the process CPU time of DoRun. Process-wide one-time costs
// (library initialisation, first-touch allocations) are not a part of any run: callers that time
// pay them first (harness/timing.h) and report them apart.
enum class Phase { kSetup, kIntegration, kObservation };
struct CpuTimes {
  double setup = 0, integration = 0, observation = 0;  // [s]
  double total() const { return setup + integration + observation; }
};

// Splits one run's time into phases. Method::Run starts it in kSetup before DoRun and stops it
// after; a method calls Enter() where its work changes phase (per sample at most: a switch costs
// one reading of the monotonic clock, about 25 ns, where the process CPU clock costs 400 ns, too
// much for thousands of samples). The phases' monotonic times are scaled to the run's process CPU
// time at the end, so the parts add up to the CPU time of the whole run.
class PhaseClock {
 public:
  void Enter(Phase p) {
    const auto now = std::chrono::steady_clock::now();
    wall_[static_cast<int>(current_)] += std::chrono::duration<double>(now - since_).count();
    current_ = p;
    since_ = now;
  }
  Phase current() const { return current_; }
  // Whether to read the process CPU clock now for a budget check: at most every 10 ms of
  // monotonic time, so that a check per sample costs one cheap reading.
  bool DueForCpuCheck() {
    const auto now = std::chrono::steady_clock::now();
    if (now < next_cpu_check_) return false;
    next_cpu_check_ = now + std::chrono::milliseconds(10);
    return true;
  }
  // Method::Run: the run starts (kSetup) and ends, with its process CPU time [s].
  void Start() {
    current_ = Phase::kSetup;
    since_ = std::chrono::steady_clock::now();
  }
  CpuTimes Stop(double cpu_total) {
    Enter(current_);
    const double wall = wall_[0] + wall_[1] + wall_[2];
    CpuTimes t;
    if (!(wall > 0)) {
      t.setup = cpu_total;
      return t;
    }
    t.setup = cpu_total * wall_[0] / wall;
    t.integration = cpu_total * wall_[1] / wall;
    t.observation = cpu_total * wall_[2] / wall;
    return t;
  }

 private:
  Phase current_ = Phase::kSetup;
  std::chrono::steady_clock::time_point since_ = std::chrono::steady_clock::now();
  double wall_[3] = {0, 0, 0};
  std::chrono::steady_clock::time_point next_cpu_check_{};
};

struct Result {
  std::string method;
  Status status = Status::kOk;
  std::string reason;  // why not ok, in words a user can act on
  std::vector<std::string> messages;  // notes that do not change the status (e.g. redundancy)
  std::vector<Sample> trajectory;     // the instant is trajectory[0] when there is no motion
  Quantities quantities;              // at the instant
  double cpu_seconds = 0.0;           // process CPU time of DoRun (= cpu.total())
  CpuTimes cpu;                       // the same, in phases
  double wall_seconds = 0.0;
  long steps = -1;                    // time steps taken (integrators) or samples solved; -1: none
  std::map<std::string, std::string> settings;  // everything that changes the result
  bool ok() const { return status == Status::kOk; }
};

// What a work–precision sweep varies for a method: nothing (exact kinematics), its time step
// (RunOptions::step) or its error tolerance (RunOptions::tolerance).
enum class Control { kNone, kStep, kTolerance };
const char* ToString(Control c);

struct RunOptions {
  bool motion = true;  // also run the motion when the scenario has one
  // Work–precision sweeps: a method that integrates in time uses this step [s] or this relative
  // tolerance instead of its own default (NaN = default), and records what it used in
  // Result::settings. Kinematic methods ignore both.
  double step = kNaN;
  double tolerance = kNaN;
  // CPU budget of the run [s] (NaN: none). Time-stepping methods check it once per output sample
  // (CheckBudget) and stop with Status::kOverBudget, keeping the samples so far, so that a slow
  // variant on a big scene is still a row with the time it reached.
  double cpu_budget = kNaN;
  // Set by Method::Run from cpu_budget: the process CPU time [s] past which CheckBudget stops the
  // run. Callers leave it alone.
  double cpu_deadline = kNaN;
  // Set by Method::Run: the run's phase clock (EnterPhase). Callers leave it alone.
  PhaseClock* clock = nullptr;
  // A caller's watch on the motion: called with each output sample once it is recorded (by
  // CheckBudget, which every stepping loop calls after a sample); a reason returned stops the
  // run there with Status::kStopped and that reason, keeping the samples so far. For a search
  // that need not finish a run already known to miss what it looks for (a precision level
  // passed at some sample can no longer be met by the whole run).
  std::function<std::optional<std::string>(const Sample&)> watch = nullptr;
  // Set by Method::Run when `watch` is: the samples recorded so far and how many were watched.
  struct Watched {
    const std::vector<Sample>* samples = nullptr;
    size_t seen = 0;
  };
  Watched* watched = nullptr;
};

// Marks where a run's work changes phase (PhaseClock::Enter); nothing without a clock.
inline void EnterPhase(const RunOptions& options, Phase p) {
  if (options.clock) options.clock->Enter(p);
}

// Called by a method's stepping loop after the output sample at `t` [s]: throws BudgetExceeded
// once the run is past options.cpu_deadline. Method::Run turns that into Status::kOverBudget.
void CheckBudget(const RunOptions& options, double t);
// The same from inside a stepping loop, every 64th step (`step` counts them): samples may be far
// apart (a scene followed for 1e9 s in 100 samples), and a run must still stop near its budget.
// `t` is the last sample recorded.
inline void CheckBudgetInStep(const RunOptions& options, long step, double t) {
  if ((step & 63) == 0) CheckBudget(options, t);
}
struct BudgetExceeded {
  double t = 0;  // the last sample recorded [s]
};
struct WatchStopped {
  double t = 0;        // the sample the watch stopped at [s]
  std::string reason;  // what the watch said
};

class Method {
 public:
  virtual ~Method() = default;
  const std::string& name() const { return name_; }
  const std::string& description() const { return description_; }

  // What a sweep varies, and the method's own value of it (its step [s] or relative tolerance;
  // NaN for Control::kNone). A method whose control is not kNone honours the matching
  // RunOptions override and records the value it used in Result::settings.
  virtual Control control() const { return Control::kNone; }
  virtual double default_control() const { return kNaN; }

  // Why this method cannot do `model`, or nullopt when it can.
  virtual std::optional<std::string> Applicability(const Model& model) const = 0;

  // Validates, times and packs the result; never throws for a failing run.
  Result Run(const Model& model, const RunOptions& options = {}) const;

  // The computation Run(model, options) does, beyond the scene and the caller's budget and watch:
  // the engine, its code path and every numeric setting in use, resolved (an engine's default
  // read from the engine). Two methods that return the same non-empty text do the same run bit
  // for bit, so a campaign may run it once for both (Simbody's default and tuned variants at one
  // swept accuracy; ODE's dWorldStep variants at one swept step). Empty (the default): not
  // stated, never shared. Tests run every pair that states the same text and compare.
  virtual std::string Computation(const RunOptions& options) const {
    (void)options;
    return {};
  }

 protected:
  Method(std::string name, std::string description)
      : name_(std::move(name)), description_(std::move(description)) {}
  // Fill result.trajectory / quantities / settings. Throw ScenarioError for an impossible scene,
  // set result.status = kDiverged for a run that does not converge.
  virtual void DoRun(const Model& model, const RunOptions& options, Result& result) const = 0;

 private:
  std::string name_, description_;
};

using MethodPtr = std::unique_ptr<Method>;

}  // namespace mechbench
