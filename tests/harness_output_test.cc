// Output files: `run --csv` (every method's trajectory, residuals measured alike, names quoted as
// RFC 4180 says), and AtomicFile (nothing touched before the work succeeded, inputs never overwritten).
#include "mechbench/harness/compare.h"
#include "mechbench/harness/output.h"
#include "mechbench/harness/registry.h"
#include "mechbench/harness/tolerances.h"
#include "mechbench/errors.h"
#include "mechbench/loader.h"
#include "mechbench/references/nfourbar.h"

#include <gtest/gtest.h>

#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

namespace mechbench::harness {
namespace harness_output_test {  // this file's own names (the tests build in unity batches)
namespace {

namespace fs = std::filesystem;

std::string Fixture(const std::string& name) { return std::string(MECHBENCH_TEST_DATA) + "/scenes/" + name; }

// A minimal RFC 4180 reader: fields in double quotes may hold commas, doubled quotes, line breaks.
std::vector<std::vector<std::string>> ParseCsv(const std::string& text) {
  std::vector<std::vector<std::string>> rows(1);
  std::string field;
  bool quoted = false, fresh = true;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (quoted) {
      if (c == '"' && i + 1 < text.size() && text[i + 1] == '"') field += '"', ++i;
      else if (c == '"') quoted = false;
      else field += c;
    } else if (c == '"' && fresh) {
      quoted = true;
    } else if (c == ',') {
      rows.back().push_back(field), field.clear(), fresh = true;
      continue;
    } else if (c == '\n') {
      rows.back().push_back(field), field.clear(), fresh = true;
      rows.emplace_back();
      continue;
    } else {
      field += c;
    }
    fresh = false;
  }
  if (rows.back().empty()) rows.pop_back();
  return rows;
}

std::string Read(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(TrajectoryCsv, NamesAreQuotedAndEveryRowHasItsNineFields) {
  const Model m = LoadScenario(Fixture("odd_names.yaml"));
  std::vector<MethodPtr> methods;
  for (MethodPtr& meth : AllMethods())
    if (meth->name() == "analytic" || meth->name() == "numeric") methods.push_back(std::move(meth));
  const RunReport rep = RunScenario(m, methods, {}, LoadTolerances(m.name));
  std::ostringstream out;
  out << kTrajectoryCsvHeader << "\n";
  WriteTrajectoryCsv(out, m, rep);
  const auto rows = ParseCsv(out.str());
  ASSERT_EQ(rows.size(), 1 + 2 * m.analysis.samples * m.q_layout.size());
  std::set<std::string> coordinates;
  for (const auto& row : rows) {
    ASSERT_EQ(row.size(), 9u);
    coordinates.insert(row[4]);
  }
  EXPECT_TRUE(coordinates.count("xp,1"));
  EXPECT_TRUE(coordinates.count("yp\"2\""));
  EXPECT_TRUE(coordinates.count(" theta"));
}

// The residual no trajectory can go below grows with the coordinates' size against the links':
// a chain of 1 m links 40 m long stays far below ALI3-P's bound of 1e-12, one 3000 m long does not
// (its run reached 1.8e-12 = 2^-39 at N = 2500 and 3000, the README's recipe flagged for it).
TEST(Residuals, TheRoundOffFloorGrowsWithTheChainsExtent) {
  const auto at_start = [](const Model& m) { return std::vector<Sample>{Sample{0.0, m.GuessQ(), {}, {}}}; };
  const Model a02 = references::NFourBar({.n = 40, .t1 = 0.01, .samples = 2});
  const Model long_chain = references::NFourBar({.n = 3000, .t1 = 0.01, .samples = 2});
  const double small = ResidualRoundOff(a02, at_start(a02)), large = ResidualRoundOff(long_chain, at_start(long_chain));
  EXPECT_GT(small, 0);
  EXPECT_LT(small, 1e-13);
  EXPECT_GT(large, 1.8e-12);
  EXPECT_LT(large, 1e-11);
  EXPECT_GT(large / small, 30.0);  // about linear in the extent (3000 / 40 = 75)
  EXPECT_LT(large / small, 150.0);
}

// The residual column is the same measure for every method, the scaled ‖Φ‖ of ScaledResiduals:
// engines used to write 0 on every row while their max_residual reached 0.33.
TEST(TrajectoryCsv, ResidualIsMeasuredAlikeForEveryMethod) {
  const Model m = LoadScenario(ResolveScenario("fourbar_free"));
  std::vector<MethodPtr> methods;
  for (MethodPtr& meth : AllMethods())
    if (meth->name() == "dyn-ali3p" || meth->name().find("-default") != std::string::npos) methods.push_back(std::move(meth));
  const RunReport rep = RunScenario(m, methods, {}, LoadTolerances(m.name));
  std::ostringstream out;
  WriteTrajectoryCsv(out, m, rep);
  const auto rows = ParseCsv(out.str());
  const size_t slots = m.q_layout.size();
  size_t row = 0;
  for (const Result& r : rep.results) {
    if (r.trajectory.empty()) continue;
    SCOPED_TRACE(r.method);
    const std::vector<double> expected = ScaledResiduals(m, r.trajectory);
    double largest = 0;
    for (size_t k = 0; k < r.trajectory.size(); ++k, row += slots) {
      ASSERT_LT(row, rows.size());
      ASSERT_EQ(rows[row][1], r.method);
      EXPECT_EQ(std::stod(rows[row][8]), expected[k]) << "sample " << k;
      largest = std::max(largest, std::stod(rows[row][8]));
    }
    EXPECT_EQ(largest, rep.max_residual.at(r.method));
    if (r.method != "dyn-ali3p") {
      EXPECT_GT(largest, 1e-12) << "an engine's loop drifts: its residual is not 0";
    }
  }
}

TEST(AtomicFile, TheTargetIsUntouchedUntilCommit) {
  const fs::path dir = fs::temp_directory_path() / ("mechbench_atomic_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string target = (dir / "out.csv").string();
  std::ofstream(target) << "old\n";
  {
    AtomicFile f(target);
    f.stream() << "new\n";
    EXPECT_EQ(Read(target), "old\n");
    // Destroyed without Commit (an exception, bad input): the old file stays, no temporary is left.
  }
  EXPECT_EQ(Read(target), "old\n");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
  {
    AtomicFile f(target);
    f.stream() << "new\n";
    f.Commit();
  }
  EXPECT_EQ(Read(target), "new\n");
  EXPECT_THROW(AtomicFile((dir / "no" / "such" / "dir.csv").string()), ScenarioError);
  EXPECT_THROW(AtomicFile(dir.string()), ScenarioError);
  fs::remove_all(dir);
}

// An interrupt runs no destructors: SIGINT or SIGTERM in the middle of the work must still leave
// no temporary file and the target as it was, and the process must still end by that signal.
TEST(AtomicFile, AnInterruptLeavesNoTemporaryAndTheTargetAsItWas) {
  for (int sig : {SIGINT, SIGTERM}) {
    const fs::path dir = fs::temp_directory_path() / ("mechbench_interrupt_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    const std::string target = (dir / "out.csv").string();
    std::ofstream(target) << "old\n";
    int ready[2];
    ASSERT_EQ(::pipe(ready), 0);
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      ::close(ready[0]);
      AtomicFile f(target);
      f.stream() << "half of the new contents\n" << std::flush;
      ReportWriter report((dir / "report").string());  // its lock file stays; no temporary folder yet
      const char byte = 1;
      if (::write(ready[1], &byte, 1) != 1) ::_exit(3);
      for (;;) ::pause();  // the work, interrupted here
    }
    ::close(ready[1]);
    char byte = 0;
    ASSERT_EQ(::read(ready[0], &byte, 1), 1);
    ::close(ready[0]);
    EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 3) << "out.csv, its temporary, report/";
    ASSERT_EQ(::kill(child, sig), 0);
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFSIGNALED(status)) << "the process ends by the signal, as without the handler";
    EXPECT_EQ(WTERMSIG(status), sig);
    EXPECT_EQ(Read(target), "old\n");
    for (const auto& e : fs::recursive_directory_iterator(dir))
      EXPECT_EQ(e.path().filename().string().find(".partial"), std::string::npos) << e.path();
    fs::remove_all(dir);
  }
}

TEST(AtomicFile, AnInputIsNeverAnOutput) {
  const std::string input = Fixture("odd_names.yaml");
  EXPECT_THROW(RefuseToOverwriteInputs(input, {input}, "--csv"), ScenarioError);
  // The same file under another spelling.
  const std::string other = std::string(MECHBENCH_TEST_DATA) + "/scenes/../scenes/odd_names.yaml";
  EXPECT_THROW(RefuseToOverwriteInputs(other, {input}, "--csv"), ScenarioError);
  EXPECT_NO_THROW(RefuseToOverwriteInputs("/tmp/not-an-input.csv", {input}, "--csv"));
}

// Two reports into one folder: the second stops before its work; a written report leaves no
// temporary folder behind and never touches a file of the user's there.
// A link is followed (the file behind it replaced, the link kept); a pipe (as /dev/null or
// /dev/stdout in a pipeline, a special file) is written through and stays a pipe: the rename
// that makes a file whole once replaced /dev/null itself with a plain file when run as root.
TEST(AtomicFile, LinksAndSpecialFilesAreWrittenThroughNotReplaced) {
  const fs::path dir = fs::temp_directory_path() / ("mechbench_special_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path real = dir / "real.csv", link = dir / "link.csv";
  std::ofstream(real) << "old\n";
  fs::create_symlink("real.csv", link);
  {
    AtomicFile f(link.string());
    f.stream() << "new\n";
    f.Commit();
  }
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(link)));
  EXPECT_EQ(Read(real.string()), "new\n");
  const fs::path fifo = dir / "fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::string got;
  std::thread reader([&] {
    std::ifstream in(fifo);
    got.assign(std::istreambuf_iterator<char>(in), {});
  });
  {
    AtomicFile f(fifo.string());
    f.stream() << "through the pipe\n";
    f.Commit();
  }
  reader.join();
  EXPECT_EQ(got, "through the pipe\n");
  EXPECT_TRUE(fs::is_fifo(fs::symlink_status(fifo)));
  EXPECT_TRUE(IsStream(fifo.string()));
  // Two outputs naming one file, under two spellings or through a link, are refused; a special
  // file may take both.
  EXPECT_THROW(RefuseClashingOutputs({{"--csv", (dir / "a.out").string()}, {"--junit", (dir / "." / "a.out").string()}}),
               ScenarioError);
  EXPECT_THROW(RefuseClashingOutputs({{"--csv", real.string()}, {"--junit", link.string()}}), ScenarioError);
  EXPECT_NO_THROW(RefuseClashingOutputs({{"--csv", (dir / "a.out").string()}, {"--junit", (dir / "b.out").string()}}));
  EXPECT_NO_THROW(RefuseClashingOutputs({{"--csv", "/dev/null"}, {"--junit", "/dev/null"}}));
  fs::remove_all(dir);
}

TEST(ReportWriter, OneReportAtATimeAndNothingButItsFiles) {
  const fs::path dir = fs::temp_directory_path() / ("mechbench_writer_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "notes.txt") << "mine\n";
  {
    ReportWriter first(dir.string());
    EXPECT_THROW(ReportWriter second(dir.string()), ScenarioError);
    const nlohmann::json results = {{"schema", "mechbench-results/1"}, {"records", nlohmann::json::array()}};
    first.Write(results);
  }
  for (const char* f : {"report.html", "results.json", "results.csv", "summary.md", "notes.txt"})
    EXPECT_TRUE(fs::exists(dir / f)) << f;
  EXPECT_EQ(Read((dir / "notes.txt").string()), "mine\n");
  for (const auto& e : fs::directory_iterator(dir))
    EXPECT_EQ(e.path().filename().string().rfind(".partial", 0), std::string::npos) << e.path();
  ReportWriter again(dir.string());  // the lock went with the first writer
  EXPECT_THROW(ReportWriter((dir / "notes.txt").string()), ScenarioError);  // a file is not a folder
  fs::remove_all(dir);
}

}  // namespace
}  // namespace harness_output_test
}  // namespace mechbench::harness
