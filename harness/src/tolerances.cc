#include "mechbench/harness/tolerances.h"

#include "mechbench/errors.h"
#include "mechbench/loader.h"
#include "mechbench/harness/registry.h"
#include "mechbench/model.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <mutex>
#include <set>
#include <sstream>

namespace mechbench::harness {
namespace {

// Classes of scene a known failure may name (`class:`): a property of a method on every scene of
// the kind, a user's file included, rather than of one file. Decided from the model's structure.
using SceneClass = std::pair<std::string, bool (*)(const Model&)>;  // description, member
const std::map<std::string, SceneClass>& SceneClasses() {
  static const std::map<std::string, SceneClass> k{
      {"free_coupling",
       {"a free scene with a coupling of two joint coordinates (a rack and pinion, a belt)",
        [](const Model& m) { return m.IsFree() && !m.couplings.empty(); }}},
  };
  return k;
}
std::string SceneClassNames() {
  std::string out;
  for (const auto& [name, c] : SceneClasses()) out += (out.empty() ? "" : ", ") + name + " (" + c.first + ")";
  return out;
}

// A tolerances file is read as strictly as a scenario: an unknown key is an error with the file,
// the line and the keys allowed there, and every bound is a positive number (or .inf).
class TolerancesReader {
 public:
  explicit TolerancesReader(std::string file) : file_(std::move(file)) {
    std::error_code ec;
    if (std::filesystem::is_directory(file_, ec))
      throw ScenarioError({file_, 0}, "is a folder, not a tolerances file",
                          "give the path of a YAML file in harness/tolerances.yaml's format");
    try {
      root_ = YAML::LoadFile(file_);
    } catch (const YAML::BadFile&) {
      throw ScenarioError({file_, 0}, "cannot open the tolerances file", "give the path of a readable YAML file");
    } catch (const YAML::Exception& e) {
      throw ScenarioError({file_, e.mark.line + 1}, "cannot read tolerances: " + e.msg, "fix the YAML syntax");
    } catch (const std::exception& e) {  // a stream's own failure (a special file): never an abort
      throw ScenarioError({file_, 0}, std::string("cannot read the tolerances file: ") + e.what(),
                          "give the path of a readable YAML file");
    }
    if (root_.IsNull()) return;  // an empty file changes nothing
    Map(root_, "the file", {"default", "scenarios", "known_failures"});
    if (root_["default"]) Section(root_["default"], "default");
    if (const YAML::Node s = root_["scenarios"]) {
      Map(s, "scenarios", {});
      for (const auto& kv : s) {
        Section(kv.second, "scenarios: " + kv.first.as<std::string>());
        scenario_names_.emplace_back(kv.first.as<std::string>(), kv.first.Mark().line + 1);
      }
    }
    if (const YAML::Node k = root_["known_failures"]) {
      if (!k.IsSequence())
        Fail(k, "known_failures must be a list", "write - {scenario: NAME, method: NAME, why: \"…\"} entries");
      for (const YAML::Node& e : k) {
        Map(e, "a known failure", {"scenario", "class", "method", "why"});
        if (e["scenario"] && e["class"])
          Fail(e, "a known failure with both a scenario and a class",
               "give scenario (one file's stem) or class (a kind of scene: " + SceneClassNames() + "), not both");
        if (const YAML::Node c = e["class"]; c && (!c.IsScalar() || !SceneClasses().count(c.as<std::string>())))
          Fail(c, "unknown class of scene '" + (c.IsScalar() ? c.as<std::string>() : std::string("?")) + "'",
               "write one of: " + SceneClassNames());
        for (const char* key : {e["class"] ? "class" : "scenario", "method", "why"})
          if (!e[key] || !e[key].IsScalar() || e[key].as<std::string>().empty())
            Fail(e, std::string("a known failure without its ") + key,
                 "give scenario (the file's stem) or class (a kind of scene: " + SceneClassNames() +
                     "), method (a name from `mechbench list`) and why (what is known)");
        MethodName(e["method"], "a known failure");
        if (e["scenario"]) scenario_names_.emplace_back(e["scenario"].as<std::string>(), e["scenario"].Mark().line + 1);
      }
    }
  }

  // The sections that apply to `scenario`, read over `t` in the order given: `default` first.
  void ApplyDefault(Tolerances& t) const {
    if (root_.IsMap() && root_["default"]) Read(root_["default"], t);
  }
  void ApplyScenario(const std::string& scenario, Tolerances& t) const {
    if (root_.IsMap() && root_["scenarios"] && root_["scenarios"][scenario]) Read(root_["scenarios"][scenario], t);
    if (root_.IsMap() && root_["known_failures"])
      for (const YAML::Node& e : root_["known_failures"])
        if (e["scenario"] && e["scenario"].as<std::string>() == scenario) {
          t.known_failures[e["method"].as<std::string>()] = e["why"].as<std::string>();
          t.known_where[e["method"].as<std::string>()] = Where(e);
        }
  }
  // Known failures of a class of scene (`class:`), for ApplySceneClasses.
  void ApplyClasses(const Model& model, Tolerances& t) const {
    if (!root_.IsMap() || !root_["known_failures"]) return;
    for (const YAML::Node& e : root_["known_failures"]) {
      if (!e["class"]) continue;
      const auto c = SceneClasses().find(e["class"].as<std::string>());
      if (c == SceneClasses().end() || !c->second.second(model)) continue;
      // A scene's own entry says more than its class's.
      if (t.known_failures.emplace(e["method"].as<std::string>(),
                                   e["why"].as<std::string>() + " (a known failure of its class of scene: " + c->second.first + ")")
              .second)
        t.known_where[e["method"].as<std::string>()] = Where(e);
    }
  }

