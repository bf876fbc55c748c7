// The reference cache (harness/reference.h): an entry that does not read as the scene's trajectory
// is discarded and computed again, never trusted and never a crash (a corrupt sample count once
// threw std::bad_alloc).
#include "mechbench/harness/reference.h"
#include "mechbench/loader.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace mechbench::harness {
namespace harness_reference_test {  // this file's own names (the tests build in unity batches)
namespace {

namespace fs = std::filesystem;

std::string Slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(ReferenceCache, ACorruptEntryIsDiscardedAndComputedAgain) {
  const fs::path dir = fs::temp_directory_path() / ("mechbench_cache_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const char* before = std::getenv("MECHBENCH_REFERENCE_CACHE");
  const std::string saved = before ? before : "";
  ::setenv("MECHBENCH_REFERENCE_CACHE", dir.c_str(), 1);
  const Model m = LoadScenario(std::string(MECHBENCH_TEST_DATA) + "/scenes/pendulum_horizontal.yaml");
  const ReferenceRecord first = GetReference(m);
  ASSERT_TRUE(first.confirmed) << first.description;
  ASSERT_FALSE(first.cache_file.empty());
  EXPECT_TRUE(GetReference(m).from_cache);
  const std::string good = Slurp(first.cache_file);
  const std::vector<std::pair<std::string, std::string>> corruptions = {
      {"samples 11", "samples 99999999999999"},  // a count no run of the scene has
      {"samples 11 n 3", "samples 11 n 1000000"},
      {"\n0 ", "\nx "},                           // a sample that is not a number
  };
  for (const auto& [from, to] : corruptions) {
    SCOPED_TRACE(to);
    std::string bad = good;
    const size_t at = bad.find(from);
    ASSERT_NE(at, std::string::npos);
    bad.replace(at, from.size(), to);
    std::ofstream(first.cache_file) << bad;
    const ReferenceRecord again = GetReference(m);
    EXPECT_FALSE(again.from_cache);
    EXPECT_TRUE(again.confirmed);
    EXPECT_EQ(again.trajectory.size(), first.trajectory.size());
    EXPECT_EQ(Slurp(first.cache_file), good) << "the entry is written again, whole";
  }
  // Truncated: the last lines lost.
  std::ofstream(first.cache_file) << good.substr(0, good.size() / 2);
  EXPECT_FALSE(GetReference(m).from_cache);
  EXPECT_TRUE(GetReference(m).from_cache);
  if (before) ::setenv("MECHBENCH_REFERENCE_CACHE", saved.c_str(), 1);
  else ::unsetenv("MECHBENCH_REFERENCE_CACHE");
  fs::remove_all(dir);
}

// The reference of a free scene is bounded by the CPU budget it is given: a scene followed for
// 1e4 s stops as an unconfirmed reference that says why, and nothing is cached.
TEST(ReferenceBudget, AReferenceTooLongForItsBudgetStopsUnconfirmed) {
  const fs::path dir = fs::temp_directory_path() / ("mechbench_cache_budget_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  ::setenv("MECHBENCH_REFERENCE_CACHE", dir.c_str(), 1);
  const Model m = LoadScenario(std::string(MECHBENCH_TEST_DATA) + "/scenes/fourbar_free_long.yaml");
  const ReferenceRecord r = GetReference(m, 0.2);
  EXPECT_FALSE(r.confirmed);
  EXPECT_NE(r.description.find("CPU budget of 0.2 s ran out"), std::string::npos) << r.description;
  EXPECT_FALSE(fs::exists(dir) && !fs::is_empty(dir)) << "an unconfirmed reference is not cached";
  ::unsetenv("MECHBENCH_REFERENCE_CACHE");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace harness_reference_test
}  // namespace mechbench::harness
