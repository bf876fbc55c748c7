// `mechbench diff` (diff.h): what changed between two reports, and which changes are regressions.
#include "mechbench/harness/diff.h"
#include "mechbench/errors.h"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

namespace mechbench::harness {
namespace harness_diff_test {  // this file's own names (the tests build in unity batches)
namespace {

using nlohmann::json;

json Fixture() { return LoadResults(std::string(MECHBENCH_TEST_DATA) + "/report/results_fixture.json"); }

json& Record(json& r, const std::string& id) {
  for (json& rec : r["records"])
    if (rec["id"] == id) return rec;
  ADD_FAILURE() << "no record " << id;
  static json none;
  return none;
}

TEST(Diff, AReportAgainstItselfHasNoChange) {
  const json r = Fixture();
  const DiffResult d = Diff(r, r);
  EXPECT_EQ(d.compared, static_cast<int>(r["records"].size()));
  EXPECT_TRUE(d.rows.empty());
  EXPECT_EQ(d.regressions, 0);
  for (const CpuRatio& c : d.cpu) EXPECT_EQ(c.median, 1.0) << c.method;
}

// The same numbers judged by other tolerance files: a known failure whose entry is gone is a
// plain failure now, a regression; a run stopped by its CPU budget fails the gate (gate.h), a
// regression too; and the files each report was judged by are named when they differ.
TEST(Diff, AKnownFailureNoLongerListedAndABudgetStopAreRegressions) {
  json before = Fixture();
  before["options"]["tolerances"] = json::array({"my_tolerances.yaml"});
  json after = Fixture();
  after["options"]["tolerances"] = json::array();
  json& was_known = Record(after, "run/s5_1_disc_bar_bushing/ode-worldstep-default");
  ASSERT_FALSE(Record(before, "run/s5_1_disc_bar_bushing/ode-worldstep-default")["known"].get<std::string>().empty());
  was_known["known"] = "";
  Record(after, "run/s5_1_disc_bar_bushing/dyn-ali3p")["status"] = "over-budget";
  Record(after, "run/s5_1_disc_bar_bushing/dyn-ali3p")["within"] = false;
  const DiffResult d = Diff(before, after);
  std::ostringstream text;
  PrintDiff(text, d, false);
  EXPECT_EQ(d.regressions, 2) << text.str();
  EXPECT_NE(text.str().find("REGRESSION run/s5_1_disc_bar_bushing/ode-worldstep-default: verdict known failure -> outside its "
                            "tolerance"),
            std::string::npos)
      << text.str();
  EXPECT_NE(text.str().find("REGRESSION run/s5_1_disc_bar_bushing/dyn-ali3p: within tolerance yes -> no (stopped by its CPU budget)"),
            std::string::npos)
      << text.str();
  EXPECT_NE(text.str().find("judged by different tolerance files: old harness/tolerances.yaml, then my_tolerances.yaml; new "
                            "harness/tolerances.yaml"),
            std::string::npos)
      << text.str();
}

TEST(Diff, RegressionsAreToldFromImprovements) {
  const json before = Fixture();
  json after = before;
  // Four regressions (a run that falls outside its tolerance, an engine that now crashes, an error
  // ten times worse, a book verdict that got worse) and three changes that are not (an error ten
  // times better, a case that is gone, a method twice as slow to integrate).
  Record(after, "run/s5_1_disc_bar_bushing/dyn-ali3p")["within"] = false;
  Record(after, "run/s5_1_disc_bar_bushing/dyn-baumgarte-dopri5")["status"] = "crashed";
  json& worse = Record(after, "sweep/s5_1_disc_bar_bushing/dyn-baumgarte-rk4/h=0.004");
  worse["error"]["q_max"] = worse["error"]["q_max"].get<double>() * 10;
  json& better = Record(after, "sweep/s5_1_disc_bar_bushing/dyn-baumgarte-rk4/h=0.002");
  better["error"]["q_max"] = better["error"]["q_max"].get<double>() / 10;
  Record(after, "check/s6_2_ordinary_train")["rows"][0]["verdict"] = "differs";
  json kept = json::array();
  for (const json& rec : after["records"])
    if (rec["id"] != "run/s6_2_ordinary_train/numeric") kept.push_back(rec);
  after["records"] = kept;
  for (json& rec : after["records"])
    if (rec["kind"] == "sweep" && rec["method"] == "dyn-baumgarte-dopri5" && rec.contains("cpu") && rec["cpu"].is_object())
      rec["cpu"]["integration"] = rec["cpu"]["integration"].get<double>() * 2;

  const DiffResult d = Diff(before, after);
  EXPECT_EQ(d.regressions, 4) << [&] {
    std::ostringstream s;
    PrintDiff(s, d, false);
    return s.str();
  }();
  auto row = [&](const std::string& id, const std::string& what) -> const DiffRow* {
    for (const DiffRow& r : d.rows)
      if (r.id.rfind(id, 0) == 0 && r.what == what) return &r;
    return nullptr;
  };
  ASSERT_TRUE(row("run/s5_1_disc_bar_bushing/dyn-ali3p", "within tolerance"));
  EXPECT_TRUE(row("run/s5_1_disc_bar_bushing/dyn-ali3p", "within tolerance")->regression);
  ASSERT_TRUE(row("run/s5_1_disc_bar_bushing/dyn-baumgarte-dopri5", "status"));
  EXPECT_TRUE(row("run/s5_1_disc_bar_bushing/dyn-baumgarte-dopri5", "status")->regression);
  ASSERT_TRUE(row("sweep/s5_1_disc_bar_bushing/dyn-baumgarte-rk4/h=0.004", "q error"));
  EXPECT_TRUE(row("sweep/s5_1_disc_bar_bushing/dyn-baumgarte-rk4/h=0.004", "q error")->regression);
  ASSERT_TRUE(row("sweep/s5_1_disc_bar_bushing/dyn-baumgarte-rk4/h=0.002", "q error"));
  EXPECT_FALSE(row("sweep/s5_1_disc_bar_bushing/dyn-baumgarte-rk4/h=0.002", "q error")->regression);
  ASSERT_TRUE(row("check/s6_2_ordinary_train", "verdict"));
  EXPECT_TRUE(row("check/s6_2_ordinary_train", "verdict")->regression);
  ASSERT_EQ(d.only_old.size(), 1u);
  EXPECT_EQ(d.only_old[0], "run/s6_2_ordinary_train/numeric");
  bool found = false;
  for (const CpuRatio& c : d.cpu) {
    if (c.method != "dyn-baumgarte-dopri5") continue;
    found = true;
    EXPECT_DOUBLE_EQ(c.median, 2.0);
  }
  EXPECT_TRUE(found);
  // Markdown for a job summary: a table whose regressions stand out.
  std::ostringstream md;
  PrintDiff(md, d, true);
  EXPECT_NE(md.str().find("| **regression** | `run/s5_1_disc_bar_bushing/dyn-ali3p` | within tolerance | yes | no |"),
            std::string::npos)
      << md.str();
}

TEST(Diff, NotAResultsFileIsBadInput) {
  EXPECT_THROW(LoadResults("/no/such/report"), ScenarioError);
  EXPECT_THROW(LoadResults(std::string(MECHBENCH_TEST_DATA) + "/scenes/odd_names.yaml"), ScenarioError);
}

}  // namespace
}  // namespace harness_diff_test
}  // namespace mechbench::harness
