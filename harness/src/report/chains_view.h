// The long-chains table in the results (records of kind "chain", harness/chains.h): per method,
// per N of the ladder, the integration CPU per step and the position error against the exact
// motion, the growth exponent and why the ladder stopped. Shared by the HTML page and summary.md.
#pragma once

#include <nlohmann/json.hpp>

#include <optional>
#include <string>
#include <vector>

namespace mechbench::harness::report {

using json = nlohmann::json;

struct ChainCell {
  bool ran = false;
  bool ok = false;              // the rung finished within the lost-motion limits
  std::optional<double> step_us, error, per_sim_second;  // [µs], relative, [s of CPU per simulated second]
  std::string text;             // "37 µs" or the status ("over-budget")
  std::string detail;           // "1.2e-6", or "t = 0.01 s"
};

struct ChainRow {
  std::string method, status, stop, stop_detail;
  std::vector<ChainCell> cells;  // per N of ChainTable::ladder
  std::optional<double> exponent;
  int exponent_points = 0;
  std::string exponent_range;    // "N = 10 … 300"
  double cpu_seconds = 0;        // every rung's run together
  std::optional<double> largest_n;  // the largest N it finished
};

struct ChainTable {
  std::vector<int> ladder;
  double t1 = 0, budget = 0;
  int samples = 0;
  std::vector<ChainRow> rows;    // in the methods' order
  double cpu_seconds = 0;        // Σ over the rows
  bool empty() const { return rows.empty(); }
};

ChainTable ChainTableOf(const json& results);
// "37 µs" (two or three significant digits).
std::string FmtMicros(double us);
// "N^1.02", or "—".
std::string FmtExponent(const std::optional<double>& p);

}  // namespace mechbench::harness::report
