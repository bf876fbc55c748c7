#include "mechbench/numeric/natural_data.h"

namespace mechbench::numeric {

NaturalData::NaturalData(const NaturalModel& model) {
  const int n = model.n, m = model.m(), f = model.f();
  const size_t P = model.point_const.size();
  q = qd = qdd = Eigen::VectorXd::Zero(n);
  r = model.point_const;
  rd.assign(P, Eigen::Vector2d::Zero());
  rdd.assign(P, Eigen::Vector2d::Zero());
  Phi = Phi_t = Phidot_q_qd = lambda = Eigen::VectorXd::Zero(m);
  Phi_q = Phidot_q = Eigen::MatrixXd::Zero(m, n);
  A = Eigen::MatrixXd::Zero(m + f, n);
  rhs = Eigen::VectorXd::Zero(m + f);
  M = Eigen::MatrixXd::Zero(n, n);
  Q = Eigen::VectorXd::Zero(n);
}

}  // namespace mechbench::numeric
