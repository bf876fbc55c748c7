#include "mechbench/compiled_expr.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <numbers>

namespace mechbench {

// Reads the text with EvalExpr's grammar (expr.cc) and emits postfix operations:
//   sum     := product (('+' | '-') product)*
//   product := unary (('*' | '/') unary | <implicit ×> power)*
//   unary   := ('-' | '+') unary | power
//   power   := primary ('^' unary)?
//   primary := number | name | name '(' args ')' | '(' sum ')'
// and reads a unit word only where a unit goes, as EvalExpr does (IsUnitWord in expr.h).
class ExprCompiler {
 public:
  static constexpr int kMaxDepth = 200;
  using Code = CompiledExpr::Code;
  ExprCompiler(const std::string& text, const CompiledExpr::Resolver& resolve) : s_(text), resolve_(resolve) {}

  CompiledExpr Compile() {
    out_.text_ = s_;
    Sum();
    SkipSpace();
    if (pos_ != s_.size()) Fail("unexpected '" + std::string(1, s_[pos_]) + "'");
    // Variables ascending; each kVar op learns its position there (EvalGradient's column).
    std::sort(out_.variables_.begin(), out_.variables_.end());
    out_.variables_.erase(std::unique(out_.variables_.begin(), out_.variables_.end()), out_.variables_.end());
    if (static_cast<int>(out_.variables_.size()) > CompiledExpr::kMaxVariables)
      Fail("names " + std::to_string(out_.variables_.size()) + " variables, more than the " +
           std::to_string(CompiledExpr::kMaxVariables) + " one expression may use");
    int depth = 0, most = 0;
    for (const CompiledExpr::Op& op : out_.ops_) {
      depth += Effect(op.code);
      most = std::max(most, depth);
    }
    out_.max_stack_ = most;
    for (CompiledExpr::Op& op : out_.ops_)
      if (op.code == Code::kVar)
        op.pos = static_cast<int>(std::lower_bound(out_.variables_.begin(), out_.variables_.end(), op.var) -
                                  out_.variables_.begin());
    return std::move(out_);
  }

