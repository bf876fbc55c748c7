// Tolerances as data: harness/tolerances.yaml.
#pragma once

#include <algorithm>
#include <limits>
#include <map>
#include <string>
#include <vector>

namespace mechbench {
struct Model;
}

namespace mechbench::harness {

// A method's motion of a free scene against the reference trajectory.
struct FreeTolerance {
  double position = 1e-6;   // max |q − q_ref| over the run, relative to the motion's scale
  double residual = 1e-10;  // scaled ‖Φ‖ along its motion
};

// A driven (or instant) run of one method against the reference method.
struct Agreement {
  double q = 1e-9, qd = 1e-9, qdd = 1e-9;  // relative agreement over the motion
  double instant = 1e-9;                   // every named quantity both methods give at t0
  double residual = 1e-10;                 // scaled ‖Φ‖ along its motion
  // Accelerations at t0 (q̈, α, a., aabs., …, relative to their family's largest): measured for
  // them where given (`instant_acceleration`; NaN: not given), else the larger of qdd and instant.
  double instant_acceleration = std::numeric_limits<double>::quiet_NaN();
  double AccelerationAtT0() const {
    return instant_acceleration == instant_acceleration ? instant_acceleration : std::max(qdd, instant);
  }
};

struct Tolerances {
  double q = 1e-9, qd = 1e-9, qdd = 1e-9;  // relative agreement between methods
  double instant = 1e-9;                   // every named quantity both methods give at t0
  double residual = 1e-10;                 // scaled ‖Φ‖ along a motion
  double instant_acceleration = std::numeric_limits<double>::quiet_NaN();  // Agreement's
  // Methods that integrate in time (engines) follow exact kinematics to their own accuracy.
  std::map<std::string, Agreement> methods;
  Agreement For(const std::string& method) const {
    if (auto it = methods.find(method); it != methods.end()) return it->second;
    return {q, qd, qdd, instant, residual, instant_acceleration};
  }
  // Findings kept visible: method -> why it is known to fall outside its tolerance on this
  // scenario. Reports still show the numbers; the exit code and the gates do not fail on them,
  // and the tests assert that they still fail (so a fix is noticed).
  std::map<std::string, std::string> known_failures;
  // Where each known failure's entry is: "file:line" (its verdict names it).
  std::map<std::string, std::string> known_where;
  std::string KnownWhere(const std::string& method) const {
    const auto it = known_where.find(method);
    return it == known_where.end() ? std::string() : it->second;
  }
  const std::string* KnownFailure(const std::string& method) const {
    auto it = known_failures.find(method);
    return it == known_failures.end() ? nullptr : &it->second;
  }
  FreeTolerance free;                                  // free scenes, any method not listed
  std::map<std::string, FreeTolerance> free_methods;   // free scenes, per method
  const FreeTolerance& ForFree(const std::string& method) const {
    const auto it = free_methods.find(method);
    return it == free_methods.end() ? free : it->second;
  }
  // [s] The free positions above are stated for a motion this long. A longer motion's position
  // tolerance (and the reference's agreement) grows in proportion to its duration: the global
  // error of a stable integrator on a conservative motion is mostly phase, which accumulates
  // linearly (IFToMM A01 is followed for 2000 s). A shorter one keeps the stated value.
  double free_horizon = 1.0;
  double HorizonFactor(double duration) const { return std::max(1.0, duration / free_horizon); }
  // The position tolerance of `method` on a free motion lasting `duration` [s].
  double FreePosition(const std::string& method, double duration) const {
    return ForFree(method).position * HorizonFactor(duration);
  }
};

// The tolerances for `scenario` (its file stem): harness/tolerances.yaml, then each user file
// (UserTolerancesFiles) merged over it: every file's `default` section in order, then every
// file's entry for the scenario, and the known failures of all. Throws ScenarioError (bad input:
// file, line and fix) for a file that does not read strictly.
Tolerances LoadTolerances(const std::string& scenario);
// The same for a loaded scene, with the known failures of the classes of scene it belongs to
// (known_failures entries with `class:` instead of `scenario:`, e.g. free_coupling), so that a
// user's file of the kind is told what is known of the method on it; its own entry comes first.
Tolerances LoadTolerances(const Model& model);
std::string DefaultTolerancesFile();
// The user's tolerance files: those given by SetUserTolerancesFiles (the CLI: MECHBENCH_TOLERANCES's
// files, then --tolerances'), else the colon-separated list in MECHBENCH_TOLERANCES (how the test
// suites and `check` take a user's files beside MECHBENCH_SCENARIOS), else none.
std::vector<std::string> UserTolerancesFiles();
// The colon-separated files of MECHBENCH_TOLERANCES (none when it is not set).
std::vector<std::string> EnvironmentTolerancesFiles();
// The files that judge this process's runs, for a footer: "harness/tolerances.yaml, then a.yaml".
std::string TolerancesFilesText();
// The user files' scenario names (`scenarios:` keys, known failures' `scenario:`) that are none of
// `scenes` (the stems of the scenes a command was given) nor a built-in scene: "file:line: …" each,
// for a warning (a user's own scene may be named there, so it is not refused; a misspelt one
// applies to nothing).
std::vector<std::string> UnmatchedScenarioNames(const std::vector<std::string>& scenes);
// Reads each file strictly (throws ScenarioError before any work) and uses them from now on.
void SetUserTolerancesFiles(const std::vector<std::string>& files);

}  // namespace mechbench::harness
