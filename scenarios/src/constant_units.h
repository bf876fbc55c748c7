// A constant written with a unit word (constants: {mb: 2 deg}) carries it: a field that names the
// constant outside any function's arguments is held to that word as if it were written there
// ("mass: mb" would otherwise be 0.0349 kg). Internal to the loaders (loader.cc, loader_spatial.cc).
#pragma once

#include "mechbench/expr.h"

#include <algorithm>
#include <map>
#include <string>
#include <vector>

namespace mechbench::detail {

struct ConstantUnitWords {
  std::vector<std::string> words;  // the unit words of the constant's own value (and of constants it names)
  int line = 0;                    // where it is defined
  std::string text;                // as written, and the constants it takes its words from ("0.5*L, L being 1 m")
};
using ConstantUnitMap = std::map<std::string, ConstantUnitWords>;

// The unit words the constants among `names` carry (each once, in order).
inline std::vector<std::string> ConstantsWords(const ConstantUnitMap& constants, const std::vector<std::string>& names) {
  std::vector<std::string> words;
  for (const std::string& name : names)
    if (auto it = constants.find(name); it != constants.end())
      for (const std::string& w : it->second.words)
        if (std::find(words.begin(), words.end(), w) == words.end()) words.push_back(w);
  return words;
}

// What is wrong with the unit words carried by the constants among `names` in a field (empty:
// nothing), as UnitWordsProblem says it of words written there; names the first constant whose
// words do not fit, its line and its text.
inline std::string ConstantUnitWordsProblem(const ConstantUnitMap& constants, const std::vector<std::string>& names,
                                            UnitField field, const std::string& length_unit, const std::string& unit,
                                            std::string& fix) {
  if (field == UnitField::kAny) return {};
  const std::string in = unit.empty() ? std::string("its unit") : unit;
  for (const std::string& name : names) {
    const auto it = constants.find(name);
    if (it == constants.end()) continue;
    const ConstantUnitWords& c = it->second;
    const std::string head = "names constant " + name + " (line " + std::to_string(c.line) + ": " + c.text + "), whose unit word ";
    fix = "if " + name + " is meant in " + in + ", write it on line " + std::to_string(c.line) +
          " as a plain number without the unit word; otherwise name another constant here";
    if (length_unit != "m" && std::find(c.words.begin(), c.words.end(), "m") != c.words.end())
      return head + "'m' reads as 1, but this file's length unit is " + length_unit + " (units: {length: " + length_unit + "})";
    if (const std::string misfit = UnitWordsMisfit(c.words, field); !misfit.empty())
      return head + misfit + " does not fit a value in " + in;
  }
  fix.clear();
  return {};
}

// A field's whole unit check, as both loaders make it: the words written in `text` (UnitWordsProblem:
// "<problem>"), then those the constants among `names` carry ("\"<text>\" <problem>"); the message
// to append to the field's name, or empty.
inline std::string FieldUnitWordsProblem(const ConstantUnitMap& constants, const std::vector<std::string>& units,
                                         const std::vector<std::string>& names, UnitField field,
                                         const std::string& length_unit, const std::string& text,
                                         const std::string& unit, std::string& fix) {
  if (std::string problem = UnitWordsProblem(units, field, length_unit, text, unit, fix); !problem.empty())
    return problem;
  if (std::string problem = ConstantUnitWordsProblem(constants, names, field, length_unit, unit, fix); !problem.empty())
    return "\"" + text + "\" " + problem;
  return {};
}

}  // namespace mechbench::detail
