// mechbench_bench: the speed measurements of issue 4, registered programmatically over
// scenario × method (Google Benchmark). Setup is done outside the timed loops; each benchmark
// reports its accuracy as a counter beside the time.
//
//   kinematic/<method>/fourbar_crank_rocker
//       one position + velocity + acceleration sample of the §4.5 crank-rocker per iteration, at
//       a new crank angle (5° on) each time, starting from the previous sample. `error`: the
//       largest |q_numeric − q_analytic| / coordinate scale at the last sample timed.
//   step/<method>/nfourbar/N
//       one dynamics step (h = 1 ms) of the IFToMM N-four-bar against N, with the complexity fit.
//       dyn-baumgarte-rk4 is timed step by step through the solver's own pieces (DynamicsSystem,
//       Rk4Step); dyn-baumgarte-rk4 and dyn-ali3p are also timed through Method::Run as the CPU
//       difference of a long and a short run divided by the difference in steps (ALI3-P's step
//       is not exposed), so that the set-up (compile, assembly, rank) cancels. `phi`: scaled ‖Φ‖
//       at the end of the timed steps.
//   accuracy/<method>[/<setting>]/fourbar_free
//       the whole 1 s motion of the free four-bar per iteration; `error`: ComparePositions
//       against the reference trajectory (numeric::ReferenceTrajectory, DOPRI5 at rtol 1e-12,
//       confirmed by coordinate partitioning). Every applicable method of harness::AllMethods()
//       at its default, plus sweeps: the natural-coordinate formulations through their own
//       option structs, and any method that honours RunOptions::step / ::tolerance (it does when
//       its Result::settings change with them).
#include "mechbench/analytic/linkage.h"
#include "mechbench/harness/registry.h"
#include "mechbench/loader.h"
#include "mechbench/method.h"
#include "mechbench/model.h"
#include "mechbench/numeric/constraints.h"
#include "mechbench/numeric/dynamics_methods.h"
#include "mechbench/numeric/forward_dynamics.h"
#include "mechbench/numeric/natural_data.h"
#include "mechbench/numeric/natural_model.h"
#include "mechbench/numeric/nfourbar.h"
#include "mechbench/numeric/reference.h"
#include "mechbench/numeric/solver.h"

#include <benchmark/benchmark.h>

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <memory>
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

// ---- 2. one dynamics step against N (IFToMM N-four-bar) -------------------------------------

constexpr double kStepH = 1e-3;

// dyn-baumgarte-rk4's step through the solver's pieces: index-1 KKT (dense LU) in an RK4 step.
// The state returns to t0 every kReset steps so that a long benchmark never wanders into the
// singular horizontal positions (the first is about 1.5 s away).
void BM_StepRk4(benchmark::State& state) {
  const int n_bars = static_cast<int>(state.range(0));
  const Model model = numeric::NFourBar({.n = n_bars, .t1 = 1.0, .samples = 2});
  const numeric::NaturalModel nm = numeric::Compile(model);
  const numeric::FreeStart start = numeric::AssembleFreeStart(nm);
  numeric::DynamicsSystem sys(nm);
  sys.ChooseRows(start.q);
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
  y0 << start.q, start.qd;
  Eigen::VectorXd y = y0;
  numeric::OdeStats stats;
  std::string why;
  constexpr int kReset = 500;
  int k = 0;
  double t = 0;
  long failures = 0;
  for (auto _ : state) {
    if (++k == kReset) y = y0, t = 0, k = 0;
    failures += !numeric::Rk4Step(f, {}, t, kStepH, y, why, stats);
    t += kStepH;
    benchmark::DoNotOptimize(y.data());
    benchmark::ClobberMemory();
  }
  state.SetComplexityN(n_bars);
  state.counters["n_coords"] = n;
  state.counters["phi"] = sys.ScaledPhi(y.head(n));
  state.counters["failures"] = static_cast<double>(failures);
}

// A dynamics method through Method::Run: the CPU time of runs of kLong steps minus that of runs of
// kShort steps (both as Result::cpu_seconds), divided by kLong − kShort. The table's CPU column
// for these rows is the whole runs' (set-up included); the Time column is the step.
void BM_StepByRun(benchmark::State& state, const std::function<MethodPtr()>& make) {
  constexpr int kShort = 2, kLong = 12;
  const int n_bars = static_cast<int>(state.range(0));
  const MethodPtr method = make();
  const Model short_run = numeric::NFourBar({.n = n_bars, .t1 = kShort * kStepH, .samples = 2});
  const Model long_run = numeric::NFourBar({.n = n_bars, .t1 = kLong * kStepH, .samples = 2});
  const int pairs = std::max(1, 2000 / (n_bars * n_bars));
  double phi = kNaN;
  long failures = 0;
  for (auto _ : state) {
    double difference = 0;
    for (int k = 0; k < pairs; ++k) {
      const Result a = method->Run(short_run);
      const Result b = method->Run(long_run);
      failures += !a.ok() + !b.ok();
      difference += b.cpu_seconds - a.cpu_seconds;
      auto it = b.quantities.find("max_residual");
      if (it != b.quantities.end()) phi = it->second;
      benchmark::DoNotOptimize(b.trajectory.data());
    }
    state.SetIterationTime(std::max(0.0, difference) / (pairs * (kLong - kShort)));
  }
  state.SetComplexityN(n_bars);
  state.counters["phi"] = phi;
  state.counters["failures"] = static_cast<double>(failures);
}

// ---- 3. CPU time against accuracy on the free four-bar ---------------------------------------

struct FreeScene {
  Model model;
  numeric::Reference reference;
};

