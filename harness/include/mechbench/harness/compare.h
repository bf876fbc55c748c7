// The comparison core: book checks and method-against-method comparison of a motion.
#pragma once

#include "mechbench/harness/timing.h"
#include "mechbench/harness/criteria.h"
#include "mechbench/harness/tolerances.h"
#include "mechbench/method.h"
#include "mechbench/motion_error.h"
#include "mechbench/verdict.h"
#include "mechbench/model.h"

#include <map>
#include <ostream>
#include <optional>
#include <string>
#include <vector>

namespace mechbench::harness {

// The book verdicts (mechbench/verdict.h), named here too for the harness's callers.
using mechbench::Judge;
using mechbench::Verdict;

// Evaluates a book quantity expression ("qd.phi1/qd.phi6") over one method's quantities;
// nullopt when the method does not produce a name it uses. The book's own notation works too:
// xP and yP stand for p.P.x and p.P.y, a coordinate's name for q.<name>, and the scenario's
// constants for themselves, so a printed constraint row can be evaluated on the mechanism.
std::optional<double> EvalQuantity(const std::string& expr, const Quantities& q, const Model& model);

struct BookCheck {
  BookValue book;
  std::vector<std::pair<std::string, std::optional<double>>> computed;  // per method, book unit
  std::vector<std::pair<std::string, Verdict>> verdicts;              // per method
  // Against the first method that computed it; a claim at a time (BookValue::at) of a free scene,
  // against the reference trajectory (the column "reference"); of a driven scene, against the
  // first method that computed it (its exact kinematics at t), else not-computed.
  Verdict verdict = Verdict::kNotComputed;
  std::string reason;  // why the verdict is not-computed (empty otherwise)
  bool methods_agree = true;                // the computed values agree with each other (instant claims)
  // Methods whose value is off the first method's by more than their tolerance (with tolerances:
  // tolerances.yaml's `instant`, for an acceleration the larger of `qdd` and `instant`, as `run`
  // judges them at t0): "method value (off by d, allowed a)". A method listed as a known failure
  // on the scene goes to known_outside and does not make the methods disagree.
  std::vector<std::string> outside, known_outside;
  // Methods whose tolerance for it is ∞ (an engine's q̈, "shown, not judged" in tolerances.yaml):
  // named, so that no one reads it as agreement. Their cells keep the value (`check` marks it as
  // not judged) and give no verdict; the values again in not_judged_values.
  std::vector<std::string> not_judged;
  std::vector<double> not_judged_values;
  // A claim at a time: the uncertainty it is judged within [book unit] (JudgeWithin), the larger
  // of half its last printed digit, its stated precision and the reference's confirmed agreement.
  double allowed = kNaN;
};

struct ReferenceRecord;
// Every book value of `model` beside each result. A claim about the instant is read off each
// method's instant quantities; a claim at a time of the motion (BookValue::at) off each result's
// trajectory sample there (q.<slot>, qd.<slot>, qdd.<slot>, p.<point>.<x|y|z>, SampleQuantities)
// and off `reference` (a confirmed reference trajectory, the last column "reference"), which
// decides its verdict in a free scene; in a driven scene the methods' kinematics at t decides it,
// as for a claim about the instant.
// Without `tolerances` the methods must agree to 1e-9 (the exact methods); with them, each method
// to its own tolerance for the quantity (BookCheck::outside).
std::vector<BookCheck> CheckBook(const Model& model, const std::vector<Result>& results,
                                 const ReferenceRecord* reference = nullptr, const Tolerances* tolerances = nullptr);
// The quantities a trajectory sample holds, named as a method's instant quantities are.
Quantities SampleQuantities(const Model& model, const Sample& sample);

// One measure for a quantity two methods give at t0 (M, Q, ω, v., a., aabs., q̈ at t0, …), used
// by `run` (RunScenario), `check` (CheckBook) and the report alike: each family's scale is the
// largest |value| of the family in either method, floored by the motion's scale for its kind
// (InstantScales); a difference is |base − value| over its family's scale (InstantDifference),
// judged against the method's `instant` bound, or for an acceleration (IsAccelerationAtT0) its
// bound for accelerations at t0 (InstantBound, Agreement::AccelerationAtT0).
std::map<std::string, double> InstantScales(const Quantities& base, const Quantities& other, const MotionScale& scale);
double InstantDifference(const std::string& name, double base, double value, const std::map<std::string, double>& scales);
bool IsAccelerationAtT0(const std::string& name);
double InstantBound(const Agreement& agreement, const std::string& name);

// Two methods' motions compared slot by slot over all common samples.
struct PairComparison {
  std::string reference, method;
  int samples = 0;
  double q = 0, qd = 0, qdd = 0;  // largest relative difference (see tolerances.yaml)
  std::string worst_slot;         // where the largest of the three occurred
  int quantities = 0;             // instant quantities both produce (M, Q, ω, v of points, …)
  double quantity = 0;            // the relative difference of worst_quantity: the largest, or within
                                  // round-off (1e-12 of its family's scale) of it (accelerations apart)
  std::string worst_quantity;     // among ties, the quantity that moves most (never a fixed point)
  double acceleration_quantity = 0;  // accelerations at t0 (q̈, α, a, …), judged like q̈
  std::string worst_acceleration_quantity;
  bool qdd_compared = true;       // false when one of them gives no q̈ (an engine at t0): qdd is 0 then
  bool instant_only = false;      // a free scene: compared at t0 only (the motions: FreeComparison)
  bool within = true;
  std::string problem;            // e.g. different sample times
  std::string known;              // why it is a known failure (tolerances.yaml), if it is one
  // What was measured but has no bound (∞ in tolerances.yaml): "q̈ 3.0", "accelerations at t0
  // (aabs.D.y 0.92)". Shown, not judged: `within` says nothing about them.
  std::vector<std::string> not_judged;
};

// A method's motion of a free scene against the reference trajectory (harness/reference.h).
struct FreeComparison {
  std::string method;
  int samples = 0;
  double position = 0;      // max |q − q_ref| over the run, relative to the motion's scale
  std::string worst_slot;   // where, and when [s]
  double worst_t = 0;
  double tolerance = 0;     // tolerances.yaml, free: section
  double first_outside_t = kNaN;  // the first sample whose error exceeds `tolerance` [s] (NaN: none)
  double energy_drift = kNaN;     // max |E − E0| [J], measured alike for every method (EnergyDrift)
  double reached_t = kNaN;        // a run stopped by its CPU budget: judged up to this time [s]
  bool within = true;
  std::string problem;      // e.g. different sample counts (a run that stopped early)
  std::string known;        // why it is a known failure (tolerances.yaml), if it is one
  // The scene's own precision criteria (Model::criteria), when it has them (criteria.h).
  std::optional<CriteriaVerdict> criteria;
};

// Joint reactions at t0 (reaction.<point>.<body>.x|y, [N]) of one method against the first
// method that reports them (a formulation: from its multipliers). Informative in `run`; the
// test suite holds each engine to its measured agreement (tests/reactions_test.cc).
struct ReactionComparison {
  std::string reference, method;
  int components = 0;     // reaction components both report
  double absolute = 0;    // largest |difference| [N]
  // absolute / max(largest |reaction| of the reference, 1e-3 × the scene's force scale: its
  // weight plus its loads), so that a scene whose reactions all vanish is not judged on round-off
  double relative = 0;
  std::string worst;      // where
};

struct RunReport {
  std::string scenario;
  Tolerances tolerances;
  std::vector<Result> results;                 // one per method, registry order
  std::map<std::string, StartupCost> startup;  // per method: its one-time costs, paid before its run (timing.h)
  std::map<std::string, double> max_residual;  // per method: scaled ‖Φ‖, measured alike
  // Every ok method against the base: the first ok method that is neither a known failure here
  // (tolerances.yaml) nor over its residual bound, so that a diverging run is never the base.
  std::vector<PairComparison> pairs;
  // Free scenes with a motion: every ok method that integrated it, against the reference
  // trajectory (pairs above then compare the instant t0 only).
  std::vector<FreeComparison> free;
  std::vector<ReactionComparison> reactions;
  std::string reference;                       // how the reference was made, or why there is none
  bool reference_confirmed = false;
  bool reference_from_cache = false;
  bool ok = true;                              // everything within tolerance
  bool invalid = false;                        // the scenario is impossible (exit code 2)
  std::vector<std::string> problems;           // why not ok, one line each
  std::vector<std::string> known;              // known failures (tolerances.yaml): shown, not failing
};

// max |E − E0| [J] over a free scene's motion, measured alike for every method from its own q and
// q̇ with the scene's masses, gravity, constant forces and springs, less the torques' work, plus
// what the dampers dissipated between samples (numeric::EnergyBalance; NaN where it does not apply).
double EnergyDrift(const Model& model, const std::vector<Sample>& trajectory);
// What EnergyDrift measures besides the method on a scene whose balance integrates loads between
// samples (dampers' dissipation, the work of torque laws and of varying point forces: the cubic
// Hermite rule on the samples, an error O(h⁴) in their spacing h): a note naming h, to print
// beside the drift. Empty for a scene without such loads (or without a motion).
std::string EnergyDriftNote(const Model& model);

// The scaled ‖Φ‖ (ScaledResiduals) above which a mechanism has come apart: its joints are open by
// a hundredth of their typical size, and its positions mean nothing. A run that gets there has
// diverged, whatever its method reported (RunScenario sets the status); `stress` calls it
// loop_opened.
inline constexpr double kLoopOpenedResidual = 1e-2;

// The constraint residual of every sample, measured alike for every method: the numeric model's
// Φ(q, t), each row divided by its typical size. Empty when the numeric model cannot compile.
std::vector<double> ScaledResiduals(const Model& model, const std::vector<Sample>& trajectory);
// The scaled residual no trajectory can go below, its largest over the samples: coordinates carry
// 16 significant digits, so Φ_i at q is uncertain by about ε Σ_j |∂Φ_i/∂q_j| |q_j| (twice that
// here), divided by the row's size as ScaledResiduals does. It grows with the coordinates' size
// against the links' (a chain 3000 m long of 1 m links: 2.7e-12 on one sample). RunScenario holds
// a method's residual to its bound or to this floor, whichever is larger. 0 when nothing compiles.
double ResidualRoundOff(const Model& model, const std::vector<Sample>& trajectory);

// How RunScenario runs each method: in this process, or each in its own (isolated.h: an engine
// that aborts or hangs is a crashed or timed-out row), killed after `timeout` [s] (≤ 0: never).
struct Isolation {
  bool enabled = false;
  double timeout = 0;
};

RunReport RunScenario(const Model& model, const std::vector<MethodPtr>& methods,
                      const RunOptions& options, const Tolerances& tolerances, const Isolation& isolation = {});

// Each method's run on one scene, as `run` (RunScenario) and `check` make them, in `methods`' order
// (numeric's run first when it is there: its words say bad input). Bad input stops every method
// on the same scene: once a run returns Status::kInvalidScenario, the methods not yet run are not
// run (each would find the same error again, at a cost: a driver's reach is searched by every
// engine's own assembly) and get that status, its reason and a message saying so. `warm_up`: each
// method's one-time costs paid before its run (its StartupCost in `startup` when given).
std::vector<Result> RunMethods(const Model& model, const std::vector<MethodPtr>& methods, const RunOptions& options,
                               const Isolation& isolation, bool warm_up,
                               std::map<std::string, StartupCost>* startup = nullptr);

// One method's verdict in a RunReport, read alike by run, the report's records and JUnit: within
// its tolerance (or not applicable), with the lines that say why not, and why it is a known
// failure when tolerances.yaml lists it (then it does not fail a run).
struct MethodVerdict {
  bool within = true;
  // Compared with another method or a reference trajectory (a pair's method or base, a free
  // comparison); false where it ran alone (the others n/a): nothing to agree with.
  bool compared = false;
  std::vector<std::string> not_judged;  // PairComparison::not_judged, against its base
  std::string base;                     // what it was compared with (for not_judged's text)
  std::string known;                  // tolerances.yaml's reason, when listed and outside
  std::string known_where;            // its entry's "file:line" (listed and outside, or stale)
  // Listed as a known failure on the scene, yet it ran to the end and is within its tolerance: the
  // entry's reason (the entry is stale: "known failure no longer fails: remove the entry").
  std::string stale;
  std::vector<std::string> problems;  // the report's lines about this method (problems and known)
};
MethodVerdict VerdictOf(const RunReport& report, const std::string& method);
// The methods of `report` that are outside their tolerance and listed as known failures on its
// scene (VerdictOf), in registry order: "all methods agree … except" these.
std::vector<std::string> KnownFailures(const RunReport& report);

// `run --csv`: every method's trajectory in long format, one row per (method, sample, coordinate)
// under the header kTrajectoryCsvHeader. `residual` is the sample's scaled ‖Φ‖ measured alike for
// every method (ScaledResiduals, the same number as max_residual); a value a method does not give
// (q̈ at an engine's t0) is an empty cell, never a number; names are quoted as RFC 4180 says.
inline constexpr const char* kTrajectoryCsvHeader = "scenario,method,sample,t,coordinate,q,qd,qdd,residual";
void WriteTrajectoryCsv(std::ostream& out, const Model& model, const RunReport& report);

}  // namespace mechbench::harness
