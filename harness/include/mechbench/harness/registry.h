// The explicit list of methods built into this binary (no self-registering statics that a
// linker could drop). Engines appear here behind their MECHBENCH_WITH_<NAME> options.
#pragma once

#include "mechbench/method.h"

#include <string>
#include <vector>

namespace mechbench::harness {

std::vector<MethodPtr> AllMethods();
// The engine variants of AllMethods() alone, in the same order (those built in).
std::vector<MethodPtr> EngineMethods();
// Whether `name` names a method a tolerances file may list: one of AllMethods(), or a variant of
// an engine this binary was built without (its prefix: "simbody-", "ode-", "bullet-", "mujoco-"),
// which the project's harness/tolerances.yaml lists for the builds that have it.
bool KnownMethodName(const std::string& name);

}  // namespace mechbench::harness
