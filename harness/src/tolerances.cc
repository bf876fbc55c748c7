#include "mechbench/harness/tolerances.h"

#include "mechbench/errors.h"

#include <yaml-cpp/yaml.h>

namespace mechbench::harness {
namespace {

void Read(const YAML::Node& n, Tolerances& t) {
  if (!n) return;
  if (const YAML::Node a = n["agreement"]) {
    if (a["q"]) t.q = a["q"].as<double>();
    if (a["qd"]) t.qd = a["qd"].as<double>();
    if (a["qdd"]) t.qdd = a["qdd"].as<double>();
    if (a["instant"]) t.instant = a["instant"].as<double>();
  }
  if (n["residual"]) t.residual = n["residual"].as<double>();
}

}  // namespace

std::string DefaultTolerancesFile() { return MECHBENCH_TOLERANCES_FILE; }

Tolerances LoadTolerances(const std::string& scenario, const std::string& path) {
  const std::string file = path.empty() ? DefaultTolerancesFile() : path;
  Tolerances t;
  try {
    const YAML::Node root = YAML::LoadFile(file);
    Read(root["default"], t);
    if (root["scenarios"] && root["scenarios"][scenario]) Read(root["scenarios"][scenario], t);
  } catch (const YAML::Exception& e) {
    throw ScenarioError({file, e.mark.line + 1}, "cannot read tolerances: " + e.msg);
  }
  return t;
}

}  // namespace mechbench::harness
