#include "mechbench/analytic/analytic_method.h"
#include "mechbench/analytic/energy.h"

#include "mechbench/analytic/gears.h"
#include "mechbench/analytic/kinematics.h"
#include "mechbench/analytic/linkage.h"
#include "mechbench/analytic/moving_frame.h"
#include "mechbench/analytic/spatial.h"
#include "mechbench/analytic/synthesis.h"
#include "mechbench/errors.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

namespace mechbench::analytic {

namespace {

const char* kAxis[3] = {"x", "y", "z"};

std::string Num(double x) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6g", x);
  return buf;
}

// A length that sets the scale of the scene, for relative tolerances.
double SceneScale(const Model& m) {
  double s = 0;
  for (const Point& p : m.points) s = std::max(s, p.p_W.norm());
  for (const Body& b : m.bodies)
    for (const Vec2& p : b.p_B) s = std::max(s, p.norm());
  return 1 + s;
}

void PutLayout(const Model& m, const Eigen::VectorXd& q, const Eigen::VectorXd& qd, const Eigen::VectorXd& qdd,
               Quantities& out) {
  for (size_t i = 0; i < m.q_layout.size(); ++i) {
    const std::string& n = m.q_layout[i].name;
    out["q." + n] = q[i], out["qd." + n] = qd[i], out["qdd." + n] = qdd[i];
  }
}

void Put3(Quantities& out, const std::string& prefix, const Vec3& v) {
  for (int c = 0; c < 3; ++c) out[prefix + "." + kAxis[c]] = v[c];
}

// §3.1 part 3 as the book does it: a_A is GIVEN as ω0²R/8 (−√3 j + k) and AC is taken as uniform
// (α_AC = 0). Neither holds for a constant-speed crank with C in the slot; exposing the book's
// number beside the consistent one shows where the difference comes from.
void LinkageQuantities(const Model& m, const LinkageSolver& solver, const LinkageState& s, Quantities& out) {
  Eigen::VectorXd q, qd, qdd;
  solver.ToLayout(s, q, qd, qdd);
  PutLayout(m, q, qd, qdd, out);
  out["residual"] = s.residual;
  out["residual_rate"] = s.residual_rate;
  for (size_t b = 0; b < m.bodies.size(); ++b) {
    if (m.bodies[b].points.size() < 2) continue;
    out["omega." + m.bodies[b].name] = s.bodies[b].omega;
    out["alpha." + m.bodies[b].name] = s.bodies[b].alpha;
  }
  for (size_t j = 0; j < m.joints.size(); ++j)
    if (m.joints[j].type == JointType::kPointOnBody)
      out["vslide." + m.points[m.joints[j].point].name] = solver.SlideVelocity(s, static_cast<int>(j));
  const double scale = SceneScale(m);
  for (size_t i = 0; i < m.points.size(); ++i) {
    const std::string& n = m.points[i].name;
    const PointState3 w = EmbedPoint(m.embedding, s.points[i]);
    Put3(out, "p." + n, w.p);
    Put3(out, "v." + n, w.v);
    Put3(out, "a." + n, w.a);
    if (m.points[i].fixed || !(w.v.norm() > 1e-12 * scale)) continue;
    const Intrinsic in = IntrinsicCoordinates(w.p, w.v, w.a);
    out["at." + n] = in.a_t;
    out["an." + n] = in.a_n;
    if (std::isfinite(in.radius)) out["rho." + n] = in.radius;
  }
  if (m.frame) {
    // Route 1: every point relative to the turning frame (eq. 2.12).
    for (size_t i = 0; i < m.points.size(); ++i) {
      const PointState3 abs = AbsoluteInTurningFrame(*m.frame, EmbedPoint(m.embedding, s.points[i]));
      Put3(out, "vabs." + m.points[i].name, abs.v);
      Put3(out, "aabs." + m.points[i].name, abs.a);
    }
    // Route 2: absolute angular velocities and the rigid-body chain (eq. 2.11).
    const BodyChainResult ch = AbsoluteByBodyChain(m, s);
    for (size_t b = 0; b < m.bodies.size(); ++b) {
      if (!ch.omega_abs[b].allFinite()) continue;
      Put3(out, "omegaabs." + m.bodies[b].name, ch.omega_abs[b]);
      Put3(out, "alphaabs." + m.bodies[b].name, ch.alpha_abs[b]);
    }
    for (size_t i = 0; i < m.points.size(); ++i) {
      if (!ch.reached[i]) continue;
      Put3(out, "vabs_chain." + m.points[i].name, ch.points[i].v);
      Put3(out, "aabs_chain." + m.points[i].name, ch.points[i].a);
    }
  }
}

// M and Q at the state of `at` (t0): the force elements' part of Q depends on q and q̇.
void AddMassAndForces(const Model& m, const Sample& at, Quantities& out) {
  MassAndForces mf = MassAndForcesByEnergy(m);
  if (m.HasForceElements()) mf.Q += ElementForcesByPower(m, at.q, at.qd, at.t);
  for (int i = 0; i < mf.Q.size(); ++i) {
    out["Q[" + std::to_string(i) + "]"] = mf.Q[i];
    if (mf.sparse) continue;
    for (int j = 0; j < mf.M.cols(); ++j) out["M[" + std::to_string(i) + "," + std::to_string(j) + "]"] = mf.M(i, j);
  }
  if (mf.sparse)  // its nonzeros only (n² names would not fit a long chain)
    for (int j = 0; j < mf.M_sparse.outerSize(); ++j)
      for (Eigen::SparseMatrix<double>::InnerIterator it(mf.M_sparse, j); it; ++it)
        out["M[" + std::to_string(it.row()) + "," + std::to_string(j) + "]"] = it.value();
}

// A loop that has no solution at a sample after t0 (AssemblyError::out_of_reach): the closed form
// is exact, so the driven input is past the mechanism's reach there. That is bad input, as at t0
// and as numeric says it: a ScenarioError on the driver's line. A singular position the closed
// form cannot follow stays this run's failure (a reason in its row).
[[noreturn]] void ThrowOutOfReach(const Model& m, const AssemblyError& e, double t) {
  const SourceRef where = m.drivers.empty() ? e.where() : m.drivers.front().src;
  std::string driven;
  for (const Driver& d : m.drivers) driven += (driven.empty() ? "" : ", ") + d.coordinate;
  throw ScenarioError(where, "the driven " + (driven.empty() ? std::string("input") : driven) + " at t = " + Num(t) +
                                 " s is out of the mechanism's reach: the loop cannot close there (" + e.what() + ")",
                      "keep the driver within the mechanism's reach (" + e.fix() +
                          "; `mechbench run FILE --method numeric` gives the range it reaches)");
}

void RunLinkage(const Model& m, const RunOptions& options, Result& r) {
  const LinkageSolver solver(m);  // Applicability() has checked that it plans
  std::string plan;
  for (const Step& st : solver.plan().steps) plan += (plan.empty() ? "" : "; ") + st.text;
  r.settings["decomposition"] = plan;
  r.settings["branches"] = "from the scenario's positions at t0, then tracked sample to sample";
  const double t0 = m.analysis.t0;
  const double tol = 1e-7 * SceneScale(m);
  LinkageState s0;
  try {
    s0 = solver.Solve(t0, nullptr);
  } catch (const AssemblyError& e) {
    throw ScenarioError(e.where(), std::string(e.what()) + " at t = " + Num(t0) + " s", e.fix());
  }
  Eigen::VectorXd q0, qd0, qdd0;
  solver.ToLayout(s0, q0, qd0, qdd0);
  const double rate_tol = 1e-7 * (1 + qd0.cwiseAbs().maxCoeff());
  if (!(s0.residual <= tol) || !(s0.residual_rate <= rate_tol))
    throw ScenarioError({m.source_file, 0},
                        "the closed forms leave a constraint unsatisfied at t0 (residual " + Num(s0.residual) +
                            ", rate residual " + Num(s0.residual_rate) +
                            "): the model is over-constrained or its drivers disagree",
                        "check redundant joints and the drivers' values and rates");
  LinkageQuantities(m, solver, s0, r.quantities);
  auto sample = [&](const LinkageState& s) {
    Sample out;
    out.t = s.t;
    solver.ToLayout(s, out.q, out.qd, out.qdd);
    out.residual = s.residual;
    return out;
  };
  r.trajectory.push_back(sample(s0));
  if (!options.motion || !m.analysis.HasMotion()) return;
  // The closed forms at each sample are the method's own work; the plan and t0 its set-up.
  EnterPhase(options, Phase::kIntegration);
  r.steps = m.analysis.samples - 1;
  LinkageState prev = s0;
  for (int k = 1; k < m.analysis.samples; ++k) {
    const double t = m.analysis.TimeAt(k);
    LinkageState s;
    try {
      s = solver.Solve(t, &prev);
    } catch (const AssemblyError& e) {
      if (e.out_of_reach()) ThrowOutOfReach(m, e, t);
      r.status = Status::kDiverged;
      r.reason = "loop cannot close at t = " + Num(t) + " s: " + e.what();
      return;
    }
    if (!(s.residual <= tol)) {
      r.status = Status::kDiverged;
      r.reason = "closed forms lost the loop at t = " + Num(t) + " s (residual " + Num(s.residual) + ")";
      return;
    }
    r.trajectory.push_back(sample(s));
    prev = std::move(s);
  }
}

void SynthesisQuantities(const Synthesis& goal, Result& r) {
  const SynthesisReport rep = Synthesize(goal);
  Quantities& out = r.quantities;
  for (const std::string& n : rep.notes) r.messages.push_back("synthesis: " + n);
  if (rep.cf_terms.empty()) return;
  out["synthesis.ratio.num"] = static_cast<double>(rep.ratio.num);
  out["synthesis.ratio.den"] = static_cast<double>(rep.ratio.den);
  for (size_t k = 0; k < rep.cf_terms.size(); ++k) out["synthesis.cf_term." + std::to_string(k)] = static_cast<double>(rep.cf_terms[k]);
  for (size_t k = 0; k < rep.convergents.size(); ++k) {
    const std::string p = "synthesis.cf." + std::to_string(k + 1);
    out[p + ".num"] = static_cast<double>(rep.convergents[k].num);
    out[p + ".den"] = static_cast<double>(rep.convergents[k].den);
    out[p + ".error"] = rep.convergents[k].error;
  }
  for (size_t k = 0; k < rep.ordinary.size(); ++k) {
    out["synthesis.ordinary." + std::to_string(k + 1) + ".driver"] = rep.ordinary[k].driver;
    out["synthesis.ordinary." + std::to_string(k + 1) + ".driven"] = rep.ordinary[k].driven;
  }
  if (rep.coaxial_module_ratio == rep.coaxial_module_ratio) out["synthesis.coaxial.module_ratio"] = rep.coaxial_module_ratio;
  if (rep.mu_A.den != 0 && rep.mu_A.num != 0) out["synthesis.epicyclic.mu_A"] = rep.mu_A.value();
  if (rep.epicyclic.size() == 2) {
    // Book numbering (fig. 6.2): Z1/Z2 · Z3/Z4 = μA.
    out["synthesis.epicyclic.Z1"] = rep.epicyclic[0].driver;
    out["synthesis.epicyclic.Z2"] = rep.epicyclic[0].driven;
    out["synthesis.epicyclic.Z3"] = rep.epicyclic[1].driver;
    out["synthesis.epicyclic.Z4"] = rep.epicyclic[1].driven;
    out["synthesis.epicyclic.ratio_check"] = rep.epicyclic_check.value();
  }
  if (rep.pair_within_1e4) {
    out["synthesis.pair_within_1e4.num"] = rep.pair_within_1e4->driver;
    out["synthesis.pair_within_1e4.den"] = rep.pair_within_1e4->driven;
    out["synthesis.pair_within_1e4.error"] =
        std::fabs(static_cast<double>(rep.pair_within_1e4->driver) / rep.pair_within_1e4->driven - rep.ratio.value());
  }
}

// p./v./a.<member> for every member the file's geometry places: a planet's centre on its carrier's
// arm, a fixed axis at rest.
void GearCentreQuantities(const Model& m, const GearTrainSolver& solver, const Sample& s, const std::vector<double>& w,
                          const std::vector<double>& al, Quantities& out) {
  for (size_t b = 0; b < m.gear_axes.size(); ++b) {
    const int c = m.gear_axes[b].carrier;
    double phi = 0, omega = 0, alpha = 0;
    if (c >= 0) {
      const int coord = solver.member_coordinate()[c];
      if (coord < 0) continue;
      phi = s.q[m.SlotIndex(m.coordinates[coord].name)], omega = w[c], alpha = al[c];
      if (!std::isfinite(phi) || !std::isfinite(omega) || !std::isfinite(alpha)) continue;
    }
    const auto centre = MemberCentre(m, static_cast<int>(b), phi, omega, alpha);
    if (!centre) continue;
    const PointState3 e = EmbedPoint(m.embedding, *centre);
    Put3(out, "p." + m.bodies[b].name, e.p);
    Put3(out, "v." + m.bodies[b].name, e.v);
    Put3(out, "a." + m.bodies[b].name, e.a);
  }
}

void RunGears(const Model& m, const RunOptions& options, Result& r) {
  if (m.synthesis) SynthesisQuantities(*m.synthesis, r);
  if (m.drivers.empty()) return;  // a pure design goal: nothing to simulate
  const GearTrainSolver solver(m);
  const Eigen::VectorXd guess = m.GuessQ();
  const double t0 = m.analysis.t0;
  auto at = [&](double t) {
    // Angle displacements from the guesses, rates and accelerations: one linear law for all three.
    const size_t nb = m.bodies.size();
    std::vector<double> d(nb, kNaN), w(nb, kNaN), al(nb, kNaN);
    for (size_t b = 0; b < nb; ++b) {
      const int drv = solver.member_driver()[b];
      if (drv < 0) continue;
      const Driver& dr = m.drivers[drv];
      d[b] = dr.At(t, t0) - guess[m.SlotIndex(dr.coordinate)];
      w[b] = dr.RateAt(t, t0);
      al[b] = dr.AccelerationAt(t, t0);
    }
    d = solver.Propagate(d), w = solver.Propagate(w), al = solver.Propagate(al);
    Sample s;
    s.t = t;
    const size_t n = m.q_layout.size();
    s.q.setConstant(n, kNaN), s.qd.setConstant(n, kNaN), s.qdd.setConstant(n, kNaN);
    for (size_t i = 0; i < n; ++i) {
      const int c = m.q_layout[i].coordinate;
      if (c < 0 || (m.coordinates[c].type != CoordinateType::kRotation && m.coordinates[c].type != CoordinateType::kTravel))
        continue;
      const int b = m.coordinates[c].body;
      s.q[i] = guess[i] + d[b], s.qd[i] = w[b], s.qdd[i] = al[b];
    }
    return std::make_pair(s, std::make_pair(w, al));
  };
  const auto [s0, rates] = at(t0);
  PutLayout(m, s0.q, s0.qd, s0.qdd, r.quantities);
  for (size_t b = 0; b < m.bodies.size(); ++b) {
    if (!(rates.first[b] == rates.first[b]) || m.bodies[b].IsSliding()) continue;  // a rack's speed is qd of its travel
    r.quantities["omega." + m.bodies[b].name] = rates.first[b];
    r.quantities["alpha." + m.bodies[b].name] = rates.second[b];
  }
  GearCentreQuantities(m, solver, s0, rates.first, rates.second, r.quantities);
  r.settings["gear law"] = "mesh ratio -s*Za/Zb in the carrier frame; Willis across carriers";
  r.trajectory.push_back(s0);
  if (!options.motion || !m.analysis.HasMotion()) return;
  EnterPhase(options, Phase::kIntegration);
  r.steps = m.analysis.samples - 1;
  for (int k = 1; k < m.analysis.samples; ++k) r.trajectory.push_back(at(m.analysis.TimeAt(k)).first);
}

// A spatial loop of two paths and a bar (spatial.h): every q slot, and p./v./a. of every point and
// vector (fixed ones too, as numeric gives them), at t0; the motion sample by sample.
void RunSpatial(const Model& m, const RunOptions& options, Result& r) {
  const SpatialLoopSolver solver(m);  // Applicability() has checked that it applies
  r.settings["decomposition"] = solver.Describe();
  r.settings["branches"] = "from the scenario's pose at t0, then kept (turns tracked sample to sample)";
  const double t0 = m.analysis.t0;
  SpatialLoopState s0;
  try {
    s0 = solver.Solve(t0, nullptr);
  } catch (const AssemblyError& e) {
    throw ScenarioError(e.where(), std::string(e.what()) + " at t = " + Num(t0) + " s", e.fix());
  }
  auto sample = [&](const SpatialLoopState& s) {
    Sample out;
    out.t = s.t;
    solver.ToLayout(s, out.q, out.qd, out.qdd);
    out.residual = s.residual;
    return out;
  };
  const Sample first = sample(s0);
  PutLayout(m, first.q, first.qd, first.qdd, r.quantities);
  r.quantities["residual"] = s0.residual;
  r.quantities["residual_rate"] = s0.residual_rate;
  for (size_t e = 0; e < m.spatial.entities.size(); ++e) {
    const PointState3 st = solver.Entity(s0, static_cast<int>(e));
    const std::string& n = m.spatial.entities[e].name;
    Put3(r.quantities, "p." + n, st.p);
    Put3(r.quantities, "v." + n, st.v);
    Put3(r.quantities, "a." + n, st.a);
  }
  r.trajectory.push_back(first);
  if (!options.motion || !m.analysis.HasMotion()) return;
  EnterPhase(options, Phase::kIntegration);
  r.steps = m.analysis.samples - 1;
  SpatialLoopState prev = s0;
  const double tol = 1e-7 * m.LengthScale();
  for (int k = 1; k < m.analysis.samples; ++k) {
    const double t = m.analysis.TimeAt(k);
    SpatialLoopState s;
    try {
      s = solver.Solve(t, &prev);
    } catch (const AssemblyError& e) {
      if (e.out_of_reach()) ThrowOutOfReach(m, e, t);
      r.status = Status::kDiverged;
      r.reason = "loop cannot close at t = " + Num(t) + " s: " + e.what();
      return;
    }
    if (!(s.residual <= tol)) {
      r.status = Status::kDiverged;
      r.reason = "closed forms lost the loop at t = " + Num(t) + " s (residual " + Num(s.residual) + ")";
      return;
    }
    r.trajectory.push_back(sample(s));
    prev = s;
  }
}

}  // namespace

