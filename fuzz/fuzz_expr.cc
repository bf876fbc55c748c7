// libFuzzer target: the expression reader must answer any text with a number or an ExprError,
// never a crash, a stack overflow (deep nesting) or a hang.
#include "mechbench/expr.h"

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    // A few names the harness would know (a book quantity's variables).
    mechbench::EvalExpr(text, [](const std::string& name) -> std::optional<double> {
      if (name == "x" || name == "qd.theta") return 2.5;
      return std::nullopt;
    });
  } catch (const mechbench::ExprError&) {
  }
  return 0;
}
