// Gear trains (ScenarioKind::kGearTrain) by the ratio of each mesh and Willis' formula.
//
// Every mesh between members a and b (teeth Z_a, Z_b; carrier c, or the frame) obeys, in the
// carrier's frame, Z_a (ω_a − ω_c) + s Z_b (ω_b − ω_c) = 0 with s = +1 external, −1 internal:
// (ω_b − ω_c)/(ω_a − ω_c) = −s Z_a/Z_b. Members on one shaft are one body. Starting from the driven
// members, the solver propagates through the mesh graph one closed form at a time:
//   - a mesh with two of its three rates (a, b, carrier) known gives the third;
//   - Willis across a carrier: two members with known rates, linked through meshes on one carrier
//     by the product K of their ratios, give the carrier: ω_c = (ω_y − K ω_x)/(1 − K).
// The law is linear and homogeneous, so the same propagation serves angle displacements, rates
// and accelerations.
#pragma once

#include "mechbench/analytic/linkage.h"
#include "mechbench/model.h"

#include <optional>
#include <string>
#include <vector>

namespace mechbench::analytic {

class GearTrainSolver {
 public:
  explicit GearTrainSolver(const Model& model);

  // Why the members cannot all be found from the drivers, or nullopt.
  const std::optional<std::string>& why_not() const { return why_not_; }

  // Values of every body (NaN where unknown) from the values of the driven members, where
  // `member_value[b]` is NaN for undriven members. Throws std::runtime_error when a relation is
  // degenerate (e.g. a carrier between two equal internal/external ratios).
  std::vector<double> Propagate(std::vector<double> member_value) const;

  // Per Model::bodies: the driver that prescribes its rotation, or -1.
  const std::vector<int>& member_driver() const { return member_driver_; }
  // Per Model::bodies: its rotation coordinate, or -1.
  const std::vector<int>& member_coordinate() const { return member_coord_; }

 private:
  const Model& m_;
  std::vector<int> member_driver_, member_coord_;
  std::optional<std::string> why_not_;
};

// The centre of a member's axis when the file gives the train's geometry (Model::gear_axes), from
// its carrier's angle, rate and acceleration (ignored on a fixed axis): on a fixed axis, its centre
// at rest; a planet on the carrier's arm r = arm (cos φ_c, sin φ_c) from the carrier's axis,
//   v = ω_c k × r,  a = α_c k × r + ω_c k × (ω_c k × r).
// nullopt when the file does not place the member.
std::optional<PointState2> MemberCentre(const Model& model, int body, double phi_c, double omega_c, double alpha_c);

// Speed ratio of one mesh seen from the carrier: (ω_b − ω_c)/(ω_a − ω_c) = −s Z_a/Z_b.
double MeshRatio(int z_a, int z_b, bool internal);

}  // namespace mechbench::analytic