AnalyticMethod::AnalyticMethod()
    : Method("analytic", "vector method: closed-form loop closure, rigid-body and relative-motion kinematics") {}

// A free scene (no drivers) moves under its loads; its motion is forward dynamics, but its mass
// matrix and generalised forces follow from the energy alone, at the configuration in the file.
static void RunFreeLinkage(const Model& m, Result& r) {
  if (!m.initial.empty()) {
    // The initial conditions act as drivers at t0 only: the same closed forms place the scene.
    const Model driven = m.InitialAsDrivers();
    RunLinkage(driven, RunOptions{.motion = false}, r);
    // At t0 only, and without accelerations: those come from forward dynamics.
    r.trajectory.resize(1);
    r.trajectory[0].qdd.resize(0);
    for (auto it = r.quantities.begin(); it != r.quantities.end();) {
      const std::string& k = it->first;
      const bool acc = k.rfind("qdd.", 0) == 0 || k.rfind("alpha.", 0) == 0 || k.rfind("a.", 0) == 0 ||
                       k.rfind("aabs", 0) == 0 || k.rfind("an.", 0) == 0 || k.rfind("at.", 0) == 0 ||
                       k.rfind("rho.", 0) == 0 || k.rfind("alphaabs", 0) == 0;
      it = acc ? r.quantities.erase(it) : std::next(it);
    }
  } else {
    const Eigen::VectorXd q = m.GuessQ();
    // No Newton here: without initial conditions the file's positions must close every body.
    for (const Body& b : m.bodies)
      for (size_t k = 1; k < b.points.size(); ++k) {
        const double d = (m.points[b.points[k]].p_W - m.points[b.points[0]].p_W).norm();
        if (std::fabs(d - b.p_B[k].norm()) > 1e-9 * std::max(1.0, b.p_B[k].norm())) {
          r.status = Status::kNotApplicable;
          r.reason = "free scene whose positions in the file do not close body " + b.name +
                     " and no initial: conditions to place it (the vector method has no iterative assembly)";
          return;
        }
      }
    for (size_t i = 0; i < m.q_layout.size(); ++i) r.quantities["q." + m.q_layout[i].name] = q[i];
    r.trajectory.push_back(Sample{m.analysis.t0, q, Eigen::VectorXd::Zero(q.size()), Eigen::VectorXd(), 0.0});
  }
  AddMassAndForces(m, r.trajectory.front(), r.quantities);
  r.messages.push_back("free scene: its state at t0, with M and Q from the kinetic energy and the loads' power; "
                       "the motion needs forward dynamics");
}

