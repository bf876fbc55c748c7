#include "mechbench/harness/shards.h"

#include "mechbench/errors.h"

#include <algorithm>
#include <string>

namespace mechbench::harness {

namespace {

using nlohmann::json;

const char* const kFix = "pass the .jsonl files that `report --shard K/N` wrote, each once";

bool Has(const json& j, const char* key, json::value_t type) {
  const auto it = j.find(key);
  if (it == j.end()) return false;
  if (type == json::value_t::number_integer) return it->is_number_integer();
  return it->type() == type;
}

}  // namespace

void ReadShard(std::istream& in, const std::string& f, ShardSet& set, std::vector<int>& seen) {
  std::string line;
  int line_no = 0;
  bool header = false;
  long long declared = 0, found = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.empty()) continue;
    json j;
    try {
      j = json::parse(line);
    } catch (const std::exception& e) {
      throw ScenarioError({f, line_no}, std::string("not a JSON line: ") + e.what(), kFix);
    }
    if (!j.is_object()) throw ScenarioError({f, line_no}, "not a record (a JSON object)", kFix);
    if (!header) {
      const auto hit = j.find("mechbench_shard");
      if (hit == j.end() || !hit->is_object())
        throw ScenarioError({f, line_no}, "the first line is not a shard header (mechbench_shard with shard, shards, "
                                          "records, total_cases, campaign, options)", kFix);
      const json& h = *hit;
      if (!Has(h, "shard", json::value_t::number_integer) || !Has(h, "shards", json::value_t::number_integer) ||
          !Has(h, "records", json::value_t::number_integer) || !Has(h, "total_cases", json::value_t::number_integer) ||
          !Has(h, "campaign", json::value_t::string) || !Has(h, "options", json::value_t::object))
        throw ScenarioError({f, line_no}, "the shard header lacks shard, shards, records, total_cases, campaign or options", kFix);
      const long long n = h["shards"].get<long long>(), k = h["shard"].get<long long>();
      if (n < 1 || n > 1000000 || k < 1 || k > n)
        throw ScenarioError({f, line_no}, "a shard numbered " + std::to_string(k) + " of " + std::to_string(n), kFix);
      const json& op = h["options"];
      if (!Has(op, "quick", json::value_t::boolean) || !Has(op, "repeats", json::value_t::number_integer) ||
          !(op.contains("timeout") && op["timeout"].is_number()) || !Has(op, "jobs", json::value_t::number_integer) ||
          !Has(op, "scenarios", json::value_t::array) || !Has(op, "methods", json::value_t::array) ||
          !std::all_of(op["scenarios"].begin(), op["scenarios"].end(), [](const json& x) { return x.is_string(); }) ||
          !std::all_of(op["methods"].begin(), op["methods"].end(), [](const json& x) { return x.is_string(); }))
        throw ScenarioError({f, line_no}, "the shard header's options do not read (quick, repeats, timeout, jobs, "
                                          "scenarios, methods)", kFix);
      if (set.campaign.empty()) {
        set.campaign = h["campaign"].get<std::string>();
        set.shards = static_cast<int>(n);
        set.options = op;
        set.options["total_cases"] = h["total_cases"];
      } else if (h["campaign"].get<std::string>() != set.campaign || n != set.shards) {
        throw ScenarioError({f, line_no}, "a shard of another campaign (" + h["campaign"].get<std::string>() + ", " +
                                              std::to_string(n) + " shards) than the first file's (" + set.campaign + ", " +
                                              std::to_string(set.shards) + " shards): other scenarios, methods, options or build",
                            "merge the shards of one run of `report --shard K/N`");
      }
      if (std::find(seen.begin(), seen.end(), static_cast<int>(k)) != seen.end())
        throw ScenarioError({f, line_no}, "shard " + std::to_string(k) + " of " + std::to_string(n) + " is given twice", kFix);
      seen.push_back(static_cast<int>(k));
      declared = h["records"].get<long long>();
      header = true;
      continue;
    }
    if (!Has(j, "id", json::value_t::string) || !Has(j, "kind", json::value_t::string) ||
        !Has(j, "scenario", json::value_t::string) || !Has(j, "index", json::value_t::number_integer))
      throw ScenarioError({f, line_no}, "not a case record (id, index, kind and scenario expected)", kFix);
    const std::string id = j["id"].get<std::string>();
    if (!set.ids.insert(id).second) throw ScenarioError({f, line_no}, "record " + id + " appears twice", kFix);
    set.records.push_back(std::move(j));
    ++found;
  }
  if (!header) throw ScenarioError({f, 0}, "no shard header: an empty file or not a shard", kFix);
  if (found != declared)
    throw ScenarioError({f, line_no}, "holds " + std::to_string(found) + " records where its header counts " +
                                          std::to_string(declared) + ": the file was cut short or edited",
                        "run that shard again");
}

void FinishShards(ShardSet& set, const std::vector<int>& seen, const std::string& first_file) {
  if (set.campaign.empty()) throw ScenarioError({first_file, 0}, "no shard files given", kFix);
  std::string missing;
  for (int k = 1; k <= set.shards; ++k)
    if (std::find(seen.begin(), seen.end(), k) == seen.end()) missing += (missing.empty() ? "" : ", ") + std::to_string(k);
  if (!missing.empty())
    throw ScenarioError({first_file, 0}, "shard(s) " + missing + " of " + std::to_string(set.shards) +
                                             " missing: the report would lack their cases",
                        "run the missing shard(s) and pass every shard-K-of-" + std::to_string(set.shards) + ".jsonl");
  const long long total = set.options["total_cases"].get<long long>();
  if (static_cast<long long>(set.records.size()) != total)
    throw ScenarioError({first_file, 0}, "the shards hold " + std::to_string(set.records.size()) +
                                             " records where their campaign has " + std::to_string(total) + " cases",
                        "run the shards again, each once");
  std::stable_sort(set.records.begin(), set.records.end(),
                   [](const json& a, const json& b) { return a["index"].get<long long>() < b["index"].get<long long>(); });
}

}  // namespace mechbench::harness
