// The three kinds of failure (see README):
//  - a bug in mechbench            -> MB_ASSERT (always on; aborts with file and line)
//  - bad input (a scenario file)   -> throw ScenarioError naming the file, the line and the fix
//  - a run that diverges           -> a Status in the Result, still a row in every table
#pragma once

#include "mechbench/model.h"

#include <stdexcept>
#include <string>

namespace mechbench {

class ScenarioError : public std::runtime_error {
 public:
  // what() reads "file:line: problem. fix" so that editors can jump to it.
  ScenarioError(const SourceRef& where, const std::string& problem, const std::string& fix = "")
      : std::runtime_error(Format(where, problem, fix)), where_(where), problem_(problem), fix_(fix) {}
  const SourceRef& where() const { return where_; }
  const std::string& problem() const { return problem_; }
  const std::string& fix() const { return fix_; }

 private:
  static std::string Format(const SourceRef& w, const std::string& p, const std::string& f) {
    std::string s = w.file.empty() ? std::string("<scenario>") : w.file;
    if (w.line > 0) s += ":" + std::to_string(w.line);
    s += ": " + p;
    if (!f.empty()) s += " (fix: " + f + ")";
    return s;
  }
  SourceRef where_;
  std::string problem_, fix_;
};

[[noreturn]] void AssertionFailed(const char* expr, const char* file, int line, const char* msg);

}  // namespace mechbench

// Internal consistency checks; always on (a wrong number is worse than a slow one here).
#define MB_ASSERT(cond, msg) \
  ((cond) ? (void)0 : ::mechbench::AssertionFailed(#cond, __FILE__, __LINE__, (msg)))
