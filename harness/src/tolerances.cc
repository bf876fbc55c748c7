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
  if (const YAML::Node ms = n["methods"])
    for (const auto& kv : ms) {
      Agreement& a = t.methods.try_emplace(kv.first.as<std::string>(), t.For("")).first->second;
      if (const YAML::Node g = kv.second["agreement"]) {
        if (g["q"]) a.q = g["q"].as<double>();
        if (g["qd"]) a.qd = g["qd"].as<double>();
        if (g["qdd"]) a.qdd = g["qdd"].as<double>();
        if (g["instant"]) a.instant = g["instant"].as<double>();
      }
      if (kv.second["residual"]) a.residual = kv.second["residual"].as<double>();
    }
  if (const YAML::Node f = n["free"]) {
    const auto read = [](const YAML::Node& e, FreeTolerance& ft) {
      if (e["position"]) ft.position = e["position"].as<double>();
      if (e["residual"]) ft.residual = e["residual"].as<double>();
    };
    if (f["default"]) read(f["default"], t.free);
    if (const YAML::Node ms = f["methods"])
      for (const auto& kv : ms) {
        FreeTolerance& ft = t.free_methods.try_emplace(kv.first.as<std::string>(), t.free).first->second;
        read(kv.second, ft);
      }
  }
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
    if (const YAML::Node k = root["known_failures"])
      for (const YAML::Node& e : k)
        if (e["scenario"].as<std::string>() == scenario)
          t.known_failures[e["method"].as<std::string>()] = e["why"].as<std::string>();
  } catch (const YAML::Exception& e) {
    throw ScenarioError({file, e.mark.line + 1}, "cannot read tolerances: " + e.msg);
  }
  return t;
}

}  // namespace mechbench::harness
