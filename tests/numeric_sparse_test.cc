// Sparse linear algebra for the dynamics: the sparse Φ_q against the dense one, and every
// formulation with sparse matrices against the same formulation with dense ones, to round-off, on
// fourbar_free, §5.1 and an N-four-bar (N = 3, before its first singular position).
#include "mechbench/motion_error.h"
#include "mechbench/loader.h"
#include "mechbench/numeric/ali3p.h"
#include "mechbench/numeric/constraints.h"
#include "mechbench/numeric/dynamics_methods.h"
#include "mechbench/numeric/forward_dynamics.h"
#include "mechbench/numeric/natural_model.h"
#include "mechbench/references/nfourbar.h"
#include "mechbench/numeric/reference.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>

namespace mechbench::numeric {
namespace numeric_sparse_test {  // this file's own names (the tests build in unity batches)
namespace {

using namespace ::mechbench::references;  // the N-four-bar's generator and exact motion

struct Scene {
  std::string name;
  Model model;
};

std::vector<Scene> Scenes() {
  Model nfb = NFourBar({.n = 3, .t1 = 0.5, .samples = 51});  // the first singular position is at 0.717 s
  return {{"fourbar_free", LoadScenario(ResolveScenario("fourbar_free"))},
          {"s5_1_disc_bar_bushing", LoadScenario(ResolveScenario("s5_1_disc_bar_bushing"))},
          {"nfourbar_3", nfb}};
}

// The sparse Φ_q has the dense one's entries to the bit (same partials, same summation order) at
// random q, and its Φ and Φ̇_q q̇ agree to round-off; on every built-in linkage scene, the §4.4
// quick return's redundant cos+sin rows included.
TEST(NumericSparse, SparseJacobianIsTheDenseOne) {
  std::vector<Model> models;
  for (const std::string& f : BuiltinScenarioFiles()) {
    Model m = LoadScenario(f);
    if (m.kind == ScenarioKind::kLinkage) models.push_back(std::move(m));
  }
  models.push_back(NFourBar({.n = 5}));
  ASSERT_GT(models.size(), 10u);
  for (const Model& model : models) {
    SCOPED_TRACE(model.name);
    const NaturalModel nm = Compile(model);
    NaturalData dense(nm), sparse(nm);
    std::vector<int> rows(nm.m());
    for (int i = 0; i < nm.m(); ++i) rows[i] = i;
    SparseJacobian jac(nm, rows);
    for (int trial = 0; trial < 3; ++trial) {
      const Eigen::VectorXd q = model.GuessQ() + 0.1 * Eigen::VectorXd::Random(nm.n).cwiseProduct(nm.q_scale);
      const Eigen::VectorXd qd = Eigen::VectorXd::Random(nm.n).cwiseProduct(nm.q_scale);
      EvalPhi(nm, dense, q, 0);
      EvalJacobian(nm, dense, q);
      EvalPhidotQdot(nm, dense, q, qd);
      Eigen::VectorXd phi, jdot_qd;
      jac.Evaluate(nm, sparse, q, &qd, phi, &jdot_qd);
      EXPECT_EQ(Eigen::MatrixXd(jac.J()), dense.Phi_q);
      EXPECT_EQ(phi, dense.Phi);
      const double scale = dense.Phidot_q_qd.cwiseAbs().maxCoeff() + 1;
      EXPECT_LE((jdot_qd - dense.Phidot_q_qd).cwiseAbs().maxCoeff(), 1e-13 * scale);
    }
  }
}

// Largest |Δq| over the run, each slot relative to the motion's scale (CompareMotion).
double Difference(const Model& model, const Result& a, const Result& b) {
  EXPECT_EQ(a.trajectory.size(), b.trajectory.size());
  return CompareMotion(model, a.trajectory, b.trajectory).q.max;
}

struct Formulation {
  std::string name;
  std::function<MethodPtr(LinearAlgebra)> make;
  double bound;  // sparse against dense; NaN: from the formulation's own round-off sensitivity
};

MethodPtr Ali3p(LinearAlgebra la, double penalty = Ali3pOptions{}.penalty) {
  Ali3pOptions o;
  o.linear_algebra = la;
  o.penalty = penalty;
  return MakeAli3pMethod(o);
}

// Every formulation gives the same motion with either. The index-1 ones to 2e-16 … 8e-15
// (measured; DOPRI5's step sizes follow its error estimates, which round-off moves by as little).
// ALI3-P's tangent matrix carries the penalty, α h²/4 = 250 × the mass, so each solve is exact only
// to ε × its condition number; since its Newton iteration and projections solve for corrections
// (ali3p.h) that error stays in the corrections: dense against sparse differ by 1.6e-14
// (fourbar_free), 2.9e-13 (§5.1), 3.2e-15 (N = 3), and changing the penalty by one ulp moves the
// dense run by 5.3e-14, 2.3e-14, 2.6e-15 (measured; before, 1.0e-10 … 2.4e-9). The bound is 1e-12.
TEST(NumericSparse, SparseAndDenseFormulationsAgreeToRoundOff) {
  const std::vector<Formulation> formulations = {
      {"dyn-baumgarte-rk4", [](LinearAlgebra la) { return MakeBaumgarteRk4Method({.linear_algebra = la}); }, 1e-13},
      {"dyn-baumgarte-dopri5", [](LinearAlgebra la) { return MakeBaumgarteDopri5Method({.linear_algebra = la}); }, 1e-13},
      {"dyn-ali3p", [](LinearAlgebra la) { return Ali3p(la); }, 1e-12}};
  for (const Scene& scene : Scenes()) {
    for (const Formulation& f : formulations) {
      SCOPED_TRACE(scene.name + " " + f.name);
      const Result dense = f.make(LinearAlgebra::kDense)->Run(scene.model);
      const Result sparse = f.make(LinearAlgebra::kSparse)->Run(scene.model);
      ASSERT_TRUE(dense.ok()) << dense.reason;
      ASSERT_TRUE(sparse.ok()) << sparse.reason;
      EXPECT_NE(dense.settings.at("linear_solver").find("dense"), std::string::npos);
      EXPECT_NE(sparse.settings.at("linear_solver").find("sparse"), std::string::npos);
      const double bound = f.bound;
      EXPECT_LE(Difference(scene.model, dense, sparse), bound);
      // The statistics the harness compares are the same too.
      EXPECT_NEAR(dense.quantities.at("energy"), sparse.quantities.at("energy"), 1e-12 * std::fabs(dense.quantities.at("energy")));
      EXPECT_EQ(dense.quantities.at("steps"), sparse.quantities.at("steps"));
    }
  }
}

// kAuto: the index-1 formulations stay dense on small scenes (faster there) and go sparse from
// kSparseIndex1FromCoordinates; ALI3-P is sparse at every size; the settings say which and why.
TEST(NumericSparse, AutomaticChoiceIsStatedInTheSettings) {
  Model small = LoadScenario(ResolveScenario("fourbar_free"));
  small.analysis.t1 = 0.05;
  small.analysis.samples = 6;
  Model large = NFourBar({.n = 8, .t1 = 0.05, .samples = 6});  // n = 18
  ASSERT_LT(static_cast<int>(small.q_layout.size()), kSparseIndex1FromCoordinates);
  ASSERT_GE(static_cast<int>(large.q_layout.size()), kSparseIndex1FromCoordinates);
  const std::string rk4_small = MakeBaumgarteRk4Method()->Run(small).settings.at("linear_solver");
  const std::string rk4_large = MakeBaumgarteRk4Method()->Run(large).settings.at("linear_solver");
  const std::string ali_small = MakeAli3pMethod()->Run(small).settings.at("linear_solver");
  const std::string cp_large = MakeCoordinatePartitioningMethod()->Run(large).settings.at("linear_solver");
  EXPECT_EQ(rk4_small.rfind("dense", 0), 0u) << rk4_small;
  EXPECT_NE(rk4_small.find("n = 5 < 16"), std::string::npos) << rk4_small;
  EXPECT_EQ(rk4_large.rfind("sparse", 0), 0u) << rk4_large;
  EXPECT_NE(rk4_large.find("n = 18 ≥ 16"), std::string::npos) << rk4_large;
  EXPECT_EQ(ali_small.rfind("sparse", 0), 0u) << ali_small;
  EXPECT_EQ(cp_large.rfind("dense", 0), 0u) << cp_large;  // coordinate partitioning stays dense
}

// The ALI3-P step through its stepper (what the benchmark times) with either algebra, 300 steps of
// the N-four-bar: the same state to ALI3-P's round-off floor (above: 1.0e-10 measured here).
TEST(NumericSparse, Ali3pStepperDenseAndSparseAgree) {
  const Model model = NFourBar({.n = 6, .t1 = 1, .samples = 2});
  const NaturalModel nm = Compile(model);
  const FreeStart start = AssembleFreeStart(nm);
  Eigen::VectorXd q[2], qd[2], qdd[2];
  for (int s = 0; s < 2; ++s) {
    const LinearAlgebra la = s ? LinearAlgebra::kSparse : LinearAlgebra::kDense;
    DynamicsSystem sys(nm, la, kSparseAli3pFromCoordinates);
    sys.ChooseRows(start.q);
    Eigen::VectorXd lambda0;
    std::string why;
    ASSERT_TRUE(sys.Accelerations(start.q, start.qd, 0, 0, qdd[s], lambda0, &why)) << why;
    Ali3pOptions o;
    o.linear_algebra = la;
    Ali3pStepper stepper(sys, o, 1e-3, lambda0);
    q[s] = start.q, qd[s] = start.qd;
    for (int k = 0; k < 300; ++k) ASSERT_TRUE(stepper.Step(1e-3, q[s], qd[s], qdd[s], why)) << why << " at step " << k;
    EXPECT_EQ(sys.sparse(), s == 1);
  }
  EXPECT_LE((q[0] - q[1]).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LE((qd[0] - qd[1]).cwiseAbs().maxCoeff(), 1e-8);
}

}  // namespace
}  // namespace numeric_sparse_test
}  // namespace mechbench::numeric
