// mechbench_bench: the speed measurements of issue 4, registered programmatically over
// scenario × method (Google Benchmark). Setup is done outside the timed loops; each benchmark
// reports its accuracy as a counter beside the time.
//
//   kinematic/<method>/fourbar_crank_rocker
//       one position + velocity + acceleration sample of the §4.5 crank-rocker per iteration, at
//       a new crank angle (5° on) each time, starting from the previous sample. `error`: the
//       largest |q_numeric − q_analytic| / coordinate scale at the last sample timed.
//   kinematic/floor-3-lu, kinematic/floor-1-lu-3-solves
//       the sample's floor: its three 5 × 5 solves alone (Eigen's fixed-size LU on the scene's own
//       [Φ_q; B]), with three factorizations or one.
//   step/<method>/<dense|sparse>/nfourbar/N
//       one dynamics step (h = 1 ms) of the IFToMM N-four-bar against N, with the complexity fit,
//       through the solver's own pieces: dyn-baumgarte-rk4 as DynamicsSystem + Rk4Step (four
//       index-1 solves), dyn-ali3p as Ali3pStepper::Step (Newton + two projections), each with
//       dense or sparse linear algebra forced (the methods choose by size, see LinearAlgebra in forward_dynamics.h).
//       The start is built directly (the step alone is timed). `phi`: scaled ‖Φ‖ after the timed steps.
//   run/<dyn-ali3p|numeric>/nfourbar/N
//       a whole Method::Run of the N-four-bar (10 ms of motion; numeric: the instant) against
//       N = 1 … 10,000 with the complexity fit: set-up, rank checks and statistics included.
//   chain/<method>/nfourbar/N
//       every engine's *-default variant and dyn-ali3p, dyn-baumgarte-rk4 on the N-four-bar,
//       N = 1 … 1000, 0.1 s of motion from the generator's start (a sample every 10 ms), one
//       Method::Run each in its own process (harness::RunMethodIsolated) with a CPU budget of
//       kChainBudget s and a wall limit of kChainWall s: `us_per_step` (integration CPU / steps),
//       `ms_per_sim_s`, `setup_s`, `error` (CompareMotion's q against the exact motion,
//       references::NFourBarExact, over the samples reached), `reached_t`. A run that stops on its
//       budget is a row with its label "over budget at t = …"; a method that stopped at one N is
//       not run at the larger ones (the row says so).
//   accuracy/<method>[/<setting>]/fourbar_free
//       the whole 1 s motion of the free four-bar per iteration; `error`: CompareMotion's q
//       against the reference trajectory (numeric::ReferenceTrajectory, DOPRI5 at rtol 1e-12,
//       confirmed by coordinate partitioning). Every applicable method of harness::AllMethods()
//       at its default, the natural-coordinate formulations swept through RunOptions, the
//       engines' *-default variants at two more steps (tolerances).
//   accuracy/<method>[/<setting>]/a02_nfourbar_40
//       IFToMM A02, N = 40 over 20 s, per iteration; `error` against its reference (the reduced
//       equation, confirmed between the singular positions); the formulations at the settings
//       around 1e-3, or the row says where and why the formulation stopped.
#include "mechbench/motion_error.h"
#include "mechbench/compiled_expr.h"
#include "mechbench/expr.h"
#include "mechbench/analytic/linkage.h"
#include "mechbench/harness/isolated.h"
#include "mechbench/harness/registry.h"
#include "mechbench/harness/timing.h"
#include "mechbench/loader.h"
#include "mechbench/method.h"
#include "mechbench/model.h"
#include "mechbench/numeric/ali3p.h"
#include "mechbench/numeric/constraints.h"
#include "mechbench/numeric/dynamics_methods.h"
#include "mechbench/numeric/forward_dynamics.h"
#include "mechbench/numeric/natural_data.h"
#include "mechbench/numeric/natural_model.h"
#include "mechbench/references/nfourbar.h"
#include "mechbench/references/registry.h"
#include "mechbench/numeric/reference.h"
#include "mechbench/numeric/solver.h"

#include <benchmark/benchmark.h>

#include <Eigen/Core>
#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using namespace mechbench;

// ---- 1. kinematic sample on the §4.5 crank-rocker ---------------------------------------------

struct Kinematics {
  Model model;
  double dt = 0;  // one sample: 5° of crank at one turn per second
};

Kinematics& CrankRocker() {
  static Kinematics k = [] {
    Kinematics out{LoadScenario(ResolveScenario("fourbar_crank_rocker"))};
    out.dt = (out.model.analysis.t1 - out.model.analysis.t0) / (out.model.analysis.samples - 1);
    return out;
  }();
  return k;
}

// max_j |a_j − b_j| / scale_j
double ScaledDifference(const Eigen::VectorXd& a, const Eigen::VectorXd& b, const Eigen::VectorXd& scale) {
  return (a - b).cwiseAbs().cwiseQuotient(scale).maxCoeff();
}

