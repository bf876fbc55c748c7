#include "mechbench/loader.h"
#include "mechbench/compiled_expr.h"

#include "mechbench/errors.h"
#include "mechbench/expr.h"
#include "mechbench/format.h"
#include "constant_units.h"
#include "loader_spatial.h"

#include <yaml-cpp/depthguard.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <cstdio>
#include <set>
#include <sstream>
#include <unordered_map>

namespace mechbench {
namespace {

namespace fs = std::filesystem;

// Two fixed points closer than this, relative to their distance from the origin, do not define a
// direction: rounding their coordinates (ε ≈ 2.2e-16) would turn it by more than ~2e-9 rad, past
// the tightest agreement tolerance (1e-9).
constexpr double kDirectionResolution = 1e-7;

// Mass properties the dynamics can carry in double precision (scenarios/FORMAT.md, limits):
//  - each nonzero mass and inertia within [1e-100, 1e100], so that a product of three such
//    factors (m·L²·ω², the index-1 matrix's Schur complement) stays inside double's normal range
//    (1e±308): a mass of 1e308 times gravity overflowed and was reported as "Φ_q lost rank";
//  - the largest over the smallest nonzero mass at most 1e9, and a body's inertia about its
//    first point at most 1e9 × m·L²: where the dynamics adds the smaller to the larger, rounding
//    (ε ≈ 2.2e-16) then keeps it to 2e-7 at worst, about six significant digits; beyond it the
//    smaller is gone long before it is lost altogether at 1/ε ≈ 4.5e15.
constexpr double kMassMagnitude = 1e100;
constexpr double kMassRatio = 1e9;

// A sample interval must be at least this fraction of |t|: rounding t to a double (½ ulp ≈
// 1.1e-16·|t|) then moves a sample by at most 1.1e-9 of its interval, the tightest agreement
// tolerance. Larger t0 with short intervals would compare methods on the rounding of t.
constexpr double kTimeResolution = 1e-7;

std::string Join(const std::vector<std::string>& v, const char* sep = ", ") {
  std::string s;
  for (size_t i = 0; i < v.size(); ++i) s += (i ? sep : "") + v[i];
  return s;
}

// YAML indents with spaces only; yaml-cpp reports a tab in the indentation as a broken structure
// ("illegal map value") on that line or the next without naming the tab. The 1-based line of the
// two whose indentation holds a tab, or 0.
int TabIndentedLine(const std::string& text, int mark_line) {
  std::vector<std::string> lines;
  for (size_t start = 0; start <= text.size() && static_cast<int>(lines.size()) <= mark_line;) {
    const size_t end = std::min(text.find('\n', start), text.size());
    lines.push_back(text.substr(start, end - start));
    start = end + 1;
  }
  for (const int k : {mark_line, mark_line - 1}) {
    if (k < 0 || k >= static_cast<int>(lines.size())) continue;
    const std::string& l = lines[static_cast<size_t>(k)];
    if (l.find('\t') < l.find_first_not_of(" \t")) return k + 1;
  }
  return 0;
}

// The 1-based line of the last `open` before `pos` in `text` that no `close` matches (outside
// quotes and comments), 0 if none.
int UnclosedFlowLine(const std::string& text, int pos, char open, char close) {
  std::vector<size_t> stack;
  char quote = 0;
  const size_t end = std::min(text.size(), static_cast<size_t>(std::max(pos, 0)));
  for (size_t i = 0; i < end; ++i) {
    const char c = text[i];
    if (quote) {
      if (c == quote) quote = 0;
      else if (c == '\n') quote = 0;  // a quote does not run past its line in a flow
      continue;
    }
    if (c == '"' || c == '\'') quote = c;
    else if (c == '#' && (i == 0 || text[i - 1] == ' ' || text[i - 1] == '\n'))
      while (i + 1 < end && text[i + 1] != '\n') ++i;
    else if (c == open) stack.push_back(i);
    else if (c == close && !stack.empty()) stack.pop_back();
  }
  if (stack.empty()) return 0;
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<long>(stack.back()), '\n'));
}

// Reads one file into a Model. Every accessor checks type and names the line when it fails;
// every mapping is checked for unknown and duplicate keys, so a typo never passes silently.
class Loader {
 public:
  explicit Loader(std::string file) : file_(std::move(file)) {}

  Model Load(const std::string& text) {
    try {
      return LoadChecked(text);
    } catch (const YAML::Exception& e) {
      // A shape the checks above did not foresee (e.g. a list used as a key): still bad input.
      throw ScenarioError({file_, e.mark.line + 1}, "unexpected YAML structure: " + e.msg,
                          "compare with scenarios/FORMAT.md");
    }
  }

 private:
  Model LoadChecked(const std::string& text) {
    YAML::Node root;
    try {
      root = YAML::Load(text);
    } catch (const YAML::DeepRecursion& e) {
      throw ScenarioError({file_, e.mark.line + 1}, "not valid YAML: nested deeper than the reader allows (" +
                                                        std::to_string(e.depth()) + " levels)",
                          "a scenario nests a few levels at most: check the brackets on this line");
    } catch (const YAML::Exception& e) {
      // The reader quotes the offending bytes: a NUL or another control byte (a binary file)
      // would cut the message short on a terminal, so they are shown as \xNN.
      std::string msg;
      for (const char c : e.msg) {
        const auto u = static_cast<unsigned char>(c);
        if (u < 0x20 || u == 0x7f) {
          char hex[8];
          std::snprintf(hex, sizeof hex, "\\x%02x", u);
          msg += hex;
        } else {
          msg += c;
        }
      }
      // An unclosed flow mapping or list is noticed where the next key starts, a line late: name
      // the line its `{` or `[` opened on.
      const bool map = e.msg.find("end of map flow not found") != std::string::npos;
      if (map || e.msg.find("end of sequence flow not found") != std::string::npos)
        if (const int open = UnclosedFlowLine(text, e.mark.pos, map ? '{' : '[', map ? '}' : ']'); open > 0)
          throw ScenarioError({file_, open}, std::string("not valid YAML: the ") + (map ? "{ … }" : "[ … ]") +
                                                 " opened on this line is not closed",
                              std::string("close it with ") + (map ? "`}`" : "`]`") + " on this line");
      if (const int tab = TabIndentedLine(text, e.mark.line); tab > 0)
        throw ScenarioError({file_, tab}, "not valid YAML: " + msg + ": this line is indented with a tab, and YAML indents with spaces only",
                            "replace the tab at the start of line " + std::to_string(tab) + " with spaces, as deep as its neighbours");
      throw ScenarioError({file_, e.mark.line + 1}, "not valid YAML: " + msg,
                          "check indentation, colons and brackets on this line");
    }
    if (!root.IsMap())
      throw ScenarioError({file_, 1}, "a scenario file must be a YAML mapping (key: value lines)",
                          "start from an example in scenarios/ or see scenarios/FORMAT.md");
    // The kind first, so that an unknown key's fix lists the keys of the file's own kind.
    const YAML::Node kind = Required(root, "kind", "scenario", "add `kind: linkage`, `kind: gear_train` or `kind: spatial`");
    const std::string k = Str(kind, "kind");
    if (k == "linkage") m_.kind = ScenarioKind::kLinkage;
    else if (k == "gear_train") m_.kind = ScenarioKind::kGearTrain;
    else if (k == "spatial") m_.kind = ScenarioKind::kSpatial;
    else throw ScenarioError(At(kind), "unknown kind '" + k + "'", "use linkage, gear_train or spatial");
    if (m_.kind == ScenarioKind::kSpatial)
      // The planar-only keys are accepted here to be refused with their own reason (loader_spatial.cc).
      Keys(root, "spatial scenario",
           {"section", "title", "description", "kind", "units", "points", "vectors", "bodies", "joints", "coordinates",
            "drivers", "initial", "gravity", "analysis", "constants", "book", "plane", "frame_rotation", "forces",
            "synthesis", "reference", "criteria"},
           {"section", "title", "description", "kind", "units", "points", "vectors", "bodies", "joints", "coordinates",
            "drivers", "initial", "gravity", "forces", "analysis", "constants", "book", "criteria"});
    else
      Keys(root, "scenario",
           {"section", "title", "description", "kind", "units", "points", "bodies", "joints", "coordinates", "drivers",
            "initial", "gravity", "forces", "plane", "frame_rotation", "analysis", "synthesis", "constants", "book",
            "reference", "criteria", "vectors"},
           {"section", "title", "description", "kind", "units", "points", "bodies", "joints", "coordinates", "drivers",
            "initial", "gravity", "forces", "plane", "frame_rotation", "analysis", "synthesis", "constants", "book",
            "reference", "criteria"});
    m_.source_file = file_;
    m_.name = fs::path(file_).stem().string();
    m_.section = OptStr(root, "section");
    m_.title = OptStr(root, "title");
    m_.description = OptStr(root, "description");
    if (root["vectors"] && m_.kind != ScenarioKind::kSpatial)
      throw ScenarioError(At(root["vectors"]), "vectors: belong to spatial scenes", "use kind: spatial, or remove vectors:");
    if (const YAML::Node u = root["units"]) {
      Keys(u, "units", {"length"});
      if (u["length"]) {
        m_.length_unit = Str(u["length"], "units.length");
        if (m_.length_unit != "m" && m_.length_unit != "mm" && m_.length_unit != "cm")
          throw ScenarioError(At(u["length"]), "unknown length unit '" + m_.length_unit + "'",
                              "use m, cm or mm");
      }
    }
    ReadConstants(root["constants"]);
    if (m_.kind == ScenarioKind::kSpatial) return LoadSpatial(root);  // loader_spatial.cc
    ReadPoints(root["points"]);
    ReadBodies(root["bodies"]);
    ReadJoints(root["joints"]);
    ResolvePointBodies();
    ReadCoordinates(root["coordinates"]);
    ResolveGearGeometry();
    BuildLayout();
    ReadCouplings();
    CheckSlidingMembers();
    ReadDriversAndInitial(root);
    if (const YAML::Node g = root["gravity"])
      m_.gravity = Vec2(g, "gravity", UnitField::kAcceleration, m_.length_unit + "/s²"), m_.gravity_src = At(g);
    ReadPlane(root["plane"]);
    ReadFrame(root["frame_rotation"]);
    // A turning frame's centrifugal and Coriolis forces would change a free scene's relative motion,
    // which no method's dynamics includes: refused rather than run as if the frame stood still.
    if (m_.frame && m_.drivers.empty())
      throw ScenarioError(At(root["frame_rotation"]),
                          "frame_rotation on a free scene (no drivers): the dynamics of every method is in a frame that "
                          "does not turn, so the frame's centrifugal and Coriolis forces would be left out",
                          "drive the mechanism (a kinematic scene on a turning frame), or remove frame_rotation");
    ReadAnalysis(root["analysis"]);
    ReadForces(root["forces"]);  // after the analysis: a load law is evaluated at t0
    CheckLaws();
    if (m_.analysis.HasMotion())
      for (const Driver& d : m_.drivers) {
        const double end = d.At(m_.analysis.t1, m_.analysis.t0), rate = d.RateAt(m_.analysis.t1, m_.analysis.t0);
        if (!std::isfinite(end) || !std::isfinite(rate))
          throw ScenarioError(d.src, "driver " + d.coordinate + " reaches " + Fmt(end, 3) + " (rate " + Fmt(rate, 3) +
                                         ") at t1 = " + Fmt(m_.analysis.t1, 3) + " s: beyond double range",
                              "a shorter motion (t1), or a smaller velocity or acceleration");
      }
    ReadSynthesis(root["synthesis"]);
    if (const YAML::Node c = root["constants"])
      for (const auto& kv : c) {
        const std::string name = kv.first.as<std::string>();
        if (PointIndexOf(name) >= 0 || m_.SlotIndex(name) >= 0 || BodyIndexOf(name) >= 0)
          throw ScenarioError(At(kv.first), "constant " + name + " has the name of a point, body or coordinate", "rename it");
      }
    ReadBook(root["book"]);
    ReadReference(root["reference"]);
    ReadCriteria(root["criteria"]);
    // A free scene moves under its loads by forward dynamics, which needs mass to move.
    if (m_.kind == ScenarioKind::kLinkage && m_.drivers.empty() && m_.analysis.HasMotion() && m_.HasMass()) {
      bool any = false;
      for (const Body& b : m_.bodies) any = any || (b.HasMass() && b.mass > 0);
      if (!any)
        throw ScenarioError(At(root["bodies"]), "a free scene (no drivers) whose every body has mass 0: "
                            "nothing has inertia for its loads to accelerate",
                            "give the bodies their masses, or drive a coordinate (drivers:) for kinematics");
    }
    return std::move(m_);
  }

  // kind: spatial: its own sections (loader_spatial.cc), then the common ones read as for a
  // linkage against the layout it built.
  // `drivers:` and `initial:`, a coordinate in at most one of them.
  void ReadDriversAndInitial(const YAML::Node& root) {
    ReadDrivers(root["drivers"], "driver", m_.drivers);
    ReadDrivers(root["initial"], "initial condition", m_.initial);
    for (const auto& kv : root)
      if (kv.first.IsScalar() && kv.first.as<std::string>() == "initial") m_.initial_src = At(kv.first);
    for (const Driver& d : m_.initial)
      for (const Driver& e : m_.drivers)
        if (d.coordinate == e.coordinate)
          throw ScenarioError(d.src, "coordinate " + d.coordinate + " is both driven and given an initial condition",
                              "a driver already sets it at every instant: remove one");
    // Prescribed and free coordinates in one scene are not available: a driven scene's drivers set
    // its every degree of freedom, so its `initial:` would be ignored.
    if (!m_.drivers.empty() && !m_.initial.empty())
      throw ScenarioError(m_.initial_src, "a scene has drivers (its motion prescribed: kinematics) or initial conditions "
                                          "(released from them: forward dynamics), not both, and this one has " +
                                          std::to_string(m_.drivers.size()) + " driver" + (m_.drivers.size() == 1 ? "" : "s") +
                                          " and " + std::to_string(m_.initial.size()) + " initial condition" +
                                          (m_.initial.size() == 1 ? "" : "s"),
                          "for a driven scene remove `initial:`; to hold one coordinate to a law while the rest move "
                          "freely, make the scene free (initial conditions only) and hold it by a load law of the state "
                          "(e.g. a torque keeping a rod's rate, FORMAT.md forces: laws of t, q.<slot>, qd.<slot>)");
  }

  Model LoadSpatial(const YAML::Node& root) {
    detail::ReadSpatialScene(root, file_, m_, constant_units_);
    ReadDriversAndInitial(root);
    ReadAnalysis(root["analysis"]);
    ReadForces(root["forces"]);  // torsion on angle coordinates, spring–dampers, point forces, torques
    CheckLaws();
    ReadBook(root["book"]);
    ReadCriteria(root["criteria"]);
    detail::CheckSpatialScene(root, file_, m_);
    return std::move(m_);
  }

  SourceRef At(const YAML::Node& n) const { return {file_, n.Mark().line >= 0 ? n.Mark().line + 1 : 0}; }

