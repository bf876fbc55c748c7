// Numbers in messages and settings: a short, round-trip-free rendering ("0.001", "1.5e-09").
#pragma once

#include <cstdio>
#include <string>

namespace mechbench {

inline std::string Fmt(double v, int significant_digits = 6) {
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.*g", significant_digits, v);
  return buf;
}

}  // namespace mechbench
