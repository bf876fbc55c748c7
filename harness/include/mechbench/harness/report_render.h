// Turns the object `mechbench report` collects (contract: harness/report/results.schema.json)
// into the files a person and a CI job read.
#pragma once

#include <nlohmann/json.hpp>

#include <string>

namespace mechbench::harness {

// What the rendering found and did: whether gnuplot was usable, how many plots were embedded,
// and gnuplot's own version line ("gnuplot 5.4 patchlevel 4"), empty without it.
struct RenderInfo {
  bool gnuplot = false;
  int plots = 0;
  std::string gnuplot_version;
};

// Writes DIR/results.json (the object, pretty), DIR/results.csv, DIR/summary.md and
// DIR/report.html, creating DIR if needed.
//   results.csv  one row per run-like record (run, sweep, stress, each `tried` step of
//                stable_step), full precision, empty cell for null.
//   summary.md   a short Markdown summary for a CI job ($GITHUB_STEP_SUMMARY), work–precision
//                across the scenes first.
//   report.html  one self-contained page (inline CSS and SVG, no scripts, no external URLs). It
//                opens with work–precision across the scenes (data-plot summary-work-precision
//                and a table), then the build and the scenes, then each scene; a scene's
//                work–precision is one plot (work-precision-SCENARIO), or two when it has both
//                methods at their defaults and tuned variants (…-tuned-SCENARIO), with
//                checkboxes that hide a method's line by CSS alone.
// Plots are drawn by gnuplot (found on PATH; Debian gnuplot-nox) and embedded as SVG, each in a
// <figure class="plot" data-plot="KIND-SCENARIO">; without gnuplot, or when it fails, the page
// has <figure class="plot missing" data-plot="…"> with the reason instead and is still written.
// Throws std::runtime_error naming the path if DIR cannot be created or a file cannot be
// written, and if `results` is not a JSON object. The input is not validated against the schema:
// missing or mistyped members are shown as empty, never a crash.
RenderInfo WriteReportFiles(const nlohmann::json& results, const std::string& dir);

}  // namespace mechbench::harness
