// render_report RESULTS.json DIR: WriteReportFiles on a results object read from a file. The
// ctest report_fixture_render uses it on tests/data/report/results_fixture.json, and
// report_fixture_html then opens the page in a headless browser.
#include "mechbench/harness/report_render.h"

#include <nlohmann/json.hpp>

#include <exception>
#include <fstream>
#include <iostream>

int main(int argc, char** argv) {
  if (argc != 3) {
    std::cerr << "usage: render_report RESULTS.json DIR\n";
    return 2;
  }
  std::ifstream in(argv[1]);
  if (!in) {
    std::cerr << argv[1] << ": cannot open\n";
    return 2;
  }
  nlohmann::json results;
  try {
    results = nlohmann::json::parse(in);
  } catch (const std::exception& e) {
    std::cerr << argv[1] << ": " << e.what() << "\n";
    return 2;
  }
  try {
    const auto info = mechbench::harness::WriteReportFiles(results, argv[2]);
    std::cout << "wrote " << argv[2] << "/{results.json,results.csv,summary.md,report.html}: " << info.plots
              << " plot(s), "
              << (info.gnuplot ? "gnuplot: " + info.gnuplot_version : std::string("gnuplot not found")) << "\n";
  } catch (const std::exception& e) {
    std::cerr << e.what() << "\n";
    return 1;
  }
  return 0;
}