FreeScene& FourbarFree() {
  static FreeScene s = [] {
    FreeScene out{LoadScenario(ResolveScenario("fourbar_free")), {}};
    out.reference = numeric::ReferenceTrajectory(out.model);
    return out;
  }();
  return s;
}

void BM_Accuracy(benchmark::State& state, std::shared_ptr<const Method> method, RunOptions options) {
  const FreeScene& scene = FourbarFree();
  Result r;
  double cpu = 0;
  for (auto _ : state) {
    r = method->Run(scene.model, options);
    cpu += r.cpu_seconds;
    benchmark::DoNotOptimize(r.trajectory.data());
  }
  if (!r.ok()) {
    state.SkipWithError((std::string(ToString(r.status)) + ": " + r.reason).c_str());
    return;
  }
  const numeric::PositionError e =
      numeric::ComparePositions(scene.model, scene.reference.trajectory(), r.trajectory);
  state.counters["error"] = e.value;
  auto steps = r.quantities.find("steps");
  if (steps != r.quantities.end()) state.counters["steps"] = steps->second;
}

// Settings a RunOptions override leaves its mark on (any difference from the default run's).
bool Honours(const Method& method, const Model& model, const Result& base, RunOptions options) {
  const Result r = method.Run(model, options);
  return r.ok() && r.settings != base.settings;
}

std::string Sci(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.0e", v);
  return buf;
}

void RegisterAll() {
  // 1.
  benchmark::RegisterBenchmark("kinematic/numeric/fourbar_crank_rocker", BM_KinematicNumeric)
      ->Unit(benchmark::kNanosecond);
  benchmark::RegisterBenchmark("kinematic/numeric-SolveInstant/fourbar_crank_rocker", BM_KinematicNumericChecked)
      ->Unit(benchmark::kNanosecond);
  benchmark::RegisterBenchmark("kinematic/analytic/fourbar_crank_rocker", BM_KinematicAnalytic)
      ->Unit(benchmark::kNanosecond);

  // 2.
  const std::vector<long> ns = {1, 2, 4, 8, 16, 32, 64, 128};
  {
    auto* b = benchmark::RegisterBenchmark("step/dyn-baumgarte-rk4/nfourbar", BM_StepRk4);
    for (long n : ns) b->Arg(n);
    b->ArgName("N")->Unit(benchmark::kMicrosecond)->Complexity();
  }
  const std::vector<std::pair<std::string, std::function<MethodPtr()>>> by_run = {
      {"dyn-baumgarte-rk4", [] { return numeric::MakeBaumgarteRk4Method({.h = kStepH}); }},
      {"dyn-ali3p", [] { return numeric::MakeAli3pMethod({.h = kStepH}); }},
  };
  for (const auto& [name, make] : by_run) {
    auto* b = benchmark::RegisterBenchmark(("step-by-run/" + name + "/nfourbar").c_str(), BM_StepByRun, make);
    for (long n : ns) b->Arg(n);
    // One iteration of max(1, 2000/N²) run pairs: with manual time, a minimum time would count
    // only the steps' difference, and the runs' set-up (a dense SVD for the rank) would take 20–50×
    // longer than that.
    b->ArgName("N")->Unit(benchmark::kMicrosecond)->UseManualTime()->Iterations(1)->Complexity();
  }

  // 3.
  const FreeScene& scene = FourbarFree();
  if (!scene.reference.confirmed)
    std::fprintf(stderr, "warning: the fourbar_free reference is not confirmed: %s\n", scene.reference.description.c_str());
  auto add = [](const std::string& name, std::shared_ptr<const Method> m, RunOptions o = {}) {
    benchmark::RegisterBenchmark(("accuracy/" + name + "/fourbar_free").c_str(), BM_Accuracy, std::move(m), o)
        ->Unit(benchmark::kMillisecond);
  };
  for (MethodPtr& m : harness::AllMethods()) {
    if (m->Applicability(scene.model)) continue;  // an engine that cannot do the scene
    std::shared_ptr<const Method> method(std::move(m));
    const std::string name = method->name();
    const Result base = method->Run(scene.model);
    // The kinematic methods (analytic, numeric) apply too but give the instant only.
    if (base.ok() && base.trajectory.size() < scene.reference.trajectory().size()) continue;
    add(name, method);  // a failing run shows as an error row
    if (!base.ok()) continue;
    // Sweeps through RunOptions, for the methods that honour them.
    if (Honours(*method, scene.model, base, {.step = 1e-4}))
      for (double h : {1e-2, 1e-3, 1e-4}) add(name + "/step:" + Sci(h), method, {.step = h});
    if (Honours(*method, scene.model, base, {.tolerance = 1e-10}))
      for (double tol : {1e-4, 1e-6, 1e-8, 1e-10}) add(name + "/tol:" + Sci(tol), method, {.tolerance = tol});
  }
  // The natural-coordinate formulations through their own options (RunOptions is not honoured
  // by them yet); the defaults are the registry rows above.
  for (double h : {1e-2, 5e-3, 2e-3})  // ≥ 1e-2 is capped by the 10 ms samples
    add("dyn-baumgarte-rk4/h:" + Sci(h), numeric::MakeBaumgarteRk4Method({.h = h}));
  for (double rtol : {1e-4, 1e-6, 1e-10})
    add("dyn-baumgarte-dopri5/rtol:" + Sci(rtol), numeric::MakeBaumgarteDopri5Method({.rtol = rtol}));
  for (double h : {1e-2, 3e-4, 1e-4})
    add("dyn-ali3p/h:" + Sci(h), numeric::MakeAli3pMethod({.h = h}));
  for (double rtol : {1e-4, 1e-6, 1e-10})
    add("dyn-coordinate-partitioning/rtol:" + Sci(rtol), numeric::MakeCoordinatePartitioningMethod({.rtol = rtol}));
}

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
