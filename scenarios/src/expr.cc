#include "mechbench/expr.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <numbers>
#include <vector>

namespace mechbench {
namespace {

// Recursive-descent reader:
//   sum     := product (('+' | '-') product)*
//   product := unary (('*' | '/') unary | <implicit ×> power)*
//   unary   := ('-' | '+') unary | power
//   power   := primary ('^' unary)?
//   primary := number | name | name '(' args ')' | '(' sum ')'
// "35 deg" and "2 pi" are implicit products, so a unit word can follow a number. A unit word is
// read only where a unit goes (IsUnitWord in expr.h): `unit_slot_` says the factor being read may be
// one, `factor_valued_` that the factor just read was a number or a unit.
class Reader {
 public:
  static constexpr int kMaxDepth = 200;
  Reader(const std::string& text, const VariableLookup& lookup, std::vector<std::string>* units,
         std::vector<std::string>* names)
      : s_(text), lookup_(lookup), units_(units), names_(names) {}

  double ReadAll() {
    const double v = Sum();
    SkipSpace();
    if (pos_ != s_.size()) Fail("unexpected '" + std::string(1, s_[pos_]) + "'");
    return v;
  }

 private:
  [[noreturn]] void Fail(const std::string& what) const {
    // A long value is shown by its start only: the column says where.
    const std::string shown = s_.size() > 80 ? s_.substr(0, 60) + "…" : s_;
    throw ExprError("cannot read expression \"" + shown + "\": " + what + " at column " + std::to_string(pos_ + 1));
  }
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
  double Sum() {
    double v = Product();
    for (;;) {
      if (Eat('+')) v += Product();
      else if (Eat('-')) v -= Product();
      else return v;
    }
  }
  double Product() {
    unit_slot_ = false, angle_slot_ = false;
    double v = Unary();
    bool valued = factor_valued_;  // the product has a number or a unit so far
    for (;;) {
      if (Eat('*')) unit_slot_ = valued, angle_slot_ = true, v *= Unary();
      else if (Eat('/')) unit_slot_ = valued, v /= Unary();
      else if (AtNameStart() || (SkipSpace(), pos_ < s_.size() && s_[pos_] == '(')) unit_slot_ = true, v *= Power();
      else return v;
      valued = valued || factor_valued_;
    }
  }
  // Every nesting (parentheses, a function's arguments, signs, powers) passes through here, so the
  // depth is bounded here: an 80 KB value of '(' would otherwise overflow the stack.
  double Unary() {
    if (++depth_ > kMaxDepth)
      Fail("nested deeper than " + std::to_string(kMaxDepth) + " levels (parentheses, signs or powers)");
    double v;
    if (Eat('-')) v = -Unary();
    else if (Eat('+')) v = Unary();
    else v = Power();
    --depth_;
    return v;
  }
  double Power() {
    const double base = Primary();
    if (Eat('^')) {
      const bool valued = factor_valued_;
      unit_slot_ = false, angle_slot_ = false;
      const double e = Unary();
      factor_valued_ = valued;  // "s^2" is a unit as "s" is
      return std::pow(base, e);
    }
    return base;
  }
  double Primary() {
    const bool unit_slot = unit_slot_, angle_slot = angle_slot_;
    unit_slot_ = false, angle_slot_ = false;
    factor_valued_ = false;
    SkipSpace();
    if (pos_ >= s_.size()) Fail("value expected");
    if (Eat('(')) {
      const double v = Sum();
      if (!Eat(')')) Fail("')' expected");
      factor_valued_ = false;
      return v;
    }
    const char c = s_[pos_];
    if (std::isdigit(static_cast<unsigned char>(c)) || c == '.') {
      factor_valued_ = true;
      return Number();
    }
    if (AtNameStart()) return Name(unit_slot, angle_slot);
    Fail("value expected");
  }
  double Number() {
    const char* begin = s_.c_str() + pos_;
    char* end = nullptr;
    const double v = std::strtod(begin, &end);
    if (end == begin) Fail("number expected");
    pos_ += static_cast<size_t>(end - begin);
    return v;
  }
  std::string Identifier() {
    const size_t start = pos_;
    while (pos_ < s_.size() &&
           (std::isalnum(static_cast<unsigned char>(s_[pos_])) || s_[pos_] == '_' || s_[pos_] == '.'))
      ++pos_;
    // An index such as "[0,2]" belongs to the name (matrix entries: "Phi_q[0,2]").
    if (pos_ < s_.size() && s_[pos_] == '[') {
      const size_t close = s_.find(']', pos_);
      if (close == std::string::npos) Fail("']' expected");
      pos_ = close + 1;
    }
    std::string name = s_.substr(start, pos_ - start);
    name.erase(std::remove_if(name.begin(), name.end(), [](char ch) { return ch == ' '; }), name.end());
    return name;
  }
  double Name(bool unit_slot, bool angle_slot) {
    const size_t start = pos_;
    const std::string name = Identifier();
    if (Eat('(')) {
      std::vector<double> args;
      if (!Eat(')')) {
        ++call_depth_;
        do args.push_back(Sum());
        while (Eat(','));
        --call_depth_;
        if (!Eat(')')) Fail("')' expected");
      }
      factor_valued_ = false;
      return Call(name, args);
    }
    // A variable the caller knows wins over a unit word ("s" may be an actuator's length).
    if (lookup_) {
      if (auto v = lookup_(name)) {
        if (names_ && call_depth_ == 0) names_->push_back(name);
        return factor_valued_ = false, *v;
      }
    }
    if (IsUnitWord(name)) {
      // An angle's unit word may also follow any factor after '*' (`theta0*deg`): it is never a
      // quantity's name, as m (a mass) or s (a length) may be meant to be.
      if (!unit_slot && !(angle_slot && IsAngleUnitWord(name))) ThrowUnitWordAsValue(s_, name, start + 1);
      factor_valued_ = true;
      if (units_ && call_depth_ == 0) units_->push_back(name);
    }
    constexpr double kPi = std::numbers::pi;
    if (name == "pi") return kPi;
    if (name == "deg") return kPi / 180.0;
    if (name == "rpm") return 2.0 * kPi / 60.0;  // [rad/s] per [rev/min]
    if (name == "rad" || name == "s" || name == "m") return 1.0;
    if (IsForeignUnit(name))
      throw ExprError("cannot read expression \"" + (s_.size() > 80 ? s_.substr(0, 60) + "…" : s_) + "\": unknown name '" +
                          name + "' at column " + std::to_string(start + 1) +
                          " (the only unit words are m, s, rad, deg and rpm; everything else is a plain number in "
                          "its unit: masses in kg, forces in N, stiffnesses in N/m, lengths in the file's length unit)",
                      "write the value as a plain number in its unit, without '" + name + "'");
    Fail("unknown name '" + name + "'");
  }
  double Call(const std::string& f, const std::vector<double>& a) {
    auto need = [&](size_t n) {
      if (a.size() != n) Fail(f + "() takes " + std::to_string(n) + " argument(s)");
    };
    if (f == "atan2") { need(2); return std::atan2(a[0], a[1]); }
    if (f == "min") { need(2); return std::min(a[0], a[1]); }
    if (f == "max") { need(2); return std::max(a[0], a[1]); }
    need(1);
    const double x = a[0];
    if (f == "sin") return std::sin(x);
    if (f == "cos") return std::cos(x);
    if (f == "tan") return std::tan(x);
    if (f == "asin") return std::asin(x);
    if (f == "acos") return std::acos(x);
    if (f == "atan") return std::atan(x);
    if (f == "sqrt") return std::sqrt(x);
    if (f == "abs") return std::fabs(x);
    if (f == "exp") return std::exp(x);
    if (f == "log") return std::log(x);
    if (f == "sinh") return std::sinh(x);
    if (f == "cosh") return std::cosh(x);
    if (f == "tanh") return std::tanh(x);
    Fail("unknown function '" + f + "'");
  }