// The analytic solution at t, in q_layout order (the cross-check of both kinematic benchmarks).
// The crank turns once per second, so t0 + k s is the file's configuration (θ = 60° + 2πk): the
// closed forms start there from the scenario's guesses and follow the branch by continuity in
// 5° steps up to t.
Eigen::VectorXd AnalyticQ(const Model& model, double t) {
  const analytic::LinkageSolver solver(model);
  const double dt = CrankRocker().dt;
  double tk = model.analysis.t0 + std::floor(t - model.analysis.t0);
  analytic::LinkageState s = solver.Solve(tk);
  while (tk + dt < t) {
    tk += dt;
    analytic::LinkageState next = solver.Solve(tk, &s);
    s = std::move(next);
  }
  const analytic::LinkageState last = solver.Solve(t, &s);
  Eigen::VectorXd q, qd, qdd;
  solver.ToLayout(last, q, qd, qdd);
  return q;
}

// Numeric: Newton–Raphson from the predicted q (q + q̇Δt + ½q̈Δt², as `numeric` does along a
// motion), then the velocity and acceleration problems. The model is compiled once.
void BM_KinematicNumeric(benchmark::State& state) {
  const Model& model = CrankRocker().model;
  const double dt = CrankRocker().dt;
  const numeric::NaturalModel nm = numeric::Compile(model);
  numeric::NaturalData data(nm);
  numeric::NewtonOptions newton;
  newton.record_iterates = false;
  double t = model.analysis.t0;
  numeric::SolveInstant(nm, data, t, model.GuessQ(), newton);
  newton.simplified = true;  // as `numeric` along a motion
  Eigen::VectorXd q_pred(nm.n);
  long iterations = 0, failures = 0;
  for (auto _ : state) {
    t += dt;
    q_pred = data.q + dt * data.qd + (0.5 * dt * dt) * data.qdd;
    const numeric::NewtonReport nr = numeric::SolvePosition(nm, data, q_pred, t, newton);
    iterations += nr.iterations;
    failures += !nr.converged;
    failures += numeric::SolveVelocity(nm, data, t) < nm.n;
    numeric::SolveAcceleration(nm, data, t);
    benchmark::DoNotOptimize(data.qdd.data());
    benchmark::ClobberMemory();
  }
  state.counters["error"] = ScaledDifference(data.q, AnalyticQ(model, t), nm.q_scale);
  state.counters["newton_its"] = static_cast<double>(iterations) / static_cast<double>(state.iterations());
  state.counters["failures"] = static_cast<double>(failures);
}

// Numeric with every check of an instant (rank by SVD, degrees of freedom, messages): what
// SolveInstant costs when it is called per sample.
void BM_KinematicNumericChecked(benchmark::State& state) {
  const Model& model = CrankRocker().model;
  const double dt = CrankRocker().dt;
  const numeric::NaturalModel nm = numeric::Compile(model);
  numeric::NaturalData data(nm);
  numeric::NewtonOptions newton;
  newton.record_iterates = false;
  double t = model.analysis.t0;
  numeric::SolveInstant(nm, data, t, model.GuessQ(), newton);
  Eigen::VectorXd q_pred(nm.n);
  for (auto _ : state) {
    t += dt;
    q_pred = data.q + dt * data.qd + (0.5 * dt * dt) * data.qdd;
    numeric::InstantReport rep = numeric::SolveInstant(nm, data, t, q_pred, newton);
    benchmark::DoNotOptimize(rep);
    benchmark::DoNotOptimize(data.qdd.data());
    benchmark::ClobberMemory();
  }
  state.counters["error"] = ScaledDifference(data.q, AnalyticQ(model, t), nm.q_scale);
}

// Analytic: LinkageSolver::Solve at the next instant from the previous state (closed-form dyads,
// branch by continuity), then the layout as q, q̇, q̈.
void BM_KinematicAnalytic(benchmark::State& state) {
  const Model& model = CrankRocker().model;
  const double dt = CrankRocker().dt;
  const analytic::LinkageSolver solver(model);
  double t = model.analysis.t0;
  analytic::LinkageState s = solver.Solve(t);
  Eigen::VectorXd q, qd, qdd;
  for (auto _ : state) {
    t += dt;
    analytic::LinkageState next = solver.Solve(t, &s);
    s = std::move(next);
    solver.ToLayout(s, q, qd, qdd);
    benchmark::DoNotOptimize(qdd.data());
    benchmark::ClobberMemory();
  }
  // Cross-check against the numeric solver at the same instant.
  const numeric::NaturalModel nm = numeric::Compile(model);
  numeric::NaturalData data(nm);
  numeric::NewtonOptions newton;
  newton.record_iterates = false;
  numeric::SolveInstant(nm, data, t, q, newton);
  state.counters["error"] = ScaledDifference(q, data.q, nm.q_scale);
  state.counters["residual"] = s.residual;
}