 // The scenario names the file gives (`scenarios:` keys, known failures' `scenario:`) and their lines.
  const std::vector<std::pair<std::string, int>>& ScenarioNames() const { return scenario_names_; }
  const std::string& file() const { return file_; }

 private:
  // "file:line" of an entry, as a known failure's verdict names it.
  std::string Where(const YAML::Node& n) const { return file_ + ":" + std::to_string(n.Mark().line + 1); }

  // A method's name must be one the registry knows (KnownMethodName): a misspelt name would
  // otherwise be an entry that applies to nothing, silently.
  void MethodName(const YAML::Node& n, const std::string& what) const {
    const std::string name = n.as<std::string>();
    if (KnownMethodName(name)) return;
    std::string names;
    for (const MethodPtr& m : AllMethods()) names += (names.empty() ? "" : ", ") + m->name();
    Fail(n, "unknown method '" + name + "' in " + what, "use a name from `mechbench list`: " + names);
  }

  [[noreturn]] void Fail(const YAML::Node& n, const std::string& problem, const std::string& fix) const {
    throw ScenarioError({file_, n.Mark().line + 1}, problem, fix);
  }

  void Map(const YAML::Node& n, const std::string& what, const std::set<std::string>& allowed) const {
    if (!n.IsMap()) Fail(n, what + " must be a map of keys", "see harness/tolerances.yaml for the format");
    // The scene loader's rule: a key given twice is refused (YAML would keep the last one silently).
    std::set<std::string> seen;
    for (const auto& kv : n)
      if (!seen.insert(kv.first.as<std::string>()).second)
        Fail(kv.first, "duplicate key '" + kv.first.as<std::string>() + "' in " + what, "keep only one");
    if (allowed.empty()) return;
    for (const auto& kv : n) {
      const std::string key = kv.first.as<std::string>();
      if (allowed.count(key)) continue;
      std::string list;
      for (const std::string& a : allowed) list += (list.empty() ? "" : ", ") + a;
      Fail(kv.first, "unknown key '" + key + "' in " + what, "use one of: " + list);
    }
  }

  void Bound(const YAML::Node& n, const std::string& what) const {
    double v = kNaN;
    try {
      v = n.as<double>();
    } catch (const YAML::Exception&) {
    }
    if (!(v > 0)) Fail(n, what + " must be a positive number, not '" + (n.IsScalar() ? n.as<std::string>() : "…") + "'",
                       "write a relative bound such as 1.0e-6, or .inf for a quantity shown and not judged");
  }

  void AgreementKeys(const YAML::Node& n, const std::string& what) const {
    Map(n, what + " agreement", {"q", "qd", "qdd", "instant", "instant_acceleration"});
    for (const auto& kv : n) Bound(kv.second, what + " agreement " + kv.first.as<std::string>());
  }

  void FreeEntry(const YAML::Node& n, const std::string& what) const {
    Map(n, what, {"position", "residual"});
    for (const auto& kv : n) Bound(kv.second, what + " " + kv.first.as<std::string>());
  }

  void Section(const YAML::Node& n, const std::string& what) const {
    Map(n, what, {"agreement", "residual", "methods", "free"});
    if (n["agreement"]) AgreementKeys(n["agreement"], what);
    if (n["residual"]) Bound(n["residual"], what + " residual");
    if (const YAML::Node ms = n["methods"]) {
      Map(ms, what + " methods", {});
      for (const auto& kv : ms) {
        const std::string m = what + " method " + kv.first.as<std::string>();
        MethodName(kv.first, what + " methods");
        Map(kv.second, m, {"agreement", "residual"});
        if (kv.second["agreement"]) AgreementKeys(kv.second["agreement"], m);
        if (kv.second["residual"]) Bound(kv.second["residual"], m + " residual");
      }
    }
    if (const YAML::Node f = n["free"]) {
      Map(f, what + " free", {"horizon", "default", "methods"});
      if (const YAML::Node h = f["horizon"]) {  // a time, not a relative bound: its own fix
        double v = kNaN;
        try {
          v = h.as<double>();
        } catch (const YAML::Exception&) {
        }
        if (!(v > 0))
          Fail(h, what + " free horizon must be a positive number, not '" + (h.IsScalar() ? h.as<std::string>() : "…") + "'",
               "write the length in s of the motion the free positions are stated for, e.g. horizon: 1 (a motion "
               "twice as long is allowed twice the position bound)");
      }
      if (f["default"]) FreeEntry(f["default"], what + " free default");
      if (const YAML::Node ms = f["methods"]) {
        Map(ms, what + " free methods", {});
        for (const auto& kv : ms) {
          MethodName(kv.first, what + " free methods");
          FreeEntry(kv.second, what + " free method " + kv.first.as<std::string>());
        }
      }
    }
  }