  void Keys(const YAML::Node& map, const std::string& what, std::initializer_list<const char*> allowed) {
    Keys(map, what, allowed, allowed);
  }
  // `shown`: the keys the fix lists (the allowed ones a file of this kind should use).
  void Keys(const YAML::Node& map, const std::string& what, std::initializer_list<const char*> allowed,
            std::initializer_list<const char*> shown) {
    if (!map.IsMap())
      throw ScenarioError(At(map), what + " must be a mapping of keys to values", "write it as {key: value, ...}");
    std::set<std::string> seen;
    std::string prev_key, prev_value;  // the entry before: an unquoted expression cut at its comma
    for (const auto& kv : map) {
      if (!kv.first.IsScalar()) throw ScenarioError(At(kv.first), "a key in " + what + " is not a plain name",
                          "write the key as a plain name (letters, digits, _), not a list or a mapping");
      const std::string key = kv.first.as<std::string>();
      if (!seen.insert(key).second)
        throw ScenarioError(At(kv.first), "duplicate key '" + key + "' in " + what, "keep only one");
      // `law: max(0.1, 0.5-0.1*t)` in {…}: YAML ends the value at the comma and reads the rest as
      // a key without a value. Say so, instead of "unknown key '0.5-0.1*t)'".
      const bool unbalanced = std::count(prev_value.begin(), prev_value.end(), '(') >
                              std::count(prev_value.begin(), prev_value.end(), ')');
      if (!prev_key.empty() && unbalanced && (!kv.second || kv.second.IsNull()) &&
          key.find_first_of("()+-*/^ ") != std::string::npos)
        throw ScenarioError(At(kv.first),
                            "the expression of '" + prev_key + "' in " + what + " holds a comma and is not quoted: YAML "
                            "ends the value at the comma ('" + prev_value + "') and reads '" + key + "' as another key",
                            "quote the whole expression: " + prev_key + ": \"" + prev_value + ", " + key + "\"");
      prev_key = key;
      prev_value = kv.second && kv.second.IsScalar() ? kv.second.as<std::string>() : std::string();
      if (std::find_if(allowed.begin(), allowed.end(), [&](const char* a) { return key == a; }) == allowed.end()) {
        std::vector<std::string> known(shown.begin(), shown.end());
        throw ScenarioError(At(kv.first), "unknown key '" + key + "' in " + what,
                            "known keys are: " + Join(known));
      }
    }
  }
  YAML::Node Required(const YAML::Node& map, const char* key, const std::string& what, const std::string& fix) {
    const YAML::Node n = map[key];
    if (!n) throw ScenarioError(At(map), what + " needs '" + key + "'", fix);
    return n;
  }
  std::string Str(const YAML::Node& n, const std::string& what) {
    if (!n.IsScalar()) throw ScenarioError(At(n), what + " must be a single value",
                          "write one value here, not a list or a mapping");
    return n.as<std::string>();
  }
  std::string OptStr(const YAML::Node& map, const char* key) {
    return map[key] ? Str(map[key], key) : std::string();
  }
  // Named numbers, read first and in file order, so that every later number (and each constant
  // after it) may use them: a published definition's parameters (rr, d, xb, …) then its positions.
  void ReadConstants(const YAML::Node& c) {
    if (!c) return;
    if (!c.IsMap()) throw ScenarioError(At(c), "constants must map names to numbers", "write {L_B1: 0.15, ...}");
    for (const auto& kv : c) {
      const std::string name = Str(kv.first, "constant name");
      const bool plain = !name.empty() && (std::isalpha(static_cast<unsigned char>(name[0])) || name[0] == '_') &&
                         std::all_of(name.begin(), name.end(), [](char ch) {
                           return std::isalnum(static_cast<unsigned char>(ch)) || ch == '_';
                         });
      if (!plain)
        throw ScenarioError(At(kv.first), "constant name '" + name + "' is not a plain name",
                            "use letters, digits and '_', starting with a letter (e.g. x_B)");
      static const std::set<std::string> kWords{"pi", "deg", "rpm", "rad", "s", "m"};
      if (kWords.count(name))
        throw ScenarioError(At(kv.first), "constant " + name + " would hide the unit word or constant of the same name",
                            "rename it");
      if (m_.constants.count(name)) throw ScenarioError(At(kv.first), "constant " + name + " given twice", "keep one");
      std::vector<std::string> carried;
      m_.constants[name] = Num(kv.second, "constant " + name, UnitField::kAny, "", &carried);
      if (carried.empty()) continue;
      std::string text = kv.second.as<std::string>();
      std::vector<std::string> names;
      (void)TopLevelUnitWords(text, &names);
      std::vector<std::string> via;  // the constants it takes words from, once each
      for (const std::string& n : names)
        if (const auto it = constant_units_.find(n);
            it != constant_units_.end() && std::find(via.begin(), via.end(), n) == via.end()) {
          via.push_back(n);
          text += ", " + n + " being " + it->second.text;
        }
      constant_units_[name] = {carried, At(kv.second).line, text};
    }
  }
  // A number or an expression of the constants. `field` says which unit words the value may carry
  // (outside function arguments: `L*cos(30 deg)` is a length); `unit` names its unit for the
  // message when one does not fit ("mass: 2 deg" would silently be 0.035 kg). A constant named
  // outside function arguments brings its own unit words (constant_units.h). `carried`, when given,
  // receives the unit words the value carries, its own and its constants'.
  double Num(const YAML::Node& n, const std::string& what, UnitField field = UnitField::kAny,
             const std::string& unit = "", std::vector<std::string>* carried = nullptr) {
    if (!n.IsScalar()) throw ScenarioError(At(n), what + " must be a number or an expression such as 35 deg",
                          "write one number or expression on this line, not a list or a mapping");
    std::vector<std::string> units, names;
    double v = 0;
    try {
      v = EvalExpr(n.as<std::string>(), [this](const std::string& name) -> std::optional<double> {
        if (auto it = m_.constants.find(name); it != m_.constants.end()) return it->second;
        return std::nullopt;
      }, &units, &names);
      if (!std::isfinite(v)) throw ExprError("the value is not finite");
    } catch (const ExprError& e) {
      throw ScenarioError(At(n), what + ": " + e.what(),
                          e.fix.empty() ? "write a number or an expression such as 15*sin(35 deg)" : e.fix);
    }
    CheckUnitWords(n, what, units, names, field, unit);
    if (carried) {
      *carried = units;
      for (const std::string& w : detail::ConstantsWords(constant_units_, names))
        if (std::find(carried->begin(), carried->end(), w) == carried->end()) carried->push_back(w);
    }
    return v;
  }
  // A law's unit words (outside function arguments) against its field, as a number's: "0.1*sin(2*pi*t)
  // deg" on a slider's coordinate would silently be 0.0017 of the length unit.
  void CheckLawUnitWords(const YAML::Node& n, const std::string& what, UnitField field, const std::string& unit) {
    if (field == UnitField::kAny) return;
    std::vector<std::string> names;
    const std::vector<std::string> units = TopLevelUnitWords(n.as<std::string>(), &names);
    CheckUnitWords(n, what, units, names, field, unit);
  }
  // Which unit words a driver's or an initial condition's value, rates and law may carry: an angle
  // rad, deg, rpm and s ("30 deg", "2 rpm", "0.5 rad/s"); a length m and s ("0.2 m", "1 m/s"); a unit
  // vector's component s (its rate in 1/s).
  std::pair<UnitField, std::string> SlotUnits(const std::string& coordinate) const {
    const int slot = m_.SlotIndex(coordinate);
    if (slot < 0) return {UnitField::kAny, ""};
    const Model::Slot& sl = m_.q_layout[slot];
    bool angle = false, vector = false;
    if (sl.coordinate >= 0)
      angle = m_.coordinates[sl.coordinate].type == CoordinateType::kAngle ||
              m_.coordinates[sl.coordinate].type == CoordinateType::kRotation;
    else if (sl.spatial_coordinate >= 0)
      angle = m_.spatial.coordinates[sl.spatial_coordinate].IsAngle();
    else if (sl.entity >= 0)
      vector = m_.spatial.entities[sl.entity].vector;
    if (angle) return {UnitField::kAngularRate, "rad (an angle; rad/s for its rate)"};
    if (vector) return {UnitField::kTime, "a unit vector's component (1/s for its rate)"};
    return {UnitField::kAcceleration, m_.length_unit + " (a length; " + m_.length_unit + "/s for its rate)"};
  }
  // The unit words of a value or a law against its field (UnitWordsProblem), then those of the
  // constants it names (`names`: its variables outside function arguments).
  void CheckUnitWords(const YAML::Node& n, const std::string& what, const std::vector<std::string>& units,
                      const std::vector<std::string>& names, UnitField field, const std::string& unit) {
    std::string fix;
    if (const std::string problem = detail::FieldUnitWordsProblem(constant_units_, units, names, field, m_.length_unit,
                                                                  n.as<std::string>(), unit, fix);
        !problem.empty())
      throw ScenarioError(At(n), what + " " + problem, fix);
  }
  bool Bool(const YAML::Node& n, const std::string& what) {
    const std::string s = Str(n, what);
    if (s == "true" || s == "yes") return true;
    if (s == "false" || s == "no") return false;
    throw ScenarioError(At(n), what + " must be true or false",
                          "write true or false");
  }
  // A count: a whole number (an expression allowed), never a list or a fraction. `meaning` says
  // what the count is and `fix` a working value, for every way it can be wrong.
  int Int(const YAML::Node& n, const std::string& what, const std::string& meaning, const std::string& fix) {
    const std::string head = what + " must be a whole number (" + meaning + ")";
    if (!n.IsScalar())
      throw ScenarioError(At(n), head + ", not " + (n.IsSequence() ? "a list" : n.IsMap() ? "a mapping" : "empty"), fix);
    double v = 0;
    try {
      v = Num(n, what);
    } catch (const ScenarioError& e) {
      throw ScenarioError(e.where(), head + "; " + e.problem(), fix);
    }
    if (std::fabs(v) > 1e9)
      throw ScenarioError(At(n), what + " is " + Fmt(v, 3) + ", beyond the limit of 1e9 a count is read to", fix);
    if (v != std::floor(v)) throw ScenarioError(At(n), head + ", not " + Fmt(v, 6), fix);
    return static_cast<int>(v);
  }
  std::vector<YAML::Node> Seq(const YAML::Node& n, const std::string& what, size_t size) {
    if (!n.IsSequence() || (size && n.size() != size))
      throw ScenarioError(At(n), what + " must be a list" + (size ? " of " + std::to_string(size) + " items" : ""),
                          size ? "write it as [a, b" + std::string(size == 3 ? ", c" : "") + "]" : "write it as [a, b, ...]");
    return {n.begin(), n.end()};
  }
  Eigen::Vector2d Vec2(const YAML::Node& n, const std::string& what, UnitField field = UnitField::kAny,
                       const std::string& unit = "") {
    const auto s = Seq(n, what, 2);
    return {Num(s[0], what + "[0]", field, unit), Num(s[1], what + "[1]", field, unit)};
  }
  Eigen::Vector3d Vec3(const YAML::Node& n, const std::string& what, UnitField field = UnitField::kAny,
                       const std::string& unit = "") {
    const auto s = Seq(n, what, 3);
    return {Num(s[0], what + "[0]", field, unit), Num(s[1], what + "[1]", field, unit), Num(s[2], what + "[2]", field, unit)};
  }
  // Points and bodies by name through maps kept beside m_ (Model::PointIndex scans: O(N²) over a
  // long chain's references).
  int PointIndexOf(const std::string& name) const {
    const auto it = point_index_.find(name);
    return it == point_index_.end() ? -1 : it->second;
  }
  int BodyIndexOf(const std::string& name) const {
    const auto it = body_index_.find(name);
    return it == body_index_.end() ? -1 : it->second;
  }
  int PointRef(const YAML::Node& n, const std::string& what) {
    const std::string name = Str(n, what);
    const int i = PointIndexOf(name);
    if (i < 0) {
      // A gear train has no points to declare (its members are bodies without points): say what
      // needs points and what the gear train takes, not "declare it under points:".
      if (m_.kind == ScenarioKind::kGearTrain)
        throw ScenarioError(At(n), what + " names point '" + name + "', but a gear train has no points",
                            "a force element between points (a spring–damper, a point force, a torque, which needs a "
                            "body's two points) needs a linkage: write it as kind: linkage, the gears as links turning "
                            "about fixed points and each mesh as a coupling of their angles under joints: "
                            "(scenarios/FORMAT.md, Couplings); a gear train takes drivers on its members' rotations only");
      std::vector<std::string> names;
      for (const Point& p : m_.points) names.push_back(p.name);
      throw ScenarioError(At(n), what + " names unknown point '" + name + "'",
                          names.empty() ? "declare it under points:" : "declared points are: " + Join(names));
    }
    return i;
  }
  int BodyRef(const YAML::Node& n, const std::string& what) {
    const std::string name = Str(n, what);
    const int i = BodyIndexOf(name);
    if (i < 0) {
      std::vector<std::string> names;
      for (const Body& b : m_.bodies) names.push_back(b.name);
      throw ScenarioError(At(n), what + " names unknown body '" + name + "'",
                          names.empty() ? "declare it under bodies:" : "declared bodies are: " + Join(names));
    }
    return i;
  }
  std::array<int, 2> PointPair(const YAML::Node& n, const std::string& what) {
    const auto s = Seq(n, what, 2);
    std::array<int, 2> r{PointRef(s[0], what), PointRef(s[1], what)};
    if (r[0] == r[1])
      throw ScenarioError(At(n), what + " needs two different points; both are " + m_.points[r[0]].name,
                          "name the two points it joins, e.g. [A, B] for two points of the file");
    return r;
  }
  static std::string XY(const Eigen::Vector2d& p) { return "(" + Fmt(p.x()) + ", " + Fmt(p.y()) + ")"; }
  // A direction from two fixed points (a guide, an angle's reference): they must be apart by more
  // than the rounding of their coordinates, else the direction is the rounding's (a guide through
  // one point used to pass as horizontal and then fail as "not on its guide").
  void RequireDirection(const std::array<int, 2>& pq, const YAML::Node& n, const std::string& what) {
    const Point &a = m_.points[pq[0]], &b = m_.points[pq[1]];
    const double apart = (b.p_W - a.p_W).norm();
    const double scale = std::max(a.p_W.norm(), b.p_W.norm());
    if (apart > kDirectionResolution * scale) return;
    throw ScenarioError(At(n), what + " runs through " + a.name + " and " + b.name + ", which " +
                                   (apart == 0 ? "coincide at " + XY(a.p_W)
                                               : "are only " + Fmt(apart, 3) + " apart at " + XY(a.p_W) +
                                                     ", within the rounding of their coordinates") +
                                   ": two points at one place give it no direction",
                        "give " + b.name + " another place on the intended line, e.g. " + b.name + ": {fixed: [" + Fmt(a.p_W.x()) +
                            ", " + Fmt(a.p_W.y() + std::max(1.0, scale)) + "]} for a vertical one, or name two distinct "
                            "fixed points");
  }

  void ReadPoints(const YAML::Node& pts) {
    if (!pts) {
      if (m_.kind == ScenarioKind::kLinkage)
        throw ScenarioError({file_, 1}, "a linkage needs points:", "declare its fixed and moving points");
      return;
    }
    if (m_.kind == ScenarioKind::kGearTrain)
      throw ScenarioError(At(pts), "a gear train has no points",
                          "remove points: (members are bodies without points); for a spring or force between points, "
                          "write the mechanism as kind: linkage, its meshes as couplings under joints: "
                          "(scenarios/FORMAT.md, Couplings)");
    if (!pts.IsMap()) throw ScenarioError(At(pts), "points must be a mapping name: {fixed: [x, y]} or {at: [x, y]}",
                          "write each point on its own line under points:, e.g. O: {fixed: [0, 0]}");
    for (const auto& kv : pts) {
      Point p;
      p.name = kv.first.as<std::string>();
      p.src = At(kv.first);
      if (PointIndexOf(p.name) >= 0) throw ScenarioError(p.src, "point '" + p.name + "' declared twice",
                          "rename one of the two, or remove the copy (a name is declared once under points:)");
      Keys(kv.second, "point " + p.name, {"fixed", "at"});
      if (kv.second["fixed"] && kv.second["at"])
        throw ScenarioError(p.src, "point " + p.name + " is both fixed and moving", "keep fixed: or at:");
      if (kv.second["fixed"]) {
        p.fixed = true;
        p.p_W = Vec2(kv.second["fixed"], "point " + p.name + " fixed", UnitField::kLength, m_.length_unit);
      } else if (kv.second["at"]) {
        p.p_W = Vec2(kv.second["at"], "point " + p.name + " at", UnitField::kLength, m_.length_unit);
      } else {
        throw ScenarioError(p.src, "point " + p.name + " needs fixed: [x, y] or at: [x, y]",
                          "give fixed: [x, y] for a ground point or at: [x, y] for a moving one");
      }
      point_index_.emplace(p.name, static_cast<int>(m_.points.size()));
      m_.points.push_back(p);
    }
  }

  void ReadBodies(const YAML::Node& bodies) {
    if (!bodies) throw ScenarioError({file_, 1}, "a scenario needs bodies:", "declare the links or gear members");
    if (!bodies.IsMap()) throw ScenarioError(At(bodies), "bodies must be a mapping name: {points: [...]}",
                          "write each body on its own line under bodies:, e.g. crank: {points: [O, A]}");
    for (const auto& kv : bodies) {
      Body b;
      b.name = kv.first.as<std::string>();
      b.src = At(kv.first);
      if (BodyIndexOf(b.name) >= 0) throw ScenarioError(b.src, "body '" + b.name + "' declared twice",
                          "rename one of the two, or remove the copy");
      const std::string what = "body " + b.name;
      const YAML::Node n = kv.second;
      if (n.IsNull() || (n.IsMap() && n.size() == 0)) {
        if (m_.kind == ScenarioKind::kLinkage)
          throw ScenarioError(b.src, what + " has no points", "give it points: [P, Q]");
        body_index_.emplace(b.name, static_cast<int>(m_.bodies.size()));
        m_.bodies.push_back(b);
        continue;
      }
      Keys(n, what, {"points", "length", "shape", "mass", "com", "inertia", "centre", "arm", "planets", "slides", "at"});
      ReadMemberGeometry(n, b, what);
      ReadSlidingMember(n, b, what);
      if (n["points"]) {
        if (m_.kind == ScenarioKind::kGearTrain)
          throw ScenarioError(At(n["points"]), "gear-train members have no points", "remove points:");
        for (const YAML::Node& p : Seq(n["points"], what + " points", 0)) b.points.push_back(PointRef(p, what));
        if (b.points.empty()) throw ScenarioError(At(n["points"]), what + " needs at least one point",
                          "list its points: [P, Q, ...]");
        std::set<int> uniq(b.points.begin(), b.points.end());
        if (uniq.size() != b.points.size()) throw ScenarioError(At(n["points"]), what + " lists a point twice",
                          "list each point once");
      } else if (m_.kind == ScenarioKind::kLinkage) {
        throw ScenarioError(b.src, what + " needs points: [P, Q, ...]",
                          "give points: [P, Q, ...] (its first two points set its frame)");
      }
      ReadShape(n, b, what);
      if (b.IsPointBody() && n["mass"]) {
        ReadPointBodyMass(n, b, what);
      } else if (n["mass"] || n["com"] || n["inertia"]) {
        if (!n["mass"] || !n["com"] || !n["inertia"])
          throw ScenarioError(b.src, what + " gives only part of its mass properties",
                              "give mass, com and inertia together (or none for kinematics only)");
        b.mass = Num(n["mass"], what + " mass", UnitField::kPlain, "kg");
        mass_at_[b.name] = At(n["mass"]);
        b.com_B = Vec2(n["com"], what + " com", UnitField::kLength, m_.length_unit);
        b.inertia_com = Num(n["inertia"], what + " inertia", UnitField::kPlain, "kg·" + m_.length_unit + "²");
        if (b.mass < 0 || b.inertia_com < 0)
          throw ScenarioError(At(n["mass"]), what + " has a negative mass or inertia",
                          "give a mass and an inertia of 0 or more (0 for a massless body)");
        if (b.mass == 0 && b.inertia_com != 0)
          throw ScenarioError(At(n["inertia"]), what + " has inertia " + Fmt(b.inertia_com) + " but no mass",
                              "a body's inertia about its centre of mass is 0 when its mass is: give its mass, or "
                              "inertia: 0 for a massless link");
        CheckMassMagnitudes(b, n, what);
      }
      body_index_.emplace(b.name, static_cast<int>(m_.bodies.size()));
      m_.bodies.push_back(b);
    }
    CheckMassRatio();
  }

  // A point body's mass: `mass` alone is enough (centre of mass at the point, no inertia); com
  // and inertia, in the frame its guide gives it, are checked against its guide in
  // ResolvePointBodies once the joints are known.
  void ReadPointBodyMass(const YAML::Node& n, Body& b, const std::string& what) {
    b.mass = Num(n["mass"], what + " mass", UnitField::kPlain, "kg");
    mass_at_[b.name] = At(n["mass"]);
    b.com_B = n["com"] ? Vec2(n["com"], what + " com", UnitField::kLength, m_.length_unit) : Eigen::Vector2d(0, 0);
    b.inertia_com = n["inertia"] ? Num(n["inertia"], what + " inertia", UnitField::kPlain, "kg·" + m_.length_unit + "²") : 0.0;
    if (b.mass < 0 || b.inertia_com < 0)
      throw ScenarioError(At(n["mass"]), what + " has a negative mass or inertia",
                          "give a mass and an inertia of 0 or more (0 for a massless body)");
    if (b.mass == 0 && (b.inertia_com != 0 || b.com_B.squaredNorm() != 0))
      throw ScenarioError(At(n["mass"]), what + " has a com or inertia but no mass",
                          "give its mass, or leave com and inertia out for a massless point");
    CheckMassMagnitudes(b, n, what);
  }

