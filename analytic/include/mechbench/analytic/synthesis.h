// §6.2 ratio synthesis with spur gears: ordinary trains by factorising the ratio, the coaxial
// (recurrent) condition, arm-driven epicyclic trains from the apparent ratio μA = 1/(1 − i), and
// single-pair approximations by continued fractions. Ratios are i = ω_out/ω_in.
#pragma once

#include "mechbench/model.h"

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace mechbench::analytic {

struct Fraction {
  std::int64_t num = 0, den = 1;
  double value() const { return static_cast<double>(num) / static_cast<double>(den); }
  bool operator==(const Fraction&) const = default;
};
Fraction Reduced(std::int64_t num, std::int64_t den);

// The exact fraction behind a ratio read as a double (221/1005 from 0.2199004975...), by
// continued fractions; nullopt when no denominator up to max_den reproduces it to 1e-12.
std::optional<Fraction> RecoverFraction(double ratio, std::int64_t max_den = 1000000);

// Continued-fraction terms [a0; a1, a2, ...] of a positive fraction (221/1005 -> [0;4,1,1,4,1,3,5]).
std::vector<std::int64_t> ContinuedFraction(Fraction f);

// Convergents p_k/q_k after a0 (1/4, 1/5, 2/9, ... for 221/1005) with their errors |f − p/q|.
struct Convergent {
  std::int64_t num, den;
  double error;
};
std::vector<Convergent> Convergents(Fraction f);

// One spur-gear pair: ω_driven/ω_driver = Z_driver/Z_driven (the sign of external meshes aside).
struct GearPair {
  int driver = 0, driven = 0;
  bool operator==(const GearPair&) const = default;
};

struct GearLimits {
  int z_min = 10, z_max = 100;
  double max_pair_ratio = 5.0;  // max(Z)/min(Z) per pair
  bool Fits(const GearPair& p) const;
};

// Every way (up to pair order) of writing `ratio` as a product of `pairs` pair ratios within the
// limits, the book's way: split the prime factors of numerator and denominator among the pairs,
// then scale each pair by the smallest whole factor that brings both wheels to z_min or more.
std::vector<std::vector<GearPair>> FactorizeIntoPairs(Fraction ratio, int pairs, const GearLimits& limits);
// The fewest pairs that work (up to max_pairs), or empty.
std::vector<std::vector<GearPair>> FewestPairs(Fraction ratio, const GearLimits& limits, int max_pairs = 3);

// Coaxial (recurrent) two-stage train: r1 + r2 = r3 + r4 with r = m Z/2, so
// m2/m1 = (Z1 + Z2)/(Z3 + Z4).
double CoaxialModuleRatio(const GearPair& first, const GearPair& second);

// Arm-driven ("de balancín") epicyclic train with a compound planet: the central wheel F is fixed,
// planet wheel P1 meshes F, planet wheel P2 (on P1's shaft) meshes the output central wheel O;
// the arm is the input. Willis in the arm frame: (ω_O − ω_arm)/(ω_F − ω_arm) = (Z_F/Z_P1)(Z_P2/Z_O),
// so i = ω_O/ω_arm = 1 − (Z_F Z_P2)/(Z_P1 Z_O).
Fraction EpicyclicRatio(int z_fixed, int z_p1, int z_p2, int z_out);
// μA = 1/(1 − i).
Fraction ApparentRatio(Fraction i);

// A single pair within `tol` of the ratio: the first convergent whose wheels fit the limits
// (scaled by the smallest whole factor that brings both to z_min).
std::optional<GearPair> PairWithin(Fraction ratio, double tol, const GearLimits& limits);

// Everything above for a Model::synthesis, as named quantities ("synthesis.cf.3.num", ...).
struct SynthesisReport {
  Fraction ratio;
  std::vector<std::int64_t> cf_terms;
  std::vector<Convergent> convergents;
  std::vector<GearPair> ordinary;      // fewest pairs (empty if none)
  double coaxial_module_ratio = kNaN;  // when the ordinary train has two pairs
  Fraction mu_A;
  std::vector<GearPair> epicyclic;     // two pairs for μA: (Z_P1/Z_F), (Z_O/Z_P2)
  Fraction epicyclic_check;            // i recomputed by Willis from those wheels
  std::optional<GearPair> pair_within_1e4;
  std::vector<std::string> notes;
};
SynthesisReport Synthesize(const Synthesis& goal);

}  // namespace mechbench::analytic
