// The report renderer (harness/src/report_render.cc) on a small hand-written results object,
// tests/data/report/results_fixture.json (valid against harness/report/results.schema.json:
// the ctest report_fixture_schema checks that).
#include "mechbench/harness/report_render.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <regex>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace mechbench::harness {
namespace harness_report_test {  // this file's own names (the tests build in unity batches)
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

json Fixture() {
  std::ifstream in(MECHBENCH_TEST_DATA "/report/results_fixture.json");
  EXPECT_TRUE(in) << "cannot open the fixture";
  return json::parse(in);
}

std::string Read(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

size_t Count(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t i = text.find(what); i != std::string::npos; i = text.find(what, i + what.size())) ++n;
  return n;
}

bool GnuplotOnPath() {
  const char* path = std::getenv("PATH");
  if (!path) return false;
  std::stringstream ss(path);
  std::string d;
  while (std::getline(ss, d, ':'))
    if (!d.empty() && ::access((fs::path(d) / "gnuplot").c_str(), X_OK) == 0) return true;
  return false;
}

// The output folders this process made, removed when its tests end (every run left its reports in
// the temporary folder: 4 MB a run); MECHBENCH_KEEP_TEST_OUTPUT keeps them to look at.
std::vector<fs::path>& MadeDirs() {
  static std::vector<fs::path> dirs;
  return dirs;
}
class RemoveOutDirs : public testing::Environment {
 public:
  void TearDown() override {
    if (std::getenv("MECHBENCH_KEEP_TEST_OUTPUT")) return;
    for (const fs::path& d : MadeDirs()) {
      std::error_code ec;
      fs::remove_all(d, ec);
    }
  }
};
[[maybe_unused]] testing::Environment* const kRemoveOutDirs = testing::AddGlobalTestEnvironment(new RemoveOutDirs);

// A fresh output folder per test.
fs::path OutDir() {
  const auto* info = testing::UnitTest::GetInstance()->current_test_info();
  fs::path dir = fs::path(testing::TempDir()) /
                 ("mechbench_report_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  MadeDirs().push_back(dir);
  return dir;
}

// RFC 4180: quoted fields may hold commas, doubled quotes and line breaks.
std::vector<std::vector<std::string>> ParseCsv(const std::string& text) {
  std::vector<std::vector<std::string>> rows;
  std::vector<std::string> row;
  std::string field;
  bool quoted = false, any = false;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    any = true;
    if (quoted) {
      if (c == '"' && i + 1 < text.size() && text[i + 1] == '"') {
        field += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        field += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      row.push_back(field);
      field.clear();
    } else if (c == '\n') {
      row.push_back(field);
      rows.push_back(row);
      row.clear();
      field.clear();
      any = false;
    } else if (c != '\r') {
      field += c;
    }
  }
  EXPECT_FALSE(quoted) << "unterminated quoted field";
  if (any) {
    row.push_back(field);
    rows.push_back(row);
  }
  return rows;
}

bool IsTunedVariant(const std::string& method) {
  return method.size() > 6 && method.compare(method.size() - 6, 6, "-tuned") == 0;
}

// The plots the page is meant to have: the summary across the scenes when some method was swept
// (a rung that was not "not-applicable"); a drawing per scenario that has one; per scenario, a
// work–precision plot for the methods at their defaults and one for the tuned variants when both
// have an ok sweep rung with a finite, positive error (one plot, named for the scenario, when only
// one group has).
std::set<std::string> ExpectedPlots(const json& r) {
  std::set<std::string> plots;
  for (const auto& rec : r["records"])
    if (rec["kind"] == "sweep" && rec["status"] != "not-applicable") plots.insert("summary-work-precision");
  // The long chains: one plot of the CPU per step against N, when a rung has one.
  for (const auto& rec : r["records"])
    if (rec["kind"] == "chain")
      for (const auto& g : rec["rungs"])
        if (g["step_us"].is_number() && g["step_us"].get<double>() > 0) plots.insert("chains-nfourbar");
  for (const auto& s : r["scenarios"]) {
    const std::string name = s["scenario"];
    if (s["drawing"].is_object()) plots.insert("drawing-" + name);
    bool group[2] = {false, false};
    for (const auto& rec : r["records"]) {
      if (rec["kind"] == "sweep" && rec["scenario"] == name && rec["status"] == "ok" && rec.contains("error") &&
          rec["error"]["q_max"].is_number() && rec["error"]["q_max"].get<double>() > 0)
        group[IsTunedVariant(rec["method"]) ? 1 : 0] = true;
    }
    if (group[0] || group[1]) plots.insert("work-precision-" + name);
    if (group[0] && group[1]) plots.insert("work-precision-tuned-" + name);
  }
  return plots;
}

std::vector<std::string> DataPlots(const std::string& html, const std::string& cls) {
  std::vector<std::string> out;
  const std::regex re("<figure class=\"" + cls + "\" data-plot=\"([^\"]*)\"");
  for (auto it = std::sregex_iterator(html.begin(), html.end(), re); it != std::sregex_iterator(); ++it)
    out.push_back((*it)[1]);
  return out;
}

TEST(ReportRender, WritesAllFourFiles) {
  const json r = Fixture();
  const fs::path dir = OutDir() / "nested" / "report";  // created as needed
  WriteReportFiles(r, dir.string());
  for (const char* f : {"results.json", "results.csv", "summary.md", "report.html"}) {
    ASSERT_TRUE(fs::exists(dir / f)) << f;
    EXPECT_GT(fs::file_size(dir / f), 100u) << f;
  }
  // results.json is the object itself, pretty-printed.
  const std::string text = Read(dir / "results.json");
  EXPECT_EQ(json::parse(text), r);
  EXPECT_NE(text.find("\n  \"build\": {"), std::string::npos) << "not indented";
  // Writing again over an existing report replaces it.
  EXPECT_NO_THROW(WriteReportFiles(r, dir.string()));
}

TEST(ReportRender, CsvHasOneRowPerRunLikeRecordAndParsesBack) {
  const json r = Fixture();
  const fs::path dir = OutDir();
  WriteReportFiles(r, dir.string());
  const auto rows = ParseCsv(Read(dir / "results.csv"));
  ASSERT_FALSE(rows.empty());
  const std::vector<std::string> header = {"kind",         "scenario",     "case",           "method",
                                           "control",      "value",        "status",         "cpu_seconds",
                                           "cpu_setup",    "cpu_integration", "cpu_observation", "steps",
                                           "step_us",      "q_max",        "q_rms",          "qd_max",
                                           "qdd_max",      "max_residual", "energy_drift",   "reason"};
  EXPECT_EQ(rows[0], header);

  // Expected rows, in record order: run, sweep, stress, and one per tried step of stable_step.
  std::vector<const json*> expected;
  std::vector<const json*> tried_of;
  size_t tried = 0;
  for (const auto& rec : r["records"]) {
    const std::string kind = rec["kind"];
    if (kind == "run" || kind == "sweep" || kind == "stress") expected.push_back(&rec);
    if (kind == "stable_step")
      for (const auto& t : rec["tried"]) {
        expected.push_back(&rec);
        tried_of.push_back(&t);
        ++tried;
      }
  }
  ASSERT_EQ(rows.size(), expected.size() + 1);
  EXPECT_EQ(tried, 7u);
  size_t t = 0;
  for (size_t i = 0; i < expected.size(); ++i) {
    const auto& row = rows[i + 1];
    const json& rec = *expected[i];
    ASSERT_EQ(row.size(), header.size()) << "row " << i + 1;
    const std::string kind = rec["kind"];
    EXPECT_EQ(row[0], kind);
    EXPECT_EQ(row[1], rec["scenario"].get<std::string>());
    EXPECT_EQ(row[3], rec["method"].get<std::string>());
    if (kind == "stable_step") {
      const json& step = *tried_of[t++];
      EXPECT_EQ(row[4], "step");
      EXPECT_EQ(std::stod(row[5]), step["step"].get<double>());
      EXPECT_EQ(row[6], step["outcome"].get<std::string>());
      EXPECT_EQ(row[19], step["detail"].get<std::string>());
      continue;
    }
    EXPECT_EQ(row[6], rec[kind == "stress" ? "outcome" : "status"].get<std::string>());
    EXPECT_EQ(row[19], rec[kind == "stress" ? "detail" : "reason"].get<std::string>());
    // Full precision: the number read back is the same double.
    EXPECT_EQ(std::stod(row[7]), rec["cpu_seconds"].get<double>()) << rec["id"];
    if (rec.contains("cpu") && rec["cpu"].is_object()) {
      EXPECT_EQ(std::stod(row[8]), rec["cpu"]["setup"].get<double>()) << rec["id"];
      EXPECT_EQ(std::stod(row[9]), rec["cpu"]["integration"].get<double>()) << rec["id"];
      EXPECT_EQ(std::stod(row[10]), rec["cpu"]["observation"].get<double>()) << rec["id"];
      if (rec["cpu"]["steps"].is_number()) EXPECT_EQ(std::stod(row[11]), rec["cpu"]["steps"].get<double>()) << rec["id"];
      else EXPECT_EQ(row[11], "") << rec["id"];
    } else {
      EXPECT_EQ(row[9], "") << "no phases: empty cells " << rec["id"];
    }
    if (rec.contains("error") && rec["error"]["q_max"].is_number()) {
      EXPECT_EQ(std::stod(row[13]), rec["error"]["q_max"].get<double>()) << rec["id"];
    } else {
      EXPECT_EQ(row[13], "") << "null or absent is an empty cell: " << rec["id"];
    }
    if (rec["max_residual"].is_null()) {
      EXPECT_EQ(row[17], "") << rec["id"];
    }
    if (kind == "sweep") {
      EXPECT_EQ(row[4], rec["control"].get<std::string>());
      if (rec["value"].is_number()) EXPECT_EQ(std::stod(row[5]), rec["value"].get<double>());
      else EXPECT_EQ(row[5], "") << "a rung without a step or tolerance (exact kinematics): " << rec["id"];
      if (rec["energy_drift"].is_number()) {
        EXPECT_EQ(std::stod(row[18]), rec["energy_drift"].get<double>()) << rec["id"];
      } else {
        EXPECT_EQ(row[18], "") << rec["id"];
      }
    }
    if (kind == "stress") {
      EXPECT_EQ(row[2], rec["case"].get<std::string>());
    }
  }
  // The fixture's awkward strings made it through the quoting: a comma and quotes in a reason, a
  // line break and quotes in a stress detail.
  bool comma = false, newline = false;
  for (const auto& row : rows) {
    if (row[19].find(", no driver") != std::string::npos && row[19].find("\"driven\"") != std::string::npos)
      comma = true;
    if (row[19].find("\"blow-up\"\nafter") != std::string::npos) newline = true;
  }
  EXPECT_TRUE(comma);
  EXPECT_TRUE(newline);
}

TEST(ReportRender, SummaryIsShortAndMentionsEveryScenario) {
  const json r = Fixture();
  const fs::path dir = OutDir();
  WriteReportFiles(r, dir.string());
  const std::string md = Read(dir / "summary.md");
  for (const auto& s : r["scenarios"]) EXPECT_NE(md.find(s["scenario"].get<std::string>()), std::string::npos);
  EXPECT_LT(Count(md, "\n"), 80u) << md;  // with a benchmark's table of three methods and the chains' of three
  // Totals: book values by verdict, runs, stress outcomes by kind.
  EXPECT_NE(md.find("7 agrees, 1 last-digit"), std::string::npos) << md;
  EXPECT_NE(md.find("runs: 5 ok, 1 outside tolerance (1 known), 1 failed, 2 not applicable"), std::string::npos) << md;
  EXPECT_NE(md.find("stress: 2 ok, 1 diverged, 1 loop_opened"), std::string::npos) << md;
  // Work–precision per scene from `derived`: CPU to 1e-3 / 1e-6, order, largest stable step.
  EXPECT_NE(md.find("1.8 ms / 1.8 ms · p 3.98 · h 6.5 ms"), std::string::npos) << md;
  // DOPRI5's rungs vary its tolerance: the error's slope against it, no order.
  EXPECT_NE(md.find("774 µs / 2.64 ms · tol. slope 0.98"), std::string::npos) << md;
  EXPECT_EQ(md.find("· p 0.98"), std::string::npos) << md;
  // The stress outcomes that are not ok, one line each (no raw line break from the detail).
  EXPECT_NE(md.find("| `s5_1_disc_bar_bushing` | mass_ratio=1e6 | `dyn-baumgarte-rk4` | **diverged** |"),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("loop_opened"), std::string::npos);
  // Runs not passing the gate (gate.h): failing ones in bold with their words, a known failure
  // with its reason; no "not known" without the figure.
  for (const auto& line : {std::string("| `s6_2_ordinary_train` | `ode-worldstep-default` | **failed** |"),
                           std::string("| known failure | known: ")})
    EXPECT_NE(md.find(line), std::string::npos) << md;
  // Every table row has the same number of cells as its header.
  std::stringstream ss(md);
  std::string line;
  size_t cells = 0;
  while (std::getline(ss, line)) {
    if (line.rfind("|", 0) != 0) {
      cells = 0;
      continue;
    }
    std::string unescaped = std::regex_replace(line, std::regex("\\\\\\|"), "");
    const size_t n = Count(unescaped, "|");
    if (!cells) cells = n;
    EXPECT_EQ(n, cells) << line;
  }
}

TEST(ReportRender, HtmlHasOneDrawnFigurePerPlot) {
  if (!GnuplotOnPath()) GTEST_SKIP() << "gnuplot is not on PATH (Debian: apt-get install gnuplot-nox)";
  const json r = Fixture();
  const fs::path dir = OutDir();
  const RenderInfo info = WriteReportFiles(r, dir.string());
  EXPECT_TRUE(info.gnuplot);
  EXPECT_NE(info.gnuplot_version.find("gnuplot"), std::string::npos) << info.gnuplot_version;
  const std::string html = Read(dir / "report.html");

  const std::set<std::string> expected = ExpectedPlots(r);
  ASSERT_EQ(expected, (std::set<std::string>{"summary-work-precision", "drawing-s5_1_disc_bar_bushing",
                                             "work-precision-s5_1_disc_bar_bushing", "work-precision-fourbar_free",
                                             "work-precision-tuned-fourbar_free", "chains-nfourbar"}));
  const auto drawn = DataPlots(html, "plot");
  EXPECT_EQ(std::set<std::string>(drawn.begin(), drawn.end()), expected);
  EXPECT_EQ(drawn.size(), expected.size());
  EXPECT_EQ(Count(html, "<figure class=\"plot\""), expected.size());
  EXPECT_EQ(static_cast<size_t>(info.plots), expected.size());
  EXPECT_EQ(html.find("plot missing"), std::string::npos);

  // Each figure holds an inline SVG that draws, without an XML prolog or DOCTYPE.
  size_t at = 0;
  for (size_t i = 0; i < expected.size(); ++i) {
    at = html.find("<figure class=\"plot\"", at);
    ASSERT_NE(at, std::string::npos);
    const size_t end = html.find("</figure>", at);
    const std::string fig = html.substr(at, end - at);
    EXPECT_NE(fig.find("<svg"), std::string::npos);
    EXPECT_NE(fig.find("<path"), std::string::npos);
    EXPECT_NE(fig.find("</svg>"), std::string::npos);
    at = end;
  }
  EXPECT_EQ(html.find("<?xml"), std::string::npos);
  EXPECT_EQ(Count(html, "<!DOCTYPE"), 1u);
  // The legend of the work–precision plot names the methods swept.
  EXPECT_NE(html.find(">dyn-baumgarte-rk4</text>"), std::string::npos);
  EXPECT_NE(html.find(">dyn-baumgarte-dopri5</text>"), std::string::npos);

  // Ids unique across the page (gnuplot's SVGs all use gnuplot_canvas, gpPt0, …), and every
  // in-page reference points at one of them.
  std::map<std::string, int> ids;
  const std::regex id_re("\\sid=[\"']([^\"']+)[\"']");
  for (auto it = std::sregex_iterator(html.begin(), html.end(), id_re); it != std::sregex_iterator(); ++it)
    ++ids[(*it)[1]];
  EXPECT_GT(ids.size(), 10u);
  for (const auto& [id, n] : ids) EXPECT_EQ(n, 1) << "duplicate id " << id;
  const std::regex ref_re("(?:href=[\"']#|url\\(#)([^\"')]+)");
  for (auto it = std::sregex_iterator(html.begin(), html.end(), ref_re); it != std::sregex_iterator(); ++it)
    EXPECT_TRUE(ids.count((*it)[1])) << "dangling reference #" << (*it)[1];

  // Self-contained: no scripts, no external style sheets, images or links.
  EXPECT_EQ(html.find("<script"), std::string::npos);
  EXPECT_EQ(html.find("<link"), std::string::npos);
  EXPECT_EQ(html.find("<img"), std::string::npos);
  EXPECT_EQ(html.find("href=\"http"), std::string::npos);
  EXPECT_EQ(html.find("src="), std::string::npos);
}

TEST(ReportRender, HtmlHasTheTablesOfEveryScenario) {
  const json r = Fixture();
  const fs::path dir = OutDir();
  WriteReportFiles(r, dir.string());
  const std::string html = Read(dir / "report.html");
  // Header: build, engines with versions, machine, options, created.
  for (const char* s : {"RelWithDebInfo", "GNU 12.2.0", "0.16.2 (double)", "Intel(R) Xeon(R) CPU @ 2.20GHz",
                        "2026-11-23T09:41:07Z", "s5_1_disc_bar_bushing, s6_2_ordinary_train"})
    EXPECT_NE(html.find(s), std::string::npos) << s;
  // Sections in `scenarios` order.
  const size_t s51 = html.find("<section id=\"sc-s5_1_disc_bar_bushing\">");
  const size_t s62 = html.find("<section id=\"sc-s6_2_ordinary_train\">");
  ASSERT_NE(s51, std::string::npos);
  ASSERT_NE(s62, std::string::npos);
  EXPECT_LT(s51, s62);
  const std::string linkage = html.substr(s51, s62 - s51), gears = html.substr(s62, html.find("</section>", s62) - s62);
  // Book values with every method's value and the verdict coloured.
  EXPECT_NE(linkage.find("<td class=\"num\">9.222</td><td class=\"num\">9.222222222</td>"), std::string::npos);
  EXPECT_NE(gears.find("<td class=\"st warn\">last-digit</td>"), std::string::npos);
  EXPECT_NE(gears.find("truncated: 0.2199004975 rounds to 0.21990050"), std::string::npos);
  // Runs: status, CPU in phases (set-up, integration, observation, steps, µs per step), errors,
  // residual, within/known, reason (escaped).
  EXPECT_NE(linkage.find("<td class=\"st ok\">ok</td><td class=\"num\">831 µs</td><td class=\"num\">7.07 ms</td>"
                         "<td class=\"num\">416 µs</td><td class=\"num\">1000</td><td class=\"num\">7.07</td>"
                         "<td class=\"num\">1.4e-09</td>"),
            std::string::npos);
  EXPECT_NE(linkage.find("no — known: the engines need a mass"), std::string::npos);
  EXPECT_NE(linkage.find("solves &quot;driven&quot; kinematics only"), std::string::npos);
  EXPECT_NE(gears.find("<td class=\"st bad\">failed</td>"), std::string::npos);
  // Derived, stability (stress + stable_step) and settings.
  EXPECT_NE(linkage.find("<td class=\"num\">3.98</td><td class=\"num\">6.5 ms</td>"), std::string::npos);
  EXPECT_NE(linkage.find("<td class=\"num\">tol. slope 0.98</td>"), std::string::npos);
  EXPECT_NE(linkage.find("<td class=\"st bad\">diverged</td>"), std::string::npos);
  EXPECT_NE(linkage.find("<td class=\"st bad\">loop_opened</td>"), std::string::npos);
  EXPECT_NE(linkage.find("<td class=\"num\">6.5 ms</td><td class=\"num\">7 ms</td>"), std::string::npos);
  EXPECT_NE(linkage.find("<details><summary><code>dyn-baumgarte-rk4</code></summary>"), std::string::npos);
  EXPECT_NE(linkage.find("0.001 | 0.008 | 0.004 | 0.002 | 0.0005"), std::string::npos) << "the swept step";
  // A gear train has no drawing and no sweeps, and says so.
  EXPECT_NE(gears.find("No drawing: a gear train"), std::string::npos);
  EXPECT_NE(gears.find("No work–precision sweeps"), std::string::npos);
  EXPECT_EQ(gears.find("<figure"), std::string::npos);
}

TEST(ReportRender, WithoutGnuplotEveryPlotIsAPlaceholder) {
  const json r = Fixture();
  const fs::path dir = OutDir();
  const fs::path empty = dir / "empty-path";
  fs::create_directories(empty);
  const char* old = std::getenv("PATH");
  const std::string saved = old ? old : "";
  ::setenv("PATH", empty.c_str(), 1);
  RenderInfo info;
  try {
    info = WriteReportFiles(r, (dir / "out").string());
  } catch (...) {
    ::setenv("PATH", saved.c_str(), 1);
    throw;
  }
  ::setenv("PATH", saved.c_str(), 1);
  EXPECT_FALSE(info.gnuplot);
  EXPECT_EQ(info.plots, 0);
  EXPECT_EQ(info.gnuplot_version, "");
  const std::string html = Read(dir / "out" / "report.html");
  const auto missing = DataPlots(html, "plot missing");
  const auto expected = ExpectedPlots(r);
  EXPECT_EQ(std::set<std::string>(missing.begin(), missing.end()), expected);
  EXPECT_EQ(Count(html, "<figure class=\"plot\""), 0u);
  EXPECT_EQ(html.find("<svg"), std::string::npos);
  EXPECT_NE(html.find("gnuplot is not installed"), std::string::npos);
  // The rest of the report is still there.
  EXPECT_NE(html.find("<td class=\"st bad\">diverged</td>"), std::string::npos);
  EXPECT_TRUE(fs::exists(dir / "out" / "summary.md"));
}

TEST(ReportRender, EscapesTextAndSurvivesOddInput) {
  json r = Fixture();
  r["scenarios"][0]["title"] = "<script>alert('x')</script> & \"quotes\"";
  r["scenarios"][0]["drawing"]["bodies"][0]["name"] = "o'brien \"disc\" <b>";
  for (auto& rec : r["records"])
    if (rec["kind"] == "sweep" && rec["method"] == "dyn-baumgarte-rk4") rec["method"] = "rk4 'quoted' <m>";
  r["records"].push_back({{"id", "x"}, {"index", 99}, {"kind", "run"}, {"scenario", "not_listed"}});  // sparse
  r["records"].push_back({{"id", "y"}, {"index", 100}, {"kind", "mystery"}, {"scenario", "not_listed"}});
  const fs::path dir = OutDir();
  RenderInfo info;
  ASSERT_NO_THROW(info = WriteReportFiles(r, dir.string()));
  const std::string html = Read(dir / "report.html");
  EXPECT_EQ(html.find("<script"), std::string::npos);
  EXPECT_NE(html.find("&lt;script&gt;alert(&#39;x&#39;)&lt;/script&gt; &amp; &quot;quotes&quot;"), std::string::npos);
  EXPECT_EQ(html.find("<m>"), std::string::npos);
  EXPECT_NE(html.find("not_listed"), std::string::npos);
  if (GnuplotOnPath()) {
    // Quotes in names do not break gnuplot's scripts.
    EXPECT_EQ(static_cast<size_t>(info.plots), ExpectedPlots(r).size())
        << html.substr(html.find("plot missing") == std::string::npos ? 0 : html.find("plot missing"), 400);
    EXPECT_NE(html.find("rk4 &#39;quoted&#39; &lt;m&gt;"), std::string::npos);
  }
  EXPECT_NE(Read(dir / "summary.md").find("not_listed"), std::string::npos);
}

TEST(ReportRender, ThrowsWhenTheFolderCannotBeWritten) {
  const fs::path dir = OutDir();
  fs::create_directories(dir);
  std::ofstream(dir / "a-file") << "x";
  try {
    WriteReportFiles(Fixture(), (dir / "a-file" / "report").string());
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("a-file"), std::string::npos) << e.what();
  }
  try {
    WriteReportFiles(Fixture(), (dir / "a-file").string());
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("a-file"), std::string::npos) << e.what();
  }
  EXPECT_THROW(WriteReportFiles(json::array(), dir.string()), std::runtime_error);
}