  // Each point body's guide: the slider joint whose sliding point is its point. A com off the
  // point or an inertia needs a direction, so a point body with either needs exactly one guide.
  void ResolvePointBodies() {
    for (Body& b : m_.bodies) {
      if (!b.IsPointBody()) continue;
      std::vector<int> guides;
      for (size_t j = 0; j < m_.joints.size(); ++j)
        if (m_.joints[j].type != JointType::kGear && m_.joints[j].point == b.points[0])
          guides.push_back(static_cast<int>(j));
      // On several guides (a point that slides on a rocker and on a fixed line) a point mass
      // takes the first: it does not turn, so which frame it has does not matter.
      if (!guides.empty()) b.guide = guides[0];
      const bool oriented = b.HasMass() && (b.com_B.squaredNorm() != 0 || b.inertia_com != 0);
      if (!oriented) continue;
      const std::string P = m_.points[b.points[0]].name;
      if (guides.empty())
        throw ScenarioError(b.src, "body " + b.name + " has one point (" + P + ") and no guide, so no orientation: "
                                       "its com must be its point and its inertia 0",
                            "leave out com and inertia (a point mass), make " + P +
                                " the sliding point of a slider joint (a block on a guide), or give the body a second point");
      if (guides.size() > 1)
        throw ScenarioError(b.src, "body " + b.name + ": point " + P + " slides on " + std::to_string(guides.size()) +
                                       " guides, so its block's direction is ambiguous",
                            "leave out com and inertia, or give the body a second point");
      // kMassRatio within the block on a moving guide: its inertia about the point against
      // m·L² of the guide body, the scale of the mass-matrix entries where the two are added.
      const Joint& j = m_.joints[b.guide];
      if (j.type != JointType::kPointOnBody) continue;
      const double length = m_.bodies[j.body].Length();
      const double about_point = b.inertia_com + b.mass * b.com_B.squaredNorm();
      if (about_point > kMassRatio * b.mass * length * length)
        throw ScenarioError(b.src, "body " + b.name + " has an inertia about its point " + P + " of " +
                                       Fmt(about_point / (b.mass * length * length), 3) + " × m·L² of its guide " +
                                       m_.bodies[j.body].name + ": beyond 1e9 the mass matrix keeps m to fewer than "
                                       "six significant digits",
                            "check the inertia's units (kg·" + m_.length_unit + "²) and exponent, and the com's");
    }
  }

  // kMassMagnitude: each nonzero mass, inertia, and inertia about the body's first point
  // (I + m|com|², what the natural-coordinate mass matrix holds), within 1e±100.
  void CheckMassMagnitudes(const Body& b, const YAML::Node& n, const std::string& what) {
    const std::string L = m_.length_unit;
    const auto refuse = [&](const YAML::Node& at, const std::string& quantity, double v, const std::string& unit) {
      throw ScenarioError(At(at), what + ": its " + quantity + " of " + Fmt(v, 3) + " " + unit +
                                      " is beyond what the dynamics can multiply in double precision (a nonzero mass or "
                                      "inertia must lie within 1e-100 … 1e100)",
                          "check its units and exponent; a body without mass is mass: 0, com: [0, 0], inertia: 0");
    };
    const auto out = [](double v) { return v != 0 && !(v >= 1 / kMassMagnitude && v <= kMassMagnitude); };
    if (out(b.mass)) refuse(n["mass"], "mass", b.mass, "kg");
    if (out(b.inertia_com)) refuse(n["inertia"], "inertia", b.inertia_com, "kg·" + L + "²");
    if (b.p_B.empty()) return;  // a gear-train member turns about its centre of mass
    const double about_origin = b.inertia_com + b.mass * b.com_B.squaredNorm();
    const std::string origin = m_.points[b.points[0]].name;
    if (!(about_origin <= kMassMagnitude))
      refuse(n["com"], "inertia about its point " + origin + " (I + m|com|²)", about_origin, "kg·" + L + "²");
    // kMassRatio within the body: its mass against its inertia about its first point over
    // L², the scale of the mass-matrix entries where the two are added (a point body: against
    // its guide's length, in ResolvePointBodies).
    if (b.IsPointBody()) return;
    const double length = b.p_B[1].norm();
    if (b.mass > 0 && about_origin > kMassRatio * b.mass * length * length)
      throw ScenarioError(At(n["inertia"]), what + " has an inertia about its point " + origin + " (" +
                                                Fmt(about_origin, 3) + " kg·" + L + "²) of " +
                                                Fmt(about_origin / (b.mass * length * length), 3) + " × m·L² (m = " +
                                                Fmt(b.mass, 3) + " kg, L = " + Fmt(length, 3) + " " + L +
                                                "): beyond 1e9 × m·L² the mass matrix, whose entries add m to I/L², "
                                                "keeps m to fewer than six significant digits",
                          "check the inertia's units (kg·" + L + "²) and exponent, and the com's");
  }

  // kMassRatio across the scene: the heaviest body over the lightest with mass.
  void CheckMassRatio() {
    const Body* light = nullptr;
    const Body* heavy = nullptr;
    for (const Body& b : m_.bodies) {
      if (!(b.mass > 0)) continue;
      if (!light || b.mass < light->mass) light = &b;
      if (!heavy || b.mass > heavy->mass) heavy = &b;
    }
    if (!light || heavy->mass <= kMassRatio * light->mass) return;
    throw ScenarioError(mass_at_.at(light->name), "body " + light->name + " has a mass of " +
                            Fmt(light->mass, 3) + " kg, " + Fmt(heavy->mass / light->mass, 3) + " times lighter than body " +
                            heavy->name + " (" + Fmt(heavy->mass, 3) + " kg): beyond a ratio of 1e9, rounding in the dynamics' sums, "
                            "which are of the heavier's size, leaves the lighter mass fewer than six significant digits",
                        "check both masses' units and exponents; a body whose mass does not matter is mass: 0, "
                        "com: [0, 0], inertia: 0");
  }

  // Body-frame coordinates of each point: from length/shape, else from the file's positions.
  void ReadShape(const YAML::Node& n, Body& b, const std::string& what) {
    if (b.points.empty()) return;
    const auto& P = m_.points;
    if (b.IsPointBody()) {
      for (const char* key : {"length", "shape"})
        if (n[key])
          throw ScenarioError(At(n[key]), what + " has one point, so it has no " + key,
                              "leave out " + std::string(key) + " (a point body), or give the body a second point");
      b.p_B = {Eigen::Vector2d::Zero()};
      return;
    }
    if (n["length"] && n["shape"]) throw ScenarioError(At(n["length"]), what + " gives both length and shape", "keep one");
    if (n["length"]) {
      if (b.points.size() != 2)
        throw ScenarioError(At(n["length"]), what + " has more than two points, so length is not enough",
                            "give shape: {point: [x, y], ...} in the body frame");
      const double L = Num(n["length"], what + " length", UnitField::kLength, m_.length_unit);
      if (!(L > 0)) throw ScenarioError(At(n["length"]), what + " length must be positive",
                          "give the distance between its first two points (length: L > 0), or leave length: out to take it from the drawing");
      b.p_B = {Eigen::Vector2d::Zero(), Eigen::Vector2d(L, 0)};
      return;
    }
    if (n["shape"]) {
      const YAML::Node s = n["shape"];
      if (!s.IsMap()) throw ScenarioError(At(s), what + " shape must map point names to [x, y]",
                          "write shape: {B: [L, 0], C: [x, y]} (each point but the first, in the body frame)");
      b.p_B.assign(b.points.size(), Eigen::Vector2d(kNaN, kNaN));
      b.p_B[0].setZero();
      for (const auto& kv : s) {
        const int pi = PointRef(kv.first, what + " shape");
        const auto it = std::find(b.points.begin(), b.points.end(), pi);
        if (it == b.points.end()) throw ScenarioError(At(kv.first), what + " shape names a point not in the body",
                          "name points of the body's points: list, or add the point there");
        if (it == b.points.begin()) throw ScenarioError(At(kv.first), what + " shape: the first point is the origin", "leave it out");
        b.p_B[it - b.points.begin()] = Vec2(kv.second, what + " shape");
      }
      for (size_t i = 1; i < b.points.size(); ++i)
        if (!b.p_B[i].allFinite())
          throw ScenarioError(At(s), what + " shape misses point " + P[b.points[i]].name,
                          "give " + P[b.points[i]].name + ": [x, y] in shape: (every point but the first)");
      if (!(b.p_B[1].x() > 0) || b.p_B[1].y() != 0)
        throw ScenarioError(At(s), what + " shape: the second point must lie on the body's +x axis", "write it as [L, 0]");
      return;
    }
    // From the positions in the file, which must then be the assembled configuration.
    const Eigen::Vector2d o = P[b.points[0]].p_W;
    const Eigen::Vector2d ex_raw = P[b.points[1]].p_W - o;
    const double L = ex_raw.norm();
    if (!(L > 0)) throw ScenarioError(b.src, what + ": its first two points coincide", "move one, or give length:");
    const Eigen::Vector2d ex = ex_raw / L, ey(-ex.y(), ex.x());
    for (int pi : b.points) {
      const Eigen::Vector2d d = P[pi].p_W - o;
      b.p_B.emplace_back(d.dot(ex), d.dot(ey));
    }
  }

  // ---- gear geometry (optional): centres, arms, planets, module or radii ----------------------

  // A gear-train member's `centre:` (its fixed axis), a carrier's `arm:` and `planets:`.
  void ReadMemberGeometry(const YAML::Node& n, Body& b, const std::string& what) {
    for (const char* key : {"centre", "arm", "planets"})
      if (n[key] && m_.kind != ScenarioKind::kGearTrain)
        throw ScenarioError(At(n[key]), what + ": " + key + " belongs to gear-train members",
                            "a linkage body is placed by its points: remove " + std::string(key) + ":");
    if (n["centre"]) {
      b.centre = Vec2(n["centre"], what + " centre");
      geometry_at_["centre " + b.name] = At(n["centre"]);
    }
    if (n["arm"]) {
      b.arm = Num(n["arm"], what + " arm", UnitField::kLength, m_.length_unit);
      geometry_at_["arm " + b.name] = At(n["arm"]);
      if (!(b.arm > 0))
        throw ScenarioError(At(n["arm"]), what + " arm must be positive",
                            "the distance from the carrier's axis to its planets' axes, in " + m_.length_unit);
    }
    if (n["planets"]) {
      b.planets = Int(n["planets"], what + " planets", "the number of planets on this carrier", "planets: 3");
      geometry_at_["planets " + b.name] = At(n["planets"]);
      if (b.planets < 1)
        throw ScenarioError(At(n["planets"]), what + " planets must be at least 1", "the number of planets on this carrier");
    }
    geometry_ = geometry_ || n["centre"] || n["arm"] || n["planets"];
    if (n["at"]) geometry_at_["at " + b.name] = At(n["at"]);
  }

  // A gear train's sliding member (a rack, model.h Body::slides): `slides: [dx, dy]`, its direction
  // of travel on the frame, and optionally `at: [x, y]`, a point of its pitch line at travel 0.
  void ReadSlidingMember(const YAML::Node& n, Body& b, const std::string& what) {
    for (const char* key : {"slides", "at"})
      if (n[key] && m_.kind != ScenarioKind::kGearTrain)
        throw ScenarioError(At(n[key]), what + ": " + key + " belongs to a gear train's sliding member (a rack)",
                            "a linkage's rack is a body whose two points slide on one fixed guide (slider joints): remove " +
                                std::string(key) + ":");
    if (n["at"] && !n["slides"])
      throw ScenarioError(At(n["at"]), what + ": at: places a sliding member's pitch line, and " + b.name + " does not slide",
                          "give its direction of travel too: slides: [dx, dy]");
    if (!n["slides"]) return;
    for (const char* key : {"centre", "arm", "planets"})
      if (n[key])
        throw ScenarioError(At(n[key]), what + " slides (a rack), so it has no " + key,
                            "remove " + std::string(key) + ": (at: [x, y] places its pitch line)");
    const Eigen::Vector2d d = Vec2(n["slides"], what + " slides");
    if (!d.allFinite() || !(d.norm() > 0))
      throw ScenarioError(At(n["slides"]), what + " slides along a zero direction",
                          "give its direction of travel on the frame, e.g. slides: [1, 0]");
    b.slides = d.normalized();
    if (n["at"]) b.pitch_point = Vec2(n["at"], what + " at");
  }

  // A gear train's sliding members: each has a travel coordinate that a rack joint couples to a
  // turning member's rotation (the rack slides on the frame: the absolute rotation). With the
  // rack's `at:` and its pinion's `centre:`, the pitch line must be at the pitch radius from the
  // centre, on the side the joint's sense says (a counter-clockwise turn moves the rack by +r Δφ,
  // or −r Δφ with reverse: true); a pinion whose axis rides on a carrier is refused there.
  void CheckSlidingMembers() {
    if (m_.kind != ScenarioKind::kGearTrain) return;
    for (size_t b = 0; b < m_.bodies.size(); ++b) {
      const Body& rack = m_.bodies[b];
      if (!rack.IsSliding()) continue;
      const auto it = std::find_if(m_.coordinates.begin(), m_.coordinates.end(), [&](const Coordinate& c) {
        return c.type == CoordinateType::kTravel && c.body == static_cast<int>(b);
      });
      if (it == m_.coordinates.end())
        throw ScenarioError(rack.src, "sliding member " + rack.name + " has no travel coordinate",
                            "add coordinates: {x_" + rack.name + ": {type: travel, member: " + rack.name + "}}");
      const int slot = m_.SlotIndex(it->name);
      const Coupling* mesh = nullptr;
      for (const Coupling& c : m_.couplings)
        if (c.rack && c.slots[1] == slot) mesh = &c;
      if (!mesh)
        throw ScenarioError(rack.src, "sliding member " + rack.name + " meshes with nothing: no rack joint moves its travel " + it->name,
                            "add under joints: {type: rack, pinion: <a member's rotation>, rack: " + it->name + ", radius: r}");
      const int pinion = m_.coordinates[m_.q_layout[mesh->slots[0]].coordinate].body;
      if (pinion < 0 || static_cast<size_t>(pinion) >= m_.gear_axes.size() || !m_.gear_axes[pinion].Known()) continue;
      const GearAxis& axis = m_.gear_axes[pinion];
      const std::string& pn = m_.bodies[pinion].name;
      if (axis.carrier >= 0)
        throw ScenarioError(mesh->src, mesh->name + ": member " + pn + "'s axis rides on carrier " + m_.bodies[axis.carrier].name +
                                           ", and a rack slides on the frame: its pitch line cannot stay tangent to an orbiting wheel",
                            "mesh the rack with a member on a fixed axis");
      if (!rack.pitch_point.allFinite()) continue;
      const Eigen::Vector2d c = axis.centre, d = rack.slides;
      const Eigen::Vector2d off = rack.pitch_point + d * (c - rack.pitch_point).dot(d) - c;  // centre → pitch line
      const double dist = off.norm(), r = std::fabs(mesh->ratio);
      if (std::fabs(dist - r) > 1e-9 * std::max(r, dist)) {
        const Eigen::Vector2d n = dist > 0 ? Eigen::Vector2d(off / dist) : Eigen::Vector2d(-d.y(), d.x());
        const Eigen::Vector2d fit = c + r * n;
        throw ScenarioError(GeometryAt("at " + rack.name, rack.src),
                            "the pitch line of " + rack.name + " is " + Fmt(dist, 9) + " " + m_.length_unit + " from " + pn +
                                "'s centre " + XY(c) + ", not its pitch radius " + Fmt(r, 9) + " (" + mesh->name + ")",
                            "put it at the pitch radius, e.g. at: [" + Fmt(fit.x(), 9) + ", " + Fmt(fit.y(), 9) + "]");
      }
      const double sense = (Eigen::Vector2d(-off.y(), off.x())).dot(d) > 0 ? 1.0 : -1.0;  // ω k × off along d
      if (sense * mesh->ratio < 0)
        throw ScenarioError(mesh->src, mesh->name + ": on the side of " + pn + " where " + rack.name +
                                           " is drawn, a counter-clockwise turn moves it by " + (sense > 0 ? "+" : "−") +
                                           "r Δφ along " + XY(d) + ", the opposite of the joint's sense",
                            sense > 0 ? "remove reverse: true" : "add reverse: true");
    }
  }

  // A mesh's `module:` (pitch radii m Z / 2) or `radii: [r_a, r_b]` (in the ratio of the teeth).
  void ReadMeshGeometry(const YAML::Node& n, Joint& j) {
    if (n["module"] && n["radii"])
      throw ScenarioError(At(n["module"]), j.name + " gives both module and radii",
                          "keep one: module: m (pitch radius m Z / 2), or radii: [r_a, r_b]");
    const double za = j.teeth[0], zb = j.teeth[1];
    if (n["module"]) {
      const double module = Num(n["module"], j.name + " module", UnitField::kLength, m_.length_unit);
      if (!(module > 0)) throw ScenarioError(At(n["module"]), j.name + " module must be positive", "module: m in " + m_.length_unit);
      j.radii = {module * za / 2, module * zb / 2};
      geometry_at_["mesh " + std::to_string(m_.joints.size())] = At(n["module"]);
    } else if (n["radii"]) {
      const auto r = Seq(n["radii"], j.name + " radii", 2);
      j.radii = {Num(r[0], j.name + " radii"), Num(r[1], j.name + " radii")};
      geometry_at_["mesh " + std::to_string(m_.joints.size())] = At(n["radii"]);
      if (!(j.radii[0] > 0 && j.radii[1] > 0))
        throw ScenarioError(At(n["radii"]), j.name + " pitch radii must be positive", "radii: [r_a, r_b] in " + m_.length_unit);
      // Two wheels roll on their pitch circles only when the radii are in the ratio of the teeth.
      if (std::fabs(j.radii[0] * zb - j.radii[1] * za) > 1e-9 * j.radii[0] * zb)
        throw ScenarioError(At(n["radii"]), j.name + ": pitch radii " + Fmt(j.radii[0]) + " : " + Fmt(j.radii[1]) +
                                                " are not in the ratio of the teeth " + std::to_string(j.teeth[0]) + " : " +
                                                std::to_string(j.teeth[1]) + ", so the wheels cannot roll on their pitch circles",
                            "radii: [" + Fmt(j.radii[0], 10) + ", " + Fmt(j.radii[0] * zb / za, 10) + "] (r_b = r_a Z_b / Z_a), or module: m");
    } else {
      return;
    }
    geometry_ = true;
  }

  SourceRef GeometryAt(const std::string& key, const SourceRef& fallback) const {
    const auto it = geometry_at_.find(key);
    return it == geometry_at_.end() ? fallback : it->second;
  }
  // Centre distance of a mesh from its radii: external r_a + r_b, internal |r_a − r_b|.
  static double CentreDistance(const Joint& j) {
    return j.internal ? std::fabs(j.radii[0] - j.radii[1]) : j.radii[0] + j.radii[1];
  }
  // The radii a centre distance d gives a mesh: r = d Z / (Z_a ± Z_b).
  static void RadiiFromDistance(Joint& j, double d) {
    const double za = j.teeth[0], zb = j.teeth[1];
    const double k = d / (j.internal ? std::fabs(za - zb) : za + zb);
    j.radii = {k * za, k * zb};
  }
  static bool Near(double a, double b) { return std::fabs(a - b) <= 1e-9 * std::max(std::fabs(a), std::fabs(b)); }