// The floor of a kinematic sample by natural coordinates: the three n × n linear solves
// (position, velocity, acceleration) of the §4.5 four-bar with nothing around them, by Eigen's
// fixed-size LU with partial pivoting on the scene's own augmented matrix [Φ_q; B] at its start.
// `factorizations` = 3: each solve factors its own matrix (one Newton step, then the velocity and
// acceleration problems each with a fresh factorization); 1: one factorization and three
// triangular solves (the least any sample can do). A small change of the matrix each iteration
// keeps the compiler from hoisting the work.
template <int N>
void FloorSolves(benchmark::State& state, const Eigen::MatrixXd& A0, int factorizations) {
  using Mat = Eigen::Matrix<double, N, N>;
  using Vec = Eigen::Matrix<double, N, 1>;
  Mat A = A0;
  Vec b = Vec::LinSpaced(1.0, 2.0), x = Vec::Zero();
  double eps = 0;
  for (auto _ : state) {
    eps = eps > 1e-9 ? 0.0 : eps + 1e-12;
    A(0, 0) = A0(0, 0) + eps;
    Eigen::PartialPivLU<Mat> lu(A);
    x = lu.solve(b);
    for (int k = 1; k < 3; ++k) {
      if (factorizations == 3) {
        A(0, 0) += 1e-13;
        lu.compute(A);
      }
      x += lu.solve(b + x * 1e-3);
    }
    benchmark::DoNotOptimize(x.data());
    benchmark::ClobberMemory();
  }
  state.counters["n"] = N;
}

void BM_KinematicFloor(benchmark::State& state, int factorizations) {
  const Model& model = CrankRocker().model;
  const numeric::NaturalModel nm = numeric::Compile(model);
  numeric::NaturalData data(nm);
  numeric::NewtonOptions newton;
  newton.record_iterates = false;
  numeric::SolveInstant(nm, data, model.analysis.t0, model.GuessQ(), newton);
  numeric::AssembleAugmented(nm, data);
  if (data.A.rows() != 5 || data.A.cols() != 5) {
    state.SkipWithError("the floor is written for the §4.5 four-bar's 5 × 5 augmented matrix");
    return;
  }
  FloorSolves<5>(state, data.A, factorizations);
}

// ---- 2. one dynamics step against N (IFToMM N-four-bar) -------------------------------------

constexpr double kStepH = 1e-3;

// The N-four-bar's start without the set-up a Method run does (SolveInstant and the rank of Φ_q;
// run/… below times those): every coupler point at (i, 1) moving at 1 m/s along +x
// is the assembled state exactly, and every row of Φ_q is independent there.
struct NFourBarStep {
  Model model;
  numeric::NaturalModel nm;
  std::unique_ptr<numeric::DynamicsSystem> sys;
  Eigen::VectorXd q0, qd0, qdd0, lambda0;
  NFourBarStep(int n_bars, numeric::LinearAlgebra la)
      : model(references::NFourBar({.n = n_bars, .t1 = 1.0, .samples = 2})), nm(numeric::Compile(model)) {
    sys = std::make_unique<numeric::DynamicsSystem>(nm, la);
    q0 = qd0 = Eigen::VectorXd::Zero(nm.n);
    for (int i = 0; i <= n_bars; ++i) {
      q0[model.SlotIndex("xP" + std::to_string(i))] = i;
      q0[model.SlotIndex("yP" + std::to_string(i))] = 1;
      qd0[model.SlotIndex("xP" + std::to_string(i))] = 1;
    }
    std::string why;
    if (!sys->Accelerations(q0, qd0, 0, 0, qdd0, lambda0, &why)) throw std::runtime_error(why);
  }
};

numeric::LinearAlgebra Algebra(bool sparse) { return sparse ? numeric::LinearAlgebra::kSparse : numeric::LinearAlgebra::kDense; }

// dyn-baumgarte-rk4's step through the solver's pieces: the index-1 matrix (dense LU or sparse LU)
// four times in an RK4 step. The state returns to t0 every kReset steps so that a long benchmark
// never reaches the singular horizontal positions (the first is 0.72 s away).
constexpr int kReset = 500;