std::optional<std::string> AnalyticMethod::Applicability(const Model& model) const {
  if (model.kind == ScenarioKind::kSpatial) return SpatialLoopSolver(model).why_not();
  if (model.kind == ScenarioKind::kLinkage && model.drivers.empty()) {
    if (!model.HasMass()) return "no drivers and no masses: nothing to compute";
    std::string why;
    if (!model.initial.empty() && !PlanLinkage(model.InitialAsDrivers(), &why)) return why;
    return std::nullopt;  // the state at t0, M and Q by energy
  }
  if (model.kind == ScenarioKind::kGearTrain) {
    if (model.drivers.empty()) {
      if (model.synthesis) return std::nullopt;  // synthesis quantities only
      return "no drivers: nothing sets the members' speeds";
    }
    return GearTrainSolver(model).why_not();
  }
  std::string why;
  if (!PlanLinkage(model, &why)) return why;
  return std::nullopt;
}

void AnalyticMethod::DoRun(const Model& model, const RunOptions& options, Result& result) const {
  if (model.kind == ScenarioKind::kGearTrain) RunGears(model, options, result);
  else if (model.kind == ScenarioKind::kSpatial) RunSpatial(model, options, result);
  else if (model.drivers.empty()) RunFreeLinkage(model, result);
  else {
    RunLinkage(model, options, result);
    if (model.HasMass() && !result.trajectory.empty()) AddMassAndForces(model, result.trajectory.front(), result.quantities);
  }
}

std::unique_ptr<Method> MakeAnalyticMethod() { return std::make_unique<AnalyticMethod>(); }

}  // namespace mechbench::analytic
