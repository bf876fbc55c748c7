#include "text.h"

#include "access.h"

#include <array>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace mechbench::harness::report {

namespace fs = std::filesystem;

std::string Fmt(const char* tag, double x) {
  std::array<char, 64> b{};
  const std::string t = tag;
  if (t == "full") std::snprintf(b.data(), b.size(), "%.17g", x);
  else if (t == "g10") std::snprintf(b.data(), b.size(), "%.10g", x);
  else if (t == "g6") std::snprintf(b.data(), b.size(), "%.6g", x);
  else if (t == "g3") std::snprintf(b.data(), b.size(), "%.3g", x);
  else if (t == "g2") std::snprintf(b.data(), b.size(), "%.2g", x);
  else if (t == "f2") std::snprintf(b.data(), b.size(), "%.2f", x);
  else std::snprintf(b.data(), b.size(), "%g", x);
  return b.data();
}

const char* kDash = "—";

// A relative error or residual: two significant digits.
std::string FmtErr(const std::optional<double>& x) {
  if (!x) return kDash;
  if (*x == 0) return "0";
  return Fmt("g2", *x);
}
// Seconds (CPU time, steps, times) in a readable unit.
std::string FmtSeconds(const std::optional<double>& x) {
  if (!x) return kDash;
  const double s = *x, a = std::fabs(s);
  if (a == 0) return "0 s";
  if (a < 1e-6) return Fmt("g3", s * 1e9) + " ns";
  if (a < 1e-3) return Fmt("g3", s * 1e6) + " µs";
  if (a < 1) return Fmt("g3", s * 1e3) + " ms";
  return Fmt("g3", s) + " s";
}
std::string FmtOrder(const std::optional<double>& x) { return x ? Fmt("f2", *x) : kDash; }
std::string FmtLevelCpu(const nlohmann::json& d, const std::string& level) {
  const nlohmann::json* v = d.is_object() && d.contains("cpu_to_" + level) ? &d["cpu_to_" + level] : nullptr;
  std::string s = FmtSeconds(v && v->is_number() ? std::optional<double>(v->get<double>()) : std::nullopt);
  if (v && v->is_number() && d.contains("shared_at_" + level) && d["shared_at_" + level].is_string())
    s += " (" + d["shared_at_" + level].get<std::string>() + "'s run)";
  return s;
}
std::string FmtConvergence(const nlohmann::json& d) {
  if (d.is_object() && d.contains("order") && d["order"].is_number()) return FmtOrder(d["order"].get<double>());
  if (d.is_object() && d.contains("tolerance_slope") && d["tolerance_slope"].is_number())
    return "tol. slope " + Fmt("f2", d["tolerance_slope"].get<double>());
  return kDash;
}
// A sweep rung: a step in seconds or a relative tolerance.
std::string FmtRung(const std::string& control, const std::optional<double>& v) {
  if (!v) return control == "none" ? "default" : kDash;
  if (control == "step") return "h = " + FmtSeconds(v);
  if (control == "tolerance") return "tol = " + Fmt("g3", *v);
  return Fmt("g3", *v);
}

std::string Html(const std::string& s) {
  std::string out;
  out.reserve(s.size() + 16);
  for (char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&#39;"; break;
      default: out += c;
    }
  }
  return out;
}
std::string CsvNum(const json& v) {
  if (auto d = Num(v)) return Fmt("full", *d);
  return "";
}

// One line of Markdown table cell text.
std::string Md(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '|') out += "\\|";
    else if (c == '\n' || c == '\r' || c == '\t') out += ' ';
    else if (c == '<') out += "&lt;";
    else if (c == '>') out += "&gt;";
    else out += c;
  }
  return out;
}
std::string MdCode(const std::string& s) { return "`" + Md(s) + "`"; }

// A string inside a single-quoted gnuplot literal.
std::string GpStr(const std::string& s) {
  std::string out = "'";
  for (char c : s) {
    if (c == '\'') out += "''";
    else if (static_cast<unsigned char>(c) < 0x20) out += ' ';
    else out += c;
  }
  return out + "'";
}
// A string column in a gnuplot data file (double-quoted).
std::string GpDataStr(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"') out += '\'';
    else if (c == '\\') out += '/';
    else if (static_cast<unsigned char>(c) < 0x20) out += ' ';
    else out += c;
  }
  return out + "\"";
}

// Something usable in an HTML id / file name.
std::string Slug(const std::string& s) {
  std::string out;
  for (char c : s) out += (std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-') ? c : '-';
  return out.empty() ? std::string("x") : out;
}

std::string Trim(std::string s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.pop_back();
  size_t i = 0;
  while (i < s.size() && std::isspace(static_cast<unsigned char>(s[i]))) ++i;
  return s.substr(i);
}

std::string ReadFile(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void WriteFileOrThrow(const fs::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  if (!out) {
    throw std::runtime_error("report: cannot write " + p.string() + ": " + std::strerror(errno));
  }
  out << text;
  out.close();
  if (!out) throw std::runtime_error("report: error while writing " + p.string());
}

}  // namespace mechbench::harness::report
