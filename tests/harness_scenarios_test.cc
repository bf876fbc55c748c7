// Scenario × method suites over every built-in scenario file. A method that cannot do a scene
// is skipped with its own reason; tolerances come from harness/tolerances.yaml.
#include "mechbench/harness/compare.h"
#include "mechbench/harness/registry.h"
#include "mechbench/harness/tolerances.h"
#include "mechbench/loader.h"
#include "mechbench/numeric/constraints.h"
#include "mechbench/numeric/natural_data.h"
#include "mechbench/numeric/natural_model.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <iostream>

namespace mechbench::harness {
namespace harness_scenarios_test {  // this file's own names (the tests build in unity batches)
namespace {

std::vector<std::string> ScenarioNames() {
  std::vector<std::string> names;
  for (const auto& f : BuiltinScenarioFiles()) names.push_back(std::filesystem::path(f).stem().string());
  return names;
}

std::vector<std::string> MethodNames() {
  std::vector<std::string> names;
  for (const auto& m : AllMethods()) names.push_back(m->name());
  return names;
}

const Method& FindMethod(const std::vector<MethodPtr>& all, const std::string& name) {
  for (const auto& m : all)
    if (m->name() == name) return *m;
  throw std::runtime_error("no method " + name);
}

// MECHBENCH_VERBOSE=1 prints the measured numbers even when a test passes.
bool Verbose() { return std::getenv("MECHBENCH_VERBOSE") != nullptr; }

using ScenarioMethod = std::tuple<std::string, std::string>;

class ScenarioMethodTest : public ::testing::TestWithParam<ScenarioMethod> {};

// Every applicable method runs the whole motion, ends ok and keeps the loop closed to its own
// bound (tolerances.yaml: exact methods 1e-10, integrators per variant, free motions per method).
TEST_P(ScenarioMethodTest, RunsAndKeepsLoopClosed) {
  const auto& [scenario, method_name] = GetParam();
  const Model model = LoadScenario(ResolveScenario(scenario));
  const auto methods = AllMethods();
  const Method& method = FindMethod(methods, method_name);
  if (auto why = method.Applicability(model)) GTEST_SKIP() << *why;
  const Result r = method.Run(model);
  ASSERT_EQ(r.status, Status::kOk) << r.reason;
  ASSERT_FALSE(r.trajectory.empty());
  // A kinematic method gives a free scene's instant only (its motion is forward dynamics).
  const bool instant_only = !model.analysis.HasMotion() || (model.IsFree() && r.trajectory.size() == 1);
  EXPECT_EQ(static_cast<int>(r.trajectory.size()), instant_only ? 1 : model.analysis.samples);
  const Tolerances tol = LoadTolerances(model.name);
  const bool dynamics = model.IsFree() && r.trajectory.size() > 1;
  const double bound = dynamics ? tol.ForFree(method_name).residual : tol.For(method_name).residual;
  const numeric::NaturalModel nm = numeric::Compile(model);
  numeric::NaturalData data(nm);
  double worst = 0;
  for (const Sample& s : r.trajectory) {
    ASSERT_EQ(s.q.size(), static_cast<long>(model.q_layout.size()));
    numeric::EvalPhi(nm, data, s.q, s.t);
    worst = std::max(worst, numeric::ScaledResidual(nm, data));
  }
  if (Verbose()) std::cout << scenario << " " << method_name << " max scaled |Phi| = " << worst << "\n";
  if (tol.KnownFailure(method_name)) return;  // judged with its comparison below
  EXPECT_LE(worst, bound) << "constraint residual along the motion";
}

// Every applicable method agrees with the reference (the analytic method, or the numeric one
// where the analytic cannot do the scene; for a free scene's motion, the reference trajectory)
// within its own tolerance. A known failure must still fail: the finding stays visible, and a
// fix shows up here as a test to update.
TEST_P(ScenarioMethodTest, AgreesWithReferenceWithinItsTolerance) {
  const auto& [scenario, method_name] = GetParam();
  if (method_name == "analytic") GTEST_SKIP() << "analytic is the reference";
  const Model model = LoadScenario(ResolveScenario(scenario));
  const auto all = AllMethods();
  if (auto why = FindMethod(all, method_name).Applicability(model)) GTEST_SKIP() << *why;
  std::vector<MethodPtr> two;
  const bool analytic_ok = !FindMethod(all, "analytic").Applicability(model);
  for (auto& m : AllMethods())
    if (m->name() == (analytic_ok ? "analytic" : "numeric") || m->name() == method_name) two.push_back(std::move(m));
  const Tolerances tol = LoadTolerances(model.name);
  const RunReport rep = RunScenario(model, two, {}, tol);
  if (const std::string* why = tol.KnownFailure(method_name)) {
    EXPECT_FALSE(rep.known.empty()) << method_name << " on " << scenario
                                    << " now meets its tolerance; remove it from known_failures (" << *why << ")";
    return;
  }
  for (const auto& p : rep.problems) ADD_FAILURE() << p;
  if (Verbose())
    for (const auto& p : rep.pairs) std::cout << scenario << " " << p.method << " q " << p.q << " qd " << p.qd << " qdd " << p.qdd << "\n";
}

INSTANTIATE_TEST_SUITE_P(Builtin, ScenarioMethodTest,
                         ::testing::Combine(::testing::ValuesIn(ScenarioNames()), ::testing::ValuesIn(MethodNames())),
                         [](const auto& param_info) {
                           // GoogleTest names allow [A-Za-z0-9_] only: "ode-worldstep" -> "ode_worldstep".
                           std::string name = std::get<0>(param_info.param) + "__" + std::get<1>(param_info.param);
                           std::replace(name.begin(), name.end(), '-', '_');
                           return name;
                         });

class ScenarioTest : public ::testing::TestWithParam<std::string> {};

// The analytic vector method and the natural-coordinate solver agree along the whole motion.
TEST_P(ScenarioTest, AnalyticAgreesWithNumeric) {
  const Model model = LoadScenario(ResolveScenario(GetParam()));
  const auto all = AllMethods();
  std::vector<MethodPtr> two;
  for (const std::string name : {"analytic", "numeric"}) {
    const Method& m = FindMethod(all, name);
    if (auto why = m.Applicability(model)) GTEST_SKIP() << name << ": " << *why;
  }
  for (auto& m : AllMethods())
    if (m->name() == "analytic" || m->name() == "numeric") two.push_back(std::move(m));
  const Tolerances tol = LoadTolerances(model.name);
  const RunReport rep = RunScenario(model, two, {}, tol);
  for (const auto& p : rep.problems) ADD_FAILURE() << p;
  ASSERT_EQ(rep.pairs.size(), 1u);
  const PairComparison& p = rep.pairs[0];
  EXPECT_EQ(p.samples, model.analysis.HasMotion() && !model.IsFree() ? model.analysis.samples : 1);
  EXPECT_LE(p.q, tol.q) << p.worst_slot;
  EXPECT_LE(p.qd, tol.qd) << p.worst_slot;
  EXPECT_LE(p.qdd, tol.qdd) << p.worst_slot;
  if (Verbose()) std::cout << GetParam() << " q " << p.q << " qd " << p.qd << " qdd " << p.qdd << "\n";
}

// The solver's analytic Jacobian matches central finite differences at the instant.
TEST_P(ScenarioTest, JacobianMatchesFiniteDifferences) {
  const Model model = LoadScenario(ResolveScenario(GetParam()));
  const auto all = AllMethods();
  const Result r = FindMethod(all, "numeric").Run(model, {.motion = false});
  ASSERT_EQ(r.status, Status::kOk) << r.reason;
  const numeric::NaturalModel nm = numeric::Compile(model);
  numeric::NaturalData data(nm);
  const Eigen::VectorXd q = r.trajectory[0].q;
  const double t = r.trajectory[0].t;
  numeric::EvalJacobian(nm, data, q);
  const Eigen::MatrixXd J = data.Phi_q;
  Eigen::MatrixXd fd(J.rows(), J.cols());
  for (int j = 0; j < q.size(); ++j) {
    const double h = 1e-6 * std::max(1.0, std::fabs(q[j]));
    Eigen::VectorXd qp = q, qm = q;
    qp[j] += h;
    qm[j] -= h;
    numeric::EvalPhi(nm, data, qp, t);
    const Eigen::VectorXd fp = data.Phi;
    numeric::EvalPhi(nm, data, qm, t);
    fd.col(j) = (fp - data.Phi) / (2 * h);
  }
  const double scale = std::max(1.0, J.cwiseAbs().maxCoeff());
  EXPECT_LE((J - fd).cwiseAbs().maxCoeff() / scale, 1e-7) << "analytic\n" << J << "\nfinite differences\n" << fd;
}

INSTANTIATE_TEST_SUITE_P(Builtin, ScenarioTest, ::testing::ValuesIn(ScenarioNames()),
                         [](const auto& param_info) { return param_info.param; });

}  // namespace
}  // namespace harness_scenarios_test
}  // namespace mechbench::harness
