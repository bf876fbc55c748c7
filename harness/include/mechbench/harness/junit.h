// JUnit XML, the format CI systems read (Jenkins, GitLab, GitHub test reporters): `run --junit`
// and `report --junit` write one test case per (scenario, method) run, and the report one per
// printed book value too. A run outside its tolerance is a failure with the lines that say why; a
// crashed or timed-out method an error; a method that cannot do the scene, or a run outside its
// tolerance that tolerances.yaml lists as a known failure, is skipped with the reason (visible,
// never failing the job); a book value fails only when the methods disagree about it (a book
// value that differs from the methods is the book's error, named in the case's output).
#pragma once

#include "mechbench/harness/compare.h"

#include <nlohmann/json.hpp>

#include <ostream>
#include <string>
#include <vector>

namespace mechbench::harness {

struct JunitCase {
  enum class State { kPassed, kFailed, kError, kSkipped };
  std::string suite;    // "run.fourbar_free", "book.s4_1_two_sliders"
  std::string name;     // "dyn-ali3p", "qd.theta (eq. 4.11)"
  double seconds = 0;
  State state = State::kPassed;
  std::string message;  // one line
  std::string output;   // the details (system-out)
};

void WriteJunit(std::ostream& out, const std::vector<JunitCase>& cases);

// `run`: one case per method of one scenario.
std::vector<JunitCase> JunitCases(const RunReport& report);
// `report`: its run records and book checks (results.schema.json).
std::vector<JunitCase> JunitCases(const nlohmann::json& results);

}  // namespace mechbench::harness
