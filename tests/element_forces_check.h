// What the load-law suites share: numeric's Q of the force elements at one state against the
// analytic method's Q by virtual power, and its tangents ∂Q/∂q, ∂Q/∂q̇ (ALI3-P's) against central
// differences of Q.
#pragma once

#include "mechbench/analytic/energy.h"
#include "mechbench/numeric/dynamics.h"
#include "mechbench/numeric/natural_model.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

namespace mechbench::numeric::test {

inline void ExpectElementForcesAndTangents(const Model& model, const NaturalModel& nm, const Eigen::VectorXd& q,
                                           const Eigen::VectorXd& qd, double t) {
  const auto Qat = [&](const Eigen::VectorXd& x, const Eigen::VectorXd& xd) {
    Eigen::VectorXd Q = Eigen::VectorXd::Zero(nm.n);
    AddElementForces(nm, x, xd, t, Q);
    return Q;
  };
  const Eigen::VectorXd Q = Qat(q, qd), Qa = analytic::ElementForcesByPower(model, q, qd, t);
  EXPECT_LT((Q - Qa).cwiseAbs().maxCoeff(), 1e-13) << Q.transpose() << " / " << Qa.transpose();
  EXPECT_GT(Q.cwiseAbs().maxCoeff(), 0.1);  // a load is there
  std::vector<ElementDerivative> D;
  ElementDerivatives(nm, q, qd, t, D);
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(nm.n, nm.n), C = K;
  for (const ElementDerivative& d : D)
    for (size_t i = 0; i < d.slot.size(); ++i)
      for (size_t j = 0; j < d.slot.size(); ++j)
        if (d.slot[i] >= 0 && d.slot[j] >= 0) K(d.slot[i], d.slot[j]) += d.K(i, j), C(d.slot[i], d.slot[j]) += d.C(i, j);
  for (int s = 0; s < nm.n; ++s) {
    const double dx = 1e-6;
    Eigen::VectorXd qa = q, qb = q, da = qd, db = qd;
    qa[s] += dx, qb[s] -= dx, da[s] += dx, db[s] -= dx;
    const Eigen::VectorXd Kfd = (Qat(qa, qd) - Qat(qb, qd)) / (2 * dx), Cfd = (Qat(q, da) - Qat(q, db)) / (2 * dx);
    EXPECT_LT((K.col(s) - Kfd).cwiseAbs().maxCoeff(), 1e-7 * std::max(1.0, Kfd.cwiseAbs().maxCoeff())) << s;
    EXPECT_LT((C.col(s) - Cfd).cwiseAbs().maxCoeff(), 1e-7 * std::max(1.0, Cfd.cwiseAbs().maxCoeff())) << s;
  }
}

}  // namespace mechbench::numeric::test
