// Forward-dynamics methods for free scenes (no drivers, with masses), one Method per formulation,
// all on the same NaturalModel / DynamicsSystem:
//   dyn-baumgarte-rk4            index-1 Lagrange multipliers + Baumgarte, classic RK4, fixed step
//   dyn-baumgarte-dopri5         the same with an error-controlled Dormand–Prince 5(4)
//   dyn-ali3p                    index-3 augmented Lagrangian, trapezoidal rule, mass-orthogonal
//                                projections of q̇ and q̈ (García de Jalón & Bayo; Cuadrado et al.)
//   dyn-coordinate-partitioning  independent coordinates from the pivots of Φ_q (re-chosen when
//                                the dependent block gets ill-conditioned), DOPRI5 or RK4 on them,
//                                dependent ones by Newton–Raphson
// Samples land exactly on analysis.TimeAt(k). Result::quantities at t0: q., qd., qdd., lambda[i],
// energy; over the run: energy_drift [J] (max |E − E0|), max_residual (scaled ‖Φ‖),
// max_residual_rate (scaled ‖Φ̇‖ [1/s]), steps, iterations. A run that produces NaN/Inf or whose
// iteration fails ends with Status::kDiverged naming the time, keeping the samples so far.
//
// Singular positions (Φ_q loses rank, e.g. the N-four-bar's horizontal positions): no formulation
// switches assembly branch silently. RK4, DOPRI5 and ALI3-P stop (kDiverged, "at t = …: … singular
// position …") when the accelerations exceed 100 × the run's scale (the constraint forces of a
// branch switch; settings["singular_guard"] gives the run's peak); coordinate partitioning stops
// where the independent coordinates no longer determine the dependent ones. ALI3-P gets through:
// near a singular position its Newton iteration contracts only linearly (accepted within
// singular_tolerance) and a step that still fails is redone in sub-steps (settings["slow_steps"],
// ["retried_steps"]).
//
// Linear algebra (settings["linear_solver"] says which and why): dense, or sparse with Φ_q's fixed
// pattern so that a step of the N-four-bar costs O(N) (see LinearAlgebra in forward_dynamics.h).
//
// Work–precision sweeps (Method::control()): RK4 and ALI3-P are Control::kStep (default h), DOPRI5
// Control::kTolerance (default rtol; an override keeps the atol/rtol ratio), coordinate
// partitioning kTolerance in its DOPRI5 mode and kStep with rk4 = true. The override applies to
// one run only (the options below stay as constructed); settings["h"] / ["rtol"] show the value
// used and whether it came from RunOptions, settings["control_value"] the plain number (a step
// above the sample interval is capped to it, and says so).
#pragma once

#include "mechbench/method.h"
#include "mechbench/numeric/forward_dynamics.h"

#include <memory>
#include <string>

namespace mechbench::numeric {

struct BaumgarteOptions {
  double alpha = 10.0, beta = 10.0;  // [1/s] damping and stiffness of the constraint error
  double h = 1e-3;                   // RK4: largest step [s] (shortened to land on samples)
  double rtol = 1e-8;                // DOPRI5: relative tolerance
  double atol = 1e-10;               // DOPRI5: absolute tolerance, × each coordinate's scale (× 1/s for q̇)
  // Dense LU or sparse LU (COLAMD) on [M Φ_qᵀ; Φ_q 0]; kAuto: sparse from kSparseIndex1FromCoordinates.
  LinearAlgebra linear_algebra = LinearAlgebra::kAuto;
};

struct Ali3pOptions {
  double h = 1e-3;             // step [s] (shortened to land on samples)
  // α (h²/4) / max diag M: the penalty's weight against the mass in the tangent matrix
  // (dimensionless; rows scaled to length units). 250 is α = 1e9 /s² × max diag M at h = 1 ms,
  // the usual choice in the literature; keeping the ratio, not α, makes smaller steps converge alike.
  double penalty = 250.0;     // kept as is when RunOptions::step changes h
  double tolerance = 1e-10;    // Newton: max |Δq_j| / scale_j (a length: the median link; an angle: 1 rad)
  // Near singular positions the iteration contracts only linearly: a step is also accepted when
  // its remaining error, estimated from the contraction rate ρ as |Δq| ρ/(1 − ρ), is within this
  // (relative to the coordinate scale, like tolerance).
  double singular_tolerance = 1e-7;
  int max_iterations = 60;
  // A step whose Newton iteration fails (near a singular position) is redone in 4 sub-steps of
  // h/4, each of those likewise, this many levels deep (h/16 at 2); 0: the run stops at once.
  int retry_levels = 2;
  // Dense LDLᵀ or sparse SimplicialLDLT (AMD) on the tangent matrix; kAuto: always sparse (faster at
  // every size measured, kSparseAli3pFromCoordinates).
  LinearAlgebra linear_algebra = LinearAlgebra::kAuto;
};

struct PartitioningOptions {
  bool rk4 = false;            // false: DOPRI5 with rtol/atol; true: RK4 at step h
  double rtol = 1e-8, atol = 1e-10;  // as BaumgarteOptions
  double h = 1e-3;             // RK4 step [s]
  double newton_tolerance = 1e-13;   // dependent coordinates: ScaledResidual
  double rechoose_ratio = 0.1; // re-choose when the dependent block's pivot ratio falls below this × the best one
  // Always dense: the partition is a full-pivoting LU of Φ_q (pivots chosen for conditioning, which
  // a fill-reducing sparse LU does not do), and its Newton solves use dense QR of the dependent
  // block; the method is the small scenes' cross-check and stops at the N-four-bar's first
  // singular position anyway.
};

std::unique_ptr<Method> MakeBaumgarteRk4Method(BaumgarteOptions options = {});
std::unique_ptr<Method> MakeBaumgarteDopri5Method(BaumgarteOptions options = {});
std::unique_ptr<Method> MakeAli3pMethod(Ali3pOptions options = {});
std::unique_ptr<Method> MakeCoordinatePartitioningMethod(PartitioningOptions options = {});

// Why a dynamics method cannot run `model`, or nullopt.
std::optional<std::string> DynamicsApplicability(const Model& model);

}  // namespace mechbench::numeric
