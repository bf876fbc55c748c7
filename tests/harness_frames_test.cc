// The motion as frames (harness/frames.h) and its animation in report.html: frames hold every
// point of the mechanism at evenly spread samples, the run records carry the method's and the
// reference's, and the report shows them frame by frame.
#include "mechbench/harness/campaign.h"
#include "mechbench/harness/frames.h"
#include "mechbench/harness/registry.h"
#include "mechbench/harness/report_render.h"
#include "mechbench/loader.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>

namespace mechbench::harness {
namespace harness_frames_test {  // this file's own names (the tests build in unity batches)
namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

const char* kDriven = MECHBENCH_TEST_DATA "/scenes/crank_rocker_turn_cross.yaml";  // 721 samples
const char* kFree = MECHBENCH_TEST_DATA "/scenes/pendulum_horizontal.yaml";        // 11 samples

TEST(Frames, AreEvenlySpreadSamplesWithBothEnds) {
  const Model driven = LoadScenario(kDriven);
  const std::vector<int> k = FrameSamples(driven);
  ASSERT_EQ(static_cast<int>(k.size()), kMaxFrames);
  EXPECT_EQ(k.front(), 0);
  EXPECT_EQ(k.back(), driven.analysis.samples - 1);
  for (size_t i = 1; i < k.size(); ++i) {
    EXPECT_GT(k[i], k[i - 1]);
    // Evenly spread: every gap within one sample of the mean gap.
    EXPECT_NEAR(k[i] - k[i - 1], (driven.analysis.samples - 1.0) / (kMaxFrames - 1), 1.0);
  }
  // Fewer samples than frames: every sample.
  const Model free = LoadScenario(kFree);
  EXPECT_EQ(FrameSamples(free), (std::vector<int>{0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10}));
}

TEST(Frames, HoldEveryPointWhereTheTrajectoryPutsIt) {
  const Model m = LoadScenario(kDriven);
  MethodPtr numeric;
  for (MethodPtr& meth : AllMethods())
    if (meth->name() == "numeric") numeric = std::move(meth);
  ASSERT_NE(numeric, nullptr);
  const Result r = numeric->Run(m);
  ASSERT_TRUE(r.ok()) << r.reason;
  const json f = MotionFrames(m, r.trajectory);
  ASSERT_TRUE(f.is_object());
  const std::vector<int> k = FrameSamples(m);
  ASSERT_EQ(f["t"].size(), k.size());
  ASSERT_EQ(f["p"].size(), k.size());
  double worst = 0;
  for (size_t j = 0; j < k.size(); ++j) {
    const Sample& s = r.trajectory[k[j]];
    EXPECT_NEAR(f["t"][j].get<double>(), s.t, 1e-5 * std::max(1.0, s.t));
    ASSERT_EQ(f["p"][j].size(), 2 * m.points.size());
    for (size_t i = 0; i < m.points.size(); ++i)
      for (int axis = 0; axis < 2; ++axis) {
        const int slot = m.SlotOf(static_cast<int>(i), axis);
        const double want = slot >= 0 ? s.q[slot] : m.points[i].p_W[axis];
        worst = std::max(worst, std::fabs(f["p"][j][2 * i + axis].get<double>() - want) / std::max(1.0, std::fabs(want)));
      }
  }
  EXPECT_LT(worst, 1e-5);  // six significant digits
  // A motion that stopped early has the frames up to where it got; one sample is no motion.
  std::vector<Sample> half(r.trajectory.begin(), r.trajectory.begin() + k[10] + 1);
  EXPECT_EQ(MotionFrames(m, half)["t"].size(), 11u);
  EXPECT_TRUE(MotionFrames(m, {r.trajectory[0]}).is_null());
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

// A campaign's run records carry the frames, and the page animates them: one figure per scene
// with motion, every frame's items shown in turn, the first frame when nothing moves.
TEST(Frames, RunRecordsCarryThemAndTheReportAnimatesThem) {
  if (!GnuplotOnPath()) GTEST_SKIP() << "gnuplot is not on PATH (Debian: apt-get install gnuplot-nox)";
  CampaignOptions o;
  o.scenarios = {kFree};
  o.methods = {"dyn-baumgarte-rk4", "dyn-ali3p"};
  o.check = o.sweep = o.stress = false;
  o.isolate = false;
  o.progress = false;
  o.quick = true;
  std::vector<json> records;
  for (const Case& c : EnumerateCases(o))
    for (json& r : RunCase(c, o)) records.push_back(std::move(r));
  ASSERT_EQ(records.size(), 2u);
  const Model m = LoadScenario(kFree);
  for (const json& r : records) {
    SCOPED_TRACE(r["method"].get<std::string>());
    ASSERT_TRUE(r.contains("frames"));
    EXPECT_EQ(r["frames"]["t"].size(), static_cast<size_t>(m.analysis.samples));
    ASSERT_TRUE(r["reference_frames"].is_object());
    EXPECT_EQ(r["reference_against"], "reference trajectory");
    // The method's frames and the reference's are the same mechanism at the same times.
    for (size_t j = 0; j < r["frames"]["p"].size(); ++j)
      for (size_t i = 0; i < r["frames"]["p"][j].size(); ++i)
        EXPECT_NEAR(r["frames"]["p"][j][i].get<double>(), r["reference_frames"]["p"][j][i].get<double>(), 1e-3);
  }
  const json results = Assemble(records, o);
  const json& drawing = results["scenarios"][0]["drawing"];
  ASSERT_EQ(drawing["order"].size(), m.points.size());

  const fs::path dir = fs::path(testing::TempDir()) / ("mechbench_frames_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  WriteReportFiles(results, dir.string());
  std::ifstream in(dir / "report.html");
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string html = ss.str();
  fs::remove_all(dir);
  const std::string tag = "data-plot=\"motion-" + m.name + "\"";
  const size_t fig = html.find(tag);
  ASSERT_NE(fig, std::string::npos);
  const std::string svg = html.substr(fig, html.find("</figure>", fig) - fig);
  // Its key names the reference and both methods.
  EXPECT_NE(svg.find(">reference trajectory</text>"), std::string::npos);
  EXPECT_NE(svg.find(">dyn-baumgarte-rk4</text>"), std::string::npos);
  EXPECT_NE(svg.find(">dyn-ali3p</text>"), std::string::npos);
  // Every frame's three items (reference, methods, time) have a rule in the head that shows them
  // for their share of one keyframes cycle, delayed by the frame's place; all but the first start hidden.
  const int n = m.analysis.samples;
  EXPECT_NE(html.find("@keyframes mb-frames-" + std::to_string(n) + " "), std::string::npos);
  const std::regex rule("\\[id=\"([^\"]*gnuplot_plot_(\\d+))\"\\] \\{ animation: mb-frames-" + std::to_string(n) +
                        " 6s step-end ([0-9.e-]+)s infinite;( visibility: hidden;)? \\}");
  std::set<int> items;
  for (auto it = std::sregex_iterator(html.begin(), html.end(), rule); it != std::sregex_iterator(); ++it) {
    const int item = std::stoi((*it)[2]);
    const int frame = (item - 1) / 3;
    items.insert(item);
    EXPECT_NEAR(std::stod((*it)[3]), 6.0 * frame / n, 1e-4) << (*it)[0];
    EXPECT_EQ((*it)[4].matched, frame > 0) << (*it)[0];
    EXPECT_NE(svg.find("id=\"" + std::string((*it)[1]) + "\""), std::string::npos) << "no such item " << (*it)[1];
  }
  EXPECT_EQ(items.size(), static_cast<size_t>(3 * n));
  // Frame times are labelled.
  EXPECT_NE(svg.find(">t = 0.1 s</tspan>"), std::string::npos);
}

// A spatial scene: frames hold x, y, z of every point entity (the unit vectors are not drawn), from
// the trajectory's slots or the fixed points' positions; the drawing has dim 3 and its bodies list
// their points; the page draws the mechanism four times (isometric, top, front, side) and animates
// it in the isometric view.
TEST(Frames, SpatialScenesAreDrawnInThreeDimensions) {
  const char* kRssr = MECHBENCH_TEST_DATA "/scenes/rssr_fourbar.yaml";  // 21 samples, driven
  const Model m = LoadScenario(kRssr);
  ASSERT_EQ(m.kind, ScenarioKind::kSpatial);
  const std::vector<std::string> names = DrawnPointNames(m);
  EXPECT_EQ(names, (std::vector<std::string>{"A", "D", "B", "C"}));
  MethodPtr numeric;
  for (MethodPtr& meth : AllMethods())
    if (meth->name() == "numeric") numeric = std::move(meth);
  ASSERT_NE(numeric, nullptr);
  const Result r = numeric->Run(m);
  ASSERT_TRUE(r.ok()) << r.reason;
  const json f = MotionFrames(m, r.trajectory);
  ASSERT_TRUE(f.is_object());
  EXPECT_EQ(f["dim"], 3);
  ASSERT_EQ(f["p"].size(), static_cast<size_t>(m.analysis.samples));
  double worst = 0;
  for (size_t j = 0; j < f["p"].size(); ++j) {
    ASSERT_EQ(f["p"][j].size(), 3 * names.size());
    const Sample& s = r.trajectory[j];
    for (size_t i = 0; i < names.size(); ++i)
      for (int axis = 0; axis < 3; ++axis) {
        const int e = m.spatial.EntityIndex(names[i]);
        int slot = -1;
        for (size_t k = 0; k < m.q_layout.size(); ++k)
          if (m.q_layout[k].entity == e && m.q_layout[k].axis == axis) slot = static_cast<int>(k);
        const double want = slot >= 0 ? s.q[slot] : m.spatial.entities[e].r_W[axis];
        worst = std::max(worst, std::fabs(f["p"][j][3 * i + axis].get<double>() - want) / std::max(1.0, std::fabs(want)));
      }
  }
  EXPECT_LT(worst, 1e-5);  // six significant digits
  // C is the coupler's second point and the output crank's (order: A, D, B, C).
  EXPECT_NEAR(f["p"][0][9].get<double>(), 2.0, 1e-12);

  if (!GnuplotOnPath()) GTEST_SKIP() << "gnuplot is not on PATH (Debian: apt-get install gnuplot-nox)";
  // The RSSR's drawing, and a free spherical pendulum's motion (numeric alone has no reference to
  // be drawn against).
  const char* kPendulum = MECHBENCH_TEST_DATA "/scenes/spherical_pendulum.yaml";
  CampaignOptions o;
  o.scenarios = {kRssr, kPendulum};
  o.methods = {"numeric", "dyn-baumgarte-rk4"};
  o.check = o.sweep = o.stress = false;
  o.isolate = false;
  o.progress = false;
  o.quick = true;
  std::vector<json> records;
  for (const Case& c : EnumerateCases(o))
    for (json& rec : RunCase(c, o)) records.push_back(std::move(rec));
  ASSERT_FALSE(records.empty());
  const json results = Assemble(records, o);
  ASSERT_EQ(results["scenarios"].size(), 2u);
  ASSERT_EQ(results["scenarios"][0]["scenario"], m.name);
  const json& drawing = results["scenarios"][0]["drawing"];
  ASSERT_TRUE(drawing.is_object());
  EXPECT_EQ(drawing["dim"], 3);
  EXPECT_EQ(drawing["order"].size(), names.size());
  ASSERT_EQ(drawing["bodies"].size(), 3u);  // input A–B, coupler B–C, output D–C
  EXPECT_EQ(drawing["bodies"][2]["index"], json({1, 3}));
  EXPECT_EQ(drawing["bodies"][2]["points"][0], json({2, 1, 1.5}));
  const fs::path dir = fs::path(testing::TempDir()) / ("mechbench_frames3d_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  WriteReportFiles(results, dir.string());
  std::ifstream in(dir / "report.html");
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string html = ss.str();
  fs::remove_all(dir);
  const std::string pendulum = results["scenarios"][1]["scenario"];
  for (const std::string& name : {m.name, pendulum})
    for (const char* kind : {"drawing", "drawing-top", "drawing-front", "drawing-side"})
      EXPECT_NE(html.find("<figure class=\"plot\" data-plot=\"" + std::string(kind) + "-" + name + "\""),
                std::string::npos)
          << kind << " " << name;
  EXPECT_NE(html.find("<figure class=\"plot\" data-plot=\"motion-" + pendulum + "\""), std::string::npos);
  EXPECT_NE(html.find("in an isometric view"), std::string::npos);
}

}  // namespace
}  // namespace harness_frames_test
}  // namespace mechbench::harness
