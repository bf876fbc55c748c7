// A small expression reader for numbers in scenario files ("15*sin(35 deg)", "2000 rpm") and
// for book-check quantities over named results ("qd.phi1/qd.phi6", "-vslide.1").
#pragma once

#include <functional>
#include <optional>
#include <stdexcept>
#include <string>

namespace mechbench {

struct ExprError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Looks a variable up; nullopt = unknown name (an ExprError names it).
using VariableLookup = std::function<std::optional<double>(const std::string&)>;

// Evaluates `text`. Variables are names made of letters, digits, '_' and '.', optionally followed
// by an index such as "[0,2]". Without a lookup, only constants and unit words are known.
double EvalExpr(const std::string& text, const VariableLookup& lookup = nullptr);

}  // namespace mechbench