// ---------------------------------------------------------------------------------------------
// Work–precision across the scenes (the page's opening and summary.md), checked against counts
// made here from the fixture's sweep records by the rule the report states: a method ran on a
// scene when it has a sweep rung there that was not "not-applicable"; it reached a level there
// when a rung finished ok with a q error within it, at the integration CPU of the cheapest such
// rung; the median is over the scenes reached.

struct ExpectedReach {
  int scenes = 0;
  int reached[2] = {0, 0};
  std::set<std::string> where[2];  // the scenes reached
  std::vector<double> cpu[2];
  std::optional<double> median(int k) const {
    if (cpu[k].empty()) return std::nullopt;
    std::vector<double> v = cpu[k];
    std::sort(v.begin(), v.end());
    const size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
  }
};

std::map<std::string, ExpectedReach> ReachFromRecords(const json& r) {
  const double levels[2] = {1e-3, 1e-6};
  std::map<std::pair<std::string, std::string>, std::array<std::optional<double>, 2>> best;
  std::map<std::pair<std::string, std::string>, bool> ran;
  for (const auto& rec : r["records"]) {
    if (rec["kind"] != "sweep" || rec["status"] == "not-applicable") continue;
    const auto key = std::make_pair(rec["scenario"].get<std::string>(), rec["method"].get<std::string>());
    ran[key] = true;
    if (rec["status"] != "ok" || !rec.contains("error") || !rec["error"]["q_max"].is_number()) continue;
    const double e = rec["error"]["q_max"], cpu = rec["cpu"]["integration"];
    for (int k = 0; k < 2; ++k)
      if (e <= levels[k] && (!best[key][k] || cpu < *best[key][k])) best[key][k] = cpu;
  }
  std::map<std::string, ExpectedReach> out;
  for (const auto& [key, yes] : ran) {
    ExpectedReach& m = out[key.second];
    ++m.scenes;
    for (int k = 0; k < 2; ++k)
      if (best[key][k]) {
        ++m.reached[k];
        m.where[k].insert(key.first);
        m.cpu[k].push_back(*best[key][k]);
      }
  }
  return out;
}

