// Mass matrix and generalized forces in natural coordinates (book chapter 5, eq. 5.1).
//
// A planar body with basic points i, j (its first two points) places every material point at
//   r = r_i + C(ξ, η) [r_i; r_j],  C = [(1 − ξ/L) I − (η/L) P,  (ξ/L) I + (η/L) P],  P = [0 −1; 1 0]
// so its kinetic energy is ½ [ṙ_i; ṙ_j]ᵀ M_e [ṙ_i; ṙ_j] with M_e = ∫ Cᵀ C dm, which gives eq. 5.1.
// Both are constant, so they do not depend on data.q.
#pragma once

#include "mechbench/numeric/natural_data.h"
#include "mechbench/numeric/natural_model.h"

#include <Eigen/Core>

#include <array>
#include <vector>

namespace mechbench::numeric {

// Element mass matrix of eq. 5.1 for a body of mass `mass` [kg], length L = |r_j − r_i|,
// centre of mass com_B in the body frame and polar inertia about its centre of mass
// inertia_com [kg·length²]. Order [x_i, y_i, x_j, y_j].
Eigen::Matrix4d ElementMassMatrix(double mass, double L, const Eigen::Vector2d& com_B,
                                  double inertia_com);

// A point body's (Body::IsPointBody, model.h) element mass matrix and weight Cᵀ m g [N], in the
// six q slots `slot` gets: its point's x, y, then, on a guide along a moving body, that body's
// first two points' (−1: a constant coordinate or none). The block turns with such a guide:
// r_G = r_P + (c_x I + c_y P)(r2 − r1)/L, ω² = |ṙ2 − ṙ1|²/L²; on a fixed guide or none it only
// translates with its point.
Eigen::Matrix<double, 6, 6> PointBodyMassMatrix(const NaturalModel& model, const Body& body, std::array<int, 6>& slot);
Eigen::Matrix<double, 6, 1> PointBodyWeight(const NaturalModel& model, const Body& body, const Eigen::Vector2d& g_SI,
                                            std::array<int, 6>& slot);

// Assembled mass matrix → data.M [n × n] [kg] (sparse data: data.M_sparse, exact zeros left out);
// fixed and eliminated coordinates drop out.
// Bodies without mass properties add nothing.
void MassMatrix(const NaturalModel& model, NaturalData& data);

// Generalized forces → data.Q [n] [N]: each body's weight through Cᵀ(com) m g, plus the point
// forces. Weights use the file's gravity [length/s²] converted to m/s², so Q is in newtons for
// any length unit (M q̈ in kg·length/s² then equals Q / meters_per_unit).
// Both are constant; the force elements' part (below) is added where q and q̇ are known.
void GeneralizedForces(const NaturalModel& model, NaturalData& data);

// ---- force elements (Model::springs, torques, torsions): loads that depend on q, q̇ and t ------
// A spring–damper between points a and b, d = r_b − r_a, L = |d|, e = d/L, L̇ = e·(ṙ_b − ṙ_a):
// tension F = k (L − L0) u + c L̇ u + F0 [N] (u = meters_per_unit), acting +F e on a and −F e on b.
// A torque T on a body with basic points i, j and length L (constant in the rigid body):
//   Q_j = (T / u) / L² · P (r_j − r_i),  Q_i = −Q_j,  P = [0 −1; 1 0]
// (T δθ = Q·δq u with δθ = (d × δd)/L²), linear in q for a constant T. A torque law T(t, q, q̇)
// is evaluated with its gradient (compiled_expr.h), which adds (∂Q/∂T) ∇T to ∂Q/∂q and ∂Q/∂q̇.
// A varying point force (model.h: PointForce with a law or a body frame) at point P: Q_P = f_W =
// R F(t, q, q̇), R = I in the world, R = [d, P d]/L for the frame of a body with basic points
// i, j (d = r_j − r_i): a follower force, whose ∂Q_P/∂r_j = (F_x I + F_y P)/L = −∂Q_P/∂r_i.
// A torsional spring–damper on an angle coordinate θ (a slot of q): Q_θ = (−k (θ − θ0) − c θ̇ +
// T0) / u, since T δθ is its virtual work and θ is a coordinate of q.

// The force each element applies at each of its points at (q, q̇, t) [N, world]: a spring–damper's
// two ends (body −1: on whichever body holds the point), a torque's equivalent pair at its body's
// first two points (body: that body), a varying point force at its point (body: its frame body,
// or −1). Torsional springs act on their coordinate, not on points.
struct ElementPointForce {
  int point = -1, body = -1;
  Eigen::Vector2d f_W = Eigen::Vector2d::Zero();
};
std::vector<ElementPointForce> ElementPointForces(const NaturalModel& model, const Eigen::VectorXd& q,
                                                  const Eigen::VectorXd& qd, double t);

// Adds the force elements' generalized forces at (q, q̇, t) to Q [n] [N].
void AddElementForces(const NaturalModel& model, const Eigen::VectorXd& q, const Eigen::VectorXd& qd, double t,
                      Eigen::VectorXd& Q);

// Each torque's value at (q, q̇, t) [N·m], in Model::torques order (constants as given).
std::vector<double> TorqueValues(const NaturalModel& model, const Eigen::VectorXd& q, const Eigen::VectorXd& qd, double t);

// One element's derivatives in the q slots it touches (−1: a constant coordinate): K = ∂Q/∂q,
// C = ∂Q/∂q̇ [N/length, N·s/length], rows and columns in `slot` order. A spring–damper or a torque
// starts with [x_a, y_a, x_b, y_b]; a torque's or a spring–damper's laws add the slots they read; a
// torsion has θ only; a varying point force has the distinct slots of its point, its frame body's first two points and
// what its laws read (constant coordinates left out).
struct ElementDerivative {
  std::vector<int> slot;
  Eigen::MatrixXd K, C;
};
// One entry per element (springs in file order, then torques, then torsions, then the varying
// point forces) at (q, q̇, t).
void ElementDerivatives(const NaturalModel& model, const Eigen::VectorXd& q, const Eigen::VectorXd& qd, double t,
                        std::vector<ElementDerivative>& out);
// The q slots each element touches (the same layout as ElementDerivatives), without evaluating it.
std::vector<std::vector<int>> ElementSlots(const NaturalModel& model);

// The springs' potential ½ k ((L − L0) u)² + F0 (L − L0) u (springs without a law) and the
// torsions' ½ k (θ − θ0)² − T0 (θ − θ0), summed [J].
double SpringPotential(const NaturalModel& model, const Eigen::VectorXd& q);
// The power the dampers dissipate, Σ c (L̇ u)² + Σ c θ̇² [W] (≥ 0; springs without a law), and its
// time derivative given q̈ [W/s].
double DamperPower(const NaturalModel& model, const Eigen::VectorXd& q, const Eigen::VectorXd& qd,
                   const Eigen::VectorXd* qdd = nullptr, double* rate = nullptr);
// The power of the torques given as laws, Σ T(t, q, q̇) ω_body [W], and its time derivative given
// q̈ [W/s] (constant torques are left out: their work is T times the turn).
double LawTorquePower(const NaturalModel& model, const Eigen::VectorXd& q, const Eigen::VectorXd& qd, double t,
                      const Eigen::VectorXd* qdd = nullptr, double* rate = nullptr);
// The power of the varying point forces (a law, or in a body's frame: PointForce::IsConstantWorld
// false), Σ f_W · ṙ_P u [W], and its time derivative given q̈ [W/s]. A constant world force is
// in the energy as a potential instead; these are not (a follower force is not conservative).
double VaryingPointForcePower(const NaturalModel& model, const Eigen::VectorXd& q, const Eigen::VectorXd& qd, double t,
                              const Eigen::VectorXd* qdd = nullptr, double* rate = nullptr);
// The power of the spring–dampers that have a law (SpringDamper::HasLaw), Σ −F L̇ u [W] (their whole
// tension, damper included), and its time derivative given q̈ [W/s]. Those springs are left out of
// SpringPotential and DamperPower: a parameter that varies makes the spring non-conservative.
double LawSpringPower(const NaturalModel& model, const Eigen::VectorXd& q, const Eigen::VectorXd& qd, double t,
                      const Eigen::VectorXd* qdd = nullptr, double* rate = nullptr);
// The angle of each torque's body (direction of its first two points) [rad], in Model::torques
// order, in (−π, π]: callers unwrap it along a motion.
std::vector<double> TorqueBodyAngles(const NaturalModel& model, const Eigen::VectorXd& q);

}  // namespace mechbench::numeric