  // Model::gear_axes from the members' centres, the carriers' arms and the meshes' radii; a file
  // whose numbers contradict each other (a centre distance against the radii) is refused here.
  void ResolveGearGeometry() {
    if (!geometry_ || m_.kind != ScenarioKind::kGearTrain) return;
    const int nb = static_cast<int>(m_.bodies.size());
    const std::string L = m_.length_unit;
    std::vector<bool> carries(nb, false);
    for (const Joint& j : m_.joints)
      if (j.type == JointType::kGear && j.carrier >= 0) carries[j.carrier] = true;
    for (int b = 0; b < nb; ++b) {
      const Body& B = m_.bodies[b];
      for (const char* key : {"arm", "planets"}) {
        const bool given = std::string(key) == "arm" ? B.arm == B.arm : B.planets > 0;
        if (given && !carries[b])
          throw ScenarioError(GeometryAt(std::string(key) + " " + B.name, B.src),
                              "member " + B.name + " has " + key + ": but is no mesh's carrier",
                              "name it in its planets' meshes (carrier: " + B.name + "), or remove " + key + ":");
      }
      if (B.arm == B.arm && !B.centre.allFinite())
        throw ScenarioError(GeometryAt("arm " + B.name, B.src), "carrier " + B.name + " has an arm but no axis",
                            "give its axis: centre: [x, y] in " + L);
    }
    m_.gear_axes.assign(nb, GearAxis{});
    for (int b = 0; b < nb; ++b) m_.gear_axes[b].centre = m_.bodies[b].centre;
    // On a carrier's mesh, a member with centre: turns on the carrier's axis; the other is the planet.
    std::vector<std::vector<int>> meshes_of_planet(nb);
    for (size_t ji = 0; ji < m_.joints.size(); ++ji) {
      const Joint& j = m_.joints[ji];
      if (j.type != JointType::kGear || j.carrier < 0) continue;
      const Body& C = m_.bodies[j.carrier];
      int with_centre = 0, planet = -1;
      for (int k = 0; k < 2; ++k) {
        const Body& X = m_.bodies[j.members[k]];
        if (!X.centre.allFinite()) {
          planet = j.members[k];
          continue;
        }
        ++with_centre;
        const SourceRef at = GeometryAt("centre " + X.name, X.src);
        if (!C.centre.allFinite())
          throw ScenarioError(at, j.name + " turns on carrier " + C.name + ", so " + X.name +
                                      " (with centre:) turns on the carrier's axis, which the file does not give",
                              "give carrier " + C.name + " centre: " + XY(X.centre));
        if ((X.centre - C.centre).norm() > 1e-9 * std::max(1.0, C.centre.norm()))
          throw ScenarioError(at, X.name + " has its axis at " + XY(X.centre) + ", off the axis of carrier " + C.name + " " +
                                      XY(C.centre) + ", yet meshes on that carrier (" + j.name +
                                      "): a member with centre: in a carrier's mesh turns on the carrier's axis",
                              "set its centre: to " + XY(C.centre) + "; if it is the planet, remove its centre: (the planet's "
                              "axis follows from the carrier's arm)");
      }
      if (with_centre == 2)
        throw ScenarioError(j.src, "both members of " + j.name + " have centres on carrier " + C.name +
                                       "'s axis: one of them must be the planet, whose axis rides on the arm",
                            "remove centre: from the planet");
      if (with_centre == 0) continue;  // neither is placed: the mesh is tooth counts only
      GearAxis& P = m_.gear_axes[planet];
      if (P.carrier >= 0 && P.carrier != j.carrier)
        throw ScenarioError(j.src, "planet " + m_.bodies[planet].name + " would ride on carriers " +
                                       m_.bodies[P.carrier].name + " and " + C.name,
                            "a planet turns on one carrier: name the same carrier in each of its meshes");
      P.carrier = j.carrier;
      P.centre = C.centre;
      meshes_of_planet[planet].push_back(static_cast<int>(ji));
    }
    for (int p = 0; p < nb; ++p) {
      GearAxis& P = m_.gear_axes[p];
      if (P.carrier < 0) continue;
      const Body& C = m_.bodies[P.carrier];
      const std::string planet = m_.bodies[p].name;
      int from = -1;  // the mesh that set the arm, -1 for the carrier's arm:
      P.arm = C.arm;
      for (int ji : meshes_of_planet[p]) {
        const Joint& j = m_.joints[ji];
        if (!(j.radii[0] == j.radii[0])) continue;
        const double d = CentreDistance(j);
        const std::string how = j.internal ? "|r_a - r_b| = |" : "r_a + r_b = ";
        const std::string radii = how + Fmt(j.radii[0]) + (j.internal ? " - " : " + ") + Fmt(j.radii[1]) + (j.internal ? "|" : "");
        if (!(P.arm == P.arm)) {
          P.arm = d, from = ji;
        } else if (!Near(P.arm, d)) {
          const double zsum = j.internal ? std::fabs(j.teeth[0] - j.teeth[1]) : j.teeth[0] + j.teeth[1];
          if (from < 0)
            throw ScenarioError(GeometryAt("mesh " + std::to_string(ji), j.src),
                                j.name + " puts planet " + planet + "'s axis " + radii + " = " + Fmt(d) + " " + L +
                                    " from the axis of carrier " + C.name + ", whose arm is " + Fmt(P.arm) + " " + L,
                                "arm: " + Fmt(d) + ", or a module that fits the arm: " +
                                    Fmt(2 * P.arm / zsum, 10) + " = 2 arm / (Z_a " + (j.internal ? "- " : "+ ") + "Z_b)");
          throw ScenarioError(GeometryAt("mesh " + std::to_string(ji), j.src),
                              j.name + " puts planet " + planet + "'s axis " + radii + " = " + Fmt(d) + " " + L + " from carrier " +
                                  C.name + "'s axis, but " + m_.joints[from].name + " puts it at " + Fmt(P.arm) + " " + L,
                              "teeth or modules for which both centre distances agree: module " + Fmt(2 * P.arm / zsum, 10) +
                                  " on " + j.name + " puts it at " + Fmt(P.arm) + " " + L +
                                  " too (with one module, a ring needs Z_ring = Z_sun + 2 Z_planet)");
        }
      }
      if (!(P.arm == P.arm)) continue;  // no radii and no arm: the planet's axis is not known
      for (int ji : meshes_of_planet[p])
        if (!(m_.joints[ji].radii[0] == m_.joints[ji].radii[0])) RadiiFromDistance(m_.joints[ji], P.arm);
    }
    // A planet's axis moves: every mesh it takes part in turns on its carrier.
    for (const Joint& j : m_.joints) {
      if (j.type != JointType::kGear) continue;
      for (int x : j.members) {
        const int c = m_.gear_axes[x].carrier;
        if (c >= 0 && j.carrier != c)
          throw ScenarioError(j.src, "planet " + m_.bodies[x].name + " rides on the arm of " + m_.bodies[c].name + " but meshes in " +
                                         j.name + (j.carrier < 0 ? " on the frame" : " on carrier " + m_.bodies[j.carrier].name),
                              "a mesh with a planet turns on its carrier: carrier: " + m_.bodies[c].name);
      }
    }
    // Meshes on the frame between two fixed axes: their distance against the radii.
    for (size_t ji = 0; ji < m_.joints.size(); ++ji) {
      Joint& j = m_.joints[ji];
      if (j.type != JointType::kGear || j.carrier >= 0) continue;
      const Body &A = m_.bodies[j.members[0]], &B = m_.bodies[j.members[1]];
      if (!A.centre.allFinite() || !B.centre.allFinite()) continue;
      const double d = (B.centre - A.centre).norm();
      const double zsum = j.internal ? std::fabs(j.teeth[0] - j.teeth[1]) : j.teeth[0] + j.teeth[1];
      if (!(j.radii[0] == j.radii[0])) {
        if (!(d > 0))
          throw ScenarioError(GeometryAt("centre " + B.name, B.src), j.name + ": " + A.name + " and " + B.name +
                                                                          " have one axis " + XY(A.centre) + ", so they cannot mesh",
                              "their centres " + std::string(j.internal ? "|r_a - r_b|" : "r_a + r_b") + " apart");
        RadiiFromDistance(j, d);
        continue;
      }
      const double e = CentreDistance(j);
      if (!Near(d, e)) {
        const Eigen::Vector2d u = d > 0 ? Eigen::Vector2d((B.centre - A.centre) / d) : Eigen::Vector2d(1, 0);
        throw ScenarioError(GeometryAt("mesh " + std::to_string(ji), j.src),
                            j.name + ": the centres of " + A.name + " " + XY(A.centre) + " and " + B.name + " " + XY(B.centre) +
                                " are " + Fmt(d) + " " + L + " apart, but the pitch radii " + Fmt(j.radii[0]) + " and " +
                                Fmt(j.radii[1]) + " put them " + (j.internal ? "|r_a - r_b|" : "r_a + r_b") + " = " + Fmt(e) +
                                " " + L + " apart",
                            "move " + B.name + " to " + XY(A.centre + e * u) + ", or take module " + Fmt(2 * d / zsum, 10) +
                                " = 2 d / (Z_a " + (j.internal ? "- " : "+ ") + "Z_b)");
      }
    }
  }

  void ReadJoints(const YAML::Node& joints) {
    if (!joints) return;
    for (const YAML::Node& n : Seq(joints, "joints", 0)) {
      Joint j;
      j.src = At(n);
      if (!n.IsMap() || !n["type"]) throw ScenarioError(j.src, "a joint needs type: slider, gear, rack or coupling",
                          "write the joint as a mapping with its type, e.g. - {type: slider, point: B, line: [O, G]}");
      const std::string type = Str(n["type"], "joint type");
      if (type == "slider") {
        Keys(n, "slider joint", {"type", "point", "line", "body", "eliminate"});
        if (m_.kind != ScenarioKind::kLinkage) throw ScenarioError(j.src, "sliders belong to linkages",
                          "use kind: linkage, or a rack joint (type: rack) in a gear train");
        j.point = PointRef(Required(n, "point", "slider joint", "name the sliding point"), "slider point");
        if (m_.points[j.point].fixed) throw ScenarioError(j.src, "slider point " + m_.points[j.point].name + " is fixed",
                          "slide a moving point (declared with at:), or remove the slider");
        if (n["line"] && n["body"]) throw ScenarioError(j.src, "a slider runs on a line or along a body, not both",
                          "keep line: [P, Q] (a fixed guide) or body: NAME (a moving one)");
        if (n["line"]) {
          j.type = JointType::kPointOnFixedLine;
          j.line = PointPair(n["line"], "slider line");
          for (int p : j.line)
            if (!m_.points[p].fixed)
              throw ScenarioError(At(n["line"]), "slider line point " + m_.points[p].name + " is not fixed",
                                  "a moving guide is a body: use body: NAME");
          RequireDirection(j.line, n["line"], "the guide of slider " + m_.points[j.point].name);
          if (n["eliminate"]) j.eliminate = Bool(n["eliminate"], "eliminate");
          j.name = "slider " + m_.points[j.point].name + " on " + m_.points[j.line[0]].name + "-" + m_.points[j.line[1]].name;
        } else if (n["body"]) {
          j.type = JointType::kPointOnBody;
          j.body = BodyRef(n["body"], "slider body");
          const Body& b = m_.bodies[j.body];
          if (b.points.size() < 2)
            throw ScenarioError(At(n["body"]), "slider " + m_.points[j.point].name + " along body " + b.name +
                                                   ", which has one point: no line to slide along",
                                "slide along a body with two points (its first two give the line), or on a fixed line:");
          j.line = {b.points[0], b.points[1]};
          if (j.point == j.line[0] || j.point == j.line[1])
            throw ScenarioError(j.src, "point " + m_.points[j.point].name + " defines the line of " + b.name + " and cannot slide on it",
                          "slide another point along it, or use a guide line through other points");
          if (n["eliminate"]) throw ScenarioError(At(n["eliminate"]), "eliminate applies to fixed guides only",
                          "remove eliminate:, or guide the point on a fixed line: [P, Q]");
          j.name = "slider " + m_.points[j.point].name + " along " + b.name;
        } else {
          throw ScenarioError(j.src, "a slider needs line: [P, Q] (fixed guide) or body: NAME",
                          "add line: [P, Q] (two fixed points) or body: NAME");
        }
      } else if (type == "gear") {
        Keys(n, "gear joint", {"type", "members", "teeth", "mesh", "carrier", "module", "radii"});
        if (m_.kind != ScenarioKind::kGearTrain) throw ScenarioError(j.src, "gear meshes belong to gear trains", "use kind: gear_train");
        j.type = JointType::kGear;
        const auto mem = Seq(Required(n, "members", "gear joint", "members: [driver, driven]"), "gear members", 2);
        j.members = {BodyRef(mem[0], "gear member"), BodyRef(mem[1], "gear member")};
        if (j.members[0] == j.members[1]) throw ScenarioError(j.src, "a gear cannot mesh with itself",
                          "name two different members in members: [A, B]");
        for (int b : j.members) RequireTurning(b, At(n["members"]), "gear member");
        const auto z = Seq(Required(n, "teeth", "gear joint", "teeth: [Z1, Z2]"), "gear teeth", 2);
        j.teeth = {Int(z[0], "teeth", "a tooth count", "teeth: [Z1, Z2], e.g. [20, 40]"),
                   Int(z[1], "teeth", "a tooth count", "teeth: [Z1, Z2], e.g. [20, 40]")};
        if (j.teeth[0] <= 0 || j.teeth[1] <= 0) throw ScenarioError(At(n["teeth"]), "tooth counts must be positive",
                          "give teeth of 1 or more");
        const std::string mesh = Str(Required(n, "mesh", "gear joint", "mesh: external or internal"), "mesh");
        if (mesh == "internal") j.internal = true;
        else if (mesh == "rack")
          throw ScenarioError(At(n["mesh"]), "a rack is not a mesh between two gear members",
                              "give the rack member slides: [dx, dy] and a travel coordinate, and mesh it with "
                              "{type: rack, pinion: ROTATION, rack: TRAVEL, radius: r} (scenarios/FORMAT.md, Gear trains with a rack)");
        else if (mesh != "external") throw ScenarioError(At(n["mesh"]), "unknown mesh '" + mesh + "'", "use external or internal");
        // In an internal mesh the member with more teeth is the internal (ring) gear, around its pinion.
        if (j.internal && j.teeth[0] == j.teeth[1])
          throw ScenarioError(At(n["teeth"]), "an internal mesh between equal tooth counts (" + std::to_string(j.teeth[0]) +
                                                  "): the internal gear must be larger than the pinion inside it",
                              "give the ring gear more teeth than its pinion, or use mesh: external");
        if (n["carrier"]) j.carrier = BodyRef(n["carrier"], "gear carrier");
        if (j.carrier >= 0) RequireTurning(j.carrier, At(n["carrier"]), "gear carrier");
        j.name = "gear " + m_.bodies[j.members[0]].name + "-" + m_.bodies[j.members[1]].name;
        ReadMeshGeometry(n, j);
      } else if (type == "rack" || type == "coupling") {
        // Names coordinates of q, which exist once the layout is built: read in ReadCouplings.
        coupling_nodes_.push_back(n);
        continue;
      } else {
        throw ScenarioError(At(n["type"]), "unknown joint type '" + type + "'",
                            "use slider, gear, rack or coupling (a revolute pair is a point two bodies share)");
      }
      m_.joints.push_back(j);
    }
  }

  void ReadCoordinates(const YAML::Node& coords) {
    if (!coords) return;
    if (!coords.IsMap()) throw ScenarioError(At(coords), "coordinates must be a mapping name: {type: ...}",
                          "write each coordinate on its own line under coordinates:, e.g. theta: {type: angle, vector: [O, A]}");
    for (const auto& kv : coords) {
      Coordinate c;
      c.name = kv.first.as<std::string>();
      c.src = At(kv.first);
      const std::string what = "coordinate " + c.name;
      const YAML::Node n = kv.second;
      if (!n.IsMap() || !n["type"]) throw ScenarioError(c.src, what + " needs type: angle, distance or rotation",
                          "add type: angle, distance, rotation or travel");
      const std::string type = Str(n["type"], what + " type");
      if (type == "angle") {
        Keys(n, what, {"type", "vector", "reference", "form", "guess"});
        if (m_.kind != ScenarioKind::kLinkage) throw ScenarioError(c.src, "angles between points belong to linkages",
                          "use type: rotation in a gear train, or kind: linkage");
        c.type = CoordinateType::kAngle;
        c.vec = PointPair(Required(n, "vector", what, "vector: [P, Q]"), what + " vector");
        if (n["reference"]) {
          c.ref = PointPair(n["reference"], what + " reference");
          if (m_.points[c.ref[0]].fixed && m_.points[c.ref[1]].fixed)
            RequireDirection(c.ref, n["reference"], what + " reference");
        }
        if (n["form"]) {
          const std::string f = Str(n["form"], what + " form");
          static const std::map<std::string, AngleForm> forms{
              {"cross", AngleForm::kCross}, {"dot", AngleForm::kDot}, {"cos", AngleForm::kCos},
              {"sin", AngleForm::kSin}, {"cos+sin", AngleForm::kCosSin}};
          const auto it = forms.find(f);
          if (it == forms.end()) throw ScenarioError(At(n["form"]), what + ": unknown form '" + f + "'", "use cross, dot, cos, sin or cos+sin");
          c.form = it->second;
        }
        const bool ground = c.ref[0] < 0;
        if (c.form == AngleForm::kDot && ground)
          throw ScenarioError(c.src, what + ": the dot form needs a reference vector", "add reference: [P, Q] or use form: cos");
        if ((c.form == AngleForm::kCos || c.form == AngleForm::kSin || c.form == AngleForm::kCosSin) && !ground)
          throw ScenarioError(c.src, what + ": cos/sin forms measure from the ground x axis", "remove reference: or use form: dot or cross");
      } else if (type == "distance") {
        Keys(n, what, {"type", "between", "guess"});
        if (m_.kind != ScenarioKind::kLinkage) throw ScenarioError(c.src, "distances between points belong to linkages",
                          "use type: travel for a gear train's sliding member, or kind: linkage");
        c.type = CoordinateType::kDistance;
        c.vec = PointPair(Required(n, "between", what, "between: [P, Q]"), what + " between");
      } else if (type == "rotation") {
        Keys(n, what, {"type", "member", "guess"});
        if (m_.kind != ScenarioKind::kGearTrain) throw ScenarioError(c.src, "rotation coordinates belong to gear trains", "use an angle");
        c.type = CoordinateType::kRotation;
        c.body = BodyRef(Required(n, "member", what, "member: BODY"), what + " member");
        RequireTurning(c.body, At(n["member"]), what + " member");
        for (const Coordinate& o : m_.coordinates)
          if (o.type == CoordinateType::kRotation && o.body == c.body)
            throw ScenarioError(c.src, "member " + m_.bodies[c.body].name + " already has rotation " + o.name,
                          "keep one rotation coordinate per member");
      } else if (type == "travel") {
        ReadTravel(n, c, what);
      } else {
        throw ScenarioError(At(n["type"]), what + ": unknown type '" + type + "'", "use angle, distance, rotation or travel");
      }
      if (n["guess"]) c.guess = Num(n["guess"], what + " guess");
      if (PointIndexOf(c.name) >= 0 || BodyIndexOf(c.name) >= 0)
        throw ScenarioError(c.src, what + " has the name of a point or body", "rename it");
      for (const Coordinate& o : m_.coordinates)
        if (o.name == c.name) throw ScenarioError(c.src, what + " declared twice",
                          "rename one of the two, or remove the copy");
      m_.coordinates.push_back(c);
    }
    if (m_.kind == ScenarioKind::kGearTrain) {
      for (const Joint& j : m_.joints)
        for (int b : {j.members[0], j.members[1], j.carrier}) {
          if (b < 0) continue;
          const bool has = std::any_of(m_.coordinates.begin(), m_.coordinates.end(),
                                       [&](const Coordinate& c) { return c.type == CoordinateType::kRotation && c.body == b; });
          if (!has)
            throw ScenarioError(j.src, "gear member " + m_.bodies[b].name + " has no rotation coordinate",
                                "add coordinates: {phi_" + m_.bodies[b].name + ": {type: rotation, member: " + m_.bodies[b].name + "}}");
        }
    }
  }

