// Method::Computation: two methods that state one computation do the same run bit for bit, which
// is what lets a campaign run it once for both (harness/src/campaign.cc, RunShared).
#include "mechbench/harness/registry.h"
#include "mechbench/loader.h"

#include <gtest/gtest.h>

#include <map>
#include <string>
#include <utility>
#include <vector>

namespace mechbench {
namespace engines_computation_test {  // this file's own names (the tests build in unity batches)
namespace {

// The overrides a sweep or a precision walk gives: a step and a tolerance, the method honours the
// one of its control.
RunOptions Override(double step, double tolerance) {
  RunOptions o;
  o.step = step;
  o.tolerance = tolerance;
  return o;
}

// The pairs of registered methods that state the same computation under `o`.
std::vector<std::pair<const Method*, const Method*>> SharingPairs(const std::vector<MethodPtr>& all, const RunOptions& o) {
  std::vector<std::pair<const Method*, const Method*>> out;
  for (size_t a = 0; a < all.size(); ++a)
    for (size_t b = a + 1; b < all.size(); ++b) {
      const std::string ca = all[a]->Computation(o);
      if (!ca.empty() && ca == all[b]->Computation(o)) out.push_back({all[a].get(), all[b].get()});
    }
  return out;
}

void ExpectSameRun(const Result& a, const Result& b, const std::string& what) {
  ASSERT_EQ(a.status, b.status) << what << ": " << a.reason << " / " << b.reason;
  ASSERT_EQ(a.trajectory.size(), b.trajectory.size()) << what;
  for (size_t k = 0; k < a.trajectory.size(); ++k) {
    const Sample& x = a.trajectory[k];
    const Sample& y = b.trajectory[k];
    ASSERT_EQ(x.t, y.t) << what << " sample " << k;
    ASSERT_TRUE(x.q == y.q && x.qd == y.qd) << what << ": q or q̇ differ at t = " << x.t;
    ASSERT_TRUE((x.qdd.size() == 0 && y.qdd.size() == 0) || x.qdd == y.qdd) << what << ": q̈ differs at t = " << x.t;
    ASSERT_EQ(x.residual, y.residual) << what << " at t = " << x.t;
  }
  EXPECT_EQ(a.steps, b.steps) << what;
}

// Every pair that states one computation under an override runs the same, bit for bit, on a free
// scene and on a driven one, at two override values.
TEST(Computation, MethodsThatStateOneComputationRunTheSame) {
  const std::vector<MethodPtr> all = harness::AllMethods();
  const std::vector<std::string> files = {ResolveScenario("fourbar_free"),
                                          ResolveScenario("fourbar_crank_rocker")};
  size_t compared = 0;
  for (const auto& [step, tol] : std::vector<std::pair<double, double>>{{2e-3, 1e-5}, {5e-4, 1e-8}}) {
    const RunOptions o = Override(step, tol);
    for (const auto& [a, b] : SharingPairs(all, o))
      for (const std::string& f : files) {
        const Model m = LoadScenario(f);
        if (a->Applicability(m) || b->Applicability(m)) continue;
        ExpectSameRun(a->Run(m, o), b->Run(m, o), a->name() + " and " + b->name() + " on " + f);
        ++compared;
      }
  }
  if (compared == 0) GTEST_SKIP() << "no two methods of this build state one computation";
}

// Without an override every variant is its own computation (two variants that were one would be a
// duplicate in the registry), and a method that states one states it for each control value.
TEST(Computation, VariantsDifferAtTheirOwnSettingsAndValuesDifferUnderAnOverride) {
  const std::vector<MethodPtr> all = harness::AllMethods();
  EXPECT_TRUE(SharingPairs(all, RunOptions{}).empty());
  for (const MethodPtr& m : all) {
    const std::string a = m->Computation(Override(2e-3, 1e-5));
    if (a.empty()) continue;
    EXPECT_NE(a, m->Computation(Override(1e-3, 1e-6))) << m->name() << ": " << a;
  }
}

}  // namespace
}  // namespace engines_computation_test
}  // namespace mechbench
