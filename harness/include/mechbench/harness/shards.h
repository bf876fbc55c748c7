// The shard files of `report --shard K/N` read back for `merge`: every line a record of one
// campaign, each shard once and whole. Kept apart from the rest of the harness (it needs only the
// scenario library and nlohmann/json) so that the fuzzer can reach it on its own.
#pragma once

#include <nlohmann/json.hpp>

#include <istream>
#include <set>
#include <string>
#include <vector>

namespace mechbench::harness {

struct ShardSet {
  std::vector<nlohmann::json> records;  // in case order
  nlohmann::json options;               // the shards' `report` options (shard header "options")
  int shards = 0;
  std::string campaign;
  std::set<std::string> ids;  // the records' case ids, each once
};

// Adds one shard file (its text as `in`, named `file` in messages). Throws ScenarioError with the
// file and line for a line that is not a record of the same campaign, a missing header, a shard
// given twice or cut short.
void ReadShard(std::istream& in, const std::string& file, ShardSet& set, std::vector<int>& seen);
// After every file: throws ScenarioError (naming `first_file`) when a shard is missing or the
// records do not add up to the campaign's cases; sorts the records into case order.
void FinishShards(ShardSet& set, const std::vector<int>& seen, const std::string& first_file);

}  // namespace mechbench::harness