 private:
  [[noreturn]] void Fail(const std::string& what) const {
    const std::string shown = s_.size() > 80 ? s_.substr(0, 60) + "…" : s_;
    throw ExprError("cannot read expression \"" + shown + "\": " + what + " at column " + std::to_string(pos_ + 1));
  }
  static int Effect(Code c) {
    switch (c) {
      case Code::kConst: case Code::kVar: return 1;
      case Code::kAdd: case Code::kSub: case Code::kMul: case Code::kDiv: case Code::kPow: case Code::kAtan2:
      case Code::kMin: case Code::kMax: return -1;
      default: return 0;
    }
  }
  void Emit(Code c, double value = 0, int var = -1) { out_.ops_.push_back({c, var, -1, value}); }
  void SkipSpace() {
    while (pos_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[pos_]))) ++pos_;
  }
  bool Eat(char c) {
    SkipSpace();
    if (pos_ < s_.size() && s_[pos_] == c) {
      ++pos_;
      return true;
    }
    return false;
  }
  bool AtNameStart() {
    SkipSpace();
    return pos_ < s_.size() && (std::isalpha(static_cast<unsigned char>(s_[pos_])) || s_[pos_] == '_');
  }
  void Sum() {
    Product();
    for (;;) {
      if (Eat('+')) Product(), Emit(Code::kAdd);
      else if (Eat('-')) Product(), Emit(Code::kSub);
      else return;
    }
  }
  void Product() {
    unit_slot_ = false, angle_slot_ = false;
    Unary();
    bool valued = factor_valued_;  // the product has a number or a unit so far
    for (;;) {
      if (Eat('*')) unit_slot_ = valued, angle_slot_ = true, Unary(), Emit(Code::kMul);
      else if (Eat('/')) unit_slot_ = valued, Unary(), Emit(Code::kDiv);
      else if (AtNameStart() || (SkipSpace(), pos_ < s_.size() && s_[pos_] == '(')) unit_slot_ = true, Power(), Emit(Code::kMul);
      else return;
      valued = valued || factor_valued_;
    }
  }
  void Unary() {
    if (++depth_ > kMaxDepth)
      Fail("nested deeper than " + std::to_string(kMaxDepth) + " levels (parentheses, signs or powers)");
    if (Eat('-')) Unary(), Emit(Code::kNeg);
    else if (Eat('+')) Unary();
    else Power();
    --depth_;
  }
  void Power() {
    Primary();
    if (Eat('^')) {
      const size_t first = out_.ops_.size();
      const bool valued = factor_valued_;
      unit_slot_ = false, angle_slot_ = false;
      Unary();
      factor_valued_ = valued;  // "s^2" is a unit as "s" is
      // A constant exponent (x^2, x^-1.5) takes the power rule, which also holds for x < 0.
      if (out_.ops_.size() == first + 1 && out_.ops_.back().code == Code::kConst) {
        out_.ops_.back().code = Code::kPowConst;
      } else if (out_.ops_.size() == first + 2 && out_.ops_[first].code == Code::kConst &&
                 out_.ops_[first + 1].code == Code::kNeg) {
        const double e = -out_.ops_[first].value;
        out_.ops_.resize(first);
        Emit(Code::kPowConst, e);
      } else {
        Emit(Code::kPow);
      }
    }
  }
  void Primary() {
    const bool unit_slot = unit_slot_, angle_slot = angle_slot_;
    unit_slot_ = false, angle_slot_ = false;
    factor_valued_ = false;
    SkipSpace();
    if (pos_ >= s_.size()) Fail("value expected");
    if (Eat('(')) {
      Sum();
      if (!Eat(')')) Fail("')' expected");
      factor_valued_ = false;
      return;
    }
    const char c = s_[pos_];
    if (std::isdigit(static_cast<unsigned char>(c)) || c == '.') {
      factor_valued_ = true;
      return Number();
    }
    if (AtNameStart()) return Name(unit_slot, angle_slot);
    Fail("value expected");
  }
  void Number() {
    const char* begin = s_.c_str() + pos_;
    char* end = nullptr;
    const double v = std::strtod(begin, &end);
    if (end == begin) Fail("number expected");
    pos_ += static_cast<size_t>(end - begin);
    Emit(Code::kConst, v);
  }
  std::string Identifier() {
    const size_t start = pos_;
    while (pos_ < s_.size() &&
           (std::isalnum(static_cast<unsigned char>(s_[pos_])) || s_[pos_] == '_' || s_[pos_] == '.'))
      ++pos_;
    return s_.substr(start, pos_ - start);
  }
  void Name(bool unit_slot, bool angle_slot) {
    const size_t start = pos_;
    const std::string name = Identifier();
    if (Eat('(')) {
      int args = 0;
      if (!Eat(')')) {
        do Sum(), ++args;
        while (Eat(','));
        if (!Eat(')')) Fail("')' expected");
      }
      factor_valued_ = false;
      return Call(name, args, start);
    }
    if (resolve_) {
      if (auto b = resolve_(name)) {
        factor_valued_ = false;
        if (b->variable >= 0) {
          out_.variables_.push_back(b->variable);
          Emit(Code::kVar, 0, b->variable);
        } else {
          Emit(Code::kConst, b->value);
        }
        return;
      }
    }
    if (IsUnitWord(name)) {
      // An angle's unit word may also follow any factor after '*' (`theta0*deg`): it is never a
      // quantity's name, as m (a mass) or s (a length) may be meant to be.
      if (!unit_slot && !(angle_slot && IsAngleUnitWord(name))) ThrowUnitWordAsValue(s_, name, start + 1);
      factor_valued_ = true;
    }
    constexpr double kPi = std::numbers::pi;
    if (name == "pi") return Emit(Code::kConst, kPi);
    if (name == "deg") return Emit(Code::kConst, kPi / 180.0);
    if (name == "rpm") return Emit(Code::kConst, 2.0 * kPi / 60.0);
    if (name == "rad" || name == "s" || name == "m") return Emit(Code::kConst, 1.0);
    pos_ = start;
    Fail("unknown name '" + name + "'");
  }
  void Call(const std::string& f, int args, size_t start) {
    auto need = [&](int n) {
      if (args != n) {
        pos_ = start;
        Fail(f + "() takes " + std::to_string(n) + " argument(s)");
      }
    };
    static const std::array<std::pair<const char*, Code>, 13> kOne{{
        {"sin", Code::kSin}, {"cos", Code::kCos}, {"tan", Code::kTan}, {"asin", Code::kAsin},
        {"acos", Code::kAcos}, {"atan", Code::kAtan}, {"sqrt", Code::kSqrt}, {"abs", Code::kAbs},
        {"exp", Code::kExp}, {"log", Code::kLog}, {"sinh", Code::kSinh}, {"cosh", Code::kCosh},
        {"tanh", Code::kTanh}}};
    for (const auto& [name, code] : kOne)
      if (f == name) return need(1), Emit(code);
    if (f == "atan2") return need(2), Emit(Code::kAtan2);
    if (f == "min") return need(2), Emit(Code::kMin);
    if (f == "max") return need(2), Emit(Code::kMax);
    pos_ = start;
    Fail("unknown function '" + f + "'");
  }

  const std::string& s_;
  const CompiledExpr::Resolver& resolve_;
  CompiledExpr out_;
  size_t pos_ = 0;
  int depth_ = 0;
  bool unit_slot_ = false;      // the factor about to be read may be a unit word
  bool angle_slot_ = false;     // it follows '*': it may be an angle's unit word (deg, rad, rpm)
  bool factor_valued_ = false;  // the factor just read was a number or a unit word
};