  // A gear-train member that must turn (a mesh's member or carrier, a rotation's member), not slide.
  void RequireTurning(int body, const SourceRef& at, const std::string& what) const {
    const Body& b = m_.bodies[body];
    if (!b.IsSliding()) return;
    throw ScenarioError(at, what + " " + b.name + " slides (a rack): it does not turn",
                        "mesh it with {type: rack, pinion: <a member's rotation>, rack: <its travel>, radius: r}, and give "
                        "it {type: travel, member: " + b.name + "} as its coordinate");
  }

  // `{type: travel, member: RACK}`: a gear train's sliding member's travel along `slides:` [length].
  void ReadTravel(const YAML::Node& n, Coordinate& c, const std::string& what) {
    Keys(n, what, {"type", "member", "guess"});
    if (m_.kind != ScenarioKind::kGearTrain)
      throw ScenarioError(c.src, "travel coordinates belong to a gear train's sliding members",
                          "in a linkage a rack's travel is its sliding point's x or y");
    c.type = CoordinateType::kTravel;
    c.body = BodyRef(Required(n, "member", what, "member: BODY (a member with slides:)"), what + " member");
    const Body& b = m_.bodies[c.body];
    if (!b.IsSliding())
      throw ScenarioError(At(n["member"]), what + ": member " + b.name + " turns, and a travel belongs to a sliding member",
                          "use {type: rotation, member: " + b.name + "}, or give " + b.name + " slides: [dx, dy] if it is a rack");
    for (const Coordinate& o : m_.coordinates)
      if (o.type == CoordinateType::kTravel && o.body == c.body)
        throw ScenarioError(c.src, "member " + b.name + " already has travel " + o.name,
                          "keep one travel coordinate per sliding member");
  }

  // q: moving points (x, y minus eliminated), then relative coordinates; see model.h.
  void BuildLayout() {
    std::vector<std::array<bool, 2>> eliminated(m_.points.size(), {false, false});
    for (const Joint& j : m_.joints) {
      if (j.type != JointType::kPointOnFixedLine || !j.eliminate) continue;
      const Eigen::Vector2d a = m_.points[j.line[0]].p_W, b = m_.points[j.line[1]].p_W;
      int axis = -1;  // the coordinate that stays constant
      if (a.y() == b.y()) axis = 1;
      else if (a.x() == b.x()) axis = 0;
      if (axis < 0) continue;  // an oblique guide keeps both coordinates and a collinearity row
      Point& p = m_.points[j.point];
      if (eliminated[j.point][axis] || eliminated[j.point][1 - axis])
        throw ScenarioError(j.src, "point " + p.name + " has two fixed guides and cannot move", "remove one slider");
      if (std::fabs(p.p_W[axis] - a[axis]) > 1e-9 * (1 + std::fabs(a[axis])))
        throw ScenarioError(p.src, "point " + p.name + " is not on its guide (" + j.name + ")",
                            std::string("set its ") + (axis ? "y" : "x") + " to " + Fmt(a[axis], 15) + ": the guide through " +
                                m_.points[j.line[0]].name + " " + XY(a) + " and " + m_.points[j.line[1]].name + " " +
                                XY(b) + " is " + (axis ? "horizontal" : "vertical"));
      eliminated[j.point][axis] = true;
    }
    for (size_t i = 0; i < m_.points.size(); ++i) {
      if (m_.points[i].fixed) continue;
      for (int axis = 0; axis < 2; ++axis)
        if (!eliminated[i][axis])
          m_.q_layout.push_back({std::string(axis ? "y" : "x") + m_.points[i].name, static_cast<int>(i), axis, -1});
    }
    for (size_t c = 0; c < m_.coordinates.size(); ++c) {
      if (m_.SlotIndex(m_.coordinates[c].name) >= 0)
        throw ScenarioError(m_.coordinates[c].src, "coordinate " + m_.coordinates[c].name + " clashes with a point coordinate name", "rename it");
      m_.q_layout.push_back({m_.coordinates[c].name, -1, -1, static_cast<int>(c)});
    }
    if (m_.q_layout.empty()) throw ScenarioError({file_, 1}, "the scenario has nothing that moves", "add moving points or rotation coordinates");
  }

  // A coordinate of q by name, for a coupling; `what` says which end.
  int CouplingSlot(const YAML::Node& n, const std::string& what) {
    const std::string name = Str(n, what);
    const int s = m_.SlotIndex(name);
    if (s < 0) {
      std::vector<std::string> names;
      for (const auto& slot : m_.q_layout) names.push_back(slot.name);
      throw ScenarioError(At(n), what + " names unknown coordinate '" + name + "'", "coordinates in q are: " + Join(names));
    }
    return s;
  }
  bool IsAngleSlot(int s) const {
    const Model::Slot& slot = m_.q_layout[s];
    return slot.coordinate >= 0 && (m_.coordinates[slot.coordinate].type == CoordinateType::kAngle ||
                                    m_.coordinates[slot.coordinate].type == CoordinateType::kRotation);
  }

  // joints of type rack or coupling: q_b = ratio q_a + offset, the offset from the file's values.
  void ReadCouplings() {
    const Eigen::VectorXd q_file = m_.GuessQ();
    for (const YAML::Node& n : coupling_nodes_) {
      Coupling c;
      c.src = At(n);
      const std::string type = Str(n["type"], "joint type");
      if (type == "rack") {
        Keys(n, "rack joint", {"type", "pinion", "rack", "radius", "module", "teeth", "reverse"});
        c.rack = true;
        const YAML::Node pn = Required(n, "pinion", "rack joint", "pinion: the pinion's angle or rotation coordinate");
        const YAML::Node rn = Required(n, "rack", "rack joint",
                                       "rack: the coordinate the rack travels along (a sliding point's x or y, a distance, or "
                                       "a gear train's travel)");
        c.slots = {CouplingSlot(pn, "rack joint pinion"), CouplingSlot(rn, "rack joint rack")};
        if (!IsAngleSlot(c.slots[0]))
          throw ScenarioError(At(pn), "rack joint pinion '" + m_.q_layout[c.slots[0]].name + "' is not an angle",
                              "name the pinion's angle coordinate (type: angle, or rotation in a gear train)");
        if (IsAngleSlot(c.slots[1]))
          throw ScenarioError(At(rn), "rack joint rack '" + m_.q_layout[c.slots[1]].name + "' is an angle, not a travel",
                              "name a sliding point's coordinate (x or y) or a distance; two angles are a coupling "
                              "{type: coupling, coordinates: [a, b], ratio: k}");
        double r = kNaN;
        if (n["radius"] && (n["module"] || n["teeth"]))
          throw ScenarioError(c.src, "rack joint gives both radius and module/teeth", "keep one: radius: r, or module: m and teeth: Z");
        if (n["radius"]) {
          r = Num(n["radius"], "rack radius", UnitField::kLength, m_.length_unit);
        } else if (n["module"] || n["teeth"]) {
          const double module = Num(Required(n, "module", "rack joint", "module: m with teeth: Z (radius = m Z / 2)"), "rack module");
          const int z = Int(Required(n, "teeth", "rack joint", "teeth: Z with module: m (radius = m Z / 2)"), "rack teeth",
                              "the pinion's tooth count", "teeth: Z, e.g. teeth: 20 (radius = m Z / 2)");
          if (z <= 0) throw ScenarioError(At(n["teeth"]), "tooth counts must be positive",
                          "give teeth of 1 or more");
          r = module * z / 2;
        } else {
          throw ScenarioError(c.src, "rack joint needs the pinion's pitch radius",
                              "radius: r in " + m_.length_unit + ", or module: m and teeth: Z");
        }
        if (!(r > 0) || r > kMassMagnitude)
          throw ScenarioError(At(n["radius"] ? n["radius"] : n["module"]),
                              "rack joint pitch radius is " + Fmt(r, 6) + " " + m_.length_unit + ": it must be positive",
                              "give the pinion's pitch radius; for the opposite sense of travel add reverse: true");
        const bool reverse = n["reverse"] && Bool(n["reverse"], "reverse");
        c.ratio = reverse ? -r : r;
        c.name = "rack " + m_.q_layout[c.slots[1]].name + " by " + m_.q_layout[c.slots[0]].name;
      } else {
        Keys(n, "coupling joint", {"type", "coordinates", "ratio"});
        const auto co = Seq(Required(n, "coordinates", "coupling joint", "coordinates: [a, b] for b = ratio · a + const"),
                            "coupling coordinates", 2);
        c.slots = {CouplingSlot(co[0], "coupling coordinate"), CouplingSlot(co[1], "coupling coordinate")};
        const YAML::Node rn = Required(n, "ratio", "coupling joint", "ratio: k for Δb = k Δa");
        c.ratio = Num(rn, "coupling ratio", UnitField::kPlain, "a ratio (no unit)");
        if (c.ratio == 0 || !(std::fabs(c.ratio) >= 1 / kMassMagnitude && std::fabs(c.ratio) <= kMassMagnitude))
          throw ScenarioError(At(rn), "coupling ratio is " + Fmt(c.ratio, 6) + ": it must be nonzero (within 1e-100 … 1e100)",
                              "a ratio of 0 would hold b still: drive b instead (drivers:)");
        c.name = "coupling " + m_.q_layout[c.slots[1]].name + " by " + m_.q_layout[c.slots[0]].name;
      }
      if (c.slots[0] == c.slots[1])
        throw ScenarioError(c.src, c.name + " couples a coordinate with itself", "name two different coordinates");
      for (const Coupling& o : m_.couplings)
        if ((o.slots[0] == c.slots[0] && o.slots[1] == c.slots[1]) || (o.slots[0] == c.slots[1] && o.slots[1] == c.slots[0]))
          throw ScenarioError(c.src, c.name + " couples the same two coordinates as " + o.name + " (" + o.src.Str() + ")",
                              "keep one");
      for (int k = 0; k < 2; ++k) c.coordinates[k] = m_.q_layout[c.slots[k]].name;
      c.offset = q_file[c.slots[1]] - c.ratio * q_file[c.slots[0]];
      if (!std::isfinite(c.offset))
        throw ScenarioError(c.src, c.name + ": the file gives no value of " + c.coordinates[0] + " or " + c.coordinates[1] +
                                       " to hold the relation from",
                            "give the points' positions (at:) or the coordinates' guess:");
      m_.couplings.push_back(c);
    }
  }

  // drivers: prescribed for all t; initial: the same form, for t0 only. No drivers = a free scene.
  void ReadDrivers(const YAML::Node& drivers, const std::string& what, std::vector<Driver>& out) {
    if (!drivers) return;
    std::set<std::string> driven;
    for (const YAML::Node& n : Seq(drivers, what + "s", 0)) {
      if (what == "driver") Keys(n, what, {"coordinate", "value", "velocity", "acceleration", "law", "rate"});
      else Keys(n, what, {"coordinate", "value", "velocity"});
      Driver d;
      d.src = At(n);
      const YAML::Node cn = Required(n, "coordinate", what, "coordinate: NAME");
      d.coordinate = Str(cn, what + " coordinate");
      if (m_.SlotIndex(d.coordinate) < 0) {
        std::vector<std::string> names;
        for (const auto& s : m_.q_layout) names.push_back(s.name);
        throw ScenarioError(At(cn), what + " names unknown coordinate '" + d.coordinate + "'",
                            "coordinates in q are: " + Join(names));
      }
      if (!driven.insert(d.coordinate).second)
        throw ScenarioError(d.src, "coordinate " + d.coordinate + " is listed twice in " + what + "s",
                            "keep one entry for it (a coordinate has one " + what + ")");
      if (n["law"]) {
        ReadLaw(n, d, out.size());
        out.push_back(d);
        continue;
      }
      if (n["rate"])
        throw ScenarioError(At(n["rate"]), what + " " + d.coordinate + ": `rate` checks a `law`, and there is none",
                            "give law: x(t), or write the constant-acceleration law with value, velocity, acceleration");
      const auto [field, unit] = SlotUnits(d.coordinate);
      d.value = Num(Required(n, "value", what, "value: the coordinate at t0, or law: an expression of t"), what + " value",
                    field, unit);
      if (n["velocity"]) d.velocity = Num(n["velocity"], what + " velocity", field, unit);
      if (n["acceleration"]) d.acceleration = Num(n["acceleration"], what + " acceleration", field, unit);
      out.push_back(d);
    }
    if (out.empty()) throw ScenarioError(At(drivers), what + "s: is empty", "list at least one, or remove the key");
  }

  // An expression of t (and the file's constants) compiled once; its errors name the file's line.
  CompiledExpr CompileOfT(const YAML::Node& n, const std::string& what, UnitField field = UnitField::kAny,
                          const std::string& unit = "") {
    if (!n.IsScalar()) throw ScenarioError(At(n), what + " must be an expression of t such as 0.2 + 0.1*sin(2*pi*t)",
                          "write the law as one quoted expression on this line");
    CheckLawUnitWords(n, what, field, unit);
    try {
      return CompiledExpr::Compile(n.as<std::string>(), [this](const std::string& name) -> std::optional<CompiledExpr::Binding> {
        if (name == "t") return CompiledExpr::Binding{0, 0};
        if (auto it = m_.constants.find(name); it != m_.constants.end()) return CompiledExpr::Binding{-1, it->second};
        return std::nullopt;
      });
    } catch (const ExprError& e) {
      if (!e.fix.empty()) throw ScenarioError(At(n), what + ": " + e.what(), e.fix);
      throw ScenarioError(At(n), what + ": " + e.what(),
                          "a law may use t [s], the file's constants" + ConstantsInFile() +
                              ", pi, unit words (deg, rpm) and sin, cos, exp, … (FORMAT.md, drivers)");
    }
  }

  // law: x(t); rate: and acceleration:, when given, are checked against its derivatives once the
  // analysis' instants are known (CheckLaws).
  void ReadLaw(const YAML::Node& n, Driver& d, size_t index) {
    for (const char* k : {"value", "velocity"})
      if (n[k])
        throw ScenarioError(At(n[k]), "driver " + d.coordinate + " has both `law` and `" + k + "`",
                            "a law gives the value at every t (and its derivatives): remove `" + std::string(k) + "`");
    const auto [field, unit] = SlotUnits(d.coordinate);
    d.law = std::make_shared<const CompiledExpr>(CompileOfT(n["law"], "driver " + d.coordinate + " law", field, unit));
    LawCheck c;
    c.driver = index, c.at = At(n);
    if (n["rate"])
      c.rate = std::make_shared<const CompiledExpr>(CompileOfT(n["rate"], "driver " + d.coordinate + " rate", field, unit)),
      c.rate_at = At(n["rate"]);
    if (n["acceleration"])
      c.acceleration = std::make_shared<const CompiledExpr>(
          CompileOfT(n["acceleration"], "driver " + d.coordinate + " acceleration", field, unit)),
      c.acceleration_at = At(n["acceleration"]);
    law_checks_.push_back(c);
  }

  // Each law finite (with its derivatives) at every instant of the analysis; a given rate or
  // acceleration equal to the law's own derivative there, to 1e-9 relative; value, velocity and
  // acceleration set to the law's at t0.
  void CheckLaws() {
    const Analysis& a = m_.analysis;
    std::vector<double> instants;
    for (int k = 0; k < a.samples; ++k) instants.push_back(a.TimeAt(k));
    for (const LawCheck& c : law_checks_) {
      Driver& d = m_.drivers[c.driver];
      for (double t : instants) {
        const Jet2 j = d.JetAt(t, a.t0);
        if (!std::isfinite(j.v) || !std::isfinite(j.d) || !std::isfinite(j.dd))
          throw ScenarioError(c.at, "driver " + d.coordinate + " law \"" + d.law->text() + "\" is not finite at t = " +
                                        Fmt(t, 6) + " s (value " + Fmt(j.v, 6) + ", rate " + Fmt(j.d, 6) + ", acceleration " +
                                        Fmt(j.dd, 6) + ")",
                              "a law defined (with its first two derivatives) over the whole analysis [t0, t1]");
        auto check = [&](const std::shared_ptr<const CompiledExpr>& given, double derived, const char* what, const SourceRef& at) {
          if (!given) return;
          const double v = given->Eval(&t);
          if (!(std::fabs(v - derived) <= 1e-9 * std::max(1.0, std::fabs(derived))))
            throw ScenarioError(at, std::string("driver ") + d.coordinate + " " + what + " \"" + given->text() + "\" is " +
                                        Fmt(v, 12) + " at t = " + Fmt(t, 6) + " s, but the law's derivative there is " +
                                        Fmt(derived, 12),
                                "correct it, or leave it out: the law's derivatives are worked out exactly");
        };
        check(c.rate, j.d, "rate", c.rate_at);
        check(c.acceleration, j.dd, "acceleration", c.acceleration_at);
      }
      const Jet2 j0 = d.JetAt(a.t0, a.t0);
      d.value = j0.v, d.velocity = j0.d, d.acceleration = j0.dd;
    }
  }

