// libFuzzer target: merge's shard reader (shards.h) must answer any bytes with a record set or a
// ScenarioError naming the file and line, never a crash or another exception. The input is cut at
// NUL bytes into up to four shard files.
#include "mechbench/errors.h"
#include "mechbench/harness/shards.h"

#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  std::vector<std::string> files;
  size_t start = 0;
  while (files.size() < 4) {
    const size_t cut = text.find('\0', start);
    files.push_back(text.substr(start, cut == std::string::npos ? std::string::npos : cut - start));
    if (cut == std::string::npos) break;
    start = cut + 1;
  }
  mechbench::harness::ShardSet set;
  std::vector<int> seen;
  try {
    for (size_t k = 0; k < files.size(); ++k) {
      std::istringstream in(files[k]);
      mechbench::harness::ReadShard(in, "shard-" + std::to_string(k + 1) + ".jsonl", set, seen);
    }
    mechbench::harness::FinishShards(set, seen, "shard-1.jsonl");
  } catch (const mechbench::ScenarioError&) {
  }
  return 0;
}
