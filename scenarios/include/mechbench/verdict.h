// How a computed value stands against a value printed in the book (see README, "Verdicts"): one
// rule, used by `check`, the report, JUnit and the book tests alike.
#pragma once

#include "mechbench/model.h"

namespace mechbench {

enum class Verdict {
  kAgrees,       // within half a unit of the last printed digit (or 1e-9 for exact claims)
  kLastDigit,    // within one unit: the book truncated or slipped a rounding
  kDiffers,      // beyond that
  kNotComputed,  // no method produced the quantity
};
const char* ToString(Verdict v);
Verdict Judge(const BookValue& book, double computed_in_book_unit);
// The same for a value given as printed: `printed` with one unit of its last digit `last_digit`
// (0: an exact claim).
Verdict JudgePrinted(double computed, double printed, double last_digit);
// A claim about the motion at a time (BookValue::at), judged within an uncertainty `allowed` (the
// larger of half its last printed digit, its stated precision and the reference's confirmed
// agreement; harness CheckBook): agrees within it, last-digit within twice it, differs beyond.
Verdict JudgeWithin(double computed, double printed, double allowed);

}  // namespace mechbench
