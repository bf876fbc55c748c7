// Internal: the spatial rows' evaluation, called by constraints.cc once per call when
// NaturalModel::dim is 3 (never per row), so planar models run the planar loops unchanged.
#pragma once

#include "mechbench/numeric/natural_data.h"
#include "mechbench/numeric/natural_model.h"

#include <Eigen/Core>

#include <vector>

namespace mechbench::numeric::spatial {

// Φ of every row at data.q → data.Phi (sized m).
void EvalPhi(const NaturalModel& model, NaturalData& data);
// Φ_q (rate = false) or Φ̇_q (rate = true, at data.qd) of every row → J [m × n], dense.
void Differentiate(const NaturalModel& model, const NaturalData& data, bool rate, Eigen::MatrixXd& J);
// The q columns of one row's partials in the order SparseJacobian::Evaluate3 visits them (three
// per entity, then the slots; −1 for a constant component).
void Columns(const NaturalModel& model, const ConstraintRow& row, std::vector<int>& cols);

}  // namespace mechbench::numeric::spatial
