// JUnit XML (junit.h) from a report's results and from `run`: one case per (scenario, method) and
// per book value; failures, errors and skips as a CI system reads them.
#include "mechbench/harness/junit.h"

#include "mechbench/harness/registry.h"
#include "mechbench/harness/tolerances.h"
#include "mechbench/loader.h"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

namespace mechbench::harness {
namespace harness_junit_test {  // this file's own names (the tests build in unity batches)
namespace {

using nlohmann::json;

json Fixture() {
  std::ifstream in(std::string(MECHBENCH_TEST_DATA) + "/report/results_fixture.json");
  return json::parse(in);
}

int Count(const std::string& text, const std::string& what) {
  int n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

TEST(Junit, ReportRecordsBecomeCasesWithTheirState) {
  const json r = Fixture();
  const std::vector<JunitCase> cases = JunitCases(r);
  int runs = 0, rows = 0;
  for (const json& rec : r["records"]) {
    if (rec["kind"] == "run") ++runs;
    if (rec["kind"] == "check") rows += static_cast<int>(rec["rows"].size());
  }
  ASSERT_EQ(cases.size(), static_cast<size_t>(runs + rows));
  auto find = [&](const std::string& suite, const std::string& name) -> const JunitCase& {
    for (const JunitCase& c : cases)
      if (c.suite == suite && c.name == name) return c;
    ADD_FAILURE() << "no case " << suite << " " << name;
    static const JunitCase none;
    return none;
  };
  EXPECT_EQ(find("run.s5_1_disc_bar_bushing", "dyn-ali3p").state, JunitCase::State::kPassed);
  // Not applicable, and outside its tolerance but a listed known failure: skipped, with the reason.
  const JunitCase& na = find("run.s5_1_disc_bar_bushing", "analytic");
  EXPECT_EQ(na.state, JunitCase::State::kSkipped);
  EXPECT_EQ(na.message.rfind("not applicable: ", 0), 0u) << na.message;
  const JunitCase& known = find("run.s5_1_disc_bar_bushing", "ode-worldstep-default");
  EXPECT_EQ(known.state, JunitCase::State::kSkipped);
  EXPECT_NE(known.message.find("known failure"), std::string::npos) << known.message;
  // Failed and not known: a failure.
  EXPECT_EQ(find("run.s6_2_ordinary_train", "ode-worldstep-default").state, JunitCase::State::kFailed);
  // A book value the methods agree on passes whatever the book printed; its verdict is in the output.
  const JunitCase& book = find("book.s6_2_ordinary_train", "qd.phi_out/qd.phi_in (§6.2 part 3 (8 decimals))");
  EXPECT_EQ(book.state, JunitCase::State::kPassed);
  EXPECT_NE(book.output.find("verdict last-digit"), std::string::npos) << book.output;
}

TEST(Junit, TheXmlCountsItsCasesAndEscapesText) {
  std::vector<JunitCase> cases(3);
  cases[0] = {"run.a", "m1", 0.5, JunitCase::State::kPassed, "", ""};
  cases[1] = {"run.a", "m<2>", 0.25, JunitCase::State::kFailed, "error \"1e-3\" & more", "line one\nline two\x01"};
  cases[2] = {"book.b", "q (eq. 1)", 0, JunitCase::State::kSkipped, "n/a", ""};
  std::ostringstream out;
  WriteJunit(out, cases);
  const std::string xml = out.str();
  EXPECT_EQ(xml.rfind("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<testsuites name=\"mechbench\" tests=\"3\" failures=\"1\" "
                      "errors=\"0\" skipped=\"1\" time=\"0.750000\">",
                      0),
            0u)
      << xml;
  EXPECT_EQ(Count(xml, "<testsuite "), 2);
  EXPECT_EQ(Count(xml, "<testcase "), 3);
  EXPECT_NE(xml.find("name=\"m&lt;2&gt;\""), std::string::npos);
  EXPECT_NE(xml.find("<failure message=\"error &quot;1e-3&quot; &amp; more\"/>"), std::string::npos) << xml;
  EXPECT_NE(xml.find("<system-out>line one\nline two</system-out>"), std::string::npos) << "a control character is dropped";
  EXPECT_NE(xml.find("<skipped message=\"n/a\"/>"), std::string::npos);
}

TEST(Junit, RunCasesFollowTheRunsVerdict) {
  const Model m = LoadScenario(ResolveScenario("fourbar_free"));
  std::vector<MethodPtr> methods;
  for (MethodPtr& meth : AllMethods())
    if (meth->name() == "analytic" || meth->name() == "dyn-ali3p" || meth->name() == "numeric") methods.push_back(std::move(meth));
  Tolerances tol = LoadTolerances(m.name);
  tol.free_methods["dyn-ali3p"].position = 1e-12;  // far below its 1.9e-6: it fails
  const RunReport rep = RunScenario(m, methods, {}, tol);
  const std::vector<JunitCase> cases = JunitCases(rep);
  ASSERT_EQ(cases.size(), 3u);
  for (const JunitCase& c : cases) {
    EXPECT_EQ(c.suite, "run.fourbar_free");
    if (c.name == "dyn-ali3p") {
      EXPECT_EQ(c.state, JunitCase::State::kFailed);
      EXPECT_NE(c.message.find("position error"), std::string::npos) << c.message;
    } else {
      EXPECT_EQ(c.state, JunitCase::State::kPassed) << c.name << ": " << c.message;
    }
  }
}

}  // namespace
}  // namespace harness_junit_test
}  // namespace mechbench::harness
