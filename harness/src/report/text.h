// Text for the report's files: numbers in a readable form, and strings made safe for HTML,
// Markdown, gnuplot scripts and data files, and file names; whole-file reading and writing.
#pragma once

#include <nlohmann/json.hpp>

#include <filesystem>
#include <optional>
#include <string>

namespace mechbench::harness::report {

// A number by a named format (literal format strings only): "full" (%.17g), "g10", "g6", "g3",
// "g2", "f2"; any other tag is %g.
std::string Fmt(const char* tag, double x);

extern const char* kDash;  // an empty cell

// A relative error or residual: two significant digits.
std::string FmtErr(const std::optional<double>& x);
// Seconds (CPU time, steps, times) in a readable unit.
std::string FmtSeconds(const std::optional<double>& x);
std::string FmtOrder(const std::optional<double>& x);
// A `derived` row's convergence: its observed order ("3.98", a fixed-step method) or its error's
// slope against the tolerance ("tol. slope 0.93", an error-controlled method), or "—".
std::string FmtConvergence(const nlohmann::json& derived_row);
// A `derived` row's CPU to a level ("cpu_to_1e-3"), marked when the rung behind it shared its run
// with another method ("1.2 ms (X's run)"), so that a reader does not count it twice.
std::string FmtLevelCpu(const nlohmann::json& derived_row, const std::string& level);
// A sweep rung: a step in seconds or a relative tolerance.
std::string FmtRung(const std::string& control, const std::optional<double>& v);

std::string Html(const std::string& s);
// A CSV cell for a number: full precision, empty for null.
std::string CsvNum(const nlohmann::json& v);
// One line of Markdown table cell text.
std::string Md(const std::string& s);
std::string MdCode(const std::string& s);
// A string inside a single-quoted gnuplot literal.
std::string GpStr(const std::string& s);
// A string column in a gnuplot data file (double-quoted).
std::string GpDataStr(const std::string& s);
// Something usable in an HTML id / file name.
std::string Slug(const std::string& s);
std::string Trim(std::string s);

std::string ReadFile(const std::filesystem::path& p);
// Throws std::runtime_error naming the path.
void WriteFileOrThrow(const std::filesystem::path& p, const std::string& text);

}  // namespace mechbench::harness::report
