// `run` and `check` run each method in its own process (isolated.h, process.h): an engine that
// aborts, segfaults or hangs is a row with its status and its last words, and the others still run.
#include "mechbench/harness/compare.h"
#include "mechbench/harness/isolated.h"
#include "mechbench/harness/process.h"
#include "mechbench/harness/registry.h"
#include "mechbench/harness/timing.h"
#include "mechbench/harness/tolerances.h"
#include "mechbench/loader.h"

#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <thread>

namespace mechbench::harness {
namespace harness_isolated_test {  // this file's own names (the tests build in unity batches)
namespace {

// Stand-ins for an engine that misbehaves: it aborts (an engine's internal assertion), segfaults
// after a message on stderr, or never returns.
class Misbehaves final : public Method {
 public:
  enum Kind { kAbort, kSegfault, kHang };
  explicit Misbehaves(Kind k) : Method(k == kAbort ? "aborts" : k == kSegfault ? "segfaults" : "hangs", "a stand-in"), k_(k) {}
  std::optional<std::string> Applicability(const Model&) const override { return std::nullopt; }

 protected:
  void DoRun(const Model&, const RunOptions&, Result&) const override {
    if (k_ == kAbort) std::abort();
    if (k_ == kSegfault) {
      std::fprintf(stderr, "ENGINE INTERNAL ERROR: the stand-in gives up\n");
      std::raise(SIGSEGV);
    }
    for (;;) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }

 private:
  Kind k_;
};

Model FreeFourBar() { return LoadScenario(ResolveScenario("fourbar_free")); }

std::vector<MethodPtr> Pick(std::initializer_list<const char*> names) {
  std::vector<MethodPtr> out;
  for (const char* n : names)
    for (MethodPtr& m : AllMethods())
      if (m->name() == n) out.push_back(std::move(m));
  return out;
}

TEST(IsolatedRun, TheResultComesBackWhole) {
  const Model m = FreeFourBar();
  const std::vector<MethodPtr> ali = Pick({"dyn-ali3p"});
  ASSERT_EQ(ali.size(), 1u);
  const Result here = ali[0]->Run(m);
  // The child inherits this process's warm-ups: it warms the method unless a test before this one did.
  const bool warmed_here = WarmedInThisProcess(*ali[0]);
  const IsolatedRun there = RunMethodIsolated(*ali[0], m, {}, 60, true);
  const Result& r = there.result;
  ASSERT_EQ(r.status, Status::kOk) << r.reason;
  EXPECT_EQ(there.startup.done, !warmed_here);
  if (there.startup.done) {
    EXPECT_GT(there.startup.first, 0);
  }
  ASSERT_EQ(r.trajectory.size(), here.trajectory.size());
  for (size_t k = 0; k < r.trajectory.size(); ++k) {
    EXPECT_EQ(r.trajectory[k].t, here.trajectory[k].t);
    EXPECT_EQ(r.trajectory[k].q, here.trajectory[k].q);  // bit for bit: the same computation
    EXPECT_EQ(r.trajectory[k].qd, here.trajectory[k].qd);
    EXPECT_EQ(r.trajectory[k].qdd, here.trajectory[k].qdd);
  }
  EXPECT_EQ(r.quantities, here.quantities);
  EXPECT_EQ(r.settings, here.settings);
  EXPECT_EQ(r.steps, here.steps);
  EXPECT_NEAR(r.cpu.total(), r.cpu_seconds, 1e-12);
}

TEST(IsolatedRun, AMalformedMessageIsAnErrorNotACrash) {
  IsolatedRun run;
  run.result.method = "m";
  run.result.trajectory.push_back(Sample{0, Eigen::VectorXd::Ones(3), Eigen::VectorXd(), Eigen::VectorXd(), 0});
  const std::string bytes = EncodeRun(run);
  EXPECT_EQ(DecodeRun(bytes).result.trajectory[0].q, run.result.trajectory[0].q);
  for (size_t cut : {size_t{0}, size_t{7}, bytes.size() / 2, bytes.size() - 1})
    EXPECT_THROW(DecodeRun(bytes.substr(0, cut)), std::runtime_error) << "cut at " << cut;
  std::string huge = bytes;
  huge[8] = '\x7f';  // the method name's length: far past the end
  EXPECT_THROW(DecodeRun(huge), std::runtime_error);
}

// The others still run and are judged; the misbehaving one is a row with why.
TEST(IsolatedRun, AnAbortSegfaultOrHangIsARowAndTheOthersStillRun) {
  const Model m = FreeFourBar();
  std::vector<MethodPtr> methods = Pick({"analytic", "dyn-ali3p"});
  methods.push_back(std::make_unique<Misbehaves>(Misbehaves::kAbort));
  methods.push_back(std::make_unique<Misbehaves>(Misbehaves::kSegfault));
  methods.push_back(std::make_unique<Misbehaves>(Misbehaves::kHang));
  const RunReport rep = RunScenario(m, methods, {}, LoadTolerances(m.name), {.enabled = true, .timeout = 3});
  ASSERT_EQ(rep.results.size(), 5u);
  EXPECT_EQ(rep.results[0].status, Status::kOk);
  EXPECT_EQ(rep.results[1].status, Status::kOk);
  EXPECT_EQ(rep.results[2].status, Status::kCrashed);
  EXPECT_NE(rep.results[2].reason.find("signal 6"), std::string::npos) << rep.results[2].reason;
  EXPECT_EQ(rep.results[3].status, Status::kCrashed);
  // Signal 11; under AddressSanitizer its SEGV handler reports and exits with code 1 instead.
  EXPECT_TRUE(rep.results[3].reason.find("signal 11") != std::string::npos ||
              rep.results[3].reason.find("SEGV") != std::string::npos)
      << rep.results[3].reason;
  EXPECT_NE(rep.results[3].reason.find("ENGINE INTERNAL ERROR: the stand-in gives up"), std::string::npos)
      << "its last words on stderr: " << rep.results[3].reason;
  EXPECT_EQ(rep.results[4].status, Status::kTimedOut);
  EXPECT_NE(rep.results[4].reason.find("time limit of 3 s"), std::string::npos) << rep.results[4].reason;
  EXPECT_FALSE(rep.ok);  // a crash is a failure of the run, not of the command
  EXPECT_FALSE(rep.invalid);
  ASSERT_FALSE(rep.free.empty());
  EXPECT_EQ(rep.free[0].method, "dyn-ali3p");  // judged against the reference as usual
}

// A real engine that aborts on extreme input (ODE's quaternion normalisation under a gravity of
// −1e300): a crashed row with ODE's own message.
TEST(IsolatedRun, AnEngineAssertionIsACrashedRowWithItsMessage) {
  const std::vector<MethodPtr> ode = Pick({"ode-worldstep-default"});
  if (ode.empty()) GTEST_SKIP() << "built without ODE";
  const Model m = LoadScenario(std::string(MECHBENCH_TEST_DATA) + "/scenes/fourbar_free_extreme_gravity.yaml");
  const IsolatedRun run = RunMethodIsolated(*ode[0], m, {}, 60, false);
  EXPECT_EQ(run.result.status, Status::kCrashed);
  EXPECT_NE(run.result.reason.find("ODE INTERNAL ERROR"), std::string::npos) << run.result.reason;
}

}  // namespace
}  // namespace harness_isolated_test
}  // namespace mechbench::harness
