#include "mechbench/analytic/synthesis.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <set>

namespace mechbench::analytic {

namespace {

std::vector<std::int64_t> PrimeFactors(std::int64_t n) {
  std::vector<std::int64_t> f;
  for (std::int64_t p = 2; p * p <= n; ++p)
    while (n % p == 0) f.push_back(p), n /= p;
  if (n > 1) f.push_back(n);
  return f;
}

double PairRatio(const GearPair& p) {
  return static_cast<double>(std::max(p.driver, p.driven)) / std::min(p.driver, p.driven);
}

// Scale n/d by the smallest whole factor that brings both wheels to z_min; nullopt if it cannot fit.
std::optional<GearPair> Scaled(std::int64_t n, std::int64_t d, const GearLimits& lim) {
  const std::int64_t lo = std::min(n, d);
  const std::int64_t k = std::max<std::int64_t>(1, (lim.z_min + lo - 1) / lo);
  const GearPair p{static_cast<int>(std::min<std::int64_t>(n * k, 1 << 30)), static_cast<int>(std::min<std::int64_t>(d * k, 1 << 30))};
  if (!lim.Fits(p)) return std::nullopt;
  return p;
}

}  // namespace

Fraction Reduced(std::int64_t num, std::int64_t den) {
  if (den < 0) num = -num, den = -den;
  const std::int64_t g = std::gcd(num, den);
  return g ? Fraction{num / g, den / g} : Fraction{num, den};
}

bool GearLimits::Fits(const GearPair& p) const {
  return p.driver >= z_min && p.driven >= z_min && p.driver <= z_max && p.driven <= z_max &&
         PairRatio(p) <= max_pair_ratio + 1e-12;
}

std::optional<Fraction> RecoverFraction(double x, std::int64_t max_den) {
  if (!(x > 0) || !std::isfinite(x)) return std::nullopt;
  // Convergents h/k of x until one reproduces it.
  std::int64_t h0 = 1, h1 = 0, k0 = 0, k1 = 1;  // h_{-1}/k_{-1} = 1/0, h_{-2}/k_{-2} = 0/1
  double r = x;
  for (int it = 0; it < 64; ++it) {
    const double a = std::floor(r);
    const std::int64_t ai = static_cast<std::int64_t>(a);
    const std::int64_t h = ai * h0 + h1, k = ai * k0 + k1;
    if (k > max_den) return std::nullopt;
    if (std::fabs(static_cast<double>(h) / static_cast<double>(k) - x) <= 1e-12 * x) return Reduced(h, k);
    h1 = h0, h0 = h, k1 = k0, k0 = k;
    if (r - a <= 0) return std::nullopt;
    r = 1.0 / (r - a);
  }
  return std::nullopt;
}

std::vector<std::int64_t> ContinuedFraction(Fraction f) {
  std::vector<std::int64_t> a;
  std::int64_t n = f.num, d = f.den;
  while (d != 0) {  // Euclid's divisions (the book's figure 6.3)
    a.push_back(n / d);
    const std::int64_t r = n % d;
    n = d, d = r;
  }
  return a;
}

std::vector<Convergent> Convergents(Fraction f) {
  const std::vector<std::int64_t> a = ContinuedFraction(f);
  std::vector<Convergent> out;
  std::int64_t h0 = 1, h1 = 0, k0 = 0, k1 = 1;
  for (size_t i = 0; i < a.size(); ++i) {
    const std::int64_t h = a[i] * h0 + h1, k = a[i] * k0 + k1;
    h1 = h0, h0 = h, k1 = k0, k0 = k;
    if (i == 0 && h == 0) continue;  // 0/1 is no gear pair
    // |n/d − p/q| = |n q − p d| / (d q), exact in integers before the one division.
    const double err = static_cast<double>(std::llabs(f.num * k - h * f.den)) / (static_cast<double>(f.den) * static_cast<double>(k));
    out.push_back({h, k, err});
  }
  return out;
}

std::vector<std::vector<GearPair>> FactorizeIntoPairs(Fraction ratio, int pairs, const GearLimits& limits) {
  const std::vector<std::int64_t> fn = PrimeFactors(ratio.num), fd = PrimeFactors(ratio.den);
  const size_t nf = fn.size() + fd.size();
  std::set<std::vector<std::pair<int, int>>> seen;
  std::vector<std::vector<GearPair>> out;
  std::int64_t combos = 1;
  for (size_t i = 0; i < nf && combos < 5000000; ++i) combos *= pairs;
  for (std::int64_t code = 0; code < combos; ++code) {
    // Digit i of `code` in base `pairs` says which pair takes prime factor i.
    std::vector<std::int64_t> n(pairs, 1), d(pairs, 1);
    std::int64_t c = code;
    for (size_t i = 0; i < nf; ++i, c /= pairs) {
      const int g = static_cast<int>(c % pairs);
      if (i < fn.size()) n[g] *= fn[i];
      else d[g] *= fd[i - fn.size()];
    }
    std::vector<GearPair> sol;
    bool ok = true;
    for (int g = 0; g < pairs && ok; ++g) {
      if (n[g] == d[g]) ok = false;  // a 1:1 pair does nothing
      else if (auto p = Scaled(n[g], d[g], limits)) sol.push_back(*p);
      else ok = false;
    }
    if (!ok) continue;
    std::sort(sol.begin(), sol.end(), [](const GearPair& a, const GearPair& b) { return a.driven > b.driven; });
    std::vector<std::pair<int, int>> key;
    for (const GearPair& p : sol) key.emplace_back(p.driver, p.driven);
    if (seen.insert(key).second) out.push_back(sol);
  }
  // Most balanced first: the smallest largest pair ratio.
  auto worst = [](const std::vector<GearPair>& s) {
    double w = 0;
    for (const GearPair& p : s) w = std::max(w, PairRatio(p));
    return w;
  };
  std::stable_sort(out.begin(), out.end(), [&](const auto& a, const auto& b) { return worst(a) < worst(b); });
  return out;
}

std::vector<std::vector<GearPair>> FewestPairs(Fraction ratio, const GearLimits& limits, int max_pairs) {
  for (int k = 1; k <= max_pairs; ++k) {
    auto s = FactorizeIntoPairs(ratio, k, limits);
    if (!s.empty()) return s;
  }
  return {};
}

double CoaxialModuleRatio(const GearPair& first, const GearPair& second) {
  return static_cast<double>(first.driver + first.driven) / (second.driver + second.driven);
}

Fraction EpicyclicRatio(int z_fixed, int z_p1, int z_p2, int z_out) {
  const std::int64_t num = static_cast<std::int64_t>(z_fixed) * z_p2, den = static_cast<std::int64_t>(z_p1) * z_out;
  return Reduced(den - num, den);
}

Fraction ApparentRatio(Fraction i) { return Reduced(i.den, i.den - i.num); }

std::optional<GearPair> PairWithin(Fraction ratio, double tol, const GearLimits& limits) {
  for (const Convergent& c : Convergents(ratio))
    if (c.error < tol)
      if (auto p = Scaled(c.num, c.den, limits)) return p;
  return std::nullopt;
}

SynthesisReport Synthesize(const Synthesis& goal) {
  SynthesisReport r;
  const GearLimits lim{goal.z_min, goal.z_max, goal.max_pair_ratio};
  const auto f = RecoverFraction(goal.ratio);
  if (!f) {
    r.notes.push_back("the ratio is not a fraction with a denominator up to 1e6");
    return r;
  }
  r.ratio = *f;
  r.cf_terms = ContinuedFraction(r.ratio);
  r.convergents = Convergents(r.ratio);
  const auto ord = FewestPairs(r.ratio, lim);
  if (!ord.empty()) r.ordinary = ord.front();
  else r.notes.push_back("no ordinary train of up to 3 pairs within the limits");
  if (r.ordinary.size() == 2) r.coaxial_module_ratio = CoaxialModuleRatio(r.ordinary[0], r.ordinary[1]);
  if (r.ratio.num < r.ratio.den) {
    r.mu_A = ApparentRatio(r.ratio);
    const auto epi = FactorizeIntoPairs(r.mu_A, 2, lim);
    if (!epi.empty()) {
      r.epicyclic = epi.front();
      // Pair 1 = Z_P1/Z_F, pair 2 = Z_O/Z_P2 (see EpicyclicRatio).
      r.epicyclic_check = EpicyclicRatio(r.epicyclic[0].driven, r.epicyclic[0].driver, r.epicyclic[1].driven, r.epicyclic[1].driver);
    } else {
      r.notes.push_back("no two-pair epicyclic train for muA within the limits");
    }
  }
  r.pair_within_1e4 = PairWithin(r.ratio, 1e-4, lim);
  return r;
}

}  // namespace mechbench::analytic
