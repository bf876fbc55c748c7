#include "access.h"

#include "text.h"

#include <cmath>

namespace mechbench::harness::report {

const json& Null() {
  static const json kNull;
  return kNull;
}
const json& EmptyArray() {
  static const json kEmpty = json::array();
  return kEmpty;
}
const json& At(const json& o, const char* key) {
  if (o.is_object()) {
    if (auto it = o.find(key); it != o.end()) return *it;
  }
  return Null();
}
const json& Arr(const json& v) { return v.is_array() ? v : EmptyArray(); }
const json& Obj(const json& v) {
  static const json kEmpty = json::object();
  return v.is_object() ? v : kEmpty;
}
std::optional<double> Num(const json& v) {
  if (!v.is_number()) return std::nullopt;
  const double d = v.get<double>();
  if (!std::isfinite(d)) return std::nullopt;
  return d;
}
std::string Str(const json& v) {
  if (v.is_string()) return v.get<std::string>();
  if (v.is_boolean()) return v.get<bool>() ? "true" : "false";
  if (v.is_number_integer()) return std::to_string(v.get<long long>());
  if (v.is_number()) return Fmt("g6", v.get<double>());
  return "";
}
std::string Str(const json& o, const char* key) { return Str(At(o, key)); }

}  // namespace mechbench::harness::report
