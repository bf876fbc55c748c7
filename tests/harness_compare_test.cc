// The comparison of two methods' runs (compare.h): what counts as agreement.
#include "mechbench/harness/compare.h"

#include "mechbench/harness/reference.h"
#include "mechbench/harness/registry.h"
#include "mechbench/harness/tolerances.h"
#include "mechbench/loader.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <memory>

namespace mechbench::harness {
namespace harness_compare_test {  // this file's own names (the tests build in unity batches)
namespace {

// A method that gives a fixed result: the test decides what it computed.
class Given final : public Method {
 public:
  Given(std::string name, Result r) : Method(std::move(name), "a stand-in"), r_(std::move(r)) {}
  std::optional<std::string> Applicability(const Model&) const override { return std::nullopt; }

 protected:
  void DoRun(const Model&, const RunOptions&, Result& out) const override {
    out.trajectory = r_.trajectory;
    out.quantities = r_.quantities;
  }

 private:
  Result r_;
};

// A mechanism whose accelerations all vanish (a chain driven at constant speed): two methods that
// agree to round-off must agree, not be judged against a largest acceleration of 1e-16. Before
// the families of instant quantities had the motion's scale as a floor, such a run exited 1.
TEST(PairComparison, VanishingAccelerationsAreNotJudgedOnRoundOff) {
  const Model m = LoadScenario(std::string(MECHBENCH_TEST_DATA) + "/scenes/odd_names.yaml");
  Result exact;
  for (const MethodPtr& meth : AllMethods())
    if (meth->name() == "analytic") exact = meth->Run(m);
  ASSERT_TRUE(exact.ok()) << exact.reason;
  // The same positions and velocities, every acceleration zero in one and round-off in the other.
  Result zero = exact, noisy = exact;
  zero.quantities.clear(), noisy.quantities.clear();
  for (size_t k = 0; k < exact.trajectory.size(); ++k) {
    zero.trajectory[k].qdd.setZero();
    noisy.trajectory[k].qdd.setConstant(2.2e-16);
  }
  for (const char* a : {"a.A.x", "a.p,1.y", "alpha.rocker", "qdd. theta"}) {
    zero.quantities[a] = 0;
    noisy.quantities[a] = 1.1e-16;
  }
  zero.quantities["v.p,1.x"] = noisy.quantities["v.p,1.x"] = exact.quantities.at("v.p,1.x");
  std::vector<MethodPtr> methods;
  methods.push_back(std::make_unique<Given>("zero", zero));
  methods.push_back(std::make_unique<Given>("noisy", noisy));
  const RunReport rep = RunScenario(m, methods, {}, LoadTolerances(m.name));
  ASSERT_EQ(rep.pairs.size(), 1u);
  EXPECT_TRUE(rep.pairs[0].within) << rep.pairs[0].worst_acceleration_quantity << " " << rep.pairs[0].acceleration_quantity;
  EXPECT_LT(rep.pairs[0].acceleration_quantity, 1e-12);
  EXPECT_TRUE(rep.ok);
}

// Two methods that agree at t0 and part afterwards: the PROBLEM line's "at t0" part names a
// quantity that moves, never a fixed point's (newuser9/10: "...; at t0 p.B.x 0" named a pin).
TEST(PairComparison, AProblemLocatesNoFixedPointAtT0) {
  const Model m = LoadScenario(std::string(MECHBENCH_TEST_DATA) + "/scenes/odd_names.yaml");
  Result exact;
  for (const MethodPtr& meth : AllMethods())
    if (meth->name() == "analytic") exact = meth->Run(m);
  ASSERT_TRUE(exact.ok()) << exact.reason;
  // The points' positions and velocities only: the fixed pin A's p.A.x (0) comes first, where the
  // first of equal differences used to be named.
  for (auto it = exact.quantities.begin(); it != exact.quantities.end();)
    it = it->first.rfind("p.", 0) == 0 || it->first.rfind("v.", 0) == 0 ? std::next(it) : exact.quantities.erase(it);
  ASSERT_EQ(exact.quantities.begin()->first, "p.A.x");
  Result off = exact;  // the same instant, then each sample the next one's (assembled, ahead in time)
  for (size_t k = 1; k + 1 < off.trajectory.size(); ++k) {
    off.trajectory[k].q = exact.trajectory[k + 1].q;
    off.trajectory[k].qd = exact.trajectory[k + 1].qd;
    off.trajectory[k].qdd = exact.trajectory[k + 1].qdd;
  }
  std::vector<MethodPtr> methods;
  methods.push_back(std::make_unique<Given>("exact", exact));
  methods.push_back(std::make_unique<Given>("off", off));
  const RunReport rep = RunScenario(m, methods, {}, LoadTolerances(m.name));
  ASSERT_EQ(rep.pairs.size(), 1u);
  const PairComparison& p = rep.pairs[0];
  EXPECT_FALSE(p.within);
  EXPECT_EQ(p.quantity, 0);  // they agree at t0
  ASSERT_FALSE(p.worst_quantity.empty());
  for (const char* fixed : {".A.", ".B."}) EXPECT_EQ(p.worst_quantity.find(fixed), std::string::npos) << p.worst_quantity;
  EXPECT_NE(exact.quantities.at(p.worst_quantity), 0) << p.worst_quantity << " does not move";
  const auto line = std::find_if(rep.problems.begin(), rep.problems.end(),
                                 [](const std::string& l) { return l.rfind("off vs exact: ", 0) == 0; });
  ASSERT_NE(line, rep.problems.end());
  EXPECT_NE(line->find("; at t0 " + p.worst_quantity + " 0"), std::string::npos) << *line;
}

// With loads whose work is integrated between samples (a motor law, a damped torsion), the energy
// drift of even a reference motion is mostly the Hermite rule's error on the samples: the same
// confirmed reference of double_pendulum_torsion_motor drifts by far less on 10× the samples
// (O(h⁴): 10⁴ less, at least 10³ asked here). `run` says so with the spacing; a scene whose
// energy holds every load (gravity alone) gets no such note.
TEST(EnergyDrift, WithLoadLawsItIsMostlyTheSampleSpacing) {
  const Model m = LoadScenario(MECHBENCH_TEST_DATA "/scenes/double_pendulum_torsion_motor.yaml");
  Model fine = m;
  fine.analysis.samples = 10 * (m.analysis.samples - 1) + 1;
  const ReferenceRecord coarse = GetReference(m), finer = GetReference(fine);
  ASSERT_TRUE(coarse.confirmed && finer.confirmed) << coarse.description << finer.description;
  const double d_coarse = EnergyDrift(m, coarse.trajectory), d_fine = EnergyDrift(fine, finer.trajectory);
  EXPECT_GT(d_coarse, 1e3 * d_fine) << d_coarse << " J at 0.02 s, " << d_fine << " J at 0.002 s";
  EXPECT_NE(EnergyDriftNote(m).find("0.02 s apart"), std::string::npos) << EnergyDriftNote(m);
  EXPECT_NE(EnergyDriftNote(fine).find("0.002 s apart"), std::string::npos) << EnergyDriftNote(fine);
  EXPECT_EQ(EnergyDriftNote(LoadScenario(MECHBENCH_TEST_DATA "/scenes/pendulum_horizontal.yaml")), "");
}


std::vector<MethodPtr> Named(const std::vector<std::string>& names) {
  std::vector<MethodPtr> out;
  for (MethodPtr& m : AllMethods())
    if (std::find(names.begin(), names.end(), m->name()) != names.end()) out.push_back(std::move(m));
  return out;
}

// A run whose mechanism comes apart (ODE QuickStep on A01's lumped pendulum, a known failure:
// ‖Φ‖ 1e8) is diverged, whatever the engine reported, and still a row against the reference; it
// is never the base of the comparison, and it is named as the known failure it is.
TEST(RunScenario, AMechanismThatComesApartIsDivergedAndNeverTheBase) {
  const Model m = LoadScenario(std::string(MECHBENCH_TEST_DATA) + "/scenes/a01_pendulum_10s.yaml");
  // QuickStep comes first in the registry's order of these two: it would have been the base.
  std::vector<MethodPtr> methods = Named({"ode-quickstep-default", "mujoco-rk4-tuned"});
  if (methods.size() < 2) GTEST_SKIP() << "ODE or MuJoCo is not built";
  ASSERT_EQ(methods[0]->name(), "ode-quickstep-default");
  const Tolerances tol = LoadTolerances(m.name);
  ASSERT_NE(tol.KnownFailure("ode-quickstep-default"), nullptr);
  const RunReport rep = RunScenario(m, methods, {}, tol);
  const Result& quick = rep.results[0];
  EXPECT_EQ(quick.status, Status::kDiverged);
  EXPECT_NE(quick.reason.find("came apart"), std::string::npos) << quick.reason;
  EXPECT_GT(rep.max_residual.at(quick.method), kLoopOpenedResidual);
  // Its substitute inertia's note does not promise QuickStep the lag: QuickStep says it diverges.
  EXPECT_TRUE(std::any_of(quick.messages.begin(), quick.messages.end(), [](const std::string& s) {
    return s.find("dWorldQuickStep does not hold the joints") != std::string::npos;
  }));
  for (const PairComparison& p : rep.pairs) EXPECT_NE(p.reference, quick.method);
  // Still a row against the reference, with how far off it went.
  bool row = false;
  for (const FreeComparison& f : rep.free)
    if (f.method == quick.method) {
      row = true;
      EXPECT_GT(f.position, 1.0);
    }
  EXPECT_TRUE(row);
  EXPECT_TRUE(rep.ok) << "a known failure does not fail the run";
  EXPECT_EQ(KnownFailures(rep), std::vector<std::string>{"ode-quickstep-default"});
}

// Bad input stops every method on the same scene: numeric runs first and finds the driver out of
// reach; the others are not run (each would search the reach again) and carry its status and words.
TEST(RunScenario, BadInputFoundByNumericStopsTheOtherMethods) {
  const Model m = LoadScenario(MECHBENCH_TEST_DATA "/bad/121_spatial_driver_out_of_reach.yaml");
  const std::vector<MethodPtr> methods = Named({"analytic", "mujoco-rk4-tuned", "numeric"});
  ASSERT_GE(methods.size(), 2u);
  const std::vector<Result> results = RunMethods(m, methods, {}, {}, false);
  ASSERT_EQ(results.size(), methods.size());
  const auto numeric = std::find_if(results.begin(), results.end(), [](const Result& r) { return r.method == "numeric"; });
  ASSERT_NE(numeric, results.end());
  EXPECT_EQ(numeric->status, Status::kInvalidScenario);
  EXPECT_NE(numeric->reason.find("out of the mechanism's reach"), std::string::npos) << numeric->reason;
  EXPECT_TRUE(numeric->messages.empty() || numeric->messages[0].rfind("not run", 0) != 0);
  for (size_t i = 0; i < results.size(); ++i) {
    EXPECT_EQ(results[i].method, methods[i]->name()) << "results keep the methods' order";
    if (results[i].method == "numeric") continue;
    EXPECT_EQ(results[i].status, Status::kInvalidScenario) << results[i].method;
    EXPECT_EQ(results[i].reason, numeric->reason);
    ASSERT_FALSE(results[i].messages.empty());
    EXPECT_EQ(results[i].messages.back(), "not run: numeric found the scene to be bad input, which stops every method");
  }
}

// On a free scene the methods share only t0, where q and q̇ are the initial state they were all
// given: the pair says it compared the instant only, and an engine's missing q̈ is not a 0.
TEST(RunScenario, AFreeScenesPairsSayTheyCompareTheInstantOnly) {
  const Model m = LoadScenario(std::string(MECHBENCH_TEST_DATA) + "/scenes/pendulum_user_plain.yaml");
  std::vector<MethodPtr> methods = Named({"dyn-baumgarte-rk4", "ode-worldstep-default"});
  if (methods.size() < 2) GTEST_SKIP() << "ODE is not built";
  const RunReport rep = RunScenario(m, methods, {}, LoadTolerances(m.name));
  ASSERT_EQ(rep.pairs.size(), 1u);
  EXPECT_TRUE(rep.pairs[0].instant_only);
  EXPECT_FALSE(rep.pairs[0].qdd_compared) << "ODE has no q̈ at t0";
  EXPECT_EQ(rep.free.size(), 2u) << "the motions are judged against the reference";
  EXPECT_TRUE(KnownFailures(rep).empty());
}

}  // namespace
}  // namespace harness_compare_test
}  // namespace mechbench::harness