void BM_StepRk4(benchmark::State& state, bool sparse) {
  const int n_bars = static_cast<int>(state.range(0));
  NFourBarStep s(n_bars, Algebra(sparse));
  numeric::DynamicsSystem& sys = *s.sys;
  const numeric::BaumgarteOptions bo;
  const int n = sys.n();
  Eigen::VectorXd qdd, lambda;
  const numeric::OdeRhs f = [&](double, const Eigen::VectorXd& y, Eigen::VectorXd& dy, std::string& why) {
    if (!sys.Accelerations(y.head(n), y.tail(n), bo.alpha, bo.beta, qdd, lambda, &why)) return false;
    dy.resize(2 * n);
    dy.head(n) = y.tail(n);
    dy.tail(n) = qdd;
    return true;
  };
  Eigen::VectorXd y0(2 * n);
  y0 << s.q0, s.qd0;
  Eigen::VectorXd y = y0;
  numeric::OdeStats stats;
  numeric::Rk4Scratch scratch;
  std::string why;
  int k = 0;
  double t = 0;
  long failures = 0;
  for (auto _ : state) {
    if (++k == kReset) y = y0, t = 0, k = 0;
    failures += !numeric::Rk4Step(f, {}, t, kStepH, y, why, stats, &scratch);
    t += kStepH;
    benchmark::DoNotOptimize(y.data());
    benchmark::ClobberMemory();
  }
  state.SetComplexityN(n_bars);
  state.counters["n_coords"] = n;
  state.counters["phi"] = sys.ScaledPhi(y.head(n));
  state.counters["failures"] = static_cast<double>(failures);
}

// dyn-ali3p's step (Ali3pStepper::Step, the method's own): Newton on the tangent matrix (dense
// LDLᵀ or sparse SimplicialLDLT), then the two projections.
void BM_StepAli3p(benchmark::State& state, bool sparse) {
  const int n_bars = static_cast<int>(state.range(0));
  NFourBarStep s(n_bars, Algebra(sparse));
  numeric::Ali3pOptions options;
  options.linear_algebra = Algebra(sparse);
  auto stepper = std::make_unique<numeric::Ali3pStepper>(*s.sys, options, kStepH, s.lambda0);
  Eigen::VectorXd q = s.q0, qd = s.qd0, qdd = s.qdd0;
  std::string why;
  int k = 0;
  long failures = 0;
  for (auto _ : state) {
    if (++k == kReset) {
      state.PauseTiming();
      q = s.q0, qd = s.qd0, qdd = s.qdd0, k = 0;
      stepper = std::make_unique<numeric::Ali3pStepper>(*s.sys, options, kStepH, s.lambda0);
      state.ResumeTiming();
    }
    failures += !stepper->Step(kStepH, q, qd, qdd, why);
    benchmark::DoNotOptimize(q.data());
    benchmark::ClobberMemory();
  }
  state.SetComplexityN(n_bars);
  state.counters["n_coords"] = s.nm.n;
  state.counters["newton_its"] = static_cast<double>(stepper->iterations()) / std::max(1, k);
  state.counters["phi"] = s.sys->ScaledPhi(q);
  state.counters["failures"] = static_cast<double>(failures);
}

// ---- 2b. a whole Method::Run against N (IFToMM N-four-bar) --------------------------------------

// Method::Run on the N-four-bar over 10 ms (10 steps of 1 ms for dyn-ali3p; the instant for
// numeric): everything a run does, set-up included (compile, the start assembled by SolveInstant
// and its rank checks, DynamicsSystem, the statistics at the samples), so that any part that grows
// faster than N shows in the fit. The model is built outside the timed loop. `cpu_s` is the last
// run's own CPU time (Result::cpu_seconds), `setup_s` its set-up phase.
void BM_Run(benchmark::State& state, std::shared_ptr<const Method> method) {
  const int n_bars = static_cast<int>(state.range(0));
  const Model model = references::NFourBar({.n = n_bars, .t1 = 0.01, .samples = 2});
  Result r;
  for (auto _ : state) {
    r = method->Run(model);
    benchmark::DoNotOptimize(r.trajectory.data());
  }
  if (!r.ok()) {
    state.SkipWithError((std::string(ToString(r.status)) + ": " + r.reason).c_str());
    return;
  }
  state.SetComplexityN(n_bars);
  state.counters["n_coords"] = static_cast<double>(model.q_layout.size());
  state.counters["cpu_s"] = r.cpu_seconds;
  state.counters["setup_s"] = r.cpu.setup;
  state.counters["samples"] = static_cast<double>(r.trajectory.size());
}

// ---- 2c. every engine on long closed chains (issue 14) ----------------------------------------

constexpr double kChainBudget = 5.0;  // CPU seconds per run (RunOptions::cpu_budget)
constexpr double kChainWall = 60.0;   // wall seconds per child (a step or a set-up past the budget)

struct ChainScene {
  Model model;
  std::vector<Sample> reference;  // the exact motion at the model's samples
};

// The N-four-bar over 0.1 s and its exact motion, built once per N (outside any timed run).
const ChainScene& ChainSceneFor(int n_bars) {
  static std::map<int, std::unique_ptr<ChainScene>> scenes;
  std::unique_ptr<ChainScene>& s = scenes[n_bars];
  if (!s) {
    s = std::make_unique<ChainScene>();
    s->model = references::NFourBar({.n = n_bars, .t1 = 0.1, .samples = 11});
    s->reference = references::NFourBarExact(s->model, 1e-12).trajectory;
  }
  return *s;
}

