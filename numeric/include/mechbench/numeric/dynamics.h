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

namespace mechbench::numeric {

// Element mass matrix of eq. 5.1 for a body of mass `mass` [kg], length L = |r_j − r_i|,
// centre of mass com_B in the body frame and polar inertia about its centre of mass
// inertia_com [kg·length²]. Order [x_i, y_i, x_j, y_j].
Eigen::Matrix4d ElementMassMatrix(double mass, double L, const Eigen::Vector2d& com_B,
                                  double inertia_com);

// Assembled mass matrix → data.M [n × n] [kg] (sparse data: data.M_sparse, exact zeros left out);
// fixed and eliminated coordinates drop out.
// Bodies without mass properties add nothing.
void MassMatrix(const NaturalModel& model, NaturalData& data);

// Generalized forces → data.Q [n] [N]: each body's weight through Cᵀ(com) m g, plus the point
// forces. Weights use the file's gravity [length/s²] converted to m/s², so Q is in newtons for
// any length unit (M q̈ in kg·length/s² then equals Q / meters_per_unit).
void GeneralizedForces(const NaturalModel& model, NaturalData& data);

}  // namespace mechbench::numeric