CompiledExpr CompiledExpr::Compile(const std::string& text, const Resolver& resolve) {
  return ExprCompiler(text, resolve).Compile();
}

bool CompiledExpr::Uses(int variable) const {
  return std::binary_search(variables_.begin(), variables_.end(), variable);
}

namespace {

// A value with its gradient over an expression's variables (at most kMaxVariables).
struct Grad {
  double v = 0;
  std::array<double, CompiledExpr::kMaxVariables> g;  // set by whoever makes one (no zeroing per stack slot)
};

// The arithmetic each number type needs: + − × ÷ and the chain rule f(a) given f, f', f''.
double Val(double a) { return a; }
double Val(const Jet2& a) { return a.v; }
double Val(const Grad& a) { return a.v; }
double Constant(double c, const double*) { return c; }
Jet2 Constant(double c, const Jet2*) { return {c, 0, 0}; }
Grad Constant(double c, const Grad*) {
  Grad r;
  r.v = c;
  r.g.fill(0.0);
  return r;
}

double Chain(double, double f, double, double) { return f; }
Jet2 Chain(const Jet2& a, double f, double f1, double f2) { return {f, f1 * a.d, f2 * a.d * a.d + f1 * a.dd}; }
Grad Chain(const Grad& a, double f, double f1, double) {
  Grad r;
  r.v = f;
  for (size_t k = 0; k < r.g.size(); ++k) r.g[k] = f1 * a.g[k];
  return r;
}
double Add(double a, double b, double s) { return a + s * b; }
Jet2 Add(const Jet2& a, const Jet2& b, double s) { return {a.v + s * b.v, a.d + s * b.d, a.dd + s * b.dd}; }
Grad Add(const Grad& a, const Grad& b, double s) {
  Grad r;
  r.v = a.v + s * b.v;
  for (size_t k = 0; k < r.g.size(); ++k) r.g[k] = a.g[k] + s * b.g[k];
  return r;
}
double Mul(double a, double b) { return a * b; }
Jet2 Mul(const Jet2& a, const Jet2& b) { return {a.v * b.v, a.d * b.v + a.v * b.d, a.dd * b.v + 2 * a.d * b.d + a.v * b.dd}; }
Grad Mul(const Grad& a, const Grad& b) {
  Grad r;
  r.v = a.v * b.v;
  for (size_t k = 0; k < r.g.size(); ++k) r.g[k] = a.g[k] * b.v + a.v * b.g[k];
  return r;
}
double Div(double a, double b) { return a / b; }
Jet2 Div(const Jet2& a, const Jet2& b) {
  const double c = a.v / b.v, c1 = (a.d - c * b.d) / b.v;
  return {c, c1, (a.dd - 2 * c1 * b.d - c * b.dd) / b.v};
}
Grad Div(const Grad& a, const Grad& b) {
  Grad r;
  r.v = a.v / b.v;
  for (size_t k = 0; k < r.g.size(); ++k) r.g[k] = (a.g[k] - r.v * b.g[k]) / b.v;
  return r;
}
template <class T>
T Neg(const T& a) {
  return Chain(a, -Val(a), -1.0, 0.0);
}
template <class T>
T Exp(const T& a) {
  const double e = std::exp(Val(a));
  return Chain(a, e, e, e);
}
template <class T>
T Log(const T& a) {
  const double x = Val(a);
  return Chain(a, std::log(x), 1 / x, -1 / (x * x));
}
// atan2(y, x) differs from atan(y/x) (or π/2 − atan(x/y)) by a constant on each side, so it
// takes their derivatives; the value is atan2's own.
template <class T>
T Atan2(const T& y, const T& x) {
  const double yv = Val(y), xv = Val(x), value = std::atan2(yv, xv);
  auto atan_of = [](const T& r) {
    const double v = Val(r), s = 1 / (1 + v * v);
    return Chain(r, std::atan(v), s, -2 * v * s * s);
  };
  if (std::fabs(xv) >= std::fabs(yv)) {
    if (xv == 0) return Chain(y, value, 0.0, 0.0);  // atan2(0, 0): no direction, no derivative
    T r = atan_of(Div(y, x));
    return Add(r, Constant(value - Val(r), static_cast<const T*>(nullptr)), 1.0);
  }
  T r = Neg(atan_of(Div(x, y)));
  return Add(r, Constant(value - Val(r), static_cast<const T*>(nullptr)), 1.0);
}

}  // namespace

