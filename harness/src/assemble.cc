// The results object around the records: what built and ran them, the scenarios with a drawing
// of each mechanism, the methods, and the figures derived from the sweeps.
#include "mechbench/harness/campaign.h"
#include "mechbench/harness/chains.h"

#include "mechbench/build_info.h"
#include "mechbench/format.h"
#include "mechbench/harness/frames.h"
#include "mechbench/harness/registry.h"
#include "mechbench/loader.h"
#include "mechbench/references/registry.h"
#include "json_number.h"

#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cmath>
#include <ctime>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <thread>

namespace mechbench::harness {

using nlohmann::json;

namespace {


std::string FirstLine(const std::string& file, const std::string& prefix) {
  std::ifstream in(file);
  std::string line;
  while (std::getline(in, line))
    if (line.rfind(prefix, 0) == 0) return line.substr(prefix.size());
  return {};
}

std::string Trim(std::string s) {
  const auto b = s.find_first_not_of(" \t:\"");
  const auto e = s.find_last_not_of(" \t\"");
  return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
}

json Machine() {
  json m;
  m["cpu"] = Trim(FirstLine("/proc/cpuinfo", "model name"));
  m["cores"] = static_cast<int>(std::thread::hardware_concurrency());
  const std::string mem = Trim(FirstLine("/proc/meminfo", "MemTotal"));
  m["memory_gib"] = std::round(std::atof(mem.c_str()) / (1024.0 * 1024.0) * 10) / 10;
  m["os"] = Trim(FirstLine("/etc/os-release", "PRETTY_NAME="));
  char host[256] = {};
  if (::gethostname(host, sizeof host - 1) == 0) m["hostname"] = host;
  return m;
}

json Build() {
  json b = {{"version", MECHBENCH_VERSION}, {"build_type", MECHBENCH_BUILD_TYPE}};
#if defined(__clang__)
  b["compiler"] = std::string("clang ") + __clang_version__;
#elif defined(__GNUC__)
  b["compiler"] = std::string("gcc ") + __VERSION__;
#else
  b["compiler"] = "unknown";
#endif
  b["git_commit"] = MECHBENCH_GIT_COMMIT " (at configure time)";
  return b;
}

// "simbody=3.7;ode=0.16.2" (from the build) -> {"simbody": "3.7", "ode": "0.16.2"}
json Engines() {
  json e = json::object();
  std::stringstream ss{std::string(MECHBENCH_ENGINE_VERSIONS)};
  std::string item;
  while (std::getline(ss, item, ';')) {
    const auto eq = item.find('=');
    if (eq != std::string::npos) e[item.substr(0, eq)] = item.substr(eq + 1);
  }
  return e;
}

std::string NowUtc() {
  const std::time_t t = std::time(nullptr);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
  return buf;
}

// The mechanism at t0 in its plane: the numeric solution's point positions.
// A spatial scene's drawing: as a planar one's with "dim": 3 and x, y, z per point. Its points are
// the point entities (frames.h order); a body lists the points among its entities (a rigid body's
// unit vectors are not drawn), a point mass is a body of one point.
json SpatialDrawing(const Model& m, const Eigen::VectorXd& q) {
  const std::vector<Eigen::Vector3d> p = SpatialPointPositions(m, q);
  const SpatialModel& sm = m.spatial;
  std::vector<int> order_of(sm.entities.size(), -1);  // entity → its place among the points
  for (size_t e = 0, k = 0; e < sm.entities.size(); ++e)
    if (!sm.entities[e].vector) order_of[e] = static_cast<int>(k++);
  auto xyz = [&](int k) { return json{p[k].x(), p[k].y(), p[k].z()}; };
  json d = {{"unit", m.length_unit}, {"dim", 3}, {"bodies", json::array()}, {"fixed", json::array()},
            {"points", json::array()}, {"order", DrawnPointNames(m)}};
  for (const SpatialBody& b : sm.bodies) {
    json pts = json::array(), index = json::array();
    for (int e : b.entities)
      if (e >= 0 && order_of[e] >= 0) pts.push_back(xyz(order_of[e])), index.push_back(order_of[e]);
    d["bodies"].push_back({{"name", b.name}, {"points", pts}, {"index", index}});
  }
  for (size_t e = 0; e < sm.entities.size(); ++e) {
    const int k = order_of[e];
    if (k < 0 || !p[k].allFinite()) continue;
    d[sm.entities[e].fixed ? "fixed" : "points"].push_back({{"name", sm.entities[e].name}, {"p", xyz(k)}});
  }
  return d;
}

json Drawing(const Model& m) {
  if (m.kind != ScenarioKind::kLinkage && m.kind != ScenarioKind::kSpatial) return nullptr;
  std::unique_ptr<Method> numeric;
  for (MethodPtr& meth : AllMethods())
    if (meth->name() == "numeric") numeric = std::move(meth);
  if (!numeric || numeric->Applicability(m)) return nullptr;
  const Result r = numeric->Run(m, {.motion = false});
  if (!r.ok() || r.trajectory.empty()) return nullptr;
  const Eigen::VectorXd& q = r.trajectory[0].q;
  if (m.kind == ScenarioKind::kSpatial) return SpatialDrawing(m, q);
  const std::vector<Eigen::Vector2d> p = PointPositions(m, q);
  // "order": the points' names in model order, the order of a run record's frames (frames.h);
  // each body's "index" lists its points in that order.
  json d = {{"unit", m.length_unit}, {"bodies", json::array()}, {"fixed", json::array()}, {"points", json::array()},
            {"order", json::array()}};
  for (const Point& pt : m.points) d["order"].push_back(pt.name);
  for (const Body& b : m.bodies) {
    json pts = json::array();
    for (int i : b.points) pts.push_back({p[i].x(), p[i].y()});
    d["bodies"].push_back({{"name", b.name}, {"points", pts}, {"index", b.points}});
  }
  for (size_t i = 0; i < m.points.size(); ++i) {
    if (!p[i].allFinite()) continue;
    d[m.points[i].fixed ? "fixed" : "points"].push_back({{"name", m.points[i].name}, {"p", {p[i].x(), p[i].y()}}});
  }
  return d;
}

json ScenarioEntry(const Model& m, const std::string& file) {
  return {{"scenario", m.name}, {"section", m.section}, {"title", m.title},
          {"kind", m.kind == ScenarioKind::kGearTrain ? "gear_train" : m.kind == ScenarioKind::kSpatial ? "spatial" : "linkage"},
          {"free", m.IsFree()},
          {"file", file}, {"drawing", Drawing(m)}};
}

// Least-squares slope of log(error) against log(control) over the rungs above round-off and
// below the qualitative range: the observed order of a fixed-step method; for an error-controlled
// one (the control a tolerance), the slope of its error against the tolerance, which is no order.
double Order(std::vector<std::pair<double, double>> pts) {
  std::vector<std::pair<double, double>> use;
  for (const auto& [x, y] : pts)
    if (x > 0 && std::isfinite(x) && y > 1e-12 && y < 0.1) use.emplace_back(x, y);
  return LogLogSlope(use);
}

}  // namespace

json Assemble(std::vector<json> records, const CampaignOptions& o) {
  std::stable_sort(records.begin(), records.end(), [](const json& a, const json& b) {
    return a["index"].get<int>() != b["index"].get<int>() ? a["index"].get<int>() < b["index"].get<int>()
                                                          : a["id"].get<std::string>() < b["id"].get<std::string>();
  });
  json out;
  out["schema"] = "mechbench-results/1";
  out["build"] = Build();
  out["engines"] = Engines();
  out["machine"] = Machine();
  out["created"] = NowUtc();
  out["options"] = {{"quick", o.quick}, {"shards", o.shards}, {"jobs", o.jobs}, {"repeats", o.quick ? 1 : o.repeats},
                    {"timeout_seconds", o.timeout}, {"selection", o.scenarios}, {"tolerances", o.tolerances}};

  // Scenarios in the order their records first appear; stress variants of generated scenes
  // (no file) are drawn from the variant.
  json scenarios = json::array();
  std::set<std::string> seen;
  for (const json& r : records) {
    const std::string name = r["scenario"].get<std::string>();
    if (name.empty() || seen.count(name) || r["kind"] == "chain") continue;  // chains: generated, a table of their own
    seen.insert(name);
    const std::string file = r.value("file", "");
    try {
      if (!file.empty()) {
        scenarios.push_back(ScenarioEntry(references::LoadScenarioValidated(file), file));
      } else {
        for (const StressVariant& v : StressVariants())
          if (v.base.empty() && v.derive(Model{}).name == name) {
            scenarios.push_back(ScenarioEntry(v.derive(Model{}), ""));
            break;
          }
      }
    } catch (const std::exception& e) {
      scenarios.push_back({{"scenario", name}, {"section", ""}, {"title", std::string("cannot load: ") + e.what()},
                           {"kind", "linkage"}, {"free", false}, {"file", file}, {"drawing", nullptr}});
    }
  }
  out["scenarios"] = scenarios;

  json methods = json::array();
  std::set<std::string> wanted(o.methods.begin(), o.methods.end());
  for (const MethodPtr& m : AllMethods())
    if (wanted.empty() || wanted.count(m->name()))
      methods.push_back({{"method", m->name()}, {"description", m->description()}, {"control", ToString(m->control())},
                         {"default", JsonNumber(m->default_control())}});
  out["methods"] = methods;

  // Derived: per (scenario, method) with sweep rungs. CPU to an accuracy is the integration time
  // of the cheapest rung that reaches it (the method's own work, Result::cpu); the set-up of that
  // rung is given beside it.
  struct Acc {
    double to3 = kNaN, to6 = kNaN, setup3 = kNaN, setup6 = kNaN;
    std::vector<std::pair<double, double>> pts;
    std::string control;  // "step", "tolerance" (the sweep records')
    std::string shared3, shared6;  // the rung chosen for each level: the method whose run it shares, or ""
  };
  std::map<std::pair<std::string, std::string>, Acc> acc;
  std::vector<std::pair<std::string, std::string>> order;
  std::map<std::pair<std::string, std::string>, double> stable;
  for (const json& r : records) {
    const auto key = std::make_pair(r["scenario"].get<std::string>(), r.value("method", ""));
    if (r["kind"] == "stable_step" && r["largest_stable"].is_number()) stable[key] = r["largest_stable"].get<double>();
    if (r["kind"] != "sweep") continue;
    if (!acc.count(key)) order.push_back(key);
    Acc& a = acc[key];
    if (a.control.empty()) a.control = r.value("control", "");
    if (r["status"] != "ok" || !r.contains("error") || !r["error"]["q_max"].is_number()) continue;
    const json cpu_parts = r.value("cpu", json());
    const double e = r["error"]["q_max"].get<double>();
    const double cpu = cpu_parts.is_object() ? cpu_parts["integration"].get<double>() : r["cpu_seconds"].get<double>();
    const double setup = cpu_parts.is_object() ? cpu_parts["setup"].get<double>() : kNaN;
    const std::string shared = r.value("shared_with", "");
    if (e <= 1e-3 && !(cpu >= a.to3)) a.to3 = cpu, a.setup3 = setup, a.shared3 = shared;
    if (e <= 1e-6 && !(cpu >= a.to6)) a.to6 = cpu, a.setup6 = setup, a.shared6 = shared;
    if (r["value"].is_number()) a.pts.emplace_back(r["value"].get<double>(), e);
  }
  json derived = json::array();
  for (const auto& key : order) {
    const Acc& a = acc[key];
    const auto st = stable.find(key);
    // An observed order only for a fixed-step method run at several steps; an error-controlled
    // method's rungs vary its tolerance, and the slope against it is given as that.
    const bool by_tolerance = a.control == "tolerance";
    const double slope = Order(a.pts);
    derived.push_back({{"scenario", key.first}, {"method", key.second}, {"cpu_to_1e-3", JsonNumber(a.to3)},
                       {"cpu_to_1e-6", JsonNumber(a.to6)}, {"setup_at_1e-3", JsonNumber(a.setup3)}, {"setup_at_1e-6", JsonNumber(a.setup6)},
                       {"order", by_tolerance ? json(nullptr) : JsonNumber(slope)},
                       {"tolerance_slope", by_tolerance ? JsonNumber(slope) : json(nullptr)},
                       {"largest_stable", st == stable.end() ? json(nullptr) : JsonNumber(st->second)}});
    // A level reached by a rung whose run is another method's (shared_with): the same run and
    // CPU time in two cells, marked so that it is not counted twice.
    if (!a.shared3.empty()) derived.back()["shared_at_1e-3"] = a.shared3;
    if (!a.shared6.empty()) derived.back()["shared_at_1e-6"] = a.shared6;
  }
  // Methods with a stable-step figure but no sweep on that scene still get a row.
  for (const auto& [key, h] : stable)
    if (!acc.count(key))
      derived.push_back({{"scenario", key.first}, {"method", key.second}, {"cpu_to_1e-3", nullptr},
                         {"cpu_to_1e-6", nullptr}, {"setup_at_1e-3", nullptr}, {"setup_at_1e-6", nullptr},
                         {"order", nullptr}, {"tolerance_slope", nullptr}, {"largest_stable", JsonNumber(h)}});
  out["derived"] = derived;

  // Each method's one-time costs (timing.h), paid once per worker process before its timed run
  // and part of no timing: the median over the cases that measured them.
  std::map<std::string, std::vector<double>> one_time;
  for (const json& r : records)
    if (r.contains("startup") && r["startup"].is_object()) one_time[r["method"].get<std::string>()].push_back(r["startup"]["one_time"].get<double>());
  json startup = json::array();
  for (auto& [method, v] : one_time) {
    std::sort(v.begin(), v.end());
    startup.push_back({{"method", method}, {"one_time_median", v[v.size() / 2]}, {"one_time_max", v.back()},
                       {"cases", static_cast<int>(v.size())}});
  }
  out["startup"] = startup;
  out["records"] = std::move(records);
  return out;
}

std::string CampaignId(const CampaignOptions& options, size_t* total_cases) {
  CampaignOptions whole = options;
  whole.shard = whole.shards = 1;
  const std::vector<Case> cases = EnumerateCases(whole);
  if (total_cases) *total_cases = cases.size();
  std::uint64_t h = 1469598103934665603ull;
  const auto add = [&h](const std::string& s) {
    for (unsigned char c : s) h = (h ^ c) * 1099511628211ull;
    h = (h ^ 0xff) * 1099511628211ull;
  };
  add(MECHBENCH_GIT_COMMIT);
  add(MECHBENCH_BUILD_TYPE);
  add(options.quick ? "quick" : "full");
  add(std::to_string(options.repeats));
  add(std::to_string(options.timeout));
  for (const Case& c : cases) add(c.id);
  // The tolerances judge every record: their files' contents are part of the campaign.
  for (const std::string& f : options.tolerances) {
    std::ifstream in(f);
    std::stringstream text;
    text << in.rdbuf();
    add(f);
    add(text.str());
  }
  char buf[20];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

}  // namespace mechbench::harness