  // Each entry is one kind, told by its keys: `point` a point force, `between` a
  // spring–damper, `body` a torque.
  void ReadForces(const YAML::Node& forces) {
    if (!forces) return;
    for (const YAML::Node& n : Seq(forces, "forces", 0)) {
      if (!n.IsMap())
        throw ScenarioError(At(n), "a force must be a mapping of keys to values", "write it as " + ForceForms());
      std::vector<std::string> kinds;
      for (const char* k : {"point", "between", "body", "torsion"})
        if (n[k]) kinds.push_back(k);
      if (kinds.size() > 1)
        throw ScenarioError(At(n), "a force entry mixes the keys " + Join(kinds) + " of different kinds of force",
                            "one entry per element: `point` for a point force, `between` for a spring–damper, `body` "
                            "for a torque, `torsion` for a torsional spring–damper");
      if (kinds.empty()) {
        std::vector<std::string> keys;
        for (const auto& kv : n) keys.push_back(kv.first.Scalar());
        std::string typo;
        for (const std::string& k : keys)
          for (const char* kind : {"point", "between", "body", "torsion"})
            if (EditDistance(k, kind) <= 2 && typo.empty()) typo = "; did you mean " + std::string(kind) + ": for " + k + ":?";
        throw ScenarioError(At(n), "a force entry needs one of the keys point, between, body or torsion; this one has " +
                                       (keys.empty() ? std::string("no keys") : "the keys " + Join(keys)) + typo,
                            ForceForms());
      }
      if (m_.kind == ScenarioKind::kSpatial && kinds[0] != "torsion" && kinds[0] != "between") {
        ReadSpatialLoad(n, kinds[0] == "body");
      } else if (kinds[0] == "point") {
        ReadPointForce(n);
      } else if (kinds[0] == "between") {
        ReadSpring(n);
      } else if (kinds[0] == "torsion") {
        ReadTorsion(n);
      } else {
        ReadTorque(n);
      }
    }
  }

  // Levenshtein distance, for "did you mean" on a short key.
  static size_t EditDistance(const std::string& a, const std::string& b) {
    std::vector<size_t> row(b.size() + 1);
    for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (size_t i = 1; i <= a.size(); ++i) {
      size_t diag = row[0];
      row[0] = i;
      for (size_t j = 1; j <= b.size(); ++j) {
        const size_t up = row[j];
        row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
        diag = up;
      }
    }
    return row[b.size()];
  }

  // The force entries a scene of this kind takes (its point forces and torques in 2-D or 3-D).
  std::string ForceForms() const {
    if (m_.kind == ScenarioKind::kSpatial)
      return "write {point: P, force: [Fx, Fy, Fz]}, {between: [A, B], stiffness: k, free_length: L0}, "
             "{body: B, torque: [Tx, Ty, Tz]} (B a rigid body) or {torsion: theta, stiffness: k} (theta an angle "
             "coordinate)";
    return "write {point: P, force: [Fx, Fy]}, {between: [A, B], stiffness: k, free_length: L0}, "
           "{body: B, torque: T} or {torsion: theta, stiffness: k}";
  }

  // ---- spatial force elements (kind: spatial; scenarios/FORMAT.md "Spatial scenes", Forces) ----
  // A spatial point by name (an entity that is a point, not a vector).
  int SpatialPointRef(const YAML::Node& n, const std::string& what) {
    const std::string name = Str(n, what);
    const int i = m_.spatial.EntityIndex(name);
    if (i < 0 || m_.spatial.entities[i].vector) {
      std::vector<std::string> names;
      for (const SpatialEntity& e : m_.spatial.entities)
        if (!e.vector) names.push_back(e.name);
      throw ScenarioError(At(n), what + (i < 0 ? " names unknown point '" + name + "'"
                                               : " names vector " + name + " where a point belongs"),
                          "declared points are: " + Join(names));
    }
    return i;
  }
  std::array<int, 2> SpatialPointPair(const YAML::Node& n, const std::string& what) {
    const auto s = Seq(n, what, 2);
    std::array<int, 2> r{SpatialPointRef(s[0], what), SpatialPointRef(s[1], what)};
    if (r[0] == r[1])
      throw ScenarioError(At(n), what + " needs two different points; both are " + m_.spatial.entities[r[0]].name,
                          "name the two different points the element joins, between: [A, B] (a fixed point and a moving one, "
                          "or two moving ones)");
    return r;
  }

  // A spring–damper between two spatial points: the planar element's keys and tension, each
  // parameter a number or a law of t, q.<slot>, qd.<slot> (SpringParam); its ends apart at the pose.
  void AddSpatialSpring(const YAML::Node& n, const SpringDamper& s) {
    const SpatialEntity &a = m_.spatial.entities[s.points[0]], &b = m_.spatial.entities[s.points[1]];
    if (!((b.r_W - a.r_W).norm() > kDirectionResolution * std::max({a.r_W.norm(), b.r_W.norm(), 1e-300})))
      throw ScenarioError(At(n["between"]), "the spring–damper between " + a.name + " and " + b.name +
                                                " joins two points at one place in the file's pose: its line of action has no direction",
                          "attach it between points apart (a spring of free length 0 needs its ends apart at the start)");
    m_.spatial.springs.push_back(s);
  }

  // A spatial body by name.
  int SpatialBodyRef(const YAML::Node& n, const std::string& what) {
    const std::string name = Str(n, what);
    for (size_t b = 0; b < m_.spatial.bodies.size(); ++b)
      if (m_.spatial.bodies[b].name == name) return static_cast<int>(b);
    std::vector<std::string> names;
    for (const SpatialBody& b : m_.spatial.bodies) names.push_back(b.name);
    throw ScenarioError(At(n), what + " names unknown body '" + name + "'", "declared bodies are: " + Join(names));
  }

  // A follower force's `frame: B`: a rigid body (four entities or more: a basis that turns with
  // it) that carries the force's point.
  int SpatialForceFrame(const YAML::Node& n, int point) {
    const int fb = SpatialBodyRef(n, "force frame");
    const SpatialBody& b = m_.spatial.bodies[fb];
    const std::string& pname = m_.spatial.entities[point].name;
    const std::string& e0 = m_.spatial.entities[b.entities[0]].name;
    if (b.entities.size() < 4) {
      const bool point_mass = b.entities.size() == 1;
      throw ScenarioError(At(n), "force at " + pname + " in the frame of body " + b.name + ", " +
                                     (point_mass ? "a point mass (the one point " + e0 + ")"
                                                 : "a bar (" + std::to_string(b.entities.size()) + " entities)") +
                                     ": a body's frame in 3-D is a rigid body's basis (four entities or more), and a " +
                                     (point_mass ? "point mass" : "bar") + " has none",
                          point_mass ? "leave `frame` out and give world components, [Fx, Fy, Fz] (a law of t, q.<slot>, "
                                       "qd.<slot> may turn it), or make " + b.name +
                                       " a rigid body (a point and three more points or unit vectors)"
                                     : "leave `frame` out and give world components: a force along or across the bar "
                                       "is a law of its moving points' slots (q.x<point>, q.y<point>, q.z<point>), or "
                                       "make " + b.name + " a rigid body (a point and three more points or unit vectors)");
    }
    if (std::find(b.entities.begin(), b.entities.end(), point) == b.entities.end()) {
      std::vector<std::string> names;
      for (int e : b.entities)
        if (!m_.spatial.entities[e].vector) names.push_back(m_.spatial.entities[e].name);
      throw ScenarioError(At(n), "force at " + pname + " in the frame of body " + b.name +
                                     ", which does not carry point " + pname + ": a follower force acts on the body it turns with",
                          "apply it at one of " + b.name + "'s points (" + Join(names) + "), or name a body that carries " +
                              pname);
    }
    return fb;
  }

  // {point: P, force: [Fx, Fy, Fz]} or {body: B, torque: [Tx, Ty, Tz]} in a spatial scene: world
  // components, each a number or a law of t, q.<slot>, qd.<slot> (CompileLoad). A torque acts on
  // a rigid body (four entities or more: its basis turns with it). With `frame: B` a point force's
  // components are in world axes at the file's pose and turn with rigid body B (SpatialLoad).
  void ReadSpatialLoad(const YAML::Node& n, bool torque) {
    const std::string kind = torque ? "torque" : "point force";
    const std::string value_key = torque ? "torque" : "force";
    if (torque) Keys(n, kind, {"body", "torque"});
    else Keys(n, kind, {"point", "force", "frame"});
    SpatialLoad f;
    f.src = At(n);
    std::string what;
    if (torque) {
      f.body = SpatialBodyRef(n["body"], "torque body");
      const SpatialBody& b = m_.spatial.bodies[f.body];
      if (b.entities.size() < 4) {
        const bool point_mass = b.entities.size() == 1;
        const std::string& e0 = m_.spatial.entities[b.entities[0]].name;
        throw ScenarioError(At(n["body"]), "torque on body " + b.name + ", " +
                                               (point_mass ? "a point mass (the one point " + e0 + ")"
                                                           : "a bar (" + std::to_string(b.entities.size()) + " entities)") +
                                               ": a torque in 3-D turns a rigid body's basis (four entities or more), "
                                               "and a " + (point_mass ? "point mass" : "bar") + " has none",
                            point_mass ? "a point mass takes forces only: write {point: " + e0 + ", force: [Fx, Fy, Fz]} "
                                         "(a law of t, q.<slot>, qd.<slot> may turn it), or make " + b.name +
                                         " a rigid body (a point and three more points or unit vectors) to apply a torque"
                                       : "apply a couple of point forces to the bar's ends, {point: " + e0 +
                                         ", force: [Fx, Fy, Fz]} and the opposite force at its other end, or make " +
                                         b.name + " a rigid body (a point and three more points or unit vectors)");
      }
      what = "torque on " + b.name;
    } else {
      f.point = SpatialPointRef(n["point"], "force point");
      what = "force at " + m_.spatial.entities[f.point].name;
      if (n["frame"]) f.frame = SpatialForceFrame(n["frame"], f.point);
    }
    const YAML::Node vn = Required(n, value_key.c_str(), kind, value_key + (torque ? ": [Tx, Ty, Tz] [N·m], world axes" : ": [Fx, Fy, Fz] [N], world axes"));
    const auto comp = Seq(vn, value_key, 3);
    std::vector<double> x(1 + 2 * m_.q_layout.size(), 0.0);  // t0 and the file's guesses at rest
    x[kLoadVarTime] = m_.analysis.t0;
    const Eigen::VectorXd guess = m_.GuessQ();
    for (int i = 0; i < guess.size(); ++i) x[LoadVarQ(i)] = guess[i];
    for (int k = 0; k < 3; ++k) {
      const std::string wk = what + " [" + std::to_string(k) + "]";
      CompiledExpr law = CompileLoad(comp[k], wk, UnitField::kPlain, torque ? "N·m" : "N");
      if (law.variables().empty()) {
        f.value[k] = Load(comp[k], wk, torque ? "N·m" : "N", true);
        continue;
      }
      f.value[k] = law.Eval(x.data());
      if (!std::isfinite(f.value[k]))
        throw ScenarioError(At(comp[k]), wk + " \"" + law.text() + "\" is not finite at t0 = " + Fmt(m_.analysis.t0, 6) +
                                             " s in the file's guesses at rest",
                            "a load defined over the whole motion");
      f.law[k] = std::make_shared<const CompiledExpr>(std::move(law));
    }
    (torque ? m_.spatial.torques : m_.spatial.forces).push_back(f);
  }

  // A load's magnitude within kMassMagnitude (as masses): k·L, c·L̇ and T·ω stay inside double's range.
  double Load(const YAML::Node& n, const std::string& what, const std::string& unit, bool signed_value) {
    const double v = Num(n, what, UnitField::kPlain, unit);
    if (!signed_value && v < 0)
      throw ScenarioError(At(n), what + " is " + Fmt(v, 6) + " " + unit + ": it cannot be negative",
                          "give 0 or a positive value");
    if (v != 0 && !(std::fabs(v) >= 1 / kMassMagnitude && std::fabs(v) <= kMassMagnitude))
      throw ScenarioError(At(n), what + " of " + Fmt(v, 3) + " " + unit +
                                     " is beyond what the dynamics can multiply in double precision (a nonzero value "
                                     "must lie within 1e-100 … 1e100 in magnitude)",
                          "check its units and exponent");
    return v;
  }

  void ReadSpring(const YAML::Node& n) {
    Keys(n, "spring–damper", {"between", "stiffness", "damping", "free_length", "preload"});
    SpringDamper s;
    s.src = At(n);
    s.points = m_.kind == ScenarioKind::kSpatial ? SpatialPointPair(n["between"], "spring–damper between")
                                                 : PointPair(n["between"], "spring–damper between");
    if (!n["stiffness"] && !n["damping"])
      throw ScenarioError(s.src, "a spring–damper needs 'stiffness' or 'damping'",
                          "stiffness: k [N/m] and free_length: L0; damping: c [N·s/m]");
    if (n["stiffness"]) s.stiffness = SpringParam(n["stiffness"], s, SpringDamper::kStiffness);
    if (n["damping"]) s.damping = SpringParam(n["damping"], s, SpringDamper::kDamping);
    if (n["preload"]) s.preload = SpringParam(n["preload"], s, SpringDamper::kPreload);
    const YAML::Node l0 = Required(n, "free_length", "spring–damper",
                                   "free_length: L0 in the file's length unit (" + m_.length_unit + ")");
    s.free_length = SpringParam(l0, s, SpringDamper::kFreeLength);
    if (m_.kind == ScenarioKind::kSpatial) return AddSpatialSpring(n, s);
    const Point &a = m_.points[s.points[0]], &b = m_.points[s.points[1]];
    if (a.fixed && b.fixed) {
      const double apart = (b.p_W - a.p_W).norm(), scale = std::max(a.p_W.norm(), b.p_W.norm());
      if (!(apart > kDirectionResolution * scale))
        throw ScenarioError(At(n["between"]), "the spring–damper between " + a.name + " and " + b.name +
                                                  " joins two fixed points at one place " + XY(a.p_W) +
                                                  ": its line of action has no direction",
                            "attach at least one end to a moving point");
    }
    m_.springs.push_back(s);
  }

  // One of a spring–damper's parameters: a number (checked as before) or a law of t, q.<slot>,
  // qd.<slot> (CompileLoad), kept in s.law; the value returned is the number, or the law's value at t0
  // in the file's guesses at rest, which must be finite (and ≥ 0 for k, c and L0).
  double SpringParam(const YAML::Node& n, SpringDamper& s, SpringDamper::Param p) {
    static const char* const kName[] = {"stiffness", "damping", "free_length", "preload"};
    const std::string what = std::string("spring–damper ") + kName[p];
    const std::string unit = p == SpringDamper::kStiffness ? "N/m"
                             : p == SpringDamper::kDamping ? "N·s/m"
                             : p == SpringDamper::kPreload ? "N"
                                                            : m_.length_unit;
    CompiledExpr law = CompileLoad(n, what, p == SpringDamper::kFreeLength ? UnitField::kLength : UnitField::kPlain, unit);
    if (law.variables().empty()) {
      if (p != SpringDamper::kFreeLength) return Load(n, what, unit, p == SpringDamper::kPreload);
      const double L0 = Num(n, what, UnitField::kLength, unit);
      if (!(L0 >= 0) || L0 > kMassMagnitude)
        throw ScenarioError(At(n), what + " is " + Fmt(L0, 6) + " " + unit + ": it must be 0 or positive (and at most 1e100)",
                            "give the spring's length when it carries no force (the preload aside)");
      return L0;
    }
    std::vector<double> x(1 + 2 * m_.q_layout.size(), 0.0);  // t0 and the file's guesses at rest
    x[kLoadVarTime] = m_.analysis.t0;
    const Eigen::VectorXd guess = m_.GuessQ();
    for (int i = 0; i < guess.size(); ++i) x[LoadVarQ(i)] = guess[i];
    const double v = law.Eval(x.data());
    if (!std::isfinite(v))
      throw ScenarioError(At(n), what + " \"" + law.text() + "\" is not finite at t0 = " + Fmt(m_.analysis.t0, 6) +
                                     " s in the file's guesses at rest",
                          "a law defined over the whole motion");
    if (p != SpringDamper::kPreload && v < 0)
      throw ScenarioError(At(n), what + " \"" + law.text() + "\" is " + Fmt(v, 6) + " " + unit + " at t0 = " +
                                     Fmt(m_.analysis.t0, 6) + " s in the file's guesses at rest: it cannot be negative",
                          "a law that is 0 or positive at the start (e.g. max(0, ...)); along the motion its value is "
                          "used as given");
    s.law[p] = std::make_shared<const CompiledExpr>(std::move(law));
    return v;
  }

  // {point: P, force: [Fx, Fy], frame: B}: each component a number or an expression of t, q.<slot>,
  // qd.<slot> (CompileLoad); in the world frame, or in body B's frame (one of P's bodies, ≥ 2 points).
  void ReadPointForce(const YAML::Node& n) {
    Keys(n, "point force", {"point", "force", "frame"});
    PointForce f;
    f.src = At(n);
    f.point = PointRef(n["point"], "force point");
    const std::string& pname = m_.points[f.point].name;
    if (n["frame"]) {
      f.frame = BodyRef(n["frame"], "force frame");
      const Body& b = m_.bodies[f.frame];
      if (b.points.size() < 2)
        throw ScenarioError(At(n["frame"]), "force at " + pname + " in the frame of body " + b.name + ", which has " +
                                                std::to_string(b.points.size()) +
                                                " point(s): a body's frame is the direction of its first two points",
                            "name a linkage body with at least two points, or leave `frame` out for world components");
      if (std::find(b.points.begin(), b.points.end(), f.point) == b.points.end()) {
        std::vector<std::string> names;
        for (int p : b.points) names.push_back(m_.points[p].name);
        throw ScenarioError(At(n["frame"]), "force at " + pname + " in the frame of body " + b.name +
                                                ", which does not carry point " + pname +
                                                ": a follower force acts on the body it turns with",
                            "apply it at one of " + b.name + "'s points (" + Join(names) +
                                "), or name a body that carries " + pname);
      }
    }
    const YAML::Node fn = Required(n, "force", "point force", "force: [Fx, Fy]");
    const auto comp = Seq(fn, "force", 2);
    const std::string what = "force at " + pname;
    std::vector<double> x(1 + 2 * m_.q_layout.size(), 0.0);  // t0 and the file's guesses at rest
    x[kLoadVarTime] = m_.analysis.t0;
    const Eigen::VectorXd guess = m_.GuessQ();
    for (int i = 0; i < guess.size(); ++i) x[LoadVarQ(i)] = guess[i];
    Eigen::Vector2d at_t0;
    for (int k = 0; k < 2; ++k) {
      const std::string wk = what + " [" + std::to_string(k) + "]";
      CompiledExpr law = CompileLoad(comp[k], wk, UnitField::kPlain, "N");
      if (law.variables().empty()) {
        f.components[k] = Num(comp[k], wk, UnitField::kPlain, "N");
        at_t0[k] = f.components[k];
        continue;
      }
      at_t0[k] = law.Eval(x.data());
      if (!std::isfinite(at_t0[k]))
        throw ScenarioError(At(comp[k]), wk + " \"" + law.text() + "\" is not finite at t0 = " + Fmt(m_.analysis.t0, 6) +
                                             " s in the file's guesses at rest",
                            "a force defined over the whole motion");
      f.law[k] = std::make_shared<const CompiledExpr>(std::move(law));
    }
    f.f_W = at_t0;
    if (f.frame >= 0) {  // turned by the body's direction in the file
      const Body& b = m_.bodies[f.frame];
      const Eigen::Vector2d d = m_.points[b.points[1]].p_W - m_.points[b.points[0]].p_W;
      if (d.norm() > 0) f.f_W = (at_t0.x() * d + at_t0.y() * Eigen::Vector2d(-d.y(), d.x())) / d.norm();
    }
    m_.forces.push_back(f);
  }

