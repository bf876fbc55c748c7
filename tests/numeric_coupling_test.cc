// Couplings (Model::couplings: a rack and pinion, a linear relation between two coordinates) in
// the natural-coordinate solver: the row and its constant Jacobian, the kinematics against the
// closed forms of a rack and of a translating Scotch yoke, and a free rack under gravity and a
// spring through every dynamics formulation against its closed form.
#include "mechbench/loader.h"
#include "mechbench/numeric/constraints.h"
#include "mechbench/numeric/dynamics_methods.h"
#include "mechbench/numeric/natural_data.h"
#include "mechbench/numeric/natural_model.h"
#include "mechbench/numeric/numeric_method.h"
#include "formulations.h"
#include "quantity.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

namespace mechbench::numeric {
namespace numeric_coupling_test {  // this file's own names (the tests build in unity batches)
namespace {

using test::Formulation;
using test::Formulations;
using test::Scene;

// The coupling row q_b − k q_a − c: Jacobian −k and 1 on its two slots, nothing else, and
// Φ̇_q q̇ = 0 — the same through the dense and the sparse evaluation.
TEST(NumericCoupling, RackRowIsLinearWithAConstantJacobian) {
  const Model model = Scene("rack_pinion_driven.yaml");
  ASSERT_EQ(model.couplings.size(), 1u);
  EXPECT_EQ(model.couplings[0].ratio, 0.05);
  const NaturalModel nm = Compile(model);
  const int row = nm.m() - 1;  // couplings come last
  ASSERT_EQ(nm.rows[row].kind, RowKind::kCoupling);
  const int th = model.SlotIndex("theta"), x = model.SlotIndex("xR1");
  Eigen::VectorXd q = model.GuessQ(), qd = Eigen::VectorXd::LinSpaced(nm.n, 0.3, 1.7);
  q[th] = 0.7, q[x] = 0.05 * 0.7 + 1e-3;  // 1 mm off the relation
  for (LinearAlgebra la : {LinearAlgebra::kDense, LinearAlgebra::kSparse}) {
    NaturalData data(nm, la);
    EvalPhi(nm, data, q, 0);
    EXPECT_NEAR(data.Phi[row], 1e-3, 1e-15);
    EvalJacobian(nm, data, q);
    EvalPhidotQdot(nm, data, q, qd);
    EXPECT_EQ(data.Phidot_q_qd[row], 0.0);
    Eigen::MatrixXd J = data.sparse ? Eigen::MatrixXd(data.jac.J()) : data.Phi_q;
    for (int j = 0; j < nm.n; ++j) EXPECT_EQ(J(row, j), j == th ? -0.05 : j == x ? 1.0 : 0.0) << j;
  }
}

// x_R1 = r θ and its rates, to 1e-12, at every sample.
TEST(NumericCoupling, RackFollowsTheClosedForm) {
  const Model model = Scene("rack_pinion_driven.yaml");
  const Result r = MakeNumericMethod()->Run(model);
  ASSERT_EQ(r.status, Status::kOk) << r.reason;
  ASSERT_EQ(r.trajectory.size(), 11u);
  const int x = model.SlotIndex("xR1"), x2 = model.SlotIndex("xR2");
  for (const Sample& s : r.trajectory) {
    const double th = 2 * s.t + 0.5 * s.t * s.t, thd = 2 + s.t, thdd = 1;
    EXPECT_NEAR(s.q[x], 0.05 * th, 1e-12) << s.t;
    EXPECT_NEAR(s.q[x2], 0.05 * th + 0.2, 1e-12) << s.t;
    EXPECT_NEAR(s.qd[x], 0.05 * thd, 1e-12) << s.t;
    EXPECT_NEAR(s.qdd[x], 0.05 * thdd, 1e-12) << s.t;
  }
}

// The yoke translates: x_Y1 = a cos θ; with a rack on it, the pinion's φ = −(x_Y1 − x_Y1(0))/r.
TEST(NumericCoupling, ScotchYokeAndItsRackFollowTheClosedForm) {
  for (const char* file : {"scotch_yoke_translating.yaml", "scotch_yoke_rack_pinion.yaml"}) {
    SCOPED_TRACE(file);
    const Model model = Scene(file);
    const Result r = MakeNumericMethod()->Run(model);
    ASSERT_EQ(r.status, Status::kOk) << r.reason;
    ASSERT_EQ(r.trajectory.size(), 41u);
    const int x = model.SlotIndex("xY1"), phi = model.SlotIndex("phi");
    const double a = 0.1, r_p = 0.04, x0 = a * std::cos(std::numbers::pi / 6);
    double worst = 0;
    for (const Sample& s : r.trajectory) {
      const double th = std::numbers::pi / 6 + 3 * s.t, thd = 3;
      const double xe = a * std::cos(th), xde = -a * std::sin(th) * thd, xdde = -a * std::cos(th) * thd * thd;
      worst = std::max({worst, std::fabs(s.q[x] - xe), std::fabs(s.qd[x] - xde), std::fabs(s.qdd[x] - xdde)});
      if (phi >= 0)
        worst = std::max({worst, std::fabs(s.q[phi] + (xe - x0) / r_p), std::fabs(s.qd[phi] + xde / r_p),
                          std::fabs(s.qdd[phi] + xdde / r_p)});
    }
    std::printf("  %s: largest deviation from the closed form %.2e\n", file, worst);
    EXPECT_LT(worst, 1e-12);
  }
}

// A belt between gear-train members: one more linear row beside the mesh's.
TEST(NumericCoupling, BeltAfterAGearPair) {
  const Model model = Scene("gear_belt_train.yaml");
  const Result r = MakeNumericMethod()->Run(model);
  ASSERT_EQ(r.status, Status::kOk) << r.reason;
  ASSERT_EQ(r.trajectory.size(), 11u);
  const int p = model.SlotIndex("phi_pulley");
  for (const Sample& s : r.trajectory) {
    EXPECT_NEAR(s.q[p], -(3 * s.t + 0.5 * s.t * s.t) / 6, 1e-12) << s.t;
    EXPECT_NEAR(s.qd[p], -(3 + s.t) / 6, 1e-12) << s.t;
    EXPECT_NEAR(s.qdd[p], -1.0 / 6, 1e-12) << s.t;
  }
}

// The free rack: effective mass m + I/r² = 2 kg, y(t) = y_eq (1 − cos ω t), ω = √10 rad/s,
// y_eq = 0.2 − 9.81/20 m; the pinion follows at θ = y / r.
TEST(NumericCoupling, FreeRackUnderGravityAndASpringFollowsTheClosedForm) {
  const Model model = Scene("rack_pinion_free.yaml");
  const int y = model.SlotIndex("yR1"), th = model.SlotIndex("theta");
  const double w = std::sqrt(10.0), y_eq = 0.2 - 9.81 / 20;
  for (const Formulation& f : Formulations()) {
    const Result r = f.make()->Run(model);
    ASSERT_EQ(r.status, Status::kOk) << f.name << ": " << r.reason;
    ASSERT_EQ(r.trajectory.size(), 201u) << f.name;
    double worst = 0, worst_th = 0;
    for (const Sample& s : r.trajectory) {
      worst = std::max(worst, std::fabs(s.q[y] - y_eq * (1 - std::cos(w * s.t))));
      worst_th = std::max(worst_th, std::fabs(s.q[th] - s.q[y] / 0.05));
    }
    std::printf("  free rack, %-24s max |y − y_eq (1 − cos ωt)| = %.2e m, coupling %.1e rad, energy drift %.2e J\n",
                f.name.c_str(), worst, worst_th, Get(r, "energy_drift"));
    const bool ali = f.name.rfind("ali3p", 0) == 0;
    EXPECT_LT(worst, ali ? 1e-4 : 1e-7) << f.name;
    EXPECT_LT(worst_th, 1e-6) << f.name;
    // ÿ at t0 = (−m g + k (L − L0)) / (m + I/r²) = (−9.81 + 20·0.2) / 2.
    EXPECT_NEAR(Get(r, "qdd.yR1"), (-9.81 + 4.0) / 2, 1e-12) << f.name;
  }
}

}  // namespace
}  // namespace numeric_coupling_test
}  // namespace mechbench::numeric
