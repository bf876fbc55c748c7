// The three rendered files of a report: results.csv, summary.md and report.html.
#pragma once

#include "gnuplot.h"

#include <nlohmann/json.hpp>

#include <string>

namespace mechbench::harness::report {

// One row per run-like record (run, sweep, stress, each `tried` step of stable_step).
std::string RenderCsv(const nlohmann::json& results);
// A short Markdown summary for a CI job summary.
std::string RenderSummary(const nlohmann::json& results);

struct HtmlPage {
  std::string text;
  int plots = 0;  // plots drawn and embedded
};
// The self-contained page, its plots drawn by `gp` (placeholders when it cannot).
HtmlPage RenderHtml(const nlohmann::json& results, Gnuplot& gp);

}  // namespace mechbench::harness::report