  void ReadTorque(const YAML::Node& n) {
    Keys(n, "torque", {"body", "torque"});
    BodyTorque t;
    t.src = At(n);
    t.body = BodyRef(n["body"], "torque body");
    const Body& b = m_.bodies[t.body];
    if (b.points.size() < 2)
      throw ScenarioError(At(n["body"]), "torque on body " + b.name + ", which has " + std::to_string(b.points.size()) +
                                             " point(s): a torque acts through the direction of a body's first two points",
                          "apply it to a linkage body with at least two points");
    const YAML::Node tn = Required(n, "torque", "torque", "torque: T [N·m], counter-clockwise positive");
    CompiledExpr law = CompileLoad(tn, "torque on " + b.name, UnitField::kPlain, "N·m");
    if (law.variables().empty()) {
      t.torque = Load(tn, "torque", "N·m", true);
    } else {
      // Its value at t0 in the file's guesses at rest: a size for the comparisons' scales.
      std::vector<double> x(1 + 2 * m_.q_layout.size(), 0.0);
      x[kLoadVarTime] = m_.analysis.t0;
      const Eigen::VectorXd guess = m_.GuessQ();
      for (int i = 0; i < guess.size(); ++i) x[LoadVarQ(i)] = guess[i];
      t.torque = law.Eval(x.data());
      if (!std::isfinite(t.torque))
        throw ScenarioError(At(tn), "torque on " + b.name + " \"" + law.text() + "\" is not finite at t0 = " +
                                        Fmt(m_.analysis.t0, 6) + " s in the file's guesses at rest",
                            "a torque defined over the whole motion");
      t.law = std::make_shared<const CompiledExpr>(std::move(law));
    }
    m_.torques.push_back(t);
  }

  // A load's expression over t, q.<slot>, qd.<slot> (model.h: LoadVarQ) and the file's constants.
  CompiledExpr CompileLoad(const YAML::Node& n, const std::string& what, UnitField field = UnitField::kAny,
                           const std::string& unit = "") {
    if (!n.IsScalar()) throw ScenarioError(At(n), what + " must be a number or an expression of t, q.<slot>, qd.<slot>",
                          "write one number or one quoted expression on this line");
    CheckLawUnitWords(n, what, field, unit);
    const int count = static_cast<int>(m_.q_layout.size());
    try {
      return CompiledExpr::Compile(n.as<std::string>(), [&](const std::string& name) -> std::optional<CompiledExpr::Binding> {
        if (name == "t") return CompiledExpr::Binding{kLoadVarTime, 0};
        for (const char* prefix : {"q.", "qd."}) {
          const std::string p = prefix;
          if (name.rfind(p, 0) != 0) continue;
          const int slot = m_.SlotIndex(name.substr(p.size()));
          if (slot < 0) return std::nullopt;
          return CompiledExpr::Binding{p == "q." ? LoadVarQ(slot) : LoadVarQd(slot, count), 0};
        }
        if (auto it = m_.constants.find(name); it != m_.constants.end()) return CompiledExpr::Binding{-1, it->second};
        return std::nullopt;
      });
    } catch (const ExprError& e) {
      if (!e.fix.empty()) throw ScenarioError(At(n), what + ": " + e.what(), e.fix);
      std::vector<std::string> names;
      for (const auto& sl : m_.q_layout) names.push_back(sl.name);
      throw ScenarioError(At(n), what + ": " + e.what(),
                          "a load may use t [s], q.<slot> and qd.<slot> for the slots " + Join(names) +
                              ", the file's constants" + ConstantsInFile() +
                              ", pi, unit words and sin, cos, exp, … (FORMAT.md, forces)");
    }
  }

  // " (F0, omega0)", or " (none: add `constants: {NAME: value}`)": the names a law could have meant.
  std::string ConstantsInFile() const {
    if (m_.constants.empty()) return " (none in this file: define one under constants: {NAME: value})";
    std::vector<std::string> names;
    for (const auto& kv : m_.constants) names.push_back(kv.first);
    return " (" + Join(names) + ")";
  }

  // A torsion's parameter is a constant (a number or an expression of the file's constants). A
  // law of t, q.<slot>, qd.<slot> there is refused as such, with the load that takes one, rather
  // than as "unknown name 't'".
  double TorsionParam(const YAML::Node& n, const std::string& what, const std::string& unit, bool signed_value) {
    if (n.IsScalar() && NamesLoadVariable(n.as<std::string>()))
      throw ScenarioError(At(n), what + " \"" + n.as<std::string>() + "\" is a law: a torsion's stiffness, damping and "
                                     "preload are constants (numbers or expressions of the file's constants)",
                          "keep the constant part here and add the varying torque as a load law on the turning body, "
                          "{body: B, torque: LAW} (in 3-D {body: B, torque: [Tx, Ty, Tz]}, the law times the hinge "
                          "axis' components; FORMAT.md, forces)");
    return Load(n, what, unit, signed_value);
  }
  // Whether `text` reads as an expression that names t, q.<slot> or qd.<slot> (a load law).
  bool NamesLoadVariable(const std::string& text) const {
    bool names = false;
    try {
      (void)EvalExpr(text, [&](const std::string& name) -> std::optional<double> {
        if (auto it = m_.constants.find(name); it != m_.constants.end()) return it->second;
        const bool slot = (name.rfind("q.", 0) == 0 && m_.SlotIndex(name.substr(2)) >= 0) ||
                          (name.rfind("qd.", 0) == 0 && m_.SlotIndex(name.substr(3)) >= 0);
        if (name != "t" && !slot) return std::nullopt;
        names = true;
        return 1.0;
      });
    } catch (const ExprError&) {
      return false;
    }
    return names;
  }

  void ReadTorsion(const YAML::Node& n) {
    Keys(n, "torsional spring–damper", {"torsion", "stiffness", "damping", "free_angle", "preload"});
    TorsionSpring ts;
    ts.src = At(n);
    ts.coordinate = Str(n["torsion"], "torsion");
    if (m_.kind == ScenarioKind::kSpatial) {  // on a spatial angle coordinate (a revolute joint's)
      std::vector<std::string> angles;
      for (const SpatialCoordinate& co : m_.spatial.coordinates)
        if (co.IsAngle()) angles.push_back(co.name);
      if (std::find(angles.begin(), angles.end(), ts.coordinate) == angles.end())
        throw ScenarioError(At(n["torsion"]), "torsion names '" + ts.coordinate + "', which is not an angle coordinate",
                            angles.empty() ? std::string("declare one under coordinates: {type: angle, axis: a, from: u, to: w}")
                                           : "angle coordinates are: " + Join(angles));
    } else {
      int c = -1;
      for (size_t i = 0; i < m_.coordinates.size(); ++i)
        if (m_.coordinates[i].name == ts.coordinate) c = static_cast<int>(i);
      if (c < 0 || m_.coordinates[c].type != CoordinateType::kAngle) {
        std::vector<std::string> angles;
        for (const Coordinate& co : m_.coordinates)
          if (co.type == CoordinateType::kAngle) angles.push_back(co.name);
        throw ScenarioError(At(n["torsion"]), "torsion names '" + ts.coordinate + "', which is not an angle coordinate",
                            angles.empty() ? std::string("declare one under coordinates: {type: angle, vector: [P, Q]} (with "
                                                         "reference: [R, S] for the angle between two bodies at their pin)")
                                           : "angle coordinates are: " + Join(angles));
      }
    }
    ts.slot = m_.SlotIndex(ts.coordinate);
    if (!n["stiffness"] && !n["damping"])
      throw ScenarioError(ts.src, "a torsional spring–damper needs 'stiffness' or 'damping'",
                          "stiffness: k [N·m/rad] and free_angle: θ0; damping: c [N·m·s/rad]");
    if (n["stiffness"]) ts.stiffness = TorsionParam(n["stiffness"], "torsion stiffness", "N·m/rad", false);
    if (n["damping"]) ts.damping = TorsionParam(n["damping"], "torsion damping", "N·m·s/rad", false);
    if (n["preload"]) ts.preload = TorsionParam(n["preload"], "torsion preload", "N·m", true);
    if (n["free_angle"]) ts.free_angle = Num(n["free_angle"], "torsion free_angle");
    else if (ts.stiffness > 0)
      throw ScenarioError(ts.src, "a torsional spring needs its free_angle", "free_angle: θ0 (e.g. 0 or 30 deg)");
    m_.torsions.push_back(ts);
  }

  void ReadPlane(const YAML::Node& n) {
    if (!n) return;
    Keys(n, "plane", {"origin", "u", "v"});
    if (n["origin"]) m_.embedding.origin = Vec3(n["origin"], "plane origin");
    if (n["u"]) m_.embedding.u = Vec3(n["u"], "plane u");
    if (n["v"]) m_.embedding.v = Vec3(n["v"], "plane v");
    const Embedding& e = m_.embedding;
    if (std::fabs(e.u.norm() - 1) > 1e-12 || std::fabs(e.v.norm() - 1) > 1e-12 || std::fabs(e.u.dot(e.v)) > 1e-12)
      throw ScenarioError(At(n), "plane u and v must be orthonormal", "use unit vectors at right angles, e.g. [0,1,0] and [0,0,1]");
  }

  void ReadFrame(const YAML::Node& n) {
    if (!n) return;
    Keys(n, "frame_rotation", {"axis_point", "axis", "omega"});
    FrameRotation f;
    f.axis_point = Vec3(Required(n, "axis_point", "frame_rotation", "axis_point: [x, y, z]"), "axis_point");
    f.axis = Vec3(Required(n, "axis", "frame_rotation", "axis: [x, y, z]"), "axis");
    if (!(f.axis.norm() > 0))
      throw ScenarioError(At(n["axis"]), "frame_rotation axis is zero", "the direction the frame turns about, e.g. axis: [0, 0, 1]");
    f.axis.normalize();
    f.omega = Num(Required(n, "omega", "frame_rotation", "omega: rad/s"), "omega", UnitField::kAngularRate, "rad/s");
    m_.frame = f;
  }

  // `reference: {exact: NAME}`: the name only; the registry checks it (model.h, ExactReferenceName).
  void ReadReference(const YAML::Node& n) {
    if (!n) return;
    Keys(n, "reference", {"exact"});
    const YAML::Node e = Required(n, "exact", "reference", "name the exact solution: reference: {exact: pendulum}");
    const std::string name = Str(e, "reference exact");
    const bool plain = !name.empty() && std::all_of(name.begin(), name.end(), [](char ch) {
      return std::islower(static_cast<unsigned char>(ch)) || std::isdigit(static_cast<unsigned char>(ch)) || ch == '_';
    });
    if (!plain)
      throw ScenarioError(At(e), "reference exact '" + name + "' is not a plain name",
                          "a registry name in lower case, e.g. pendulum or nfourbar");
    m_.exact_reference = ExactReferenceName{name, At(e)};
  }

  // `criteria: {point, levels, output_steps, source}` (model.h, Criteria).
  void ReadCriteria(const YAML::Node& n) {
    if (!n) return;
    Keys(n, "criteria", {"point", "levels", "output_steps", "source"});
    Criteria c;
    c.src = At(n);
    const YAML::Node pn = Required(n, "point", "criteria", "the point whose position is judged: point: P1");
    bool fixed = false;
    if (m_.kind == ScenarioKind::kSpatial) {  // a spatial point: its entity
      c.name = Str(pn, "criteria point");
      c.point = m_.spatial.EntityIndex(c.name);
      if (c.point < 0 || m_.spatial.entities[c.point].vector) {
        std::vector<std::string> names;
        for (const SpatialEntity& e : m_.spatial.entities)
          if (!e.vector && !e.fixed) names.push_back(e.name);
        throw ScenarioError(At(pn), "criteria point '" + c.name + "' is " +
                                        (c.point < 0 ? std::string("not a point of the scene")
                                                     : "a unit vector, not a point: criteria judge a point's position"),
                            "name a moving point: " + Join(names));
      }
      fixed = m_.spatial.entities[c.point].fixed;
    } else {
      c.point = PointRef(pn, "criteria point");
      c.name = m_.points[c.point].name;
      fixed = m_.points[c.point].fixed;
    }
    if (fixed)
      throw ScenarioError(At(pn), "criteria point " + c.name + " is fixed: it has no error to judge", "name a moving point");
    const YAML::Node lv = Required(n, "levels", "criteria", "the allowed position errors: levels: [1e-3, 1e-1]");
    const std::vector<YAML::Node> items = Seq(lv, "criteria levels", 0);
    if (items.empty()) throw ScenarioError(At(lv), "criteria levels is empty", "give at least one level: [1e-3, 1e-1]");
    for (const YAML::Node& l : items) {
      const double v = Num(l, "criteria level");
      if (!(v > 0)) throw ScenarioError(At(l), "a criteria level must be a positive length", "write e.g. 1e-3");
      if (!c.levels.empty() && !(v > c.levels.back()))
        throw ScenarioError(At(l), "criteria levels must be ascending and distinct (the finest first)",
                            "write them as [1e-3, 1e-1]");
      c.levels.push_back(v);
    }
    const int motion_steps = m_.analysis.HasMotion() ? m_.analysis.samples - 1 : 0;
    const std::string steps_here = motion_steps > 0 ? std::to_string(motion_steps) : "N";
    const YAML::Node os = Required(n, "output_steps", "criteria",
                                   "the benchmark's number of output steps, the motion's samples − 1: output_steps: " + steps_here);
    c.output_steps = Int(os, "criteria output_steps", "the benchmark's number of output steps, the motion's samples − 1",
                         "output_steps: " + steps_here);
    if (c.output_steps < 1)
      throw ScenarioError(At(os), "criteria output_steps " + std::to_string(c.output_steps) + " is not a number of steps",
                          "the motion's samples − 1: output_steps: " + steps_here);
    if (!m_.drivers.empty())
      throw ScenarioError(At(n), "criteria judge a free scene's motion (forward dynamics against its reference), and this "
                                 "scene is driven: its motion is the drivers' laws",
                          "remove `criteria:`, or make the scene free: initial conditions instead of drivers");
    if (!m_.analysis.HasMotion())
      throw ScenarioError(At(n), "criteria judge a free scene's motion, and this scene has none",
                          "give it analysis: {t0, t1, samples} with samples = output_steps + 1");
    if (c.output_steps != m_.analysis.samples - 1)
      throw ScenarioError(At(os), "criteria output_steps " + std::to_string(c.output_steps) + " does not match the motion's " +
                                      std::to_string(m_.analysis.samples) + " samples (output steps + 1)",
                          "output_steps: " + steps_here + " (the error is measured at the samples), or analysis samples: " +
                              std::to_string(c.output_steps + 1) + " if the benchmark's output steps are " +
                              std::to_string(c.output_steps));
    if (n["source"]) c.source = Str(n["source"], "criteria source");
    m_.criteria = c;
  }

  void ReadAnalysis(const YAML::Node& n) {
    if (!n) return;
    Keys(n, "analysis", {"t0", "t1", "samples"});
    if (n["t0"]) m_.analysis.t0 = Num(n["t0"], "analysis t0", UnitField::kTime, "s");
    if (n["t1"] || n["samples"]) {
      if (!n["t1"] || !n["samples"]) throw ScenarioError(At(n), "a motion needs both t1 and samples",
                          "give both, e.g. analysis: {t0: 0, t1: 1, samples: 101}, or neither for one instant");
      m_.analysis.t1 = Num(n["t1"], "analysis t1", UnitField::kTime, "s");
      if (n["samples"].IsScalar())
        if (const double samples = Num(n["samples"], "analysis samples");
            samples > 1000000 || (samples < 2 && samples == std::floor(samples)))
          throw ScenarioError(At(n["samples"]),
                              "analysis samples is " + Fmt(samples, 3) + ", " +
                                  (samples > 1000000 ? "beyond the limit of 1000000" : "below 2 (a motion starts and ends)") +
                                  ": samples must be between 2 and 1000000",
                              "give 2 … 1000000 samples (e.g. 101); for more, split the motion into runs with their own t0");
      m_.analysis.samples = Int(n["samples"], "analysis samples", "the number of output samples, from t0 to t1 inclusive",
                                "samples: 101 (every (t1 − t0)/100 s)");
      if (!(m_.analysis.t1 > m_.analysis.t0)) throw ScenarioError(At(n["t1"]), "analysis t1 must be after t0",
                          "give t1 greater than t0 (" + Fmt(m_.analysis.t0) + " s)");
      if (m_.analysis.samples < 2 || m_.analysis.samples > 1000000)
        throw ScenarioError(At(n["samples"]), "analysis samples must be between 2 and 1000000", "give 2 … 1000000 samples");
      // The sample times must be told apart by more than the rounding of t itself (kTimeResolution).
      const Analysis& a = m_.analysis;
      const double interval = (a.t1 - a.t0) / (a.samples - 1);
      const double t_max = std::max(std::fabs(a.t0), std::fabs(a.t1));
      if (!(interval >= kTimeResolution * t_max))
        throw ScenarioError(At(n["t0"] ? n["t0"] : n["t1"]),
                            (std::fabs(a.t0) >= std::fabs(a.t1) ? "t0 = " + Fmt(a.t0, 3) : "t1 = " + Fmt(a.t1, 3)) +
                                " s is too large for a sample interval of " + Fmt(interval, 3) + " s: a double holds t to " +
                                Fmt(t_max * 1.1e-16, 2) + " s there, " + Fmt(t_max * 1.1e-16 / interval, 2) +
                                " of the interval (the methods are compared to 1e-9)",
                            "count time from the start of the motion (t0: 0, t1: " + Fmt(a.t1 - a.t0, 6) + ")");
    }
  }

