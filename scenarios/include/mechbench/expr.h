// A small expression reader for numbers in scenario files ("15*sin(35 deg)", "2000 rpm") and
// for book-check quantities over named results ("qd.phi1/qd.phi6", "-vslide.1").
#pragma once

#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace mechbench {

struct ExprError : std::runtime_error {
  using std::runtime_error::runtime_error;
  ExprError(const std::string& what, std::string fix_text) : std::runtime_error(what), fix(std::move(fix_text)) {}
  std::string fix;  // the fix the reader knows (a unit word used as a value); empty: the caller's
};

// A unit word (rad, s, m, deg, rpm) reads as a unit only where a unit goes: after a value ("3 rad",
// "2*pi rad", "(a + b) m") or later in a product that has a number or a unit ("3 rad/s",
// "5 m/s^2", "30*deg", "1/s"). Anywhere else it is refused ("mass: m", "sqrt(k/m)"): read as 1 it
// would silently replace the constant the writer meant. Both readers (EvalExpr, CompiledExpr) call
// these.
bool IsUnitWord(const std::string& name);
// rad, deg, rpm: a unit word that may also follow any factor after '*' (`theta0*deg`).
bool IsAngleUnitWord(const std::string& name);
[[noreturn]] void ThrowUnitWordAsValue(const std::string& text, const std::string& name, size_t column);

// Looks a variable up; nullopt = unknown name (an ExprError names it).
using VariableLookup = std::function<std::optional<double>(const std::string&)>;

// Evaluates `text`. Variables are names made of letters, digits, '_' and '.', optionally followed
// by an index such as "[0,2]". Without a lookup, only constants and unit words are known.
// `units`, when given, receives the unit words read outside any function's arguments ("2 m/s" →
// m, s; "L*cos(30 deg)" → none): what the value itself is said to measure, for the loader to
// check against the field (UnitWordsMisfit). `names`, when given, receives the variables read
// outside any function's arguments ("mb*2" → mb; "L*cos(al)" → L): the loader holds a field to the
// unit words of a constant named there (constants: {mb: 2 deg} then mass: mb).
double EvalExpr(const std::string& text, const VariableLookup& lookup = nullptr, std::vector<std::string>* units = nullptr,
                std::vector<std::string>* names = nullptr);

// What a field's value may carry as unit words (outside function arguments): kPlain none (masses,
// inertias, stiffnesses, dampings, forces, torques, ratios: SI numbers), kLength m, kTime s,
// kAcceleration m and s, kAngularRate rad, deg, rpm and s.
enum class UnitField { kAny, kPlain, kLength, kTime, kAcceleration, kAngularRate };
// The first unit word of `used` that does not fit `field`, described ("'deg' (an angle)"); empty
// when all fit.
std::string UnitWordsMisfit(const std::vector<std::string>& used, UnitField field);

// What is wrong with the unit words `used` of a value written `text` in a field (empty: nothing):
// 'm' in a file whose length unit is not m (it reads as 1, not a metre), or a word that does not
// fit the field; `unit` names the field's unit in the message and the fix (written to `fix`).
// Both loaders call it for numbers, vectors and laws alike.
std::string UnitWordsProblem(const std::vector<std::string>& used, UnitField field, const std::string& length_unit,
                             const std::string& text, const std::string& unit, std::string& fix);

// The unit words of a law's text read outside any function's arguments (as EvalExpr gives them),
// its variables taken at 1: what the law itself is said to measure ("0.2*sin(t) deg" → deg).
// Empty when the text does not read (its compiler reports that). `names`, when given, receives
// the variables read outside any function's arguments, as EvalExpr's.
std::vector<std::string> TopLevelUnitWords(const std::string& text, std::vector<std::string>* names = nullptr);

}  // namespace mechbench