// "1.04 ms" -> 1.04e-3 (the report's readable seconds); NaN when it is not that.
double ParseSeconds(const std::string& text) {
  static const std::regex re("^\\s*([0-9.eE+-]+) (ns|µs|ms|s)\\s*$");
  std::smatch m;
  if (!std::regex_match(text, m, re)) return NAN;
  const double scale = m[2] == "ns" ? 1e-9 : m[2] == "µs" ? 1e-6 : m[2] == "ms" ? 1e-3 : 1.0;
  return std::stod(m[1]) * scale;
}

std::string Trim(const std::string& s) { return std::regex_replace(s, std::regex("^\\s+|\\s+$"), ""); }
std::string StripTags(const std::string& s) { return Trim(std::regex_replace(s, std::regex("<[^>]*>"), " ")); }

// The cells of the row of `method` in the page's summary table, tags stripped.
std::vector<std::string> SummaryRow(const std::string& html, const std::string& method) {
  const size_t table = html.find("<table class=\"reach\">");
  const size_t end = html.find("</table>", table);
  const std::string head = "<tr><td><code>" + method + "</code></td>";
  const size_t row = html.find(head, table);
  if (table == std::string::npos || row == std::string::npos || row > end) return {};
  const size_t cells_at = row + head.size();
  const std::string tr = html.substr(cells_at, html.find("</tr>", cells_at) - cells_at);
  std::vector<std::string> cells;
  const std::regex td("<td[^>]*>(.*?)</td>");
  for (auto it = std::sregex_iterator(tr.begin(), tr.end(), td); it != std::sregex_iterator(); ++it)
    cells.push_back(StripTags((*it)[1]));
  return cells;
}

