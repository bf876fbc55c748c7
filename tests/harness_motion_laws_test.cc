// Drivers with a motion law x(t) (tests/data/scenes/*_harmonic.yaml): the exact methods follow the
// law's closed-form derivatives; every method agrees with the analytic reference within its own
// tolerance (harness/tolerances.yaml), each engine driving its joint its own way per step.
#include "mechbench/harness/compare.h"
#include "mechbench/harness/registry.h"
#include "mechbench/harness/tolerances.h"
#include "mechbench/loader.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <functional>
#include <iostream>
#include <numbers>

namespace mechbench::harness {
namespace harness_motion_laws_test {  // this file's own names (the tests build in unity batches)
namespace {

constexpr double kPi = std::numbers::pi;

struct LawCase {
  const char* file;
  const char* slot;
  std::function<Jet2(double)> law;  // the closed form: value, rate, acceleration
};

std::vector<LawCase> Cases() {
  const double a = 40 * kPi / 180, w = 2 * kPi;
  const double b = 0.08, v = kPi / 0.12;
  return {
      {"crank_rocker_harmonic.yaml", "theta",
       [=](double t) { return Jet2{kPi / 3 + a * std::sin(w * t), a * w * std::cos(w * t), -a * w * w * std::sin(w * t)}; }},
      {"actuator_harmonic.yaml", "s",
       [=](double t) { return Jet2{std::sqrt(2.0) + b * std::sin(v * t), b * v * std::cos(v * t), -b * v * v * std::sin(v * t)}; }},
  };
}

Model Load(const char* file) { return LoadScenario(std::string(MECHBENCH_TEST_DATA) + "/scenes/" + file); }
bool Verbose() { return std::getenv("MECHBENCH_VERBOSE") != nullptr; }

// The loader keeps the law's value and derivatives at t0 where the polynomial's were.
TEST(MotionLaw, LoaderSetsTheInstantFromTheLaw) {
  for (const LawCase& c : Cases()) {
    SCOPED_TRACE(c.file);
    const Model m = Load(c.file);
    ASSERT_EQ(m.drivers.size(), 1u);
    const Driver& d = m.drivers[0];
    ASSERT_TRUE(d.law);
    const Jet2 x0 = c.law(m.analysis.t0);
    EXPECT_NEAR(d.value, x0.v, 1e-15);
    EXPECT_NEAR(d.velocity, x0.d, 1e-14);
    EXPECT_NEAR(d.acceleration, x0.dd, 1e-13);
    EXPECT_FALSE(d.IsStill());
  }
}

// The polynomial form is one case of a law: the same motion written either way.
TEST(MotionLaw, PolynomialIsOneCaseOfTheLaw) {
  Driver poly;
  poly.value = 1.0, poly.velocity = 2 * kPi, poly.acceleration = 0.3;
  Driver law = poly;
  law.law = std::make_shared<const CompiledExpr>(CompiledExpr::Compile(
      "1 + 2*pi*(t - 0.5) + 0.5*0.3*(t - 0.5)^2",
      [](const std::string& n) -> std::optional<CompiledExpr::Binding> {
        if (n == "t") return CompiledExpr::Binding{0, 0};
        return std::nullopt;
      }));
  for (double t : {0.5, 0.7, 1.9}) {
    EXPECT_NEAR(law.At(t, 0.5), poly.At(t, 0.5), 1e-14);
    EXPECT_NEAR(law.RateAt(t, 0.5), poly.RateAt(t, 0.5), 1e-14);
    EXPECT_NEAR(law.AccelerationAt(t, 0.5), poly.AccelerationAt(t, 0.5), 1e-14);
  }
}

// analytic and numeric: the driven coordinate is the law, its rate and acceleration the law's
// derivatives, at every sample, to rounding.
TEST(MotionLaw, ExactMethodsFollowTheClosedForm) {
  const auto methods = AllMethods();
  for (const LawCase& c : Cases()) {
    const Model m = Load(c.file);
    const int slot = m.SlotIndex(c.slot);
    for (const MethodPtr& method : methods) {
      if (method->name() != "analytic" && method->name() != "numeric") continue;
      SCOPED_TRACE(std::string(c.file) + " " + method->name());
      ASSERT_FALSE(method->Applicability(m).has_value()) << *method->Applicability(m);
      const Result r = method->Run(m);
      ASSERT_TRUE(r.ok()) << r.reason;
      ASSERT_EQ(static_cast<int>(r.trajectory.size()), m.analysis.samples);
      double worst = 0;
      for (const Sample& s : r.trajectory) {
        const Jet2 x = c.law(s.t);
        worst = std::max({worst, std::fabs(s.q[slot] - x.v), std::fabs(s.qd[slot] - x.d) / (1 + std::fabs(x.d)),
                          std::fabs(s.qdd[slot] - x.dd) / (1 + std::fabs(x.dd))});
      }
      if (Verbose()) std::cout << c.file << " " << method->name() << " worst " << worst << "\n";
      EXPECT_LE(worst, 1e-12);
    }
  }
}

// Every other method against the analytic reference, judged as `mechbench run` judges it.
TEST(MotionLaw, EveryMethodAgreesWithinItsTolerance) {
  for (const LawCase& c : Cases()) {
    const Model m = Load(c.file);
    const Tolerances tol = LoadTolerances(m.name);
    for (MethodPtr& method : AllMethods()) {
      if (method->name() == "analytic") continue;
      SCOPED_TRACE(std::string(c.file) + " " + method->name());
      if (auto why = method->Applicability(m)) {
        std::cout << "  " << method->name() << " skipped: " << *why << "\n";
        continue;
      }
      std::vector<MethodPtr> two;
      for (MethodPtr& a : AllMethods())
        if (a->name() == "analytic") two.push_back(std::move(a));
      const std::string name = method->name();
      two.push_back(std::move(method));
      const RunReport rep = RunScenario(m, two, {}, tol);
      if (Verbose())
        for (const auto& p : rep.pairs) std::cout << c.file << " " << p.method << " q " << p.q << " qd " << p.qd << " qdd " << p.qdd << "\n";
      if (const std::string* why = tol.KnownFailure(name)) {
        EXPECT_FALSE(rep.known.empty()) << name << " now meets its tolerance; remove it from known_failures (" << *why << ")";
        continue;
      }
      for (const auto& p : rep.problems) ADD_FAILURE() << p;
    }
  }
}

}  // namespace
}  // namespace harness_motion_laws_test
}  // namespace mechbench::harness
