// Tolerant access to a results object (harness/report/results.schema.json): the renderer shows
// what is there and never throws on a missing or mistyped member.
#pragma once

#include <nlohmann/json.hpp>

#include <optional>
#include <string>

namespace mechbench::harness::report {

using json = nlohmann::json;

const json& Null();
const json& EmptyArray();
// o[key], or null when o is not an object or has no such member.
const json& At(const json& o, const char* key);
// v when it is an array (object), else an empty one.
const json& Arr(const json& v);
const json& Obj(const json& v);
// A finite number, or nothing.
std::optional<double> Num(const json& v);
// A string, a boolean, an integer or a number (6 significant digits) as text; "" otherwise.
std::string Str(const json& v);
std::string Str(const json& o, const char* key);

}  // namespace mechbench::harness::report