// The cells of the row of `method` in summary.md's table across the scenes.
std::vector<std::string> MarkdownRow(const std::string& md, const std::string& method) {
  const size_t section = md.find("### Work–precision across the");
  if (section == std::string::npos) return {};
  const size_t row = md.find("| `" + method + "` |", section);
  if (row == std::string::npos) return {};
  std::string line = md.substr(row, md.find('\n', row) - row);
  std::vector<std::string> cells;
  std::stringstream ss(line.substr(1));
  std::string cell;
  while (std::getline(ss, cell, '|')) cells.push_back(std::regex_replace(cell, std::regex("^\\s+|\\s+$|\\*\\*"), ""));
  return cells;
}

TEST(ReportRender, SummaryAcrossTheScenesCountsWhatTheRecordsSay) {
  const json r = Fixture();
  const auto expected = ReachFromRecords(r);
  // The fixture has the cases worth telling apart: every scene reached, some, none, and a method
  // whose only rung was not applicable.
  ASSERT_GE(expected.size(), 4u);
  bool some_never = false, some_partial = false, some_all = false;
  for (const auto& [m, e] : expected) {
    some_never |= e.reached[0] == 0;
    some_partial |= e.reached[1] > 0 && e.reached[1] < e.scenes;
    some_all |= e.reached[1] == e.scenes && e.scenes > 1;
  }
  EXPECT_TRUE(some_never && some_partial && some_all) << "the fixture lost its interesting cases";

  const fs::path dir = OutDir();
  WriteReportFiles(r, dir.string());
  const std::string html = Read(dir / "report.html"), md = Read(dir / "summary.md");
  for (const auto& [method, e] : expected) {
    SCOPED_TRACE(method);
    const auto row = SummaryRow(html, method);
    const auto mdrow = MarkdownRow(md, method);
    ASSERT_EQ(row.size(), 4u) << html.substr(html.find("<table class=\"reach\">"), 3000);
    ASSERT_GE(mdrow.size(), 5u) << md;
    for (int k = 0; k < 2; ++k) {
      const std::string of = std::to_string(e.reached[k]) + " of " + std::to_string(e.scenes);
      EXPECT_EQ(row[2 * k], of);
      // summary.md may say where, in parentheses: "only A, B" (reached) or "not C" (missed).
      const std::string& cell = mdrow[1 + 2 * k];
      EXPECT_EQ(cell.substr(0, of.size()), of) << cell;
      if (cell.size() > of.size()) {
        const std::string tail = cell.substr(of.size());
        std::smatch where;
        ASSERT_TRUE(std::regex_match(tail, where, std::regex(" \\((only|not) (.*)\\)"))) << cell;
        std::stringstream names(where[2].str());
        std::string name;
        while (std::getline(names, name, ',')) {
          name = std::regex_replace(name, std::regex("^ +"), "");
          EXPECT_EQ(e.where[k].count(name), where[1] == "only" ? 1u : 0u) << cell;
        }
      }
      if (auto median = e.median(k)) {
        // Three significant digits on the page.
        EXPECT_NEAR(ParseSeconds(row[2 * k + 1]), *median, 0.005 * *median) << row[2 * k + 1];
        EXPECT_NEAR(ParseSeconds(mdrow[2 + 2 * k]), *median, 0.005 * *median) << mdrow[2 + 2 * k];
      } else {
        // Never reached is said, not left blank.
        EXPECT_NE(row[2 * k + 1].find("never"), std::string::npos) << row[2 * k + 1];
        EXPECT_NE(mdrow[2 + 2 * k].find("never"), std::string::npos) << mdrow[2 + 2 * k];
      }
    }
  }
  // Listed methods never swept (analytic's only rung was not applicable) still have a row.
  for (const auto& m : r["methods"]) {
    const std::string name = m["method"];
    if (expected.count(name)) continue;
    SCOPED_TRACE(name);
    const auto row = SummaryRow(html, name);
    ASSERT_EQ(row.size(), 1u);
    EXPECT_NE(row[0].find("not swept"), std::string::npos);
    EXPECT_EQ(MarkdownRow(md, name).at(1), "not swept");
  }
}

