// Constraint rows of the natural-coordinate model: row order, and the analytic Φ_q and Φ̇_q
// against central finite differences on random configurations (off the constraint manifold too:
// the identities hold everywhere).
#include "mechbench/errors.h"
#include "mechbench/loader.h"
#include "mechbench/numeric/constraints.h"
#include "mechbench/numeric/natural_data.h"
#include "mechbench/numeric/natural_model.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

namespace mechbench::numeric {
namespace numeric_constraints_test {  // this file's own names (the tests build in unity batches)
namespace {

// One scene with every row kind (tests/data/scenes/every_row_kind.yaml): a 3-point body (linear
// rows), an oblique fixed guide (kept coordinates, collinearity row), a slider along a body, an
// eliminated coordinate, and angles in every form (cos, sin, cos+sin, dot with a shared point, cross
// from ground / body / fixed vector), plus a distance coordinate.
std::string EveryRowFile() { return std::string(MECHBENCH_TEST_DATA) + "/scenes/every_row_kind.yaml"; }

// Gear rows, with a carrier: §6.1 case 1 (carrier held, ring at 715 rpm).
std::string PlanetaryFile() { return ResolveScenario("s6_1_planetary_case1"); }

Eigen::MatrixXd FiniteDifferenceJacobian(const NaturalModel& nm, const Eigen::VectorXd& q) {
  NaturalData d(nm);
  Eigen::MatrixXd J(nm.m(), nm.n);
  for (int j = 0; j < nm.n; ++j) {
    const double h = 1e-6 * std::max(1.0, std::abs(q[j]));
    Eigen::VectorXd qp = q, qm = q;
    qp[j] += h;
    qm[j] -= h;
    EvalPhi(nm, d, qp, 0.0);
    const Eigen::VectorXd fp = d.Phi;
    EvalPhi(nm, d, qm, 0.0);
    J.col(j) = (fp - d.Phi) / (2 * h);
  }
  return J;
}

// Max over entries of |A − B| / (1 + |B|).
double RelativeGap(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B) {
  return ((A - B).array().abs() / (1.0 + B.array().abs())).maxCoeff();
}

Eigen::VectorXd RandomAround(const Eigen::VectorXd& q0, double spread, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-spread, spread);
  Eigen::VectorXd q = q0;
  for (int j = 0; j < q.size(); ++j) q[j] += u(rng);
  return q;
}

TEST(NumericConstraints, RowsFollowBodiesJointsCoordinatesInFileOrder) {
  const NaturalModel nm = Compile(LoadScenario(EveryRowFile()));
  using K = RowKind;
  const std::vector<K> expected = {
      K::kBodyDistance,                                      // crank
      K::kBodyDistance, K::kBodyLinearX, K::kBodyLinearY,    // plate (point 3)
      K::kBodyDistance, K::kBodyDistance, K::kBodyDistance,  // rocker, bar4, bar5
      K::kBodyDistance,                                      // bar6
      K::kPointOnLine, K::kPointOnLine,                      // slider 4 on G1-G2, slider 5 along crank
      // slider 6 on the horizontal A-B removes y6 from q instead of adding a row
      K::kAngleCos, K::kAngleSin, K::kAngleCos, K::kAngleSin,  // th_cos, th_sin, th_cs
      K::kAngleDot, K::kAngleCross, K::kAngleCross, K::kAngleCross, K::kDistance};
  ASSERT_EQ(nm.m(), static_cast<int>(expected.size()));
  for (int i = 0; i < nm.m(); ++i) EXPECT_EQ(nm.rows[i].kind, expected[i]) << "row " << i << " " << nm.rows[i].Where();
  EXPECT_EQ(nm.point_slot[nm.model.PointIndex("6")][1], -1);  // y6 eliminated
  EXPECT_EQ(nm.n, 2 * 5 + 1 + 8);                             // 5 free points, x6, 8 coordinates
  EXPECT_NE(nm.rows[0].Where().find("body crank (" + EveryRowFile() + ":"), std::string::npos) << nm.rows[0].Where();
  // Linear-row constants: point 3 at (4, 1.5) in a body of length 8.
  EXPECT_DOUBLE_EQ(nm.rows[2].a, 0.5);
  EXPECT_DOUBLE_EQ(nm.rows[2].b, 1.5 / 8);
  // The dot form's constant is |A1|·|12| from the bodies.
  EXPECT_NEAR(nm.rows[14].L, std::sqrt(5.0) * 8.0, 1e-12);
}

TEST(NumericConstraints, JacobianMatchesFiniteDifferencesForEveryRowKind) {
  for (const std::string& file : {EveryRowFile(), PlanetaryFile()}) {
    SCOPED_TRACE(file);
    const NaturalModel nm = Compile(LoadScenario(file));
    NaturalData d(nm);
    std::mt19937 rng(42);
    for (int trial = 0; trial < 10; ++trial) {
      const Eigen::VectorXd q = RandomAround(nm.model.GuessQ(), 1.5, rng);
      EvalJacobian(nm, d, q);
      const Eigen::MatrixXd fd = FiniteDifferenceJacobian(nm, q);
      EXPECT_LT(RelativeGap(d.Phi_q, fd), 1e-6) << "trial " << trial << "\nanalytic\n"
                                                << d.Phi_q << "\nfinite differences\n" << fd;
      // Every row has at least one nonzero entry (a row that never varies is a compile bug).
      for (int i = 0; i < nm.m(); ++i) EXPECT_GT(d.Phi_q.row(i).cwiseAbs().maxCoeff(), 0.0) << nm.rows[i].Where();
    }
  }
}

TEST(NumericConstraints, PhidotQMatchesDerivativeOfJacobianAlongQdot) {
  for (const std::string& file : {EveryRowFile(), PlanetaryFile()}) {
    SCOPED_TRACE(file);
    const NaturalModel nm = Compile(LoadScenario(file));
    NaturalData d(nm);
    std::mt19937 rng(7);
    for (int trial = 0; trial < 10; ++trial) {
      const Eigen::VectorXd q = RandomAround(nm.model.GuessQ(), 1.5, rng);
      const Eigen::VectorXd qd = RandomAround(Eigen::VectorXd::Zero(nm.n), 2.0, rng);
      const double h = 1e-6;
      EvalJacobian(nm, d, q + h * qd);
      const Eigen::MatrixXd Jp = d.Phi_q;
      EvalJacobian(nm, d, q - h * qd);
      const Eigen::MatrixXd fd = (Jp - d.Phi_q) / (2 * h);
      EvalPhidotQdot(nm, d, q, qd);
      EXPECT_LT(RelativeGap(d.Phidot_q, fd), 1e-6) << "trial " << trial << "\nanalytic\n"
                                                   << d.Phidot_q << "\nfinite differences\n" << fd;
      EXPECT_LT(RelativeGap(d.Phidot_q_qd, fd * qd), 1e-6);
      // Φ̇_q q̇ is also the second directional derivative of Φ along q̇: d²Φ(q + s q̇)/ds².
      EvalPhi(nm, d, q + 1e-4 * qd, 0.0);
      Eigen::VectorXd second = d.Phi;
      EvalPhi(nm, d, q - 1e-4 * qd, 0.0);
      second += d.Phi;
      EvalPhi(nm, d, q, 0.0);
      second = (second - 2 * d.Phi) / 1e-8;
      EvalPhidotQdot(nm, d, q, qd);
      EXPECT_LT(RelativeGap(d.Phidot_q_qd, second), 1e-4);
    }
  }
}

TEST(NumericConstraints, PhiTIsZeroAndDriversCarryTime) {
  const NaturalModel nm = Compile(LoadScenario(PlanetaryFile()));
  NaturalData d(nm);
  EvalPhit(nm, d, nm.model.GuessQ(), 0.3);
  EXPECT_EQ(d.Phi_t.size(), nm.m());
  EXPECT_EQ(d.Phi_t.cwiseAbs().maxCoeff(), 0.0);
  const double w = 715 * 2 * std::numbers::pi / 60;
  EXPECT_NEAR(DriverRates(nm, 0.3)[1], w, 1e-12);
  Eigen::VectorXd q = Eigen::VectorXd::Zero(nm.n);
  q[nm.drivers[1].slot] = 0.5;
  EXPECT_NEAR(DriverResiduals(nm, q, 0.3)[1], 0.5 - w * 0.3, 1e-12);
}

TEST(NumericConstraints, CosineAngleBetweenPointsOfDifferentBodiesIsRejected) {
  // tests/data/bad/28_cos_angle_across_bodies.yaml: the command line refuses it too.
  const std::string file = std::string(MECHBENCH_TEST_DATA) + "/bad/28_cos_angle_across_bodies.yaml";
  try {
    Compile(LoadScenario(file));
    FAIL() << "expected ScenarioError";
  } catch (const ScenarioError& e) {
    EXPECT_NE(std::string(e.what()).find("28_cos_angle_across_bodies.yaml:"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("not on one body"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace numeric_constraints_test
}  // namespace mechbench::numeric
