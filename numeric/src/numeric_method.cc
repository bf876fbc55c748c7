#include "mechbench/format.h"
#include "mechbench/numeric/numeric_method.h"

#include "mechbench/motion_error.h"

#include "mechbench/errors.h"
#include "mechbench/numeric/constraints.h"
#include "mechbench/numeric/derived.h"
#include "mechbench/numeric/dynamics.h"
#include "mechbench/numeric/natural_model.h"
#include "mechbench/numeric/spatial.h"

#include <cmath>
#include <cstdio>

namespace mechbench::numeric {
namespace {

std::string Index(const char* name, int i) { return std::string(name) + "[" + std::to_string(i) + "]"; }
std::string Index(const char* name, int i, int j) {
  return std::string(name) + "[" + std::to_string(i) + "," + std::to_string(j) + "]";
}

void PutVector3(Quantities& out, const std::string& prefix, const Eigen::Vector3d& v) {
  out[prefix + ".x"] = v.x();
  out[prefix + ".y"] = v.y();
  out[prefix + ".z"] = v.z();
}

// A spatial scene's points (fixed ones too) and unit vectors: p., v., a.<name>.<x|y|z>.
void FillSpatialPoints(const NaturalModel& nm, const NaturalData& data, Quantities& out) {
  for (int e = 0; e < static_cast<int>(nm.entities.size()); ++e) {
    const std::string& name = nm.entities[e].name;
    if (name.rfind("world ", 0) == 0) continue;  // a point mass's world axes (spatial_compile.cc)
    PutVector3(out, "p." + name, EntityValue(nm, data.q, e));
    PutVector3(out, "v." + name, EntityRate(nm, data.qd, e));
    if (data.qdd.size() == nm.n) PutVector3(out, "a." + name, EntityRate(nm, data.qdd, e));
  }
}

// Every quantity of method.h that this method computes at the solved instant in `data`.
void FillInstant(const NaturalModel& nm, NaturalData& data, const InstantReport& inst, Quantities& out) {
  const Model& model = nm.model;
  for (int s = 0; s < nm.n; ++s) {
    const std::string& name = model.q_layout[s].name;
    out["q." + name] = data.q[s];
    out["qd." + name] = data.qd[s];
    out["qdd." + name] = data.qdd[s];
  }
  for (size_t b = 0; b < model.bodies.size(); ++b) {
    const auto w = BodyAngularRates(nm, data, static_cast<int>(b));
    if (!w) continue;
    const std::string& name = model.bodies[b].name;
    out["omega." + name] = w->omega;
    out["alpha." + name] = w->alpha;
    if (model.frame)  // planar rate about the plane normal plus the frame's own rate
      PutVector3(out, "omegaabs." + name,
                 w->omega * model.embedding.Normal() + model.frame->omega * model.frame->axis.normalized());
  }
  for (size_t p = 0; p < model.points.size(); ++p) {
    const std::string& name = model.points[p].name;
    const WorldPoint w = PointInWorld(nm, data, static_cast<int>(p));
    PutVector3(out, "p." + name, w.p);
    PutVector3(out, "v." + name, w.v);
    PutVector3(out, "a." + name, w.a);
    if (model.frame) {
      const WorldPoint abs = AbsolutePoint(*model.frame, w);
      PutVector3(out, "vabs." + name, abs.v);
      PutVector3(out, "aabs." + name, abs.a);
    }
  }
  if (nm.dim == 3) FillSpatialPoints(nm, data, out);
  for (size_t b = 0; b < model.gear_axes.size(); ++b) {
    const auto w = MemberCentreInWorld(nm, data, static_cast<int>(b));
    if (!w) continue;
    const std::string& name = model.bodies[b].name;
    PutVector3(out, "p." + name, w->p);
    PutVector3(out, "v." + name, w->v);
    PutVector3(out, "a." + name, w->a);
  }
  for (size_t j = 0; j < model.joints.size(); ++j) {
    const auto s = SliderRates(nm, data, static_cast<int>(j));
    if (!s) continue;
    const std::string& name = model.points[model.joints[j].point].name;
    out["vslide." + name] = s->v;
    out["aslide." + name] = s->a;
  }
  EvalPhi(nm, data, data.q, data.t);
  EvalJacobian(nm, data, data.q);
  EvalPhidotQdot(nm, data, data.q, data.qd);
  for (int i = 0; i < nm.m(); ++i) {
    out[Index("Phi", i)] = data.Phi[i];
    out[Index("Phidot_q_qd", i)] = data.Phidot_q_qd[i];
    if (data.sparse) continue;
    for (int j = 0; j < nm.n; ++j) {
      out[Index("Phi_q", i, j)] = data.Phi_q(i, j);
      out[Index("Phidot_q", i, j)] = data.Phidot_q(i, j);
    }
  }
  if (data.sparse) {
    // Φ_q and Φ̇_q on their pattern only (every other entry is 0 by structure): m × n entries
    // would be 400 million names at N = 10,000.
    const SparseJacobian::Matrix &J = data.jac.J(), &Jd = data.jac.Jdot();
    for (int i = 0; i < nm.m(); ++i)
      for (SparseJacobian::Matrix::InnerIterator it(J, i), dt(Jd, i); it; ++it, ++dt) {
        const int j = static_cast<int>(it.col());
        out[Index("Phi_q", i, j)] = it.value();
        out[Index("Phidot_q", i, j)] = dt.value();
      }
  }
  for (size_t k = 0; k < inst.newton.iterates.size(); ++k)
    for (int s = 0; s < nm.n; ++s)
      out["newton." + std::to_string(k + 1) + "." + model.q_layout[s].name] = inst.newton.iterates[k][s];
  out["rank"] = inst.rank.rank;
  out["dof"] = inst.rank.dof;
  out["iterations"] = inst.newton.iterations;
  out["n"] = nm.n;
  out["rows"] = nm.m();
  if (model.HasMass()) {
    MassMatrix(nm, data);
    GeneralizedForces(nm, data);
    if (model.HasForceElements()) AddElementForces(nm, data.q, data.qd, model.analysis.t0, data.Q);  // at the solved state
    for (int i = 0; i < nm.n; ++i) {
      out[Index("Q", i)] = data.Q[i];
      if (data.sparse) continue;
      for (int j = 0; j < nm.n; ++j) out[Index("M", i, j)] = data.M(i, j);
    }
    if (data.sparse)  // M's nonzeros only, as Φ_q's
      for (int j = 0; j < data.M_sparse.outerSize(); ++j)
        for (Eigen::SparseMatrix<double>::InnerIterator it(data.M_sparse, j); it; ++it)
          out[Index("M", static_cast<int>(it.row()), j)] = it.value();
  }
}

// A motion's position problem that fails within a driver's scale: the drivers are stepped from the
// previous sample toward t, as at t0 (solver.h, DescribeUnreachableDrivers), which tells a value
// past the mechanism's reach (with one driver, its range from there) from a prediction that was
// only too far.
// A value past the mechanism's reach is bad input, as at t0 (a ScenarioError on the first driver's
// line: the file asks for a motion that does not exist, and no method should run it), with the
// range from the previous sample; a prediction only too far is this run's failure (the hint).
std::string ReachHint(const NaturalModel& nm, const Sample& prev, double t, const NewtonOptions& options,
                      const NewtonReport& failed, const std::string& head) {
  NaturalData at(nm);
  at.q = prev.q;
  const ReachReport r =
      DescribeUnreachableDrivers(nm, at, t, options, failed, "the position at t = " + Fmt(prev.t) + " s (the previous sample)");
  if (r.reachable)
    return ": the mechanism does reach the driven values at t = " + Fmt(t) + " s when its drivers are stepped there from "
           "the previous sample (t = " + Fmt(prev.t) + " s), so the prediction from that sample was too far (a fast "
           "passage, or a branch near a singular position): more samples";
  const Model& m = nm.model;
  SourceRef where{m.source_file, 0};
  if (!m.drivers.empty()) where = m.drivers.front().src;
  throw ScenarioError(where, head + ": " + r.what, r.fix);
}

Sample MakeSample(const NaturalData& data) { return Sample{data.t, data.q, data.qd, data.qdd, data.Phi.norm()}; }

// When a sample interval carries the drivers further than their scale (a radian, the scene's
// size), the prediction from the previous sample is no guide: Newton–Raphson fails on the interval,
// not on the mechanism, and the reason says so (t1 = 1e9 s in 73 samples turns a crank 1.4e7
// times between samples). Empty otherwise.
std::string IntervalHint(const NaturalModel& nm, double t_prev, double t) {
  const Model& model = nm.model;
  std::string moves;
  bool far = false;
  for (const Driver& d : model.drivers) {
    const int slot = model.SlotIndex(d.coordinate);
    const double travel = std::fabs(d.At(t, model.analysis.t0) - d.At(t_prev, model.analysis.t0));
    if (slot < 0 || !(travel > nm.q_scale[slot])) continue;
    far = true;
    const bool angle = SlotKind(model, slot) == 1;  // an angle (planar or spatial) or a rotation
    moves += (moves.empty() ? "" : ", ") + d.coordinate + " by " + Fmt(travel, 3) +
             (angle ? " rad (" + Fmt(travel / (2 * 3.14159265358979323846), 3) + " turns)" : " " + model.length_unit);
  }
  if (!far) return "";
  return ": the sample interval of " + Fmt(t - t_prev, 3) + " s moves " + moves +
         ", further than a prediction from the previous sample can follow (more samples, or a shorter t1)";
}

}  // namespace

NumericMethod::NumericMethod(NewtonOptions options)
    : Method("numeric", "natural coordinates: Newton–Raphson position, linear velocity and acceleration problems"),
      newton_(options) {}

std::optional<std::string> NumericMethod::Applicability(const Model& model) const {
  if (model.kind != ScenarioKind::kLinkage && model.kind != ScenarioKind::kGearTrain &&
      model.kind != ScenarioKind::kSpatial)
    return "the numeric method solves linkages, gear trains and spatial linkages only";
  if (model.q_layout.empty()) return "the scene has no coordinates to solve (nothing moves)";
  return std::nullopt;
}

void NumericMethod::DoRun(const Model& model, const RunOptions& options, Result& result) const {
  const NaturalModel nm = Compile(model);
  NaturalData data(nm);
  result.settings["phi_tolerance"] = Fmt(newton_.phi_tolerance) + " (max |Φ_i| / row scale)";
  result.settings["step_tolerance"] = Fmt(newton_.step_tolerance) + " (max |Δq_j| / coordinate scale)";
  result.settings["max_iterations"] = std::to_string(newton_.max_iterations);
  result.settings["linear_solver"] =
      data.sparse ? "row-scaled least squares, sparse (n = " + std::to_string(nm.n) + " ≥ " +
                        std::to_string(kSparseKinematicsFromCoordinates) +
                        "): Newton by sparse LU (square), else by the minimum-norm solution from a sparse QR of "
                        "[Φ_q; B]ᵀ in row order, which also gives the ranks, the redundant rows and the velocity and "
                        "acceleration; Phi_q, Phidot_q and M reported on their nonzero pattern only"
                  : "row-scaled least squares: LU (square, well conditioned), else complete orthogonal decomposition";
  const std::string relative = data.sparse ? " (|R_kk| of the sparse QR, rows in order, relative to the largest singular "
                                             "value of the row-normalized "
                                           : " (relative singular value of the row-normalized ";
  result.settings["rank_tolerance"] = Fmt(kRankTolerance) + relative + "Φ_q)";
  result.settings["singular_tolerance"] = Fmt(kSingularTolerance) + relative + "[Φ_q; B])";

  // The instant, from the file's guesses; an impossible scene throws ScenarioError from here.
  const double t0 = model.analysis.t0;
  // The closure residual of the file's own positions and guesses, before anything is solved: a
  // state written out in full (a published initial state) shows here whether it satisfies its own
  // constraints (ScaledResidual; a book claim `residual.guess` = 0 checks it).
  if (const Eigen::VectorXd guess = model.GuessQ(); guess.size() == nm.n && guess.allFinite()) {
    EvalPhi(nm, data, guess, t0);
    result.quantities["residual.guess"] = ScaledResidual(nm, data);
  }
  const InstantReport inst = SolveInstant(nm, data, t0, model.GuessQ(), newton_);
  result.messages.insert(result.messages.end(), inst.messages.begin(), inst.messages.end());
  FillInstant(nm, data, inst, result.quantities);
  result.trajectory.push_back(MakeSample(data));
  if (nm.f() == 0) {
    // At rest, but not in equilibrium: q̈ comes from forward dynamics, so none is claimed here.
    result.trajectory.back().qdd.resize(0);
    for (auto it = result.quantities.begin(); it != result.quantities.end();) {
      const std::string& k = it->first;
      const bool acc = k.rfind("qdd.", 0) == 0 || k.rfind("alpha.", 0) == 0 || k.rfind("a.", 0) == 0 ||
                       k.rfind("aabs.", 0) == 0 || k.rfind("aslide.", 0) == 0;
      it = acc ? result.quantities.erase(it) : std::next(it);
    }
  }
  if (!options.motion || !model.analysis.HasMotion()) return;
  if (nm.f() == 0) {
    // SolveInstant already said why (once): a free scene's motion is forward dynamics, which the
    // dyn-* methods integrate; this kinematic method reports the instant only.
    result.settings["motion"] = "instant only: a free scene's motion is forward dynamics (dyn-* methods)";
    return;
  }

  result.settings["predictor"] = "q + q̇ Δt + ½ q̈ Δt² from the previous sample";
  NewtonOptions sweep = newton_;
  sweep.record_iterates = false;
  sweep.simplified = true;
  result.settings["newton"] = "simplified along the motion: Φ_q refactored only when a step shrinks ‖Φ‖ less than 4×";
  // The motion: one position, velocity and acceleration problem per sample is the method's own
  // work (Result::cpu.integration); the instant above, with its checks, is its set-up.
  EnterPhase(options, Phase::kIntegration);
  result.steps = model.analysis.samples - 1;
  for (int k = 1; k < model.analysis.samples; ++k) {
    const Sample& prev = result.trajectory.back();
    const double t = model.analysis.TimeAt(k), dt = t - prev.t;
    const Eigen::VectorXd q_pred = prev.q + prev.qd * dt + 0.5 * dt * dt * prev.qdd;
    const NewtonReport nr = SolvePosition(nm, data, q_pred, t, sweep);
    if (!nr.converged) {
      const std::string head = "Newton–Raphson did not converge at t = " + Fmt(t) + " s (‖Φ‖ = " + Fmt(nr.residual) +
                               " after " + std::to_string(nr.iterations) + " iterations)";
      const std::string interval = IntervalHint(nm, prev.t, t);
      result.reason = head + (interval.empty() ? ReachHint(nm, prev, t, newton_, nr, head) : interval);
      result.status = Status::kDiverged;
      return;
    }
    // A singular augmented matrix (a toggle position, a cos-form angle at 0 or π) has no unique
    // velocity: stop there rather than report a least-squares answer as the motion.
    if (SolveVelocity(nm, data, t) < nm.n || !data.qd.allFinite()) {
      result.status = Status::kDiverged;
      result.reason = "singular position at t = " + Fmt(t) +
                      " s: rank [Φ_q; B] < n, the drivers do not fix the velocity there";
      return;
    }
    SolveAcceleration(nm, data, t);
    EvalPhi(nm, data, data.q, t);
    result.trajectory.push_back(MakeSample(data));
    CheckBudget(options, t);
  }
}

std::unique_ptr<Method> MakeNumericMethod() { return std::make_unique<NumericMethod>(); }

}  // namespace mechbench::numeric