template <class T>
T CompiledExpr::Run(const T* x, bool compact) const {
  constexpr int kLocal = 32;
  std::array<T, kLocal> local;
  std::vector<T> heap;
  T* st = local.data();
  if (max_stack_ > kLocal) {
    heap.resize(static_cast<size_t>(max_stack_));
    st = heap.data();
  }
  st[0] = Constant(0.0, x);  // an empty program is 0
  int n = 0;
  for (const Op& op : ops_) {
    switch (op.code) {
      case Code::kConst: st[n++] = Constant(op.value, x); break;
      case Code::kVar: st[n++] = x[compact ? op.pos : op.var]; break;
      case Code::kAdd: --n, st[n - 1] = Add(st[n - 1], st[n], 1.0); break;
      case Code::kSub: --n, st[n - 1] = Add(st[n - 1], st[n], -1.0); break;
      case Code::kMul: --n, st[n - 1] = Mul(st[n - 1], st[n]); break;
      case Code::kDiv: --n, st[n - 1] = Div(st[n - 1], st[n]); break;
      case Code::kNeg: st[n - 1] = Neg(st[n - 1]); break;
      case Code::kPowConst: {
        const double a = Val(st[n - 1]), e = op.value;
        st[n - 1] = Chain(st[n - 1], std::pow(a, e), e * std::pow(a, e - 1), e * (e - 1) * std::pow(a, e - 2));
        break;
      }
      case Code::kPow: --n, st[n - 1] = Exp(Mul(st[n], Log(st[n - 1]))); break;
      case Code::kSin: {
        const double a = Val(st[n - 1]), s = std::sin(a);
        st[n - 1] = Chain(st[n - 1], s, std::cos(a), -s);
        break;
      }
      case Code::kCos: {
        const double a = Val(st[n - 1]), c = std::cos(a);
        st[n - 1] = Chain(st[n - 1], c, -std::sin(a), -c);
        break;
      }
      case Code::kTan: {
        const double t = std::tan(Val(st[n - 1])), s = 1 + t * t;
        st[n - 1] = Chain(st[n - 1], t, s, 2 * t * s);
        break;
      }
      case Code::kAsin: case Code::kAcos: {
        const double a = Val(st[n - 1]), r = 1 / std::sqrt(1 - a * a), sign = op.code == Code::kAsin ? 1.0 : -1.0;
        st[n - 1] = Chain(st[n - 1], op.code == Code::kAsin ? std::asin(a) : std::acos(a), sign * r, sign * a * r * r * r);
        break;
      }
      case Code::kAtan: {
        const double a = Val(st[n - 1]), s = 1 / (1 + a * a);
        st[n - 1] = Chain(st[n - 1], std::atan(a), s, -2 * a * s * s);
        break;
      }
      case Code::kAtan2: --n, st[n - 1] = Atan2(st[n - 1], st[n]); break;
      case Code::kSqrt: {
        const double r = std::sqrt(Val(st[n - 1]));
        st[n - 1] = Chain(st[n - 1], r, 0.5 / r, -0.25 / (r * r * r));
        break;
      }
      case Code::kAbs: {
        const double a = Val(st[n - 1]);
        st[n - 1] = Chain(st[n - 1], std::fabs(a), a < 0 ? -1.0 : 1.0, 0.0);
        break;
      }
      case Code::kExp: st[n - 1] = Exp(st[n - 1]); break;
      case Code::kLog: st[n - 1] = Log(st[n - 1]); break;
      case Code::kSinh: {
        const double a = Val(st[n - 1]), s = std::sinh(a);
        st[n - 1] = Chain(st[n - 1], s, std::cosh(a), s);
        break;
      }
      case Code::kCosh: {
        const double a = Val(st[n - 1]), c = std::cosh(a);
        st[n - 1] = Chain(st[n - 1], c, std::sinh(a), c);
        break;
      }
      case Code::kTanh: {
        const double t = std::tanh(Val(st[n - 1])), s = 1 - t * t;
        st[n - 1] = Chain(st[n - 1], t, s, -2 * t * s);
        break;
      }
      case Code::kMin: --n, st[n - 1] = Val(st[n]) < Val(st[n - 1]) ? st[n] : st[n - 1]; break;
      case Code::kMax: --n, st[n - 1] = Val(st[n]) > Val(st[n - 1]) ? st[n] : st[n - 1]; break;
    }
  }
  return st[0];
}

double CompiledExpr::Eval(const double* x) const { return Run(x, false); }
Jet2 CompiledExpr::Eval(const Jet2* x) const { return Run(x, false); }

double CompiledExpr::EvalGradient(const double* x, double* grad) const {
  // The seeds in the variables' compact order (Op::pos), so only the named ones are made.
  std::array<Grad, kMaxVariables> seed;
  for (size_t k = 0; k < variables_.size(); ++k) {
    seed[k].v = x[variables_[k]];
    seed[k].g.fill(0.0);
    seed[k].g[k] = 1;
  }
  const Grad r = Run(seed.data(), true);
  for (size_t k = 0; k < variables_.size(); ++k) grad[k] = r.g[k];
  return r.v;
}

}  // namespace mechbench