TEST(ReportRender, SummaryFigureOpensThePage) {
  if (!GnuplotOnPath()) GTEST_SKIP() << "gnuplot is not on PATH (Debian: apt-get install gnuplot-nox)";
  const json r = Fixture();
  const fs::path dir = OutDir();
  WriteReportFiles(r, dir.string());
  const std::string html = Read(dir / "report.html");
  const size_t fig = html.find("<figure class=\"plot\" data-plot=\"summary-work-precision\"");
  const size_t table = html.find("<table class=\"reach\">");
  const size_t first_scene = html.find("<section id=\"sc-");
  const size_t build = html.find("<h3>Build</h3>");
  ASSERT_NE(fig, std::string::npos);
  ASSERT_NE(first_scene, std::string::npos);
  EXPECT_LT(fig, first_scene);
  EXPECT_LT(table, first_scene);
  EXPECT_LT(fig, build) << "the answer comes before the build and machine tables";
  const std::string svg = html.substr(fig, html.find("</figure>", fig) - fig);
  // A row per swept method, a key entry per swept scene, both levels.
  const auto expected = ReachFromRecords(r);
  for (const auto& [method, e] : expected) EXPECT_NE(svg.find(">" + method + "</text>"), std::string::npos) << method;
  std::set<std::string> scenes;
  for (const auto& rec : r["records"])
    if (rec["kind"] == "sweep" && rec["status"] != "not-applicable") scenes.insert(rec["scenario"]);
  for (const auto& s : scenes) EXPECT_NE(svg.find(">" + s + "</text>"), std::string::npos) << s;
  EXPECT_NE(svg.find("q error ≤ 1e-3"), std::string::npos);
  EXPECT_NE(svg.find("q error ≤ 1e-6"), std::string::npos);
  EXPECT_NE(svg.find("not reached"), std::string::npos);
  // A method never swept has no row in the figure (the table lists it).
  EXPECT_EQ(svg.find(">analytic</text>"), std::string::npos);
}