void BM_Chain(benchmark::State& state, std::shared_ptr<const Method> method) {
  const int n_bars = static_cast<int>(state.range(0));
  // A method that stopped at a smaller N (budget, wall limit, failure) is not run again.
  static std::map<std::string, std::string> stopped;
  auto it = stopped.find(method->name());
  if (it != stopped.end()) {
    state.SkipWithError(("not run: " + it->second).c_str());
    return;
  }
  const ChainScene& scene = ChainSceneFor(n_bars);
  if (auto why = method->Applicability(scene.model)) {
    state.SkipWithError(("not applicable: " + *why).c_str());
    return;
  }
  // The method's one-time costs, paid once in this process on N = 1 (the children inherit it).
  harness::WarmUp(*method, ChainSceneFor(1).model);
  RunOptions options;
  options.cpu_budget = kChainBudget;
  Result r;
  for (auto _ : state) {
    r = harness::RunMethodIsolated(*method, scene.model, options, kChainWall, /*warm_up=*/true).result;
    state.SetIterationTime(r.cpu_seconds);
  }
  const bool partial = r.status == Status::kOverBudget;
  if (!(r.ok() || partial) || r.trajectory.size() < 2) {
    const std::string why = std::string(ToString(r.status)) + ": " + r.reason;
    stopped[method->name()] = why + " (at N = " + std::to_string(n_bars) + ")";
    state.SkipWithError(why.c_str());
    return;
  }
  const size_t n = std::min(scene.reference.size(), r.trajectory.size());
  const std::vector<Sample> ref_span(scene.reference.begin(), scene.reference.begin() + static_cast<long>(n));
  const MotionError e = CompareMotion(scene.model, ScaleOfMotion(scene.model, scene.reference), ref_span, r.trajectory);
  const double reached = r.trajectory.back().t - scene.model.analysis.t0;
  state.SetComplexityN(n_bars);
  state.counters["error"] = e.q.max;
  state.counters["setup_s"] = r.cpu.setup;
  state.counters["integration_s"] = r.cpu.integration;
  state.counters["reached_t"] = reached;
  state.counters["ms_per_sim_s"] = reached > 0 ? 1e3 * r.cpu.integration / reached : kNaN;
  state.counters["steps"] = static_cast<double>(r.steps);
  state.counters["us_per_step"] = r.steps > 0 ? 1e6 * r.cpu.integration / static_cast<double>(r.steps) : kNaN;
  if (partial) {
    char label[96];
    std::snprintf(label, sizeof label, "over budget at t = %.3g s of %.3g s", r.trajectory.back().t,
                  scene.model.analysis.t1);
    state.SetLabel(label);
    stopped[method->name()] = std::string(label) + " at N = " + std::to_string(n_bars);
  }
}

// ---- 3. CPU time against accuracy: the free four-bar and A02 -----------------------------------

struct FreeScene {
  std::string label;
  Model model;
  numeric::Reference reference;
};

FreeScene& FourbarFree() {
  static FreeScene s = [] {
    FreeScene out{"fourbar_free", LoadScenario(ResolveScenario("fourbar_free")), {}};
    out.reference = numeric::ReferenceTrajectory(out.model);
    return out;
  }();
  return s;
}

// IFToMM A02: the N-four-bar with N = 40 over 20 s (scenarios/benchmarks/a02_nfourbar_40.yaml is
// the same mechanism and motion as a file, sampled at the specification's 400 output steps; the
// benchmark keeps 200, the figures in the README). Its reference is the reduced equation, confirmed between the singular
// positions (references::ReferenceFor, about 4 s to compute once).
FreeScene& A02() {
  static FreeScene s = [] {
    FreeScene out{"a02_nfourbar_40", references::NFourBar({.n = 40, .t1 = 20, .samples = 201}), {}};
    out.reference = references::ReferenceFor(out.model);
    return out;
  }();
  return s;
}

void BM_Accuracy(benchmark::State& state, FreeScene* scene, std::shared_ptr<const Method> method, RunOptions options) {
  Result r;
  for (auto _ : state) {
    r = method->Run(scene->model, options);
    benchmark::DoNotOptimize(r.trajectory.data());
  }
  if (!r.ok()) {
    state.SkipWithError((std::string(ToString(r.status)) + ": " + r.reason).c_str());
    return;
  }
  state.counters["error"] = CompareMotion(scene->model, scene->reference.trajectory(), r.trajectory).q.max;
  state.counters["cpu_s"] = r.cpu_seconds;  // the last run's own CPU time (Result::cpu_seconds)
  // Its phases (Result::cpu), for the cross-check with the report's sweep (scripts/timing_crosscheck.py).
  state.counters["setup_s"] = r.cpu.setup;
  state.counters["integration_s"] = r.cpu.integration;
  state.counters["observation_s"] = r.cpu.observation;
  auto steps = r.quantities.find("steps");
  if (steps != r.quantities.end()) state.counters["steps"] = steps->second;
}