  void ReadSynthesis(const YAML::Node& n) {
    if (!n) return;
    Keys(n, "synthesis", {"ratio", "z_min", "z_max", "max_pair_ratio"});
    Synthesis s;
    s.src = At(n);
    s.ratio = Num(Required(n, "ratio", "synthesis", "ratio: out/in, e.g. 221/1005"), "synthesis ratio");
    if (n["z_min"]) s.z_min = Int(n["z_min"], "z_min", "the fewest teeth on a gear", "z_min: 12");
    if (n["z_max"]) s.z_max = Int(n["z_max"], "z_max", "the most teeth on a gear", "z_max: 100");
    if (n["max_pair_ratio"]) s.max_pair_ratio = Num(n["max_pair_ratio"], "max_pair_ratio");
    if (s.z_min < 1 || s.z_max < s.z_min || !(s.ratio > 0) || !(s.max_pair_ratio >= 1))
      throw ScenarioError(s.src, "synthesis limits are inconsistent", "need 1 <= z_min <= z_max, ratio > 0, max_pair_ratio >= 1");
    m_.synthesis = s;
  }

  // Display units of book values: the factor from the printed value to the internal one.
  double UnitFactor(const YAML::Node& n, const std::string& unit) {
    constexpr double kPi = 3.14159265358979323846;
    static const std::map<std::string, double> angular{
        {"", 1}, {"rad", 1}, {"rad/s", 1}, {"rad/s^2", 1}, {"rpm", 2 * kPi / 60},
        {"deg", kPi / 180}, {"deg/s", kPi / 180}, {"deg/s^2", kPi / 180}, {"kg", 1}, {"N", 1}, {"1", 1},
        {"1/s", 1}, {"1/s^2", 1}};
    if (auto it = angular.find(unit); it != angular.end()) return it->second;
    const std::string L = unit.substr(0, unit.find('/'));
    const std::string rest = unit.substr(L.size());
    if ((L == "m" || L == "mm" || L == "cm") && (rest.empty() || rest == "/s" || rest == "/s^2")) {
      if (L != m_.length_unit)
        throw ScenarioError(At(n), "book unit " + unit + " is not in the file's length unit (" + m_.length_unit + ")",
                            "write the book value in " + m_.length_unit);
      return 1.0;
    }
    throw ScenarioError(At(n), "unknown unit '" + unit + "'",
                        "use rad, rad/s, rad/s^2, deg, deg/s, rpm, kg, N, or the file's length unit with /s or /s^2");
  }

  // What a book quantity measures, for its unit: the kind of a single quantity name (method.h),
  // or kUnchecked for an expression (a ratio) and for names of other kinds (M, Q, Φ_q, reactions,
  // synthesis …); a unit vector's component is kDirection (no unit).
  enum class QuantityKind {
    kUnchecked, kAngle, kAngularRate, kAngularAcceleration, kLength, kVelocity, kAcceleration,
    kDirection, kDirectionRate, kDirectionAcceleration  // a unit vector's component (no unit), its rates
  };
  static const char* KindText(QuantityKind k) {
    switch (k) {
      case QuantityKind::kAngle: return "an angle";
      case QuantityKind::kAngularRate: return "an angular velocity";
      case QuantityKind::kAngularAcceleration: return "an angular acceleration";
      case QuantityKind::kLength: return "a length";
      case QuantityKind::kVelocity: return "a velocity";
      case QuantityKind::kAcceleration: return "an acceleration";
      case QuantityKind::kDirection: return "a unit vector's component (a number without unit)";
      case QuantityKind::kDirectionRate: return "a unit vector's component's rate";
      case QuantityKind::kDirectionAcceleration: return "a unit vector's component's acceleration";
      case QuantityKind::kUnchecked: break;
    }
    return "a quantity";
  }
  static constexpr QuantityKind kDirectionKinds[3] = {QuantityKind::kDirection, QuantityKind::kDirectionRate,
                                                       QuantityKind::kDirectionAcceleration};
  QuantityKind KindOfQuantity(const std::string& q) const {
    std::vector<std::string> part;
    for (size_t at = 0;;) {
      const size_t dot = q.find('.', at);
      part.push_back(q.substr(at, dot == std::string::npos ? std::string::npos : dot - at));
      if (dot == std::string::npos) break;
      at = dot + 1;
    }
    for (char c : q)
      if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '.')) return QuantityKind::kUnchecked;
    const auto by_order = [](bool angle, int order) {
      static constexpr QuantityKind kAngular[3] = {QuantityKind::kAngle, QuantityKind::kAngularRate,
                                                   QuantityKind::kAngularAcceleration};
      static constexpr QuantityKind kLinear[3] = {QuantityKind::kLength, QuantityKind::kVelocity, QuantityKind::kAcceleration};
      return angle ? kAngular[order] : kLinear[order];
    };
    // A coordinate's value, rate or acceleration: an angle's or a length's.
    const auto slot_kind = [&](const std::string& name, int order) {
      const int s = m_.SlotIndex(name);
      if (s < 0) return QuantityKind::kUnchecked;
      const Model::Slot& slot = m_.q_layout[s];
      if (IsAngleSlot(s)) return by_order(true, order);
      if (slot.spatial_coordinate >= 0) return by_order(m_.spatial.coordinates[slot.spatial_coordinate].IsAngle(), order);
      if (slot.entity >= 0)  // a point's component is a length; a unit vector's has no unit
        return m_.spatial.entities[slot.entity].vector ? kDirectionKinds[order] : by_order(false, order);
      return by_order(false, order);  // a point's component, a distance, a rack's travel
    };
    const std::string& head = part[0];
    if (part.size() == 2 && (head == "q" || head == "qd" || head == "qdd"))
      return slot_kind(part[1], head == "q" ? 0 : head == "qd" ? 1 : 2);
    if (part.size() == 3 && head == "newton") return slot_kind(part[2], 0);
    if (part.size() == 2 && head == "omega") return QuantityKind::kAngularRate;
    if (part.size() == 2 && head == "alpha") return QuantityKind::kAngularAcceleration;
    if (part.size() == 3 && head == "omegaabs") return QuantityKind::kAngularRate;
    if (part.size() == 3 && (head == "vabs" || head == "aabs")) return head == "vabs" ? QuantityKind::kVelocity : QuantityKind::kAcceleration;
    if (part.size() == 3 && (head == "p" || head == "v" || head == "a")) {
      if (const int e = m_.spatial.EntityIndex(part[1]); e >= 0 && m_.spatial.entities[e].vector)
        return kDirectionKinds[head == "p" ? 0 : head == "v" ? 1 : 2];
      return by_order(false, head == "p" ? 0 : head == "v" ? 1 : 2);
    }
    return QuantityKind::kUnchecked;
  }
  // The units a quantity of that kind accepts (UnitFactor's), and whether `unit` is one of them.
  std::string UnitsFor(QuantityKind k) const {
    const std::string& L = m_.length_unit;
    switch (k) {
      case QuantityKind::kAngle: return "rad or deg";
      case QuantityKind::kAngularRate: return "rad/s, deg/s or rpm";
      case QuantityKind::kAngularAcceleration: return "rad/s^2 or deg/s^2";
      case QuantityKind::kLength: return L;
      case QuantityKind::kVelocity: return L + "/s";
      case QuantityKind::kAcceleration: return L + "/s^2";
      case QuantityKind::kDirection: return "1";
      case QuantityKind::kDirectionRate: return "1/s";
      case QuantityKind::kDirectionAcceleration: return "1/s^2";
      case QuantityKind::kUnchecked: break;
    }
    return "";
  }
  void CheckUnitFitsQuantity(const YAML::Node& n, const std::string& unit, const std::string& quantity) const {
    const QuantityKind k = KindOfQuantity(quantity);
    if (k == QuantityKind::kUnchecked) return;
    static const std::map<std::string, QuantityKind> angular{
        {"rad", QuantityKind::kAngle},           {"deg", QuantityKind::kAngle},
        {"rad/s", QuantityKind::kAngularRate},   {"deg/s", QuantityKind::kAngularRate},
        {"rpm", QuantityKind::kAngularRate},     {"rad/s^2", QuantityKind::kAngularAcceleration},
        {"deg/s^2", QuantityKind::kAngularAcceleration}};
    QuantityKind u = QuantityKind::kUnchecked;  // kg, N, 1: none of the kinds above
    if (auto it = angular.find(unit); it != angular.end()) u = it->second;
    else if (unit == m_.length_unit) u = QuantityKind::kLength;
    else if (unit == m_.length_unit + "/s") u = QuantityKind::kVelocity;
    else if (unit == m_.length_unit + "/s^2") u = QuantityKind::kAcceleration;
    else if (unit == "1") u = QuantityKind::kDirection;
    else if (unit == "1/s") u = QuantityKind::kDirectionRate;
    else if (unit == "1/s^2") u = QuantityKind::kDirectionAcceleration;
    if (u == k) return;
    // "1" on another kind of quantity: said as for any other unit that does not fit.
    if (u == QuantityKind::kDirection && k != QuantityKind::kDirection) u = QuantityKind::kUnchecked;
    throw ScenarioError(At(n), "book unit " + unit + " does not fit " + quantity + ", " + KindText(k) +
                                   (u == QuantityKind::kUnchecked ? std::string() : std::string(" (") + unit + " is " + KindText(u) + "'s unit)"),
                        "give " + quantity + " in " + UnitsFor(k) + " (or leave the unit out for " +
                            (k == QuantityKind::kAngle ? "rad" : k == QuantityKind::kAngularRate ? "rad/s"
                             : k == QuantityKind::kAngularAcceleration ? "rad/s^2" : UnitsFor(k)) + "), or claim the quantity the value is");
  }

  void ReadBook(const YAML::Node& book) {
    if (!book) return;
    for (const YAML::Node& n : Seq(book, "book", 0)) {
      Keys(n, "book value", {"quantity", "value", "unit", "where", "note", "exact", "at", "precision"});
      BookValue b;
      b.src = At(n);
      b.quantity = Str(Required(n, "quantity", "book value", "quantity: a name such as qd.theta"), "quantity");
      b.printed = Str(Required(n, "value", "book value", "value: \"-0.8138\" (quoted, as printed)"), "book value");
      if (n["exact"] && Bool(n["exact"], "exact")) {
        // A symbolic result (3ω0, −2√3 ω0 R) evaluated with the scenario's numbers: no rounding.
        b.value = Num(n["value"], "book value");
        b.last_digit = 0.0;
      } else {
        ParsePrinted(n["value"], b);
      }
      if (n["unit"]) b.unit = Str(n["unit"], "unit");
      b.unit_factor = UnitFactor(n["unit"] ? n["unit"] : n, b.unit);
      if (n["unit"]) CheckUnitFitsQuantity(n["unit"], b.unit, b.quantity);
      b.where = OptStr(n, "where");
      b.note = OptStr(n, "note");
      if (n["at"]) ReadClaimTime(n["at"], b);
      if (n["precision"]) {
        b.precision = Num(n["precision"], "book value precision");
        if (!(b.precision >= 0 && b.precision < 1))
          throw ScenarioError(At(n["precision"]), "book value precision " + Fmt(b.precision, 3) +
                                                      " is not a relative precision (0 ≤ p < 1)",
                              "give the source's stated tolerance, e.g. precision: 1e-14 for rtol = atol = 1e-14");
      }
      try {  // the quantity must at least be a well-formed expression
        // Every name is taken as known but the reader's own (pi, unit words), which compare.cc's
        // lookup leaves to the reader too, unless a coordinate has that name.
        EvalExpr(b.quantity, [this](const std::string& name) {
          const bool reader = name == "pi" || IsUnitWord(name);
          return reader && m_.SlotIndex(name) < 0 ? std::nullopt : std::optional<double>(1.0);
        });
      } catch (const ExprError& e) {
        throw ScenarioError(At(n["quantity"]), e.what(), e.fix.empty() ? "see the quantity names in FORMAT.md" : e.fix);
      }
      m_.book.push_back(b);
    }
  }

  // `at:` a time of the motion, which must be one of its samples (the claim is read off them).
  void ReadClaimTime(const YAML::Node& n, BookValue& b) {
    b.at = Num(n, "book value at");
    const Analysis& a = m_.analysis;
    if (!a.HasMotion())
      throw ScenarioError(At(n), "book value at t = " + Fmt(b.at, 6) + " s, but the scene has no motion",
                          "add analysis: {t0: ..., t1: ..., samples: ...} with a sample at that time, or remove at:");
    const double interval = (a.t1 - a.t0) / (a.samples - 1);
    const double k = std::round((b.at - a.t0) / interval);
    if (!(k >= 0 && k <= a.samples - 1) || std::fabs(a.TimeAt(static_cast<int>(k)) - b.at) > 1e-9 * interval)
      throw ScenarioError(At(n), "book value at t = " + Fmt(b.at, 9) + " s is not a sample time of the motion (t0 = " +
                                     Fmt(a.t0, 9) + ", t1 = " + Fmt(a.t1, 9) + " s, " + std::to_string(a.samples) +
                                     " samples, every " + Fmt(interval, 6) + " s)",
                          "give the time of a sample, or choose samples: so that one falls on it");
    b.at_sample = static_cast<int>(k);
  }

  // A book value written as an expression of the file's constants ("0.15 + 0.2*pi/w"): its value,
  // nullopt when it is not one either.
  std::optional<double> ValueOfExpression(const std::string& s) const {
    try {
      return EvalExpr(s, [this](const std::string& name) -> std::optional<double> {
        if (auto it = m_.constants.find(name); it != m_.constants.end()) return it->second;
        return std::nullopt;
      });
    } catch (const ExprError&) {
      return std::nullopt;
    }
  }
  std::string AsExpression(const std::string& s) const {
    return ValueOfExpression(s) ? " (it is an expression: a book value is the number as printed, whose digits say "
                                  "how precise it is)"
                                : "";
  }
  std::string BookValueFix(const std::string& s) const {
    if (const auto v = ValueOfExpression(s)) {
      std::ostringstream digits;
      digits.precision(17);
      digits << *v;
      return "keep the expression and add exact: true (a symbolic result, evaluated with the file's constants), or "
             "write its value, value: \"" + digits.str() + "\", with precision: for the tolerance you mean (e.g. "
             "precision: 1e-9)";
    }
    return "write it exactly as printed, e.g. \"-0.8138\", \"3.009951e-2\" or a fraction of whole numbers \"1005/784\"";
  }

  // "−0.8138" claims four decimals; "1.99004910e-2" claims a last digit of 1e-10; a printed
  // fraction "1005/784" is exact.
  void ParsePrinted(const YAML::Node& n, BookValue& b) {
    const std::string& s = b.printed;
    if (const size_t slash = s.find('/'); slash != std::string::npos) {
      char* e1 = nullptr;
      char* e2 = nullptr;
      const long num = std::strtol(s.c_str(), &e1, 10);
      const long den = std::strtol(s.c_str() + slash + 1, &e2, 10);
      if (e1 != s.c_str() + slash || *e2 != '\0' || den == 0)
        throw ScenarioError(At(n), "book value \"" + s + "\" is not a fraction of whole numbers" + AsExpression(s),
                            BookValueFix(s));
      b.value = static_cast<double>(num) / static_cast<double>(den);
      b.last_digit = 0.0;
      return;
    }
    size_t i = 0;
    if (i < s.size() && (s[i] == '-' || s[i] == '+')) ++i;
    size_t digits_before = 0, decimals = 0;
    while (i < s.size() && std::isdigit(static_cast<unsigned char>(s[i]))) ++i, ++digits_before;
    if (i < s.size() && s[i] == '.') {
      ++i;
      while (i < s.size() && std::isdigit(static_cast<unsigned char>(s[i]))) ++i, ++decimals;
    }
    int exponent = 0;
    if (i < s.size() && (s[i] == 'e' || s[i] == 'E')) {
      char* end = nullptr;
      exponent = static_cast<int>(std::strtol(s.c_str() + i + 1, &end, 10));
      if (end == s.c_str() + i + 1) i = std::string::npos;
      else i = static_cast<size_t>(end - s.c_str());
    }
    if (i != s.size() || digits_before + decimals == 0)
      throw ScenarioError(At(n), "book value \"" + s + "\" is not a plain number" + AsExpression(s), BookValueFix(s));
    b.value = std::strtod(s.c_str(), nullptr);
    b.last_digit = std::pow(10.0, exponent - static_cast<int>(decimals));
  }

  std::string file_;
  Model m_;
  detail::ConstantUnitMap constant_units_;  // the constants written with unit words (constant_units.h)
  std::unordered_map<std::string, int> point_index_, body_index_;
  std::map<std::string, SourceRef> mass_at_;  // where each body's mass is written
  // Gear geometry: whether the file gives any, and where each item is written ("centre NAME",
  // "arm NAME", "planets NAME", "mesh JOINT-INDEX" for a module or radii).
  bool geometry_ = false;
  std::map<std::string, SourceRef> geometry_at_;
  std::vector<YAML::Node> coupling_nodes_;  // joints of type rack or coupling, read after the layout
  // A driver's law with the rate and acceleration the file gives to check it (CheckLaws).
  struct LawCheck {
    size_t driver = 0;
    std::shared_ptr<const CompiledExpr> rate, acceleration;
    SourceRef at, rate_at, acceleration_at;
  };
  std::vector<LawCheck> law_checks_;
};

std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ScenarioError({path, 0}, "cannot open the file", "check the path, or run `mechbench list`");
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace

Model LoadScenarioFromString(const std::string& text, const std::string& name) {
  return Loader(name).Load(text);
}

Model LoadScenario(const std::string& path) { return LoadScenarioFromString(ReadFile(path), path); }

std::string BuiltinScenarioDir() {
  if (const char* env = std::getenv("MECHBENCH_SCENARIOS")) return env;
  return MECHBENCH_SCENARIO_DIR;
}

std::vector<std::string> BuiltinScenarioFiles() {
  std::vector<std::string> files;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(BuiltinScenarioDir(), ec))
    if (e.path().extension() == ".yaml") files.push_back(e.path().string());
  std::sort(files.begin(), files.end());
  return files;
}

std::vector<std::string> BenchmarkScenarioFiles() {
  std::vector<std::string> files;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(fs::path(BuiltinScenarioDir()) / "benchmarks", ec))
    if (e.path().extension() == ".yaml") files.push_back(e.path().string());
  std::sort(files.begin(), files.end());
  return files;
}

std::string ResolveScenario(const std::string& name_or_path) {
  std::error_code ec;
  if (fs::is_regular_file(name_or_path, ec)) return name_or_path;
  for (const std::string& f : BuiltinScenarioFiles())
    if (fs::path(f).stem() == name_or_path) return f;
  if (fs::is_directory(name_or_path, ec))
    throw ScenarioError({name_or_path, 0}, "is a directory, not a scenario file",
                        "give a .yaml file in it (`mechbench list` names the built-in ones)");
  throw ScenarioError({name_or_path, 0}, "no scenario file or built-in scenario of that name",
                      "run `mechbench list` for the names, or give a path to a .yaml file");
}

}  // namespace mechbench