TEST(ReportRender, WorkPrecisionSplitsTunedVariantsAndLetsTheReaderPick) {
  if (!GnuplotOnPath()) GTEST_SKIP() << "gnuplot is not on PATH (Debian: apt-get install gnuplot-nox)";
  const json r = Fixture();
  const fs::path dir = OutDir();
  WriteReportFiles(r, dir.string());
  const std::string html = Read(dir / "report.html");
  auto figure = [&html](const std::string& tag) {
    const size_t at = html.find("data-plot=\"" + tag + "\"");
    return at == std::string::npos ? std::string() : html.substr(at, html.find("</figure>", at) - at);
  };
  // Per scene: the methods with a plotted rung, by group.
  for (const auto& s : r["scenarios"]) {
    const std::string name = s["scenario"];
    std::set<std::string> group[2];
    for (const auto& rec : r["records"])
      if (rec["kind"] == "sweep" && rec["scenario"] == name && rec["status"] == "ok" && rec.contains("error") &&
          rec["error"]["q_max"].is_number() && rec["error"]["q_max"].get<double>() > 0)
        group[IsTunedVariant(rec["method"]) ? 1 : 0].insert(rec["method"]);
    if (group[0].empty() && group[1].empty()) continue;
    SCOPED_TRACE(name);
    const bool split = !group[0].empty() && !group[1].empty();
    const std::string plot[2] = {figure("work-precision-" + name),
                                 split ? figure("work-precision-tuned-" + name) : std::string()};
    for (int g = 0; g < 2; ++g) {
      const std::string& fig = split ? plot[g] : plot[0];
      for (const auto& m : group[g]) EXPECT_NE(fig.find(">" + m + "</text>"), std::string::npos) << m;
      if (split) {
        for (const auto& m : group[1 - g]) EXPECT_EQ(fig.find(">" + m + "</text>"), std::string::npos) << m;
      }
    }
    // A checkbox per plotted method, before the plots, in the scene's section.
    const size_t section = html.find("<section id=\"sc-" + name + "\">");
    const size_t form = html.find("<form class=\"pick\"", section);
    ASSERT_NE(form, std::string::npos);
    const std::string picker = html.substr(form, html.find("<div class=\"wp\">", form) - form);
    for (int g = 0; g < 2; ++g)
      for (const auto& m : group[g]) EXPECT_NE(picker.find("</span>" + m + "</label>"), std::string::npos) << m;
    EXPECT_EQ(Count(picker, "type=\"checkbox\""), group[0].size() + group[1].size());
  }
  // Every picker rule hides something that is there: its checkbox and the plot group it names.
  const std::string head = html.substr(0, html.find("</head>"));
  const std::regex rule("#(pick[0-9]+-[0-9]+):not\\(:checked\\) ~ \\.wp \\[id=\"([^\"]+)\"\\]");
  size_t rules = 0;
  for (auto it = std::sregex_iterator(head.begin(), head.end(), rule); it != std::sregex_iterator(); ++it) {
    ++rules;
    EXPECT_NE(html.find("<input type=\"checkbox\" id=\"" + (*it)[1].str() + "\" checked>"), std::string::npos)
        << (*it)[1];
    EXPECT_NE(html.find("<g id=\"" + (*it)[2].str() + "\""), std::string::npos) << (*it)[2];
  }
  EXPECT_EQ(rules, static_cast<size_t>(Count(html, "type=\"checkbox\"")));
}

// A work–precision cell whose rung shared its run with another method's (derived shared_at_…) is
// marked, in the per-scene table of report.html and summary.md and in the across-scenes median.
TEST(ReportRender, ASharedRunIsMarkedInTheWorkPrecisionCells) {
  json r = Fixture();
  for (json& d : r["derived"])
    if (d["scenario"] == "fourbar_free" && d["method"] == "ode-worldstep-tuned") d["shared_at_1e-3"] = "ode-worldstep-default";
  const fs::path dir = OutDir();
  WriteReportFiles(r, dir.string());
  const std::string html = Read(dir / "report.html"), md = Read(dir / "summary.md");
  EXPECT_NE(html.find("<td class=\"num\">4.1 ms (ode-worldstep-default&#39;s run)</td>"), std::string::npos) << html;
  EXPECT_NE(md.find("4.1 ms (ode-worldstep-default's run) / —"), std::string::npos) << md;
  EXPECT_NE(md.find("(on 1 of them ode-worldstep-default's run, shared)"), std::string::npos) << md;
  // Without the mark, none of it.
  WriteReportFiles(Fixture(), (dir / "plain").string());
  EXPECT_EQ(Read(dir / "plain" / "summary.md").find("ode-worldstep-default's run"), std::string::npos);
}