  // Units people write that are not unit words here (refused with the SI rule as the fix).
  static bool IsForeignUnit(const std::string& n) {
    static const char* const kForeign[] = {"kg", "g", "N", "Nm", "kN", "mm", "cm", "km", "J", "W", "Pa", "ms", "min", "h", "Hz", "lb", "in", "ft"};
    return std::any_of(std::begin(kForeign), std::end(kForeign), [&](const char* f) { return n == f; });
  }

  const std::string& s_;
  const VariableLookup& lookup_;
  std::vector<std::string>* units_;  // the unit words read outside any function's arguments, or null
  std::vector<std::string>* names_;  // the variables read outside any function's arguments, or null
  size_t pos_ = 0;
  int depth_ = 0;
  int call_depth_ = 0;  // inside how many functions' arguments
  bool unit_slot_ = false;      // the factor about to be read may be a unit word
  bool angle_slot_ = false;     // it follows '*': it may be an angle's unit word (deg, rad, rpm)
  bool factor_valued_ = false;  // the factor just read was a number or a unit word
};

}  // namespace

bool IsUnitWord(const std::string& name) {
  return name == "rad" || name == "s" || name == "m" || name == "deg" || name == "rpm";
}

bool IsAngleUnitWord(const std::string& name) { return name == "rad" || name == "deg" || name == "rpm"; }

void ThrowUnitWordAsValue(const std::string& text, const std::string& name, size_t column) {
  const std::string shown = text.size() > 80 ? text.substr(0, 60) + "…" : text;
  throw ExprError("cannot read expression \"" + shown + "\": '" + name + "' at column " + std::to_string(column) +
                      " is a unit word, which stands for a unit only after a value (1 " + name + ", 3 rad/s, 2*pi rad), "
                      "not for a value of its own",
                  "'" + name + "' is a unit here; name your constant something else, e.g. " + name + "1, or write 1 " + name);
}

std::string UnitWordsMisfit(const std::vector<std::string>& used, UnitField field) {
  auto fits = [&](const std::string& u) {
    switch (field) {
      case UnitField::kAny: return true;
      case UnitField::kPlain: return false;
      case UnitField::kLength: return u == "m";
      case UnitField::kTime: return u == "s";
      case UnitField::kAcceleration: return u == "m" || u == "s";
      case UnitField::kAngularRate: return u == "rad" || u == "deg" || u == "rpm" || u == "s";
    }
    return true;
  };
  for (const std::string& u : used)
    if (!fits(u))
      return "'" + u + "' (" + (u == "m" ? "a length" : u == "s" ? "a time" : u == "rpm" ? "an angular rate" : "an angle") + ")";
  return {};
}

std::string UnitWordsProblem(const std::vector<std::string>& used, UnitField field, const std::string& length_unit,
                             const std::string& text, const std::string& unit, std::string& fix) {
  if (field == UnitField::kAny) return {};
  const std::string in = unit.empty() ? std::string("its unit") : unit;
  if (length_unit != "m" && std::find(used.begin(), used.end(), "m") != used.end()) {
    fix = "write the value in " + length_unit + " without 'm'";
    return "\"" + text + "\": the unit word 'm' reads as 1, but this file's length unit is " + length_unit +
           " (units: {length: " + length_unit + "})";
  }
  if (const std::string misfit = UnitWordsMisfit(used, field); !misfit.empty()) {
    fix = "write it as a plain number in " + in + ", without that word";
    return "\"" + text + "\": the unit word " + misfit + " does not fit a value in " + in +
           " (unit words stand only for lengths m, times s, angles rad and deg, and rpm)";
  }
  return {};
}

std::vector<std::string> TopLevelUnitWords(const std::string& text, std::vector<std::string>* names) {
  std::vector<std::string> units;
  try {
    // Every variable at 1; a unit word is left to the reader (it would read as a variable).
    (void)EvalExpr(text, [](const std::string& name) -> std::optional<double> {
      if (IsUnitWord(name) || name == "pi") return std::nullopt;
      return 1.0;
    }, &units, names);
  } catch (const ExprError&) {
    if (names) names->clear();
    return {};
  }
  return units;
}

double EvalExpr(const std::string& text, const VariableLookup& lookup, std::vector<std::string>* units,
                std::vector<std::string>* names) {
  Reader r(text, lookup, units, names);
  return r.ReadAll();
}

}  // namespace mechbench
