// A method's named result in the tests: a quantity that is missing fails the test and reads NaN.
#pragma once

#include "mechbench/method.h"

#include <gtest/gtest.h>

#include <limits>
#include <string>

namespace mechbench {

inline double Get(const Result& r, const std::string& name) {
  const auto it = r.quantities.find(name);
  if (it == r.quantities.end()) {
    ADD_FAILURE() << r.method << " has no quantity " << name;
    return std::numeric_limits<double>::quiet_NaN();
  }
  return it->second;
}

}  // namespace mechbench
