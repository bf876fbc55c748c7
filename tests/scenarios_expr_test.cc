#include "mechbench/expr.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

namespace mechbench {
namespace scenarios_expr_test {  // this file's own names (the tests build in unity batches)
namespace {

TEST(Expr, NumbersUnitsAndFunctions) {
  EXPECT_DOUBLE_EQ(EvalExpr("2"), 2.0);
  EXPECT_DOUBLE_EQ(EvalExpr("-1.5e-2"), -0.015);
  EXPECT_DOUBLE_EQ(EvalExpr("pi/3"), std::numbers::pi / 3);
  EXPECT_DOUBLE_EQ(EvalExpr("35 deg"), 35 * std::numbers::pi / 180);
  EXPECT_DOUBLE_EQ(EvalExpr("2000 rpm"), 2000 * 2 * std::numbers::pi / 60);
  EXPECT_DOUBLE_EQ(EvalExpr("15*sin(35 deg)"), 15 * std::sin(35 * std::numbers::pi / 180));
  EXPECT_DOUBLE_EQ(EvalExpr("0.5*10*0.06^2"), 0.5 * 10 * 0.0036);
  EXPECT_DOUBLE_EQ(EvalExpr("-2^2"), -4.0);  // unary minus binds looser than ^
  EXPECT_DOUBLE_EQ(EvalExpr("2^-1"), 0.5);
  EXPECT_DOUBLE_EQ(EvalExpr("atan2(1, -1)"), 3 * std::numbers::pi / 4);
  EXPECT_DOUBLE_EQ(EvalExpr("1 - 1/tan(60 deg)"), 1 - 1 / std::tan(std::numbers::pi / 3));
}

TEST(Expr, VariablesWithDotsAndIndices) {
  auto lookup = [](const std::string& n) -> std::optional<double> {
    if (n == "qd.phi1") return 10.0;
    if (n == "qd.phi6") return -4.0;
    if (n == "Phi_q[0,2]") return 7.0;
    if (n == "vslide.1") return 3.0;
    return std::nullopt;
  };
  EXPECT_DOUBLE_EQ(EvalExpr("qd.phi1/qd.phi6", lookup), -2.5);
  EXPECT_DOUBLE_EQ(EvalExpr("Phi_q[0,2] + 1", lookup), 8.0);
  EXPECT_DOUBLE_EQ(EvalExpr("-vslide.1", lookup), -3.0);
  EXPECT_DOUBLE_EQ(EvalExpr("sqrt(qd.phi1^2 + qd.phi6^2)", lookup), std::sqrt(116.0));
}

TEST(Expr, ErrorsNameTheProblem) {
  EXPECT_THROW(EvalExpr("sinn(3)"), ExprError);
  EXPECT_THROW(EvalExpr("2 +"), ExprError);
  EXPECT_THROW(EvalExpr("(2"), ExprError);
  EXPECT_THROW(EvalExpr("x"), ExprError);
  EXPECT_THROW(EvalExpr("atan2(1)"), ExprError);
  try {
    EvalExpr("3 * bogus");
    FAIL() << "no error";
  } catch (const ExprError& e) {
    EXPECT_NE(std::string(e.what()).find("unknown name 'bogus'"), std::string::npos) << e.what();
  }
}

// A unit word is a unit after a value or later in a product with a number or a unit; anywhere else
// it is refused, with the fix (it used to be 1: `mass: m` gave 1 kg, `sqrt(k/m)` gave sqrt(k)).
TEST(Expr, UnitWordOnlyWhereAUnitGoes) {
  EXPECT_DOUBLE_EQ(EvalExpr("3 rad/s"), 3.0);
  EXPECT_DOUBLE_EQ(EvalExpr("5 m/s^2"), 5.0);
  EXPECT_DOUBLE_EQ(EvalExpr("2*pi rad"), 2 * std::numbers::pi);
  EXPECT_DOUBLE_EQ(EvalExpr("30*deg"), std::numbers::pi / 6);
  EXPECT_DOUBLE_EQ(EvalExpr("1/s"), 1.0);
  EXPECT_DOUBLE_EQ(EvalExpr("(1 + 2) m"), 3.0);
  EXPECT_DOUBLE_EQ(EvalExpr("-3 rad"), -3.0);
  auto lookup = [](const std::string& n) -> std::optional<double> {
    if (n == "k") return 200.0;
    if (n == "L") return 0.5;
    if (n == "s") return 7.0;  // a coordinate named s (an actuator's length) wins over the unit
    return std::nullopt;
  };
  EXPECT_DOUBLE_EQ(EvalExpr("L m", lookup), 0.5);
  EXPECT_DOUBLE_EQ(EvalExpr("2*s", lookup), 14.0);
  // An angle's unit word also after '*' and any factor (a constant in degrees); never m or s there.
  EXPECT_DOUBLE_EQ(EvalExpr("L*deg", lookup), 0.5 * std::numbers::pi / 180);
  EXPECT_DOUBLE_EQ(EvalExpr("k*rpm", lookup), 200 * 2 * std::numbers::pi / 60);
  EXPECT_DOUBLE_EQ(EvalExpr("sin(L*rad)", lookup), std::sin(0.5));
  for (const char* text : {"m", "k/m", "sqrt(k/m)", "k*m", "-m", "deg", "rpm*2", "L/deg", "k*(deg)", "(m)", "2^m",
                           "k + m", "L^deg"}) {
    try {
      EvalExpr(text, lookup);
      ADD_FAILURE() << text << ": no error";
    } catch (const ExprError& e) {
      EXPECT_NE(std::string(e.what()).find("is a unit word"), std::string::npos) << text << ": " << e.what();
      EXPECT_NE(e.fix.find("is a unit here; name your constant something else"), std::string::npos) << text << ": " << e.fix;
    }
  }
}

// The variables read outside any function's arguments (a constant named there carries its unit
// words into the field: loader.cc, constant_units.h); those inside sin(…) do not measure the value.
TEST(Expr, NamesOutsideFunctionArguments) {
  const VariableLookup lookup = [](const std::string& n) -> std::optional<double> {
    if (n == "mb" || n == "al" || n == "L" || n == "t") return 2.0;
    return std::nullopt;
  };
  std::vector<std::string> units, names;
  EXPECT_DOUBLE_EQ(EvalExpr("3*mb + L*sin(al deg) m", lookup, &units, &names), 6 + 2 * std::sin(2 * std::numbers::pi / 180));
  EXPECT_EQ(names, (std::vector<std::string>{"mb", "L"}));
  EXPECT_EQ(units, (std::vector<std::string>{"m"}));
  names.clear();
  EXPECT_EQ(TopLevelUnitWords("(mb + t) deg*cos(L)", &names), (std::vector<std::string>{"deg"}));
  EXPECT_EQ(names, (std::vector<std::string>{"mb", "t"}));
}

}  // namespace
}  // namespace scenarios_expr_test
}  // namespace mechbench
