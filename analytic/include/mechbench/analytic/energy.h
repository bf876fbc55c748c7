// Mass matrix and generalised forces of the natural-coordinate model, obtained the vector-method
// way: from the kinetic energy of each body (König: T = ½ m |v_G|² + ½ I_G |ṙ_01|²/L²) and the
// virtual power of its loads, never from the assembled element matrix of eq. 5.1. It is the
// independent check of the numeric solver's M and Q.
//
// Each body is carried by its first two points r0, r1 (L apart): a material point at body-frame
// coordinates (X, Y) is r0 + C (r1 − r0), C = [[X, −Y], [Y, X]] / L. ṙ_01 / L is then the body's
// rate of turning (and, off the rigid manifold, of stretching) and its kinetic energy about G is
// ½ I_G |ṙ_01|²/L².
#pragma once

#include "mechbench/model.h"

#include <Eigen/Core>
#include <Eigen/SparseCore>

namespace mechbench::analytic {

// From this many coordinates on, M is polarised only over the pairs of coordinates that share a
// body (every other entry is 0: no body's energy couples them) and kept sparse: the dense
// polarisation is O(n²) energies of O(bodies) each, hours at N = 1000 four-bars (n = 2002).
inline constexpr int kSparseMassFromCoordinates = 64;

struct MassAndForces {
  bool sparse = false;  // n ≥ kSparseMassFromCoordinates: M_sparse holds M and M is empty
  Eigen::MatrixXd M;  // [n × n] in Model::q_layout order [kg]
  Eigen::SparseMatrix<double> M_sparse;  // the same, sparse: its nonzeros only
  Eigen::VectorXd Q;  // [n] gravity and point forces [N]
};

// A point body (model.h) moves with its point and, on a guide along a moving body, turns with
// that body: v_G = v_P + C(com) ṙ_12, ω² = |ṙ_12|²/L_guide². Independent of q: in natural
// coordinates both are constant.
// Sparse from `sparse_from` coordinates on (tests force either).
MassAndForces MassAndForcesByEnergy(const Model& model, int sparse_from = kSparseMassFromCoordinates);

// The force elements' part of Q at the state (q, q̇) [N], by virtual power: Q_e[i] is the power of
// every spring–damper's tension F = k (L − L0) u + c L̇ u + F0 on its two ends and of every torque
// T ω on its body (ω = r_01 × ṙ_01 / |r_01|²) for the virtual velocity e_i (a torque law T(t, q,
// q̇) taken at t), and of every torsional spring–damper's torque on its angle coordinate's rate.
// Dense, O(n · elements).
Eigen::VectorXd ElementForcesByPower(const Model& model, const Eigen::VectorXd& q, const Eigen::VectorXd& qd, double t);

}  // namespace mechbench::analytic