namespace mechbench::harness {
namespace harness_compare_test {  // this file's own names (the tests build in unity batches)
namespace {

// A q̈ 300 % off where the method has no bound for it (∞ in tolerances.yaml): measured and named
// as not judged (PairComparison::not_judged, MethodVerdict::not_judged), so that `run` never
// prints "ok" or "within" beside it; q and q̇, which have bounds, are still judged.
TEST(RunScenario, AnUnboundedQddIsNotJudgedNeverWithin) {
  const Model m = LoadScenario(ResolveScenario("fourbar_crank_rocker"));
  std::vector<MethodPtr> exact = Named({"numeric"});
  ASSERT_EQ(exact.size(), 1u);
  Result given = exact[0]->Run(m, {});
  ASSERT_TRUE(given.ok()) << given.reason;
  for (Sample& s : given.trajectory) s.qdd *= 4;  // 300 % off
  given.quantities.clear();
  std::vector<MethodPtr> methods;
  methods.push_back(std::move(exact[0]));
  methods.push_back(std::make_unique<Given>("stand-in", given));
  Tolerances tol = LoadTolerances(m.name);
  Agreement a = tol.For("stand-in");
  a.qdd = std::numeric_limits<double>::infinity();
  tol.methods["stand-in"] = a;
  const RunReport rep = RunScenario(m, methods, {}, tol);
  ASSERT_EQ(rep.pairs.size(), 1u);
  const PairComparison& p = rep.pairs[0];
  EXPECT_GT(p.qdd, 1.0);
  EXPECT_TRUE(p.within) << "q and q̇ are within";
  ASSERT_EQ(p.not_judged.size(), 1u);
  EXPECT_EQ(p.not_judged[0].rfind("q̈ ", 0), 0u) << p.not_judged[0];
  const MethodVerdict v = VerdictOf(rep, "stand-in");
  EXPECT_TRUE(v.compared);
  EXPECT_EQ(v.not_judged, p.not_judged);
  EXPECT_EQ(v.base, "numeric");
  // With a bound, the same q̈ is judged, and outside.
  tol.methods["stand-in"].qdd = 1e-9;
  const RunReport judged = RunScenario(m, methods, {}, tol);
  EXPECT_FALSE(judged.pairs.at(0).within);
  EXPECT_TRUE(judged.pairs.at(0).not_judged.empty());
}

// A spatial scene that only numeric runs among the methods asked for (a driven rotor, no loop:
// analytic has no closed form for it, the dynamics formulations do not take a driven scene; MuJoCo,
// which would run it, is not asked): no pair, nothing compared, so no method "agrees" with anything.
TEST(RunScenario, AMethodThatRanAloneWasNotCompared) {
  const Model m = LoadScenario(MECHBENCH_TEST_DATA "/scenes/spatial_rotor_driven.yaml");
  std::vector<MethodPtr> methods;
  for (MethodPtr& meth : AllMethods())
    if (meth->name() == "numeric" || meth->name() == "analytic" || meth->name().rfind("dyn-", 0) == 0)
      methods.push_back(std::move(meth));
  ASSERT_EQ(methods.size(), 6u);
  const RunReport rep = RunScenario(m, methods, {}, LoadTolerances(m));
  int ran = 0;
  for (const Result& r : rep.results) ran += r.ok();
  ASSERT_EQ(ran, 1) << "only numeric runs a driven spatial scene";
  EXPECT_TRUE(rep.pairs.empty());
  EXPECT_TRUE(rep.free.empty());
  const MethodVerdict v = VerdictOf(rep, "numeric");
  EXPECT_TRUE(v.within);
  EXPECT_FALSE(v.compared);
}

}  // namespace
}  // namespace harness_compare_test
}  // namespace mechbench::harness