TEST(ReportRender, SummaryWithoutSweepsSaysSo) {
  json r = Fixture();
  json kept = json::array();
  for (const auto& rec : r["records"])
    if (rec["kind"] != "sweep") kept.push_back(rec);
  r["records"] = kept;
  r["derived"] = json::array();
  const fs::path dir = OutDir();
  ASSERT_NO_THROW(WriteReportFiles(r, dir.string()));
  const std::string html = Read(dir / "report.html");
  EXPECT_NE(html.find("No work–precision sweeps in these results"), std::string::npos);
  EXPECT_EQ(html.find("summary-work-precision"), std::string::npos);
  EXPECT_EQ(Read(dir / "summary.md").find("across the"), std::string::npos);
  // `derived` gone but the sweeps there (a hand-made results object): the same table, from the
  // records, rather than "never" for every method.
  json no_derived = Fixture();
  no_derived.erase("derived");
  ASSERT_NO_THROW(WriteReportFiles(no_derived, (dir / "no-derived").string()));
  WriteReportFiles(Fixture(), (dir / "with-derived").string());
  const auto table = [](const std::string& md) {
    const size_t a = md.find("| method |", md.find("### Work–precision across the"));
    return a == std::string::npos ? std::string() : md.substr(a, md.find("\n\n", a) - a);
  };
  const std::string without = Read(dir / "no-derived" / "summary.md"), with = Read(dir / "with-derived" / "summary.md");
  // Order and stable step come from `derived` only: compare the columns before them.
  auto counts = [](const std::string& md) {
    std::string out;
    std::stringstream ss(md);
    std::string line;
    while (std::getline(ss, line))
      if (line.rfind("| `", 0) == 0) {
        size_t bar = 0;
        for (int i = 0; i < 5 && bar != std::string::npos; ++i) bar = line.find('|', bar + 1);
        out += line.substr(0, bar) + "\n";
      }
    return out;
  };
  EXPECT_EQ(Count(counts(table(with)), "\n"), r["methods"].size()) << with;
  EXPECT_EQ(counts(table(without)), counts(table(with))) << without;
}

// A published benchmark's precision records: per method, the CPU of the cheapest run meeting each
// level with the rung and its error, or "not met" with the best error and what ended the walk;
// a method that cannot do the scene shows its reason. The same in summary.md.
TEST(ReportRender, BenchmarksTableGivesTheCpuToEachLevel) {
  const json r = Fixture();
  const fs::path dir = OutDir();
  WriteReportFiles(r, dir.string());
  const std::string html = Read(dir / "report.html");
  const size_t at = html.find("<section id=\"benchmarks\">");
  ASSERT_NE(at, std::string::npos);
  const std::string b = html.substr(at, html.find("</section>", at) - at);
  EXPECT_NE(b.find("<code>a01_pendulum</code>: point P1, 4000 output steps"), std::string::npos) << b;
  EXPECT_NE(b.find("<td class=\"num ok\">2.03 s<br><small>h = 1.25 ms, 0.00014, median of 3</small>"), std::string::npos) << b;
  EXPECT_NE(b.find("<td class=\"num ok\">446 ms<br><small>h = 5 ms, 0.033, median of 3</small>"), std::string::npos) << b;
  EXPECT_NE(b.find("<td class=\"num bad\">not met<br><small>best 2 at tol = 0.0001; stopped: its CPU budget ran out at tolerance 1e-08</small>"),
            std::string::npos)
      << b;
  EXPECT_NE(b.find("body link has mass but no inertia"), std::string::npos) << b;
  // The benchmark's own section has no runs and points to the table.
  const size_t sec = html.find("<section id=\"sc-a01_pendulum\">");
  ASSERT_NE(sec, std::string::npos);
  EXPECT_NE(html.find("the benchmarks' table", sec), std::string::npos);
  const std::string md = Read(dir / "summary.md");
  EXPECT_NE(md.find("| `dyn-baumgarte-rk4` | 2.03 s (h = 1.25 ms, 0.00014, median of 3) | 446 ms (h = 5 ms, 0.033, median of 3) |  |"),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("**not met** (best 2 at tol = 0.0001; stopped: its CPU budget ran out at tolerance 1e-08)"), std::string::npos) << md;
}

// A walk that shared its runs with another method's (README "Runs done once") is that run: its
// row says "(X's run)" instead of repeating X's cells; a walk that shared only some runs keeps its
// cells and says which it shared. The fixture's RK4 walk, given to a second method as shared.
TEST(ReportRender, BenchmarksTableMarksASharedWalkAsTheSameRun) {
  json r = Fixture();
  json* rk4 = nullptr;
  for (json& rec : r["records"])
    if (rec["kind"] == "precision" && rec["method"] == "dyn-baumgarte-rk4") rk4 = &rec;
  ASSERT_NE(rk4, nullptr);
  json twin = *rk4;
  twin["method"] = "dyn-baumgarte-rk4-twin";
  twin["id"] = "precision/a01_pendulum/dyn-baumgarte-rk4-twin";
  twin["shared_with"] = "dyn-baumgarte-rk4";
  r["records"].push_back(twin);
  const fs::path dir = OutDir();
  WriteReportFiles(r, dir.string());
  std::string html = Read(dir / "report.html");
  size_t at = html.find("<section id=\"benchmarks\">");
  ASSERT_NE(at, std::string::npos);
  std::string b = html.substr(at, html.find("</section>", at) - at);
  EXPECT_EQ(Count(b, "2.03 s<br>"), 1u) << b;  // X's cells once
  EXPECT_NE(b.find("<td class=\"num ok\">(dyn-baumgarte-rk4&#39;s run)<br><small>the same computation: its walk is "
                   "dyn-baumgarte-rk4&#39;s, run once</small></td><td class=\"num ok\">(dyn-baumgarte-rk4&#39;s run)</td>"),
            std::string::npos)
      << b;
  EXPECT_NE(Read(dir / "summary.md").find("| `dyn-baumgarte-rk4-twin` | (dyn-baumgarte-rk4's run) (the same computation: its "
                                          "walk is dyn-baumgarte-rk4's, run once) | (dyn-baumgarte-rk4's run) |"),
            std::string::npos);
  // Not the same cells (its own timed repeats): its row stays, with the note.
  r["records"].back()["met"][0]["cpu_seconds"] = 2.1;
  WriteReportFiles(r, dir.string());
  html = Read(dir / "report.html");
  at = html.find("<section id=\"benchmarks\">");
  b = html.substr(at, html.find("</section>", at) - at);
  EXPECT_NE(b.find("2.1 s<br><small>h = 1.25 ms, 0.00014, median of 3; the same computation as dyn-baumgarte-rk4&#39;s walk, "
                   "run once</small>"),
            std::string::npos)
      << b;
}

