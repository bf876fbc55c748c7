// Rendering of a mechbench results object (harness/report/results.schema.json) into
// results.json, results.csv, summary.md and report.html. Plots are made by gnuplot (SVG terminal)
// and embedded inline; nothing here draws by hand. The parts live in harness/src/report/: tolerant
// access (access.h), text and escaping (text.h), gnuplot (gnuplot.h), views of the results
// (results_view.h), and one writer per file (writers.h: csv.cc, summary_md.cc, html.cc).
#include "mechbench/harness/report_render.h"

#include "report/gnuplot.h"
#include "report/text.h"
#include "report/writers.h"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <system_error>

namespace mechbench::harness {

using json = nlohmann::json;
namespace fs = std::filesystem;

RenderInfo WriteReportFiles(const nlohmann::json& results, const std::string& dir) {
  if (!results.is_object()) throw std::runtime_error("report: the results are not a JSON object");
  const fs::path out(dir.empty() ? std::string(".") : dir);
  std::error_code ec;
  fs::create_directories(out, ec);
  if (ec || !fs::is_directory(out)) {
    throw std::runtime_error("report: cannot create the folder " + out.string() + ": " +
                             (ec ? ec.message() : std::string("a file of that name exists")));
  }
  if (::access(out.c_str(), W_OK) != 0)
    throw std::runtime_error("report: cannot write into " + out.string() + ": " + std::strerror(errno));

  report::WriteFileOrThrow(out / "results.json", results.dump(2, ' ', false, json::error_handler_t::replace) + "\n");
  report::WriteFileOrThrow(out / "results.csv", report::RenderCsv(results));
  report::WriteFileOrThrow(out / "summary.md", report::RenderSummary(results));

  report::Gnuplot gp;
  const report::HtmlPage page = report::RenderHtml(results, gp);
  report::WriteFileOrThrow(out / "report.html", page.text);

  RenderInfo info;
  info.gnuplot = gp.available();
  info.gnuplot_version = gp.version();
  info.plots = page.plots;
  return info;
}

}  // namespace mechbench::harness

