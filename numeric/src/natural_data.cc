#include "mechbench/numeric/natural_data.h"

namespace mechbench::numeric {

NaturalData::NaturalData(const NaturalModel& model, LinearAlgebra la) {
  const int n = model.n, m = model.m(), f = model.f();
  const size_t P = model.point_const.size();
  sparse = la == LinearAlgebra::kSparse || (la == LinearAlgebra::kAuto && n >= kSparseKinematicsFromCoordinates);
  q = qd = qdd = Eigen::VectorXd::Zero(n);
  r = model.point_const;
  rd.assign(P, Eigen::Vector2d::Zero());
  rdd.assign(P, Eigen::Vector2d::Zero());
  Phi = Phi_t = Phidot_q_qd = lambda = Eigen::VectorXd::Zero(m);
  rhs = Eigen::VectorXd::Zero(m + f);
  Q = Eigen::VectorXd::Zero(n);

  kin.q = kin.step = kin.col = kin.jacobian_q = kin.factored_q = Eigen::VectorXd::Zero(n);
  kin.scale = kin.b = kin.w = kin.wb = Eigen::VectorXd::Zero(m + f);
  kin.piv = Eigen::VectorXi::Zero(n);
  // Sparse: the pattern of Φ_q (jac) and M are built where first needed (EvalJacobian, MassMatrix),
  // so that a probe NaturalData (SparseJacobian's own) costs O(n).
  if (sparse) return;
  Phi_q = Phidot_q = Eigen::MatrixXd::Zero(m, n);
  A = Eigen::MatrixXd::Zero(m + f, n);
  M = Eigen::MatrixXd::Zero(n, n);
  // The dense scratch matrices of the kinematic solver for the scenes it is made for (a few
  // coordinates); a larger dense scene gets them at its first solve.
  if (n <= KinematicScratch::kMaxLuSize) {
    kin.As = Eigen::MatrixXd::Zero(m + f, n);
    kin.lu = Eigen::MatrixXd::Zero(n, n);
    kin.cod = Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd>(m + f, n);
  }
}

}  // namespace mechbench::numeric
