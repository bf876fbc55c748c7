#include "mechbench/analytic/gears.h"

#include <cmath>
#include <stdexcept>

namespace mechbench::analytic {

std::optional<PointState2> MemberCentre(const Model& model, int body, double phi_c, double omega_c, double alpha_c) {
  if (body < 0 || static_cast<size_t>(body) >= model.gear_axes.size() || !model.gear_axes[body].Known()) return std::nullopt;
  const GearAxis& g = model.gear_axes[body];
  PointState2 s;
  if (g.carrier < 0) {
    s.p = g.centre, s.v.setZero(), s.a.setZero();
    return s;
  }
  const Vec3 k(0, 0, 1), w = omega_c * k, al = alpha_c * k;
  const Vec3 r(g.arm * std::cos(phi_c), g.arm * std::sin(phi_c), 0);
  const Vec3 v = w.cross(r), a = al.cross(r) + w.cross(w.cross(r));
  s.p = g.centre + r.head<2>(), s.v = v.head<2>(), s.a = a.head<2>();
  return s;
}

double MeshRatio(int z_a, int z_b, bool internal) {
  return (internal ? 1.0 : -1.0) * static_cast<double>(z_a) / z_b;
}

GearTrainSolver::GearTrainSolver(const Model& model) : m_(model) {
  member_driver_.assign(model.bodies.size(), -1);
  member_coord_.assign(model.bodies.size(), -1);
  for (size_t c = 0; c < model.coordinates.size(); ++c)
    if (model.coordinates[c].type == CoordinateType::kRotation || model.coordinates[c].type == CoordinateType::kTravel)
      member_coord_[model.coordinates[c].body] = static_cast<int>(c);
  for (size_t d = 0; d < model.drivers.size(); ++d)
    for (size_t b = 0; b < model.bodies.size(); ++b)
      if (member_coord_[b] >= 0 && model.coordinates[member_coord_[b]].name == model.drivers[d].coordinate)
        member_driver_[b] = static_cast<int>(d);
  if (model.kind != ScenarioKind::kGearTrain) {
    why_not_ = "not a gear train";
    return;
  }
  // Dry run: which members the drivers determine.
  std::vector<double> v(model.bodies.size(), kNaN);
  for (size_t b = 0; b < v.size(); ++b)
    if (member_driver_[b] >= 0) v[b] = 1.0 + 0.37 * static_cast<double>(b);  // generic distinct values
  bool any_mesh = false;
  for (const Joint& j : model.joints) any_mesh |= j.type == JointType::kGear;
  any_mesh |= !model.couplings.empty();
  if (!any_mesh) {
    why_not_ = "the gear train has no meshes";
    return;
  }
  std::vector<double> r;
  try {
    r = Propagate(v);
  } catch (const std::exception& e) {
    why_not_ = e.what();
    return;
  }
  std::string left;
  for (size_t b = 0; b < r.size(); ++b)
    if (member_coord_[b] >= 0 && !(r[b] == r[b])) left += (left.empty() ? "" : ", ") + model.bodies[b].name;
  if (!left.empty())
    why_not_ = "the drivers do not determine members " + left + " by mesh ratios or Willis' formula";
}

std::vector<double> GearTrainSolver::Propagate(std::vector<double> w) const {
  const Model& m = m_;
  auto known = [&](int b) { return b < 0 || w[b] == w[b]; };
  auto val = [&](int b) { return b < 0 ? 0.0 : w[b]; };  // the frame does not turn
  for (bool progress = true; progress;) {
    progress = false;
    // One mesh at a time: Z_a (w_a − w_c) + s Z_b (w_b − w_c) = 0.
    for (const Joint& j : m.joints) {
      if (j.type != JointType::kGear) continue;
      const int a = j.members[0], b = j.members[1], c = j.carrier;
      const double k = MeshRatio(j.teeth[0], j.teeth[1], j.internal);  // (w_b − w_c) = k (w_a − w_c)
      if (known(a) && known(c) && !known(b)) {
        w[b] = val(c) + k * (val(a) - val(c));
        progress = true;
      } else if (known(b) && known(c) && !known(a)) {
        w[a] = val(c) + (val(b) - val(c)) / k;
        progress = true;
      } else if (known(a) && known(b) && !known(c)) {
        if (std::fabs(1 - k) < 1e-14) throw std::runtime_error("mesh " + j.name + " has ratio 1 in its carrier's frame: the carrier is undetermined");
        w[c] = (val(b) - k * val(a)) / (1 - k);
        progress = true;
      }
    }
    // A coupling between two members' rotations (a belt): Δφ_b = k Δφ_a, so also w_b = k w_a
    // (the laws here are displacements from the file's guesses, rates and accelerations). A rack
    // joint the same way: a sliding member's travel Δs = ±r Δφ (its value is then a travel, its
    // rate a speed).
    for (const Coupling& cp : m.couplings) {
      const int ca = m.q_layout[cp.slots[0]].coordinate, cb = m.q_layout[cp.slots[1]].coordinate;
      if (ca < 0 || cb < 0) continue;
      const int a = m.coordinates[ca].body, b = m.coordinates[cb].body;
      if (a < 0 || b < 0) continue;
      if (known(a) && !known(b)) w[b] = cp.ratio * w[a], progress = true;
      else if (known(b) && !known(a)) w[a] = w[b] / cp.ratio, progress = true;
    }
    if (progress) continue;
    // Willis across a carrier: relative rates on one carrier form a chain of ratios.
    for (size_t c = 0; c < m.bodies.size() && !progress; ++c) {
      if (known(static_cast<int>(c))) continue;
      std::vector<double> K(m.bodies.size(), kNaN);  // w_x − w_c = K_x (w_x0 − w_c)
      int x0 = -1;
      for (const Joint& j : m.joints)
        if (j.type == JointType::kGear && j.carrier == static_cast<int>(c))
          for (int x : j.members)
            if (x0 < 0 && known(x)) x0 = x;
      if (x0 < 0) continue;
      K[x0] = 1.0;
      for (bool grew = true; grew;) {
        grew = false;
        for (const Joint& j : m.joints) {
          if (j.type != JointType::kGear || j.carrier != static_cast<int>(c)) continue;
          const double k = MeshRatio(j.teeth[0], j.teeth[1], j.internal);
          const int a = j.members[0], b = j.members[1];
          if (K[a] == K[a] && !(K[b] == K[b])) K[b] = k * K[a], grew = true;
          if (K[b] == K[b] && !(K[a] == K[a])) K[a] = K[b] / k, grew = true;
        }
      }
      for (size_t y = 0; y < m.bodies.size() && !progress; ++y) {
        if (static_cast<int>(y) == x0 || !known(static_cast<int>(y)) || !(K[y] == K[y]) || std::fabs(1 - K[y]) < 1e-14) continue;
        w[c] = (w[y] - K[y] * w[x0]) / (1 - K[y]);
        progress = true;
      }
    }
  }
  return w;
}

}  // namespace mechbench::analytic
