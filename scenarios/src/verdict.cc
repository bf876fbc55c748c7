#include "mechbench/verdict.h"

#include <algorithm>
#include <cmath>

namespace mechbench {

const char* ToString(Verdict v) {
  switch (v) {
    case Verdict::kAgrees: return "agrees";
    case Verdict::kLastDigit: return "last-digit";
    case Verdict::kDiffers: return "differs";
    case Verdict::kNotComputed: return "not-computed";
  }
  return "?";
}

Verdict Judge(const BookValue& b, double computed) { return JudgePrinted(computed, b.value, b.last_digit); }

Verdict JudgePrinted(double computed, double printed, double last_digit) {
  const double diff = std::fabs(computed - printed);
  if (last_digit == 0.0)  // an exact claim
    return diff <= 1e-9 * std::max(1.0, std::fabs(printed)) ? Verdict::kAgrees : Verdict::kDiffers;
  // A hair of slack so that a value exactly on the half-unit boundary is not decided by rounding
  // noise in the 16th digit.
  const double slack = 1e-9 * last_digit + 1e-13 * std::fabs(printed);
  if (diff <= 0.5 * last_digit + slack) return Verdict::kAgrees;
  if (diff <= 1.0 * last_digit + slack) return Verdict::kLastDigit;
  return Verdict::kDiffers;
}

Verdict JudgeWithin(double computed, double printed, double allowed) {
  const double diff = std::fabs(computed - printed);
  const double slack = 1e-13 * std::fabs(printed);  // as JudgePrinted: not decided by the 16th digit
  if (diff <= allowed + slack) return Verdict::kAgrees;
  if (diff <= 2 * allowed + slack) return Verdict::kLastDigit;
  return Verdict::kDiffers;
}

}  // namespace mechbench
