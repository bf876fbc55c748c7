// The analytic vector method as a mechbench::Method ("analytic").
//
// Linkages: the closed-form dyad decomposition of linkage.h at the instant and along the motion;
// 3-D views through the embedding, absolute values when the frame turns (both routes of
// moving_frame.h). Gear trains: mesh ratios and Willis' formula (gears.h), plus §6.2 synthesis
// quantities when the model has a `synthesis` goal.
//
// Quantities beyond those of method.h:
//   vslide.<pt>                 sliding velocity along the body's first→second unit vector
//   at.<pt> an.<pt> rho.<pt>    intrinsic coordinates: s̈, v²/R, R (points with nonzero speed)
//   vabs_chain.<pt>.<c> aabs_chain.<pt>.<c>  absolute values by the rigid-body chain (route 2)
//   alphaabs.<body>.<c>         absolute angular acceleration when the frame turns
//   residual                    max |constraint| of the closed-form solution at the instant
//   synthesis.*                 see Synthesize(): cf.<k>.num|den|error, pair_within_1e4.num|den,
//                               ordinary.<k>.driver|driven, coaxial.module_ratio,
//                               epicyclic.mu_A, epicyclic.Z1..Z4, epicyclic.ratio_check
#pragma once

#include "mechbench/method.h"

#include <memory>

namespace mechbench::analytic {

class AnalyticMethod final : public Method {
 public:
  AnalyticMethod();
  std::optional<std::string> Applicability(const Model& model) const override;

 protected:
  void DoRun(const Model& model, const RunOptions& options, Result& result) const override;
};

std::unique_ptr<Method> MakeAnalyticMethod();

}  // namespace mechbench::analytic
