// Shared helpers of the engine suites: errors of an engine's trajectory against a reference and
// the constraint residual measured with the numeric Φ, as the harness measures them.
#pragma once

#include "mechbench/loader.h"
#include "mechbench/method.h"
#include "mechbench/numeric/constraints.h"
#include "mechbench/numeric/natural_data.h"
#include "mechbench/numeric/natural_model.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace mechbench::engines::testing {

inline Model Load(const std::string& name) { return LoadScenario(ResolveScenario(name)); }

// MECHBENCH_VERBOSE=1 prints the measured numbers even when a test passes.
inline bool Verbose() { return std::getenv("MECHBENCH_VERBOSE") != nullptr; }

// Runs `meth` on `m`, or returns not-applicable with the method's own reason.
inline Result RunIfApplicable(const Method& meth, const Model& m) {
  if (auto why = meth.Applicability(m)) {
    Result r;
    r.status = Status::kNotApplicable;
    r.reason = *why;
    return r;
  }
  return meth.Run(m);
}

struct Errors {
  double q = 0, qd = 0, qdd = 0;  // largest |Δ| of a slot ÷ max(its magnitude, 1e-3 × the largest slot of that kind)
  double residual = 0;            // largest scaled ‖Φ‖ (numeric::ScaledResidual) over the samples
};

// Over all common samples; a sample without q̈ on either side is skipped for q̈.
inline Errors Compare(const Model& m, const Result& ref, const Result& r) {
  Errors e;
  const size_t n = std::min(ref.trajectory.size(), r.trajectory.size());
  EXPECT_EQ(ref.trajectory.size(), r.trajectory.size());
  auto kind = [&](auto get) {
    const int slots = static_cast<int>(m.q_layout.size());
    std::vector<double> diff(slots, 0), mag(slots, 0);
    for (size_t k = 0; k < n; ++k) {
      const Eigen::VectorXd& a = get(ref.trajectory[k]);
      const Eigen::VectorXd& b = get(r.trajectory[k]);
      if (a.size() != slots || b.size() != slots) continue;
      EXPECT_NEAR(ref.trajectory[k].t, r.trajectory[k].t, 1e-12);
      for (int i = 0; i < slots; ++i) {
        diff[i] = std::max(diff[i], std::fabs(a[i] - b[i]));
        mag[i] = std::max({mag[i], std::fabs(a[i]), std::fabs(b[i])});
      }
    }
    const double floor = 1e-3 * *std::max_element(mag.begin(), mag.end()) + 1e-300;
    double worst = 0;
    for (int i = 0; i < slots; ++i) worst = std::max(worst, diff[i] / std::max(mag[i], floor));
    return worst;
  };
  e.q = kind([](const Sample& s) -> const Eigen::VectorXd& { return s.q; });
  e.qd = kind([](const Sample& s) -> const Eigen::VectorXd& { return s.qd; });
  e.qdd = kind([](const Sample& s) -> const Eigen::VectorXd& { return s.qdd; });
  const numeric::NaturalModel nm = numeric::Compile(m);
  numeric::NaturalData data(nm);
  for (const Sample& s : r.trajectory) {
    numeric::EvalPhi(nm, data, s.q, s.t);
    e.residual = std::max(e.residual, numeric::ScaledResidual(nm, data));
  }
  return e;
}

inline double Final(const Model& m, const Result& r, const std::string& slot) {
  return r.trajectory.back().q[m.SlotIndex(slot)];
}

// Every built-in scenario with a driver (the driven comparisons).
inline std::vector<std::string> DrivenScenarios() {
  std::vector<std::string> out;
  for (const std::string& f : BuiltinScenarioFiles()) {
    const Model m = LoadScenario(f);
    if (!m.IsFree()) out.push_back(m.name);
  }
  return out;
}

}  // namespace mechbench::engines::testing
