// An expression read once and evaluated many times: a motion law x(t) or a load T(t, q, q̇).
//
// The text is compiled to a short postfix program over numbered variables (t, q.<slot>, …) and
// constants; evaluating it walks that program once, with no allocation and no name lookup. The
// same program runs on three number types, so derivatives are exact (forward-mode automatic
// differentiation), not finite differences:
//   double  the value;
//   Jet2    the value with its first and second derivative along one parameter (a law's ẋ, ẍ);
//   a gradient over the variables the expression names (a load's ∂/∂q, ∂/∂q̇, ∂/∂t).
// The grammar and the unit words (pi, deg, rpm, rad, s, m) are those of EvalExpr (expr.h); the
// functions are sin cos tan asin acos atan atan2 sqrt abs exp log sinh cosh tanh min max.
#pragma once

#include "mechbench/expr.h"

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace mechbench {

// A value with its first and second derivative along one parameter.
struct Jet2 {
  double v = 0, d = 0, dd = 0;
};

class CompiledExpr {
 public:
  // What a name means: a variable (an index into the array the caller passes to Eval) or a
  // constant. nullopt = not known to the caller (unit words are tried next, then an ExprError).
  struct Binding {
    int variable = -1;  // ≥ 0: a variable
    double value = 0;   // the constant's value when variable < 0
  };
  using Resolver = std::function<std::optional<Binding>(const std::string&)>;

  CompiledExpr() = default;
  // Throws ExprError naming the column and the unknown name or function.
  static CompiledExpr Compile(const std::string& text, const Resolver& resolve);

  // x[i] is variable i's value.
  double Eval(const double* x) const;
  Jet2 Eval(const Jet2* x) const;
  // The value, and in grad[k] the derivative with respect to variables()[k].
  double EvalGradient(const double* x, double* grad) const;

  const std::string& text() const { return text_; }
  // The variables the expression names, ascending, each once.
  const std::vector<int>& variables() const { return variables_; }
  bool Uses(int variable) const;
  bool empty() const { return ops_.empty(); }

  // The largest number of distinct variables one expression may name (EvalGradient's width).
  static constexpr int kMaxVariables = 16;

 private:
  enum class Code : std::uint8_t {
    kConst, kVar, kAdd, kSub, kMul, kDiv, kNeg, kPowConst, kPow, kSin, kCos, kTan, kAsin, kAcos,
    kAtan, kAtan2, kSqrt, kAbs, kExp, kLog, kSinh, kCosh, kTanh, kMin, kMax,
  };
  struct Op {
    Code code = Code::kConst;
    int var = -1;       // kVar: the variable
    int pos = -1;       // kVar: its position in variables_ (EvalGradient's seeds)
    double value = 0;   // kConst: the constant; kPowConst: the exponent
  };
  template <class T>
  T Run(const T* x, bool compact) const;  // compact: x indexed by Op::pos
  friend class ExprCompiler;

  std::string text_;
  std::vector<Op> ops_;
  std::vector<int> variables_;
  int max_stack_ = 0;
};

}  // namespace mechbench