// ---- 5. the adapters' own overhead ---------------------------------------------------------------

// The same motion at the same step, run twice per iteration: as the scene asks (a sample every
// 10 ms, each observed back into q, q̇, q̈) and "bare" (the same span as one sample interval: the
// adapter's stepping loop with nothing observed between t0 and the end). Manual time: the
// observed run's integration + observation CPU (Result::cpu); counters: the bare run's integration
// CPU, the overhead (integration + observation) / bare − 1 from sums over the iterations (only when
// both runs took the same steps: an error-controlled integrator that lands on every sample takes
// more, smaller steps than one left to itself, and then no bare run does the same work), and
// observation / integration within the observed run.
void BM_Overhead(benchmark::State& state, const Model* scene, std::shared_ptr<const Method> method) {
  Model bare = *scene;
  bare.analysis.samples = 2;
  double observed_sum = 0, bare_sum = 0, observation_sum = 0;
  Result r, b;
  for (auto _ : state) {
    r = method->Run(*scene);
    b = method->Run(bare);
    const double observed = r.cpu.integration + r.cpu.observation;
    observed_sum += observed;
    observation_sum += r.cpu.observation;
    bare_sum += b.cpu.integration;
    state.SetIterationTime(observed);
  }
  if (!r.ok() || !b.ok()) {
    state.SkipWithError((std::string(ToString(r.ok() ? b.status : r.status)) + ": " + (r.ok() ? b.reason : r.reason)).c_str());
    return;
  }
  const double n = static_cast<double>(state.iterations());
  state.counters["bare_ms"] = bare_sum / n * 1e3;
  state.counters["observation_ms"] = observation_sum / n * 1e3;
  state.counters["overhead_pct"] = r.steps == b.steps ? 100 * (observed_sum / bare_sum - 1) : kNaN;
  state.counters["observation_pct"] = 100 * observation_sum / (observed_sum - observation_sum);
  state.counters["steps"] = static_cast<double>(r.steps);
  state.counters["bare_steps"] = static_cast<double>(b.steps);
  state.counters["samples"] = static_cast<double>(r.trajectory.size());
}