// The long chains (records of kind "chain"): a table method × N with the CPU per step and the
// error at each rung, the growth exponent with the rungs it was fitted on, and why each ladder
// stopped; a row per method in summary.md. The generated chain gets no scenario section.
TEST(ReportRender, ChainsTableGivesCostAndErrorPerN) {
  const json r = Fixture();
  const fs::path dir = OutDir();
  WriteReportFiles(r, dir.string());
  const std::string html = Read(dir / "report.html");
  const size_t at = html.find("<section id=\"chains\">");
  ASSERT_NE(at, std::string::npos);
  const std::string c = html.substr(at, html.find("</section>", at) - at);
  EXPECT_NE(c.find("<th>N = 1</th><th>N = 3</th><th>N = 10</th><th>N = 30</th><th>N = 100</th><th>N = 300</th><th>N = 1000</th>"),
            std::string::npos) << c;
  EXPECT_NE(c.find("<td class=\"num ok\">1.4 µs<br><small>9.1e-07</small></td>"), std::string::npos) << c;
  EXPECT_NE(c.find("<td class=\"num ok\">360 µs<br><small>1.2e-06</small></td>"), std::string::npos) << c;
  EXPECT_NE(c.find("N^0.71<br><small>N = 10 … 1000, 5 rungs</small>"), std::string::npos) << c;
  // Stopped by its budget halfway through a rung: the rung shows where it got, the larger N nothing.
  EXPECT_NE(c.find("<td class=\"num bad\">52 ms<br><small>over-budget at t = 0.005 s</small></td><td class=\"num\">—</td>"),
            std::string::npos) << c;
  EXPECT_NE(c.find("budget: its CPU budget ran out at N = 100"), std::string::npos) << c;
  EXPECT_NE(c.find("budget: N = 1000 would take about"), std::string::npos) << c;
  EXPECT_EQ(html.find("id=\"sc-nfourbar\""), std::string::npos) << "chains are not a scenario section";
  const std::string md = Read(dir / "summary.md");
  EXPECT_NE(md.find("### Long chains"), std::string::npos) << md;
  EXPECT_NE(md.find("| `dyn-ali3p` | 1000 | 360 µs | 1.2e-06 | N^0.71 | ladder_end: every rung of the ladder ran |"),
            std::string::npos) << md;
  EXPECT_NE(md.find("| `ode-worldstep-default` | 30 | 3.1 ms | 1.4e-05 | N^2.39 | budget:"), std::string::npos) << md;
}


// A scene only numeric runs (a spatial one: analytic is n/a there, and numeric is never its own
// reference) has sweep rungs that ran ok with nothing to judge them against: their records carry
// no error and say why (reference_note). The summary says "not judged" with that reason, never
// "never (no rung finished)". Here ode-worldstep-tuned's rungs on the fixture's one scene lose
// their error and their derived levels, as such a scene's would.
TEST(ReportRender, SummarySaysNotJudgedWhereNoReferenceJudgedTheRungs) {
  json r = Fixture();
  const std::string method = "ode-worldstep-tuned";
  const std::string note = "no reference: analytic n/a: spatial scenes: not yet in the analytic method; numeric is the "
                           "method judged (never its own reference)";
  int rungs = 0;
  for (json& rec : r["records"])
    if (rec["kind"] == "sweep" && rec["method"] == method && rec["status"] == "ok") {
      rec.erase("error");
      rec["reference_note"] = note;
      ++rungs;
    }
  ASSERT_GT(rungs, 0) << "the fixture lost " << method << "'s sweep";
  json derived = json::array();
  for (const json& d : r["derived"])
    if (d["method"] != method) derived.push_back(d);
  r["derived"] = derived;
  const fs::path dir = OutDir();
  WriteReportFiles(r, dir.string());
  const std::string html = Read(dir / "report.html"), md = Read(dir / "summary.md");
  const auto mdrow = MarkdownRow(md, method);
  ASSERT_GE(mdrow.size(), 5u) << md;
  for (int k = 0; k < 2; ++k) {
    EXPECT_EQ(mdrow[1 + 2 * k], "0 of 1, 1 not judged");
    EXPECT_EQ(mdrow[2 + 2 * k], "not judged (" + note + ")");
  }
  const auto row = SummaryRow(html, method);
  ASSERT_EQ(row.size(), 4u);
  EXPECT_EQ(row[1].find("no rung finished"), std::string::npos) << row[1];
  EXPECT_NE(row[1].find("not judged"), std::string::npos) << row[1];
  EXPECT_NE(row[1].find("spatial scenes: not yet in the analytic method"), std::string::npos) << row[1];
}

// A run record with a figure without a bound (run's PairComparison::not_judged) never reads a bare
// "yes" in the runs table, and one compared with nothing (it ran alone) is not judged.
TEST(ReportRender, RunsTableSaysWhatWasNotJudged) {
  json r = Fixture();
  json* first = nullptr;
  json* second = nullptr;
  for (json& rec : r["records"])
    if (rec["kind"] == "run" && rec["status"] == "ok" && rec.value("within", false)) {
      if (!first) first = &rec;
      else if (!second && rec["scenario"] != (*first)["scenario"]) second = &rec;
    }
  ASSERT_TRUE(first && second) << "the fixture lost its ok runs";
  (*first)["not_judged"] = json::array({"q̈ 3"});
  (*second)["compared"] = false;
  const fs::path dir = OutDir();
  WriteReportFiles(r, dir.string());
  const std::string html = Read(dir / "report.html");
  EXPECT_NE(html.find("yes where bounded; not judged (no bound): q̈ 3"), std::string::npos);
  EXPECT_NE(html.find("not judged: nothing to compare against"), std::string::npos);
}

}  // namespace
}  // namespace harness_report_test
}  // namespace mechbench::harness
