// The report's long-chains table (issue 14): every integrating method on the generated
// N-four-bar (references::NFourBar, the scene `mechbench generate nfourbar N` writes) as N grows
// along a ladder, each rung a fresh run (in the case's own process after the method's one-time
// costs are paid, as every report case runs), judged against the scene's exact motion
// (`reference: {exact: nfourbar}`, the registry in harness/references: no reference
// integration). One case per method, kind "chain"; its record holds the rungs, why the ladder
// stopped and the growth exponent of the integration CPU.
//
// The whole part is meant to be cheap (at most about 10 s of CPU for every method together): a
// short horizon, and a per-method CPU budget that ends the ladder, with the next rung's cost
// predicted from the last ones so that a method growing as N³ is not started on a rung it cannot
// finish.
#pragma once

#include "mechbench/harness/campaign.h"
#include "mechbench/method.h"

#include <nlohmann/json.hpp>

#include <string>
#include <utility>
#include <vector>

namespace mechbench::harness {

struct ChainPlan {
  std::vector<int> ladder{1, 3, 10, 30, 100, 300, 1000};  // N, ascending
  double t1 = 0.02;                                      // [s] horizon of each run (from t0 = 0)
  int samples = 11;                                      // output samples over [0, t1] (the budget is checked at each)
  double budget = 0.4;                                   // [s] CPU of every rung of one method together
  // A run whose position error (CompareMotion's q, max) or scaled ‖Φ‖ passes these has lost the
  // motion: its ladder stops there.
  double lost_error = 0.1, lost_residual = 1e-2;
  // Rungs from this N on are fitted for the growth exponent, when at least two reached it;
  // otherwise every rung reached.
  int fit_from = 10;
};

// The plan a campaign runs (CampaignOptions::chain_ladder and chain_budget override the default's).
ChainPlan ChainPlanFor(const CampaignOptions& options);

// Whether `method` gets a chain case: it integrates in time (a step or a tolerance; the
// kinematic methods give a free scene's instant only).
bool ChainMethod(const Method& method);

// The case of one method: id "chain/nfourbar/<method>".
Case ChainCaseFor(const std::string& method);

// Runs a chain case in this process (a rung that crashes or hangs ends the case: ChainFallback).
std::vector<nlohmann::json> ChainCase(const Case& c, const CampaignOptions& options);

// The record a chain case stands for when its process died or overran.
nlohmann::json ChainFallback(const Case& c, const std::string& what, const std::string& detail, double wall);

// Least-squares slope of log(cost) against log(N): the growth exponent. Points with a
// non-positive or non-finite value are left out; NaN with fewer than two.
double GrowthExponent(const std::vector<std::pair<double, double>>& n_cost);

// Least-squares slope of log y against log x over the points given (all x, y > 0); NaN with fewer
// than two distinct x. The one fit behind a chain's growth exponent and a sweep's observed order.
double LogLogSlope(const std::vector<std::pair<double, double>>& xy);

}  // namespace mechbench::harness
