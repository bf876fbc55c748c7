// StateLoads (graph.h): torsional spring–dampers, torque and force laws of the state and spring–dampers
// with laws, from an engine's body states.
#include "mechbench/engines/graph.h"

#include "load_variables.h"

#include "mechbench/errors.h"

#include <cmath>
#include <numbers>

namespace mechbench::engines {

StateLoads::StateLoads(const Graph& g) : g_(&g) {
  if (!g.state_torques.empty() || !g.state_forces.empty()) {
    MB_ASSERT(g.model != nullptr, "a graph with load laws of the state carries its model");
    obs_.emplace(*g.model, g);
    x_.assign(1 + 2 * g.model->q_layout.size(), 0.0);
  }
  for (const GraphTorsion& ts : g.torsions) {
    const double ref = ts.body_ref < 0 ? 0.0 : g.bodies[ts.body_ref].initial.angle;
    last_rel_.push_back(g.bodies[ts.body_vec].initial.angle - ref);
  }
}

std::pair<double, double> StateLoads::TorsionAngle(size_t k, const std::vector<PlanarState>& st) {
  const GraphTorsion& ts = g_->torsions[k];
  const PlanarState ground;
  const PlanarState& a = ts.body_ref < 0 ? ground : st[ts.body_ref];
  const PlanarState& b = st[ts.body_vec];
  // The relative rotation on the branch nearest the last one (the bodies' angles may come back
  // wrapped): continuous as long as it turns by less than π between two evaluations.
  constexpr double k2Pi = 2 * std::numbers::pi;
  double rel = b.angle - a.angle;
  rel += k2Pi * std::round((last_rel_[k] - rel) / k2Pi);
  last_rel_[k] = rel;
  return {ts.offset + ts.sigma * rel, ts.sigma * (b.omega - a.omega)};
}

void StateLoads::BodyTorques(double t, const std::vector<PlanarState>& st, std::vector<double>& out) {
  MB_ASSERT(g_->state_forces.empty(), "a graph with force laws of the state is evaluated by StateLoads::Evaluate");
  std::vector<Eigen::Vector2d> none;
  Evaluate(t, st, out, none);
}

void StateLoads::Evaluate(double t, const std::vector<PlanarState>& st, std::vector<double>& torque,
                          std::vector<Eigen::Vector2d>& force) {
  torque.assign(g_->bodies.size(), 0.0);
  force.assign(g_->state_forces.size(), Eigen::Vector2d::Zero());
  for (size_t k = 0; k < g_->torsions.size(); ++k) {
    const GraphTorsion& ts = g_->torsions[k];
    const auto [th, th_dot] = TorsionAngle(k, st);
    const double T = ts.Torque(th, th_dot);
    torque[ts.body_vec] += ts.sigma * T;
    if (ts.body_ref >= 0) torque[ts.body_ref] -= ts.sigma * T;
  }
  if (g_->state_torques.empty() && g_->state_forces.empty()) return;
  SetLoadVariables(t, obs_->Observe(t, st, false), x_);
  for (const GraphTorque& tq : g_->state_torques) torque[tq.body] += tq.scale * tq.law->Eval(x_.data());
  for (size_t k = 0; k < g_->state_forces.size(); ++k) {
    const GraphForce& f = g_->state_forces[k];
    if (f.spring < 0) {
      force[k] = f.Eval(x_.data(), st[f.body].angle);
      continue;
    }
    // A spring–damper's end: the force on b from both ends' states (a receives the opposite).
    const GraphSpring& sp = g_->state_springs[f.spring];
    const Eigen::Vector2d on_b =
        SpringForceOnB(sp, Graph::EndPos(st, sp.body_a, sp.at_a), Graph::EndVel(st, sp.body_a, sp.at_a),
                       Graph::EndPos(st, sp.body_b, sp.at_b), Graph::EndVel(st, sp.body_b, sp.at_b), x_.data());
    force[k] = f.end == 1 ? on_b : Eigen::Vector2d(-on_b);
  }
}

}  // namespace mechbench::engines