std::string Sci(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

bool IsFormulation(const std::string& name) { return name.rfind("dyn-", 0) == 0; }
bool IsEngineDefault(const std::string& name) {
  return !IsFormulation(name) && name.size() > 8 && name.compare(name.size() - 8, 8, "-default") == 0;
}

void RegisterAll() {
  // 1.
  benchmark::RegisterBenchmark("kinematic/numeric/fourbar_crank_rocker", BM_KinematicNumeric)
      ->Unit(benchmark::kNanosecond);
  benchmark::RegisterBenchmark("kinematic/numeric-SolveInstant/fourbar_crank_rocker", BM_KinematicNumericChecked)
      ->Unit(benchmark::kNanosecond);
  benchmark::RegisterBenchmark("kinematic/analytic/fourbar_crank_rocker", BM_KinematicAnalytic)
      ->Unit(benchmark::kNanosecond);
  benchmark::RegisterBenchmark("kinematic/floor-3-lu/fourbar_crank_rocker", BM_KinematicFloor, 3)
      ->Unit(benchmark::kNanosecond);
  benchmark::RegisterBenchmark("kinematic/floor-1-lu-3-solves/fourbar_crank_rocker", BM_KinematicFloor, 1)
      ->Unit(benchmark::kNanosecond);

  // 2. Sparse up to N = 1000 (linear), dense up to N = 64 (cubic: 27 ms per RK4 step at N = 128).
  const std::vector<long> sparse_ns = {1, 2, 4, 8, 16, 32, 64, 128, 256, 512, 1000};
  const std::vector<long> dense_ns = {1, 2, 4, 8, 16, 32, 64};
  for (const bool sparse : {false, true}) {
    const std::string la = sparse ? "sparse" : "dense";
    auto* rk4 = benchmark::RegisterBenchmark(("step/dyn-baumgarte-rk4/" + la + "/nfourbar").c_str(), BM_StepRk4, sparse);
    auto* ali = benchmark::RegisterBenchmark(("step/dyn-ali3p/" + la + "/nfourbar").c_str(), BM_StepAli3p, sparse);
    for (auto* b : {rk4, ali}) {
      for (long n : sparse ? sparse_ns : dense_ns) b->Arg(n);
      b->ArgName("N")->Unit(benchmark::kMicrosecond)->Complexity();
    }
  }

  // 2b. The whole run against N = 1 … 10,000 (n = 4 … 20,002 coordinates), fitted.
  for (MethodPtr& m : harness::AllMethods()) {
    if (m->name() != "dyn-ali3p" && m->name() != "numeric") continue;
    std::shared_ptr<const Method> method(std::move(m));
    auto* b = benchmark::RegisterBenchmark(("run/" + method->name() + "/nfourbar").c_str(), BM_Run, method);
    for (long n : {1, 10, 100, 300, 1000, 3000, 10000}) b->Arg(n);
    b->ArgName("N")->Unit(benchmark::kMillisecond)->Complexity();
  }

  // 2c. Every engine's default variant and two formulations on the N-four-bar, N = 1 … 1000.
  for (MethodPtr& m : harness::AllMethods()) {
    const std::string name = m->name();
    if (!IsEngineDefault(name) && name != "dyn-ali3p" && name != "dyn-baumgarte-rk4") continue;
    std::shared_ptr<const Method> method(std::move(m));
    auto* b = benchmark::RegisterBenchmark(("chain/" + name + "/nfourbar").c_str(), BM_Chain, method);
    for (long n : {1, 4, 16, 64, 256, 1000}) b->Arg(n);
    // One run each, also under scripts/bench.sh's --benchmark_repetitions=5 (the family takes about
    // 1.5 min of CPU once; the over-budget rows are most of it).
    b->ArgName("N")->Iterations(1)->Repetitions(1)->UseManualTime()->Unit(benchmark::kMillisecond)->Complexity();
  }

  // 3. Every applicable method at its default on the free four-bar; the natural-coordinate
  // formulations swept through RunOptions (step or tolerance, Method::control()), the engines'
  // *-default variants at 10 ms and 1 ms (or tolerance 1e-4, 1e-6). The *-tuned variants run at
  // their default only: swept to 0.1 ms they take seconds per run.
  FreeScene& free = FourbarFree();
  FreeScene& a02 = A02();
  for (FreeScene* scene : {&free, &a02})
    if (!scene->reference.confirmed)
      std::fprintf(stderr, "warning: the %s reference is not confirmed: %s\n", scene->label.c_str(),
                   scene->reference.description.c_str());
  auto add = [](FreeScene& scene, const std::string& name, std::shared_ptr<const Method> m, RunOptions o = {}) {
    benchmark::RegisterBenchmark(("accuracy/" + name + "/" + scene.label).c_str(), BM_Accuracy, &scene, std::move(m), o)
        ->Unit(benchmark::kMillisecond);
  };
  std::vector<std::shared_ptr<const Method>> formulations;
  for (MethodPtr& m : harness::AllMethods()) {
    if (m->Applicability(free.model)) continue;  // an engine that cannot do the scene
    std::shared_ptr<const Method> method(std::move(m));
    const std::string name = method->name();
    // The kinematic methods (analytic, numeric) apply too but give the instant only.
    if (method->control() == Control::kNone) continue;
    add(free, name, method);  // a failing run shows as an error row
    if (IsFormulation(name)) formulations.push_back(method);
    if (method->control() == Control::kStep) {
      std::vector<double> steps;
      if (IsFormulation(name)) steps = {1e-2, 5e-3, 2e-3, 3e-4, 1e-4};  // 1 ms is the default row
      else if (IsEngineDefault(name)) steps = {1e-2, 1e-3};
      for (double h : steps)
        if (h != method->default_control()) add(free, name + "/step:" + Sci(h), method, {.step = h});
    } else {
      std::vector<double> tols;
      if (IsFormulation(name)) tols = {1e-4, 1e-6, 1e-10};  // 1e-8 is the default row
      else if (IsEngineDefault(name)) tols = {1e-4, 1e-6};
      for (double tol : tols)
        if (tol != method->default_control()) add(free, name + "/tol:" + Sci(tol), method, {.tolerance = tol});
    }
  }

  // 5. The adapters' overhead (BM_Overhead) at each engine default's own step, one sample per
  // 10 ms: the free four-bar (1 s) and A02's N = 40 chain over its first second.
  static const Model a02_1s = references::NFourBar({.n = 40, .t1 = 1.0, .samples = 101});
  for (MethodPtr& m : harness::AllMethods()) {
    if (!IsEngineDefault(m->name())) continue;
    std::shared_ptr<const Method> method(std::move(m));
    for (const Model* scene : std::initializer_list<const Model*>{&free.model, &a02_1s})
      if (!method->Applicability(*scene))
        benchmark::RegisterBenchmark(("overhead/" + method->name() + "/" + (scene == &a02_1s ? "a02_nfourbar_40_1s" : "fourbar_free")).c_str(),
                                     BM_Overhead, scene, method)
            ->UseManualTime()
            ->Unit(benchmark::kMillisecond);
  }

  // 4. A02 (N = 40, 20 s) to 1e-3 in position: each formulation at the settings on either side of
  // 1e-3 (measured: ALI3-P 1.2e-3 at 2 ms, 8.7e-4 at 1.75 ms; RK4 7.8e-3 at 20 ms, 1.1e-4 at 10 ms;
  // DOPRI5 3.1e-3 at rtol 3e-7, 8.6e-4 at 1e-7), and where a formulation stops instead (DOPRI5 at
  // its default rtol 1e-8 resolves a singular position and is stopped there, coordinate
  // partitioning cannot pass one): a row with an error message. The engines are not run on A02
  // here: their tuned variants take minutes on 81 bodies over 20 s.
  for (const std::shared_ptr<const Method>& method : formulations) {
    const std::string name = method->name();
    std::vector<RunOptions> runs;
    if (name == "dyn-ali3p") runs = {{.step = 2e-3}, {.step = 1.75e-3}, {.step = 1e-3}};
    else if (name == "dyn-baumgarte-rk4") runs = {{.step = 2e-2}, {.step = 1e-2}};
    else if (name == "dyn-baumgarte-dopri5") runs = {{.tolerance = 3e-7}, {.tolerance = 1e-7}, {.tolerance = 1e-8}};
    else runs = {{}};
    for (const RunOptions& o : runs) {
      std::string label = name;
      if (!std::isnan(o.step)) label += "/step:" + Sci(o.step);
      if (!std::isnan(o.tolerance)) label += "/tol:" + Sci(o.tolerance);
      add(a02, label, method, o);
    }
  }
}

// 6. Expressions (compiled_expr.h): one evaluation of a motion law and of a motor curve, as a
// value, with two t-derivatives (a driver's Jet2), with its gradient (a load's), and read anew
// from its text each time (expr.h's EvalExpr, what a per-call reader would cost).
const char* kLawText = "60 deg + 40 deg*sin(2*pi*t)";
const char* kMotorText = "0.5*(1 - qd/3)*exp(-0.1*t) + 0.01*q";
std::optional<CompiledExpr::Binding> BenchNames(const std::string& n) {
  if (n == "t") return CompiledExpr::Binding{0, 0};
  if (n == "q") return CompiledExpr::Binding{1, 0};
  if (n == "qd") return CompiledExpr::Binding{2, 0};
  return std::nullopt;
}
void BM_ExprValue(benchmark::State& state, const char* text) {
  const CompiledExpr e = CompiledExpr::Compile(text, BenchNames);
  double x[3] = {0.3, 0.2, 1.1};
  for (auto _ : state) {
    x[0] += 1e-9;
    benchmark::DoNotOptimize(e.Eval(x));
  }
}
void BM_ExprJet(benchmark::State& state, const char* text) {
  const CompiledExpr e = CompiledExpr::Compile(text, BenchNames);
  Jet2 x[3] = {{0.3, 1, 0}, {0.2, 0, 0}, {1.1, 0, 0}};
  for (auto _ : state) {
    x[0].v += 1e-9;
    benchmark::DoNotOptimize(e.Eval(x));
  }
}
void BM_ExprGradient(benchmark::State& state, const char* text) {
  const CompiledExpr e = CompiledExpr::Compile(text, BenchNames);
  double x[3] = {0.3, 0.2, 1.1}, g[CompiledExpr::kMaxVariables];
  for (auto _ : state) {
    x[0] += 1e-9;
    benchmark::DoNotOptimize(e.EvalGradient(x, g));
    benchmark::DoNotOptimize(g[0]);
  }
}
void BM_ExprReread(benchmark::State& state, const char* text) {
  double x[3] = {0.3, 0.2, 1.1};
  const VariableLookup lookup = [&](const std::string& n) -> std::optional<double> {
    if (auto b = BenchNames(n)) return x[b->variable];
    return std::nullopt;
  };
  for (auto _ : state) {
    x[0] += 1e-9;
    benchmark::DoNotOptimize(EvalExpr(text, lookup));
  }
}
BENCHMARK_CAPTURE(BM_ExprValue, law, kLawText);
BENCHMARK_CAPTURE(BM_ExprJet, law, kLawText);
BENCHMARK_CAPTURE(BM_ExprReread, law, kLawText);
BENCHMARK_CAPTURE(BM_ExprValue, motor, kMotorText);
BENCHMARK_CAPTURE(BM_ExprGradient, motor, kMotorText);
BENCHMARK_CAPTURE(BM_ExprReread, motor, kMotorText);

}  // namespace

int main(int argc, char** argv) {
  // A shorter minimum time than the library's 0.5 s keeps the whole run to about a minute per
  // repetition; a --benchmark_min_time given on the command line comes later and wins.
  std::vector<char*> args(argv, argv + argc);
  static char min_time[] = "--benchmark_min_time=0.2";
  args.insert(args.begin() + 1, min_time);
  args.push_back(nullptr);
  argc = static_cast<int>(args.size()) - 1;
  argv = args.data();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  RegisterAll();
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