  static void Read(const YAML::Node& n, Tolerances& t) {
    if (const YAML::Node a = n["agreement"]) {
      if (a["q"]) t.q = a["q"].as<double>();
      if (a["qd"]) t.qd = a["qd"].as<double>();
      if (a["qdd"]) t.qdd = a["qdd"].as<double>();
      if (a["instant"]) t.instant = a["instant"].as<double>();
      if (a["instant_acceleration"]) t.instant_acceleration = a["instant_acceleration"].as<double>();
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
          if (g["instant_acceleration"]) a.instant_acceleration = g["instant_acceleration"].as<double>();
        }
        if (kv.second["residual"]) a.residual = kv.second["residual"].as<double>();
      }
    if (const YAML::Node f = n["free"]) {
      const auto read = [](const YAML::Node& e, FreeTolerance& ft) {
        if (e["position"]) ft.position = e["position"].as<double>();
        if (e["residual"]) ft.residual = e["residual"].as<double>();
      };
      if (f["horizon"]) t.free_horizon = f["horizon"].as<double>();
      if (f["default"]) read(f["default"], t.free);
      if (const YAML::Node ms = f["methods"])
        for (const auto& kv : ms) {
          FreeTolerance& ft = t.free_methods.try_emplace(kv.first.as<std::string>(), t.free).first->second;
          read(kv.second, ft);
        }
    }
  }

  std::string file_;
  YAML::Node root_;
  std::vector<std::pair<std::string, int>> scenario_names_;
};

std::mutex g_mutex;
std::vector<std::string> g_user_files;
bool g_user_set = false;
std::map<std::string, TolerancesReader> g_readers;  // parsed once per file and process

const TolerancesReader& ReaderFor(const std::string& file) {
  std::lock_guard<std::mutex> lock(g_mutex);
  auto it = g_readers.find(file);
  if (it == g_readers.end()) it = g_readers.emplace(file, TolerancesReader(file)).first;
  return it->second;
}

}  // namespace

std::string DefaultTolerancesFile() { return MECHBENCH_TOLERANCES_FILE; }

void SetUserTolerancesFiles(const std::vector<std::string>& files) {
  for (const std::string& f : files) (void)ReaderFor(f);  // bad input is refused here, before any work
  std::lock_guard<std::mutex> lock(g_mutex);
  g_user_files = files;
  g_user_set = true;
}

std::vector<std::string> EnvironmentTolerancesFiles() {
  std::vector<std::string> files;
  if (const char* env = std::getenv("MECHBENCH_TOLERANCES")) {
    std::stringstream in(env);
    std::string f;
    while (std::getline(in, f, ':'))
      if (!f.empty()) files.push_back(f);
  }
  return files;
}

std::vector<std::string> UserTolerancesFiles() {
  {
    std::lock_guard<std::mutex> lock(g_mutex);
    if (g_user_set) return g_user_files;
  }
  return EnvironmentTolerancesFiles();
}

std::string TolerancesFilesText() {
  std::string out = "harness/tolerances.yaml";
  for (const std::string& f : UserTolerancesFiles()) out += ", then " + f;
  return out;
}

std::vector<std::string> UnmatchedScenarioNames(const std::vector<std::string>& scenes) {
  std::set<std::string> known(scenes.begin(), scenes.end());
  for (const std::string& f : BuiltinScenarioFiles()) known.insert(std::filesystem::path(f).stem().string());
  std::vector<std::string> out;
  for (const std::string& f : UserTolerancesFiles())
    for (const auto& [name, line] : ReaderFor(f).ScenarioNames())
      if (!known.count(name))
        out.push_back(f + ":" + std::to_string(line) + ": scenario '" + name +
                      "' is none of the scenes given here nor a built-in one: its entry applies to nothing in this "
                      "command (fix: check the spelling; a scene's name is its file's stem)");
  return out;
}

Tolerances LoadTolerances(const std::string& scenario) {
  std::vector<const TolerancesReader*> files{&ReaderFor(DefaultTolerancesFile())};
  for (const std::string& f : UserTolerancesFiles()) files.push_back(&ReaderFor(f));
  Tolerances t;
  // Every file's defaults, then every file's entries for this scenario: a scenario's own entry
  // wins over any default, and a later file over an earlier one at the same level.
  for (const TolerancesReader* r : files) r->ApplyDefault(t);
  for (const TolerancesReader* r : files) r->ApplyScenario(scenario, t);
  return t;
}

Tolerances LoadTolerances(const Model& model) {
  Tolerances t = LoadTolerances(model.name);
  std::vector<const TolerancesReader*> files{&ReaderFor(DefaultTolerancesFile())};
  for (const std::string& f : UserTolerancesFiles()) files.push_back(&ReaderFor(f));
  for (const TolerancesReader* r : files) r->ApplyClasses(model, t);
  return t;
}

}  // namespace mechbench::harness
