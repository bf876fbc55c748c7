#include "mechbench/compiled_expr.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

namespace mechbench {
namespace scenarios_compiled_expr_test {  // this file's own names (the tests build in unity batches)
namespace {

constexpr double kPi = std::numbers::pi;

// Variables t (0), a (1), b (2); c is a constant 2.5.
std::optional<CompiledExpr::Binding> Names(const std::string& n) {
  if (n == "t") return CompiledExpr::Binding{0, 0};
  if (n == "a") return CompiledExpr::Binding{1, 0};
  if (n == "b") return CompiledExpr::Binding{2, 0};
  if (n == "c") return CompiledExpr::Binding{-1, 2.5};
  return std::nullopt;
}

const std::vector<std::string> kTexts = {
    "2", "-1.5e-2", "pi/3", "35 deg", "2000 rpm", "15*sin(35 deg)", "-2^2", "2^-1", "atan2(1, -1)",
    "0.2 + 0.1*sin(2*pi*t)", "a*b - c/t", "sqrt(a^2 + b^2)", "exp(-t)*cos(3 t)", "log(1 + a) + tanh(b)",
    "atan2(b, a)", "atan2(a, -b)", "min(a, b) + max(t, c)", "abs(b - a)^1.5", "a^b", "sinh(t) - cosh(a)",
    "asin(0.3 t) + acos(0.2 a) + atan(b)", "tan(0.1 a) / (1 + t^2)", "2 (a + b)", "-(t - 1)^3"};

// The same text through EvalExpr (the file reader) and the compiled program.
TEST(CompiledExpr, ValuesAgreeWithTheReader) {
  const double x[3] = {0.7, 1.3, 0.4};
  for (const std::string& text : kTexts) {
    SCOPED_TRACE(text);
    const CompiledExpr e = CompiledExpr::Compile(text, Names);
    const double read = EvalExpr(text, [&](const std::string& n) -> std::optional<double> {
      if (auto b = Names(n)) return b->variable >= 0 ? x[b->variable] : b->value;
      return std::nullopt;
    });
    EXPECT_DOUBLE_EQ(e.Eval(x), read);
  }
}

// Jet2 along t against central differences of the value (h = 1e-4: error ~h² f''' ≈ 1e-7), and the
// gradient likewise in every variable.
TEST(CompiledExpr, DerivativesAgreeWithFiniteDifferences) {
  const double x[3] = {0.7, 1.3, 0.4};
  const double h = 1e-4;
  for (const std::string& text : kTexts) {
    SCOPED_TRACE(text);
    const CompiledExpr e = CompiledExpr::Compile(text, Names);
    auto at = [&](int var, double dx) {
      double y[3] = {x[0], x[1], x[2]};
      y[var] += dx;
      return e.Eval(y);
    };
    const Jet2 jx[3] = {{x[0], 1, 0}, {x[1], 0, 0}, {x[2], 0, 0}};
    const Jet2 j = e.Eval(jx);
    EXPECT_DOUBLE_EQ(j.v, e.Eval(x));
    EXPECT_NEAR(j.d, (at(0, h) - at(0, -h)) / (2 * h), 1e-6 * (1 + std::fabs(j.d)));
    EXPECT_NEAR(j.dd, (at(0, h) - 2 * at(0, 0) + at(0, -h)) / (h * h), 1e-4 * (1 + std::fabs(j.dd)));
    double g[CompiledExpr::kMaxVariables];
    EXPECT_DOUBLE_EQ(e.EvalGradient(x, g), e.Eval(x));
    for (size_t k = 0; k < e.variables().size(); ++k) {
      const int var = e.variables()[k];
      EXPECT_NEAR(g[k], (at(var, h) - at(var, -h)) / (2 * h), 1e-6 * (1 + std::fabs(g[k]))) << "variable " << var;
    }
  }
}

// A harmonic law's derivatives in closed form: x = A sin(ω t) + B t², ẋ = A ω cos(ω t) + 2 B t,
// ẍ = −A ω² sin(ω t) + 2 B.
TEST(CompiledExpr, HarmonicLawDerivativesAreExact) {
  const CompiledExpr e = CompiledExpr::Compile("0.3*sin(5*t) + 0.25*t^2", Names);
  for (double t : {0.0, 0.1, 0.77, 2.5}) {
    const Jet2 x[1] = {{t, 1, 0}};
    const Jet2 j = e.Eval(x);
    EXPECT_NEAR(j.v, 0.3 * std::sin(5 * t) + 0.25 * t * t, 1e-15);
    EXPECT_NEAR(j.d, 1.5 * std::cos(5 * t) + 0.5 * t, 1e-14);
    EXPECT_NEAR(j.dd, -7.5 * std::sin(5 * t) + 0.5, 1e-14);
  }
  EXPECT_EQ(e.variables(), std::vector<int>({0}));
  EXPECT_TRUE(e.Uses(0));
  EXPECT_FALSE(e.Uses(1));
  EXPECT_NEAR(CompiledExpr::Compile("30 deg + 0*t", Names).Eval(std::vector<double>{0.0}.data()), kPi / 6, 1e-16);
}

TEST(CompiledExpr, ErrorsNameTheProblem) {
  auto message = [](const std::string& text) {
    try {
      CompiledExpr::Compile(text, Names);
    } catch (const ExprError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message("0.2 + omega*t").find("unknown name 'omega'"), std::string::npos) << message("0.2 + omega*t");
  EXPECT_NE(message("sinn(t)").find("unknown function 'sinn'"), std::string::npos);
  EXPECT_NE(message("atan2(t)").find("atan2() takes 2 argument(s)"), std::string::npos);
  EXPECT_NE(message("(t + 1").find("')' expected"), std::string::npos);
  EXPECT_NE(message("t +").find("value expected"), std::string::npos);
  // A unit word where no unit goes, as EvalExpr refuses it (scenarios_expr_test.cc).
  for (const char* text : {"m", "a/m", "sqrt(c/m)", "t*s", "rad + t", "t/deg"})
    EXPECT_NE(message(text).find("is a unit word"), std::string::npos) << text << ": " << message(text);
  // An angle's unit word after '*' and any factor, as EvalExpr reads it.
  EXPECT_DOUBLE_EQ(CompiledExpr::Compile("t*deg", Names).Eval(std::vector<double>{90.0}.data()), std::numbers::pi / 2);
  EXPECT_DOUBLE_EQ(CompiledExpr::Compile("3 rad/s + 2*pi rad + 5 m/s^2 + 30*deg", Names).Eval(std::vector<double>{0.0}.data()),
                   3 + 2 * kPi + 5 + kPi / 6);
}

}  // namespace
}  // namespace scenarios_compiled_expr_test
}  // namespace mechbench
