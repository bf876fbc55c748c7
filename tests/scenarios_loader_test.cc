#include "mechbench/errors.h"
#include "mechbench/loader.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

namespace mechbench {
namespace scenarios_loader_test {  // this file's own names (the tests build in unity batches)
namespace {

namespace fs = std::filesystem;

TEST(Loader, EveryBuiltinScenarioLoads) {
  const auto files = BuiltinScenarioFiles();
  ASSERT_GE(files.size(), 20u) << "built-in scenarios missing from " << BuiltinScenarioDir();
  std::set<std::string> names;
  for (const std::string& f : files) {
    SCOPED_TRACE(f);
    Model m;
    ASSERT_NO_THROW(m = LoadScenario(f));
    EXPECT_TRUE(names.insert(m.name).second);
    EXPECT_FALSE(m.title.empty());
    EXPECT_FALSE(m.q_layout.empty());
    for (const BookValue& b : m.book) {
      EXPECT_TRUE(std::isfinite(b.value)) << b.quantity;
      EXPECT_GE(b.last_digit, 0.0) << b.quantity;
      EXPECT_FALSE(b.where.empty()) << b.quantity << ": say where the book prints it";
    }
  }
}

TEST(Loader, LayoutFollowsTheBook) {
  // §4.1: the guides remove xA and yB; §4.6: y1, x2, y2, x3; §5.1: x1, y1, x2.
  auto names = [](const Model& m) {
    std::string s;
    for (const auto& slot : m.q_layout) s += slot.name + " ";
    return s;
  };
  EXPECT_EQ(names(LoadScenario(ResolveScenario("s4_1_two_sliders"))), "yA xB theta ");
  EXPECT_EQ(names(LoadScenario(ResolveScenario("s3_3_double_slider"))), "y1 x2 y2 x3 ");
  EXPECT_EQ(names(LoadScenario(ResolveScenario("s5_1_disc_bar_bushing"))), "x1 y1 x2 ");
  EXPECT_EQ(names(LoadScenario(ResolveScenario("s4_4_quick_return"))), "x1 y1 x2 y2 x3 y3 theta ");
}

TEST(Loader, BookValuesKeepTheirPrintedDigits) {
  const Model m = LoadScenario(ResolveScenario("s4_1_two_sliders"));
  ASSERT_FALSE(m.book.empty());
  EXPECT_EQ(m.book[0].printed, "-0.8138");
  EXPECT_DOUBLE_EQ(m.book[0].value, -0.8138);
  EXPECT_NEAR(m.book[0].last_digit, 1e-4, 1e-18);
  const Model g = LoadScenario(ResolveScenario("s6_3_compound_train"));
  EXPECT_NEAR(g.book[0].unit_factor, 2 * 3.141592653589793 / 60, 1e-15);  // rpm
}

TEST(Loader, ResolvesNamesAndPaths) {
  const std::string path = ResolveScenario("s6_3_compound_train");
  EXPECT_TRUE(fs::exists(path));
  EXPECT_EQ(ResolveScenario(path), path);
  EXPECT_THROW(ResolveScenario("no_such_scenario"), ScenarioError);
  // A folder is named as one, not as missing.
  try {
    ResolveScenario(MECHBENCH_TEST_DATA);
    ADD_FAILURE() << "a directory resolved";
  } catch (const ScenarioError& e) {
    EXPECT_NE(std::string(e.what()).find("is a directory"), std::string::npos) << e.what();
  }
}

// The YAML reader quotes the bytes it stumbles on; a control byte such as a binary file's NUL is
// shown as \xNN, so the message keeps its fix after it.
TEST(Loader, ControlBytesInAYamlErrorAreQuoted) {
  std::string text = "kind: \"\\";
  text += '\0';
  text += "\"\n";
  try {
    LoadScenarioFromString(text, "binary.yaml");
    ADD_FAILURE() << "loaded";
  } catch (const ScenarioError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.find('\0'), std::string::npos);
    EXPECT_NE(what.find("\\x00"), std::string::npos) << what;
    EXPECT_NE(what.find("fix:"), std::string::npos) << what;
  }
}

// Files under tests/data/bad whose problem the loader itself must catch. Their first line says
// what the message must contain; geometric problems (cannot assemble, wrong DOF, singular) are
// caught by the methods and tested through the command line (tests/expect_bad_input.cmake).
TEST(Loader, MalformedFilesNameFileLineAndProblem) {
  int load_errors = 0;
  for (const auto& e : fs::directory_iterator(MECHBENCH_TEST_DATA "/bad")) {
    std::ifstream in(e.path());
    std::string first;
    std::getline(in, first);
    ASSERT_EQ(first.rfind("# expect: ", 0), 0u) << e.path() << " must start with '# expect: <message>'";
    const std::string expected = first.substr(10);
    try {
      LoadScenario(e.path().string());
    } catch (const ScenarioError& err) {
      ++load_errors;
      const std::string what = err.what();
      EXPECT_NE(what.find(expected), std::string::npos) << what;
      EXPECT_NE(what.find(e.path().filename().string()), std::string::npos) << what;
      EXPECT_GT(err.where().line, 0) << what;
    }
  }
  EXPECT_GE(load_errors, 10);
}

TEST(Loader, NeverCrashesOnTruncatedFiles) {
  // Every prefix of a real file either loads or gives a ScenarioError: never a crash or a hang.
  std::ifstream in(ResolveScenario("s3_4_disc_slotted_bar"));
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  int loaded = 0, rejected = 0;
  for (size_t n = 0; n < text.size(); n += 7) {
    try {
      LoadScenarioFromString(text.substr(0, n), "prefix.yaml");
      ++loaded;
    } catch (const ScenarioError& e) {
      ++rejected;
      EXPECT_EQ(std::string(e.what()).rfind("prefix.yaml", 0), 0u) << e.what();
    }
  }
  EXPECT_GT(rejected, 0);
  EXPECT_NO_THROW(LoadScenarioFromString(text, "whole.yaml"));
}

}  // namespace
}  // namespace scenarios_loader_test
}  // namespace mechbench
