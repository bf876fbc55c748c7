// The published benchmarks' precision levels in the results (records of kind "precision"): per
// benchmark, per method, the CPU time of the cheapest run that met each level — the comparison
// the IFToMM library of benchmarks makes. Shared by the HTML page and summary.md.
#pragma once

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace mechbench::harness::report {

using json = nlohmann::json;

struct PrecisionCell {
  bool met = false;
  std::string cpu;     // "0.84 s" when met, else "not met" / "—"
  std::string detail;  // "h = 1.25 ms, 1.4e-4 m", or why not: "best 8.9e-3 m at tol = 1e-10", "over budget at h = …"
};

struct PrecisionRow {
  std::string method, status, reason;
  std::vector<PrecisionCell> cells;  // per level
  int rungs = 0;
  std::string shared_with;  // the method whose runs its walk shared (README "Runs done once"), or ""
};

struct PrecisionTable {
  std::string scenario, point;
  std::vector<double> levels;
  int output_steps = 0;
  std::string source;  // where the levels come from (the file's criteria source), or empty
  std::vector<PrecisionRow> rows;
};

// One table per benchmark scene, in record order.
std::vector<PrecisionTable> PrecisionTables(const json& results);
// "1e-3 m" from a level and the scene's length unit (the drawing's unit, when known).
std::string LevelText(double level, const std::string& unit);

}  // namespace mechbench::harness::report
