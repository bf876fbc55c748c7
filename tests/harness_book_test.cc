// The book checks: every printed value's verdict must match the list kept in
// tests/data/expected_verdicts.tsv, so a new disagreement (or a fixed one) fails CI and is looked at.
#include "mechbench/harness/compare.h"
#include "mechbench/harness/registry.h"
#include "mechbench/loader.h"

#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <sstream>

namespace mechbench::harness {
namespace {

TEST(Verdict, HalfAndOneUnitOfTheLastDigit) {
  BookValue b;
  b.value = -0.8138;
  b.last_digit = 1e-4;
  EXPECT_EQ(Judge(b, -0.81379), Verdict::kAgrees);
  EXPECT_EQ(Judge(b, -0.81385), Verdict::kAgrees);   // exactly half a unit
  EXPECT_EQ(Judge(b, -0.81388), Verdict::kLastDigit);
  EXPECT_EQ(Judge(b, -0.81392), Verdict::kDiffers);
  b.last_digit = 0;  // an exact claim
  EXPECT_EQ(Judge(b, -0.8138), Verdict::kAgrees);
  EXPECT_EQ(Judge(b, -0.81380001), Verdict::kDiffers);
}

using Key = std::tuple<std::string, std::string, std::string>;  // scenario, quantity, where

std::map<Key, std::string> ExpectedVerdicts() {
  std::map<Key, std::string> m;
  std::ifstream in(MECHBENCH_TEST_DATA "/expected_verdicts.tsv");
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::stringstream ss(line);
    std::string scenario, quantity, where, verdict;
    std::getline(ss, scenario, '\t');
    std::getline(ss, quantity, '\t');
    std::getline(ss, where, '\t');
    std::getline(ss, verdict, '\t');
    m[{scenario, quantity, where}] = verdict;
  }
  return m;
}

TEST(BookChecks, EveryVerdictIsTheExpectedOne) {
  const auto expected = ExpectedVerdicts();
  ASSERT_FALSE(expected.empty());
  // The exact methods, as `mechbench check` uses them by default.
  std::vector<MethodPtr> methods;
  for (auto& m : AllMethods())
    if (m->name() == "analytic" || m->name() == "numeric") methods.push_back(std::move(m));
  size_t seen = 0;
  for (const std::string& f : BuiltinScenarioFiles()) {
    const Model m = LoadScenario(f);
    std::vector<Result> results;
    for (const auto& meth : methods) results.push_back(meth->Run(m, {.motion = false}));
    for (const BookCheck& row : CheckBook(m, results)) {
      ++seen;
      const Key key{m.name, row.book.quantity, row.book.where};
      std::ostringstream values;
      for (const auto& [meth, v] : row.computed) values << " " << meth << "=" << (v ? std::to_string(*v) : "n/a");
      EXPECT_TRUE(row.methods_agree) << m.name << " " << row.book.quantity << values.str();
      const auto it = expected.find(key);
      if (it == expected.end()) {
        ADD_FAILURE() << "no expected verdict for " << m.name << "\t" << row.book.quantity << "\t" << row.book.where
                      << "\t" << ToString(row.verdict) << "\t(add it to tests/data/expected_verdicts.tsv)" << values.str();
        continue;
      }
      EXPECT_EQ(ToString(row.verdict), it->second)
          << m.name << " " << row.book.quantity << " (" << row.book.where << ") book " << row.book.printed << values.str();
    }
  }
  EXPECT_EQ(seen, expected.size()) << "expected_verdicts.tsv lists values that no scenario prints any more";
}

}  // namespace
}  // namespace mechbench::harness
