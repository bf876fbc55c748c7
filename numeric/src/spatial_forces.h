// Force elements of spatial scenes (SpatialModel::springs, forces, torques; model.h), for the
// entry points of dynamics.h, which call these after the planar elements. Private to numeric/.
#pragma once

#include "mechbench/numeric/dynamics.h"
#include "mechbench/numeric/natural_model.h"

#include <Eigen/Core>

#include <vector>

namespace mechbench::numeric::detail {

// The load variables [t, q, q̇] (model.h: LoadVarQ) a law reads (dynamics.cc).
void LoadVariables(const NaturalModel& model, const Eigen::VectorXd& q, const Eigen::VectorXd& qd, double t,
                   std::vector<double>& x);
// Adds slot s ≥ 0 to `slot` unless there; the position of s in `slot` (−1: none or s < 0).
void AddSlot(std::vector<int>& slot, int s);
int Column(const std::vector<int>& slot, int s);

// Each appends or adds the spatial elements' part, in the order springs, varying point forces (a
// law or a body frame), torques (ElementSlots and ElementDerivatives keep it). Nothing for a planar model.
void AddSpatialElementForces(const NaturalModel& model, const Eigen::VectorXd& q, const Eigen::VectorXd& qd, double t,
                             Eigen::VectorXd& Q);
void AppendSpatialElementSlots(const NaturalModel& model, std::vector<std::vector<int>>& out);
// Fills out[k], out[k + 1], … (already sized, slots set and K, C zeroed by the caller).
void SpatialElementDerivatives(const NaturalModel& model, const Eigen::VectorXd& q, const Eigen::VectorXd& qd, double t,
                               std::vector<ElementDerivative>& out, size_t k);
double SpatialSpringPotential(const NaturalModel& model, const Eigen::VectorXd& q);
double SpatialDamperPower(const NaturalModel& model, const Eigen::VectorXd& q, const Eigen::VectorXd& qd,
                          const Eigen::VectorXd* qdd, double& rate);
// The power of the torques (all of them: a constant torque's work in 3-D is no function of the
// pose alone) and of the point forces with a law [W], and its rate given q̈ [W/s].
double SpatialTorquePower(const NaturalModel& model, const Eigen::VectorXd& q, const Eigen::VectorXd& qd, double t,
                          const Eigen::VectorXd* qdd, double& rate);
double SpatialForcePower(const NaturalModel& model, const Eigen::VectorXd& q, const Eigen::VectorXd& qd, double t,
                         const Eigen::VectorXd* qdd, double& rate);
// The work rate −F L̇ u of the spring–dampers with a law (no potential), as LawSpringPower's.
double SpatialLawSpringPower(const NaturalModel& model, const Eigen::VectorXd& q, const Eigen::VectorXd& qd, double t,
                             const Eigen::VectorXd* qdd, double& rate);

}  // namespace mechbench::numeric::detail
