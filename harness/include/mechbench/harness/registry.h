// The explicit list of methods built into this binary (no self-registering statics that a
// linker could drop). Engines appear here behind their MECHBENCH_WITH_<NAME> options.
#pragma once

#include "mechbench/method.h"

#include <vector>

namespace mechbench::harness {

std::vector<MethodPtr> AllMethods();
// The engine variants of AllMethods() alone, in the same order (those built in).
std::vector<MethodPtr> EngineMethods();

}  // namespace mechbench::harness
