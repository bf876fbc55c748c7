// mechbench: the command line. Exit codes: 0 all methods agree within the scenario's tolerances,
// 1 some disagree (or a run diverged, crashed, or was stopped by its CPU budget: gate.h), 2 bad input.
#include "mechbench/errors.h"
#include "mechbench/harness/campaign.h"
#include "mechbench/harness/compare.h"
#include "mechbench/harness/diff.h"
#include "mechbench/harness/gate.h"
#include "mechbench/harness/isolated.h"
#include "mechbench/harness/junit.h"
#include "mechbench/harness/output.h"
#include "mechbench/harness/reference.h"
#include "mechbench/harness/registry.h"
#include "mechbench/harness/report_render.h"
#include "mechbench/harness/shards.h"
#include "mechbench/harness/tolerances.h"
#include "mechbench/loader.h"
#include "mechbench/references/registry.h"
#include "mechbench/references/nfourbar.h"
#include "json_number.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <optional>
#include <fstream>
#include <iostream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace mb = mechbench;
namespace hn = mechbench::harness;
using nlohmann::json;

namespace {

using hn::JsonNumber;

constexpr int kExitAgree = 0, kExitDisagree = 1, kExitBadInput = 2;


std::vector<std::string> ResolveAll(const std::vector<std::string>& names) {
  if (names.empty()) return mb::BuiltinScenarioFiles();
  std::vector<std::string> files;
  for (const std::string& n : names) files.push_back(mb::ResolveScenario(n));
  return files;
}

std::vector<mb::MethodPtr> SelectMethods(const std::vector<std::string>& wanted) {
  std::vector<mb::MethodPtr> all = hn::AllMethods(), out;
  std::set<std::string> left(wanted.begin(), wanted.end());
  for (auto& m : all)
    if (wanted.empty() || left.erase(m->name())) out.push_back(std::move(m));
  if (!left.empty()) {
    std::string known;
    for (const auto& m : hn::AllMethods()) known += " " + m->name();
    throw mb::ScenarioError({"--method", 0}, "unknown method '" + *left.begin() + "'", "built-in methods:" + known);
  }
  return out;
}

// JSON has no NaN: a missing figure is null.

std::string Num(double v, int digits = 10) {
  if (!std::isfinite(v)) return std::to_string(v);
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

// A number of seconds or a length of time: finite and positive (or ≥ 0 where 0 means "none").
CLI::Validator FiniteNumber(double lowest, bool inclusive, const std::string& what) {
  return CLI::Validator(
      [=](const std::string& text) -> std::string {
        double v = 0;
        try {
          size_t used = 0;
          v = std::stod(text, &used);
          if (used != text.size()) return what + " must be a number, not '" + text + "'";
        } catch (const std::exception&) {
          return what + " must be a number, not '" + text + "'";
        }
        if (!std::isfinite(v) || (inclusive ? v < lowest : v <= lowest))
          return what + " must be a finite number " + (inclusive ? "≥ " : "> ") + Num(lowest, 6) + ", not " + text;
        return {};
      },
      inclusive ? "NUMBER ≥ " + Num(lowest, 6) : "NUMBER > " + Num(lowest, 6));
}

std::string Join(const std::vector<std::string>& v) {
  std::string out;
  for (const std::string& e : v) out += (out.empty() ? "" : ", ") + e;
  return out;
}

// A number in at most `width` columns, with as many significant digits (up to 10) as fit: a
// table cell never cuts a number (1.778902546e-13 cut to 13 columns read "1.778902546e-").
std::string NumFit(double v, size_t width) {
  std::string s = Num(v);
  for (int digits = 9; digits >= 1 && s.size() > width; --digits) s = Num(v, digits);
  return s;
}

// A scene's heading in run and check: "§4.5  name — title" (no dash without a title).
void PrintHeading(const mechbench::Model& m) {
  std::printf("\n%s  %s%s\n", m.section.c_str(), m.name.c_str(), m.title.empty() ? "" : (" — " + m.title).c_str());
}

// Pads or cuts to `width` characters (UTF-8 aware: "§" and "°" are one column each).
std::string Pad(const std::string& s, size_t width) {
  std::string out;
  size_t cols = 0;
  for (size_t i = 0; i < s.size();) {
    size_t len = 1;
    const unsigned char c = static_cast<unsigned char>(s[i]);
    if (c >= 0xF0) len = 4;
    else if (c >= 0xE0) len = 3;
    else if (c >= 0xC0) len = 2;
    if (cols == width) break;
    out.append(s, i, len);
    i += len;
    ++cols;
  }
  out.append(width - cols, ' ');
  return out;
}

json ToJson(const std::optional<double>& v) { return v ? json(*v) : json(nullptr); }

// Columns a UTF-8 string takes (as Pad counts them).
size_t Columns(const std::string& s) {
  size_t cols = 0;
  for (unsigned char c : s) cols += (c & 0xC0) != 0x80;
  return cols;
}
constexpr size_t kCheckQuantityMax = 40, kCheckWhereMax = 36;  // check's widest columns

// Levenshtein distance, for "did you mean" on a mistyped command.
size_t EditDistance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

// ---- list ------------------------------------------------------------------------------------
int CmdList(const std::vector<std::string>& names, bool as_json) {
  const auto methods = hn::AllMethods();
  json out = json::array();
  bool invalid = false;
  for (const std::string& f : ResolveAll(names)) {
    json row;
    try {
      const mb::Model m = mb::references::LoadScenarioValidated(f);
      row = {{"scenario", m.name}, {"section", m.section}, {"title", m.title},
             {"kind", m.kind == mb::ScenarioKind::kGearTrain ? "gear_train" : m.kind == mb::ScenarioKind::kSpatial ? "spatial" : "linkage"},
             {"motion", m.analysis.HasMotion()}, {"book_values", m.book.size()}, {"file", f}};
      json ms = json::object();
      for (const auto& meth : methods) {
        const auto why = meth->Applicability(m);
        ms[meth->name()] = why ? json(*why) : json("applies");
      }
      row["methods"] = ms;
    } catch (const mb::ScenarioError& e) {
      // Still a row (the others are listed), and bad input as for every command: exit 2.
      row = {{"scenario", f}, {"error", e.what()}};
      std::cerr << "error: " << e.what() << "\n";
      invalid = true;
    }
    out.push_back(row);
  }
  if (as_json) {
    std::cout << out.dump(2) << "\n";
    return invalid ? kExitBadInput : kExitAgree;
  }
  std::printf("%-30s %-18s %-10s %-6s %s\n", "scenario", "section", "kind", "book", "methods");
  for (const json& r : out) {
    if (r.contains("error")) {
      // Its message (file, line, fix) is on stderr already: said once, not again in the table.
      std::printf("%-30s INVALID: bad input (the error printed on stderr)\n", r["scenario"].get<std::string>().c_str());
      continue;
    }
    std::string ms;
    for (const auto& [name, v] : r["methods"].items())
      ms += name + (v == "applies" ? "" : " (n/a: " + v.get<std::string>() + ")") + "  ";
    std::printf("%s %s %-10s %-6d %s\n", Pad(r["scenario"].get<std::string>(), 30).c_str(),
                Pad(r["section"].get<std::string>(), 18).c_str(), r["kind"].get<std::string>().c_str(),
                r["book_values"].get<int>(), ms.c_str());
    if (!r["title"].get<std::string>().empty()) std::printf("%-30s %s\n", "", r["title"].get<std::string>().c_str());
  }
  return invalid ? kExitBadInput : kExitAgree;
}

// ---- check -----------------------------------------------------------------------------------
// How `run` and `check` run each method: in its own process unless --in-process, killed after
// the time limit (the CPU budget leaves it twice the budget and 30 s more; none without a budget).
hn::Isolation MethodIsolation(bool in_process, double budget_seconds) {
  return {!in_process, budget_seconds > 0 ? 2 * budget_seconds + 30 : 0};
}

int CmdCheck(const std::vector<std::string>& names, const std::vector<std::string>& method_names, bool as_json,
             bool in_process) {
  // The book against the exact methods by default; engines are judged by `run`, each against
  // its own tolerance. Any method can be added with --method.
  const auto methods = SelectMethods(method_names.empty() ? std::vector<std::string>{"analytic", "numeric"} : method_names);
  json records = json::array();
  int disagreements = 0, invalid = 0, known_rows = 0, failed_rows = 0;
  std::map<std::string, int> counts;
  for (const std::string& f : ResolveAll(names)) {
    const mb::Model m = mb::references::LoadScenarioValidated(f);
    std::vector<mb::Result> results;
    // Claims at a time of the motion (book `at:`) are read off the motions: each method's, and
    // the scene's confirmed reference trajectory, which decides their verdicts.
    const bool timed = std::any_of(m.book.begin(), m.book.end(), [](const mb::BookValue& b) { return b.AtTime(); });
    const mb::RunOptions options{.motion = timed};
    const hn::Isolation iso = MethodIsolation(in_process, 60);
    results = hn::RunMethods(m, methods, options, iso, false);
    // Bad input stops every method on the same scene: said once, in the numeric solver's words
    // (else the first method's), as `run` does.
    std::string invalid_reason;
    for (const auto& r : results)
      if (r.status == mb::Status::kInvalidScenario && (invalid_reason.empty() || r.method == "numeric"))
        invalid_reason = r.reason;
    std::optional<hn::ReferenceRecord> reference;
    if (timed && m.IsFree()) {
      reference = hn::GetReference(m);
      // A reference refused for the same bad input is that error, printed once below.
      const bool same_error = !invalid_reason.empty() && reference->description.find(invalid_reason) != std::string::npos;
      if (!as_json && !same_error)
        std::printf("\nreference%s: %s\n", reference->from_cache ? " (cached)" : "", reference->description.c_str());
    }
    if (!invalid_reason.empty()) {
      ++invalid;
      std::cerr << "error: " << invalid_reason << "\n";
    }
    // Each method to its own tolerance (harness/tolerances.yaml, as `run` judges it at t0): an
    // engine's accelerations from finite differences are not held to the exact methods' 1e-9.
    const hn::Tolerances tolerances = hn::LoadTolerances(m);
    auto rows = hn::CheckBook(m, results, reference ? &*reference : nullptr, &tolerances);
    // A claim left uncomputed — a method's run went wrong (diverged, failed, crashed, …), the
    // reference is not confirmed, no method gives the quantity — was not judged: a failure of the
    // check, not a pass (exit 1, the row saying why). Bad input is exit 2 instead.
    if (!invalid_reason.empty() && !as_json)  // each row's reason names the error printed above, not its text again
      for (auto& row : rows)
        for (size_t at = row.reason.find(invalid_reason); at != std::string::npos;
             at = row.reason.find(invalid_reason, at + 1))
          row.reason.replace(at, invalid_reason.size(), "the error above");
    // Columns as wide as their longest entry (within reason): a quantity longer than its column
    // gets a line of its own above its row, a long `where` is cut with "…" and a footnote number,
    // its whole text listed under the table ("[1] IFToMM A05 reference, read off the plot …").
    const auto row_quantity = [](const hn::BookCheck& row) {
      return row.book.quantity + (row.book.AtTime() ? " @" + Num(row.book.at) + " s" : "");
    };
    size_t qw = 8, ww = 5, uw = 4;
    for (const auto& row : rows) {
      if (Columns(row_quantity(row)) <= kCheckQuantityMax) qw = std::max(qw, Columns(row_quantity(row)));
      ww = std::min(kCheckWhereMax, std::max(ww, Columns(row.book.where)));
      uw = std::max(uw, Columns(row.book.unit));
    }
    std::vector<size_t> mw;  // each method's column
    if (!rows.empty())
      for (const auto& [meth, v] : rows.front().computed) mw.push_back(std::max<size_t>(13, Columns(meth)));
    if (!as_json && !rows.empty()) {
      PrintHeading(m);
      std::printf("  %s %s %s %s", Pad("quantity", qw).c_str(), Pad("where", ww).c_str(), Pad("unit", uw).c_str(),
                  Pad("book", 13).c_str());
      size_t k = 0;
      for (const auto& [meth, v] : rows.front().computed) std::printf(" %s", Pad(meth, mw[k++]).c_str());
      std::printf(" verdict\n");
    }
    std::vector<std::string> where_notes;  // the cut `where` texts, footnotes [1], [2], … in order
    for (const auto& row : rows) {
      json rec = {{"scenario", m.name}, {"section", m.section}, {"quantity", row.book.quantity},
                  {"where", row.book.where}, {"unit", row.book.unit}, {"book", row.book.value},
                  {"printed", row.book.printed}, {"verdict", mb::ToString(row.verdict)},
                  {"methods_agree", row.methods_agree}};
      if (!row.book.note.empty()) rec["note"] = row.book.note;
      if (row.book.AtTime()) rec["at"] = row.book.at, rec["allowed"] = row.allowed;
      if (!row.reason.empty()) rec["reason"] = row.reason;
      for (const auto& [meth, v] : row.computed) rec[meth] = ToJson(v);
      if (!row.outside.empty()) rec["outside"] = row.outside;
      if (!row.known_outside.empty()) rec["known_outside"] = row.known_outside;
      if (!row.not_judged.empty()) {
        rec["not_judged"] = row.not_judged;
        json values = json::object();
        for (size_t k = 0; k < row.not_judged.size(); ++k) values[row.not_judged[k]] = JsonNumber(row.not_judged_values[k]);
        rec["not_judged_values"] = values;
      }
      records.push_back(rec);
      ++counts[mb::ToString(row.verdict)];
      if (!row.methods_agree) ++disagreements;
      if (row.verdict == hn::Verdict::kNotComputed && invalid_reason.empty()) ++failed_rows;
      known_rows += !row.known_outside.empty();
      if (!as_json) {
        std::string quantity = row_quantity(row);
        if (Columns(quantity) > qw) {
          std::printf("  %s\n", quantity.c_str());
          quantity.clear();
        }
        std::string where = row.book.where;
        if (Columns(where) > ww) {
          auto it = std::find(where_notes.begin(), where_notes.end(), where);
          if (it == where_notes.end()) it = where_notes.insert(it, where);
          const std::string mark = "[" + std::to_string(it - where_notes.begin() + 1) + "]";
          where = Pad(where, ww - 1 - Columns(mark)) + "…" + mark;
        }
        // The book's value as printed in the file ("0.6400") when it is a plain number that fits,
        // else as a number, as the methods' are; the file's expression (3*1, -sqrt(3)*0.5/8) is
        // shown beside the verdict where the book differs (--json keeps both).
        const bool plain_book = !row.book.printed.empty() &&
                                row.book.printed.find_first_not_of("0123456789.eE+-") == std::string::npos &&
                                Columns(row.book.printed) <= 13;
        std::printf("  %s %s %s %s", Pad(quantity, qw).c_str(), Pad(where, ww).c_str(), Pad(row.book.unit, uw).c_str(),
                    Pad(plain_book ? row.book.printed : NumFit(row.book.value, 13), 13).c_str());
        size_t k = 0;
        // A value without a bound is shown in brackets: not judged (the note at the row's end).
        for (const auto& [meth, v] : row.computed) {
          const bool judged = std::find(row.not_judged.begin(), row.not_judged.end(), meth) == row.not_judged.end();
          const size_t w = mw[k++];
          std::printf(" %s", Pad(!v ? "n/a" : judged ? NumFit(*v, w) : "[" + NumFit(*v, w - 2) + "]", w).c_str());
        }
        const bool expression = row.book.printed.find_first_not_of("0123456789.eE+- ") != std::string::npos;
        const std::string book_text =
            expression && row.verdict != hn::Verdict::kAgrees ? "  (book: " + row.book.printed + ")" : std::string();
        std::string disagree;
        for (const std::string& o : row.outside) disagree += (disagree.empty() ? "  METHODS DISAGREE: " : "; ") + o;
        for (const std::string& o : row.known_outside) disagree += (disagree.empty() ? "  KNOWN: " : "; known: ") + o;
        if (!row.not_judged.empty()) {
          disagree += "  ([value] of " + Join(row.not_judged) + ": not judged — no bound for their accelerations at t0 in "
                      "harness/tolerances.yaml)";
        }
        std::printf(" %s%s%s%s%s\n", mb::ToString(row.verdict), disagree.c_str(), book_text.c_str(),
                    row.book.note.empty() || row.verdict == hn::Verdict::kAgrees ? "" : ("  (" + row.book.note + ")").c_str(),
                    row.reason.empty() ? "" : ("  (" + row.reason + ")").c_str());
      }
    }
    if (!as_json) {
      for (size_t k = 0; k < where_notes.size(); ++k) std::printf("  [%zu] %s\n", k + 1, where_notes[k].c_str());
      for (const auto& r : results)
        if (!r.ok() && r.status != mb::Status::kInvalidScenario)
          std::printf("  %s: %s — %s\n", r.method.c_str(), mb::ToString(r.status), r.reason.c_str());
      // A method that ran but left cells n/a: which, and why (its notes on what it leaves out).
      for (const auto& r : results) {
        if (!r.ok()) continue;
        std::vector<std::string> missing;
        for (const auto& row : rows)
          for (const auto& [meth, v] : row.computed)
            if (meth == r.method && !v) missing.push_back(row.book.quantity);
        if (missing.empty()) continue;
        std::string list;
        for (size_t k = 0; k < missing.size() && k < 4; ++k) list += (k ? ", " : "") + missing[k];
        if (missing.size() > 4) list += " and " + std::to_string(missing.size() - 4) + " more";
        std::string why;
        for (const std::string& msg : r.messages)
          if (msg.find("not simulated") != std::string::npos || msg.find("not given") != std::string::npos ||
              msg.find("does not give") != std::string::npos || msg.find("left out") != std::string::npos)
            why += (why.empty() ? "" : "; ") + msg;
        // A reaction left out: the method's own words on which pins it leaves out and why.
        const bool reaction = std::any_of(missing.begin(), missing.end(),
                                          [](const std::string& q) { return q.rfind("reaction.", 0) == 0; });
        if (const auto re = r.settings.find("reactions"); reaction && re != r.settings.end()) {
          const std::string& text = re->second;
          for (size_t at = text.find("left out: "); at != std::string::npos; at = text.find("left out: ", at + 1)) {
            const size_t end = text.find("; left out: ", at + 1);
            why += (why.empty() ? "" : "; ") + text.substr(at, end == std::string::npos ? std::string::npos : end - at);
          }
          if (text.find("left out: ") == std::string::npos) why += (why.empty() ? "" : "; ") + std::string("its reactions: ") + text;
        }
        if (const auto acc = r.settings.find("accelerations"); acc != r.settings.end())
          why += (why.empty() ? "" : "; ") + std::string("its accelerations: ") + acc->second;
        // On a turning frame its absolute accelerations at t0 have their own source (printed
        // beside "none at t0" above, they would read as a contradiction).
        if (const auto abs = r.settings.find("absolute_accelerations"); abs != r.settings.end())
          why += (why.empty() ? "" : "; ") + std::string("its absolute accelerations (aabs): ") + abs->second;
        std::printf("  %s: n/a for %s — %s\n", r.method.c_str(), list.c_str(),
                    why.empty() ? "it does not compute these quantities" : why.c_str());
      }
    }
  }
  if (as_json) {
    std::cout << records.dump(2) << "\n";
  } else {
    if (records.empty() && invalid) std::printf("\nbad input: see the error above\n");
    else if (records.empty())
      std::printf("\nno printed values to check: check compares a file's `book:` values (a textbook's or a "
                  "paper's printed figures, scenarios/FORMAT.md) with every method; `mechbench run` compares the methods "
                  "with each other and with the reference\n");
    else
      std::printf("\n%zu printed values:", records.size());
    for (const auto& [k, v] : counts) std::printf("  %s %d", k.c_str(), v);
    if (!records.empty())
      std::printf("%s%s%s\n", disagreements ? ("  — methods disagree on " + std::to_string(disagreements)).c_str() : "",
                  known_rows ? ("  — " + std::to_string(known_rows) + " outside by a known failure (" + hn::TolerancesFilesText() + ")").c_str() : "",
                  failed_rows ? ("  — " + std::to_string(failed_rows) + " not computed, so not judged (each row says why): "
                                 "not a pass").c_str() : "");
  }
  if (invalid) return kExitBadInput;
  return disagreements || failed_rows ? kExitDisagree : kExitAgree;
}

// ---- run -------------------------------------------------------------------------------------
// What put a pair outside its tolerance: the worst coordinate if q, q̇ or q̈ is over its bound, the
// worst quantity at t0 and the worst acceleration at t0 if theirs are, its problem (only those over:
// a quantity that agrees exactly is not named).
std::vector<std::string> OutsideItems(const hn::PairComparison& p, const hn::Agreement& at) {
  std::vector<std::string> items;
  if (!p.problem.empty()) items.push_back(p.problem);
  if (p.q > at.q || p.qd > at.qd || (p.qdd_compared && p.qdd > at.qdd)) items.push_back(p.worst_slot);
  if (!p.worst_quantity.empty() && p.quantity > at.instant) items.push_back(p.worst_quantity);
  if (!p.worst_acceleration_quantity.empty() && p.acceleration_quantity > at.AccelerationAtT0())
    items.push_back(p.worst_acceleration_quantity);
  return items;
}

int CmdRun(const std::vector<std::string>& names, const std::vector<std::string>& method_names, bool as_json,
           const std::string& csv_path, bool verbose, double budget, bool in_process, const std::string& junit_path) {
  mb::RunOptions run_options;
  run_options.cpu_budget = budget > 0 ? budget : mb::kNaN;
  const auto methods = SelectMethods(method_names);
  const std::vector<std::string> files = ResolveAll(names);
  json out = json::array();
  // The CSV goes to a temporary file, moved into place only when every scenario has run: bad
  // input or an interrupt leaves an existing FILE as it was, and an input is never overwritten.
  std::optional<hn::AtomicFile> csv, junit;
  std::vector<std::string> inputs = files;  // the scenes and the tolerance files read
  for (const std::string& t : hn::UserTolerancesFiles()) inputs.push_back(t);
  hn::RefuseClashingOutputs({{"--csv", csv_path}, {"--junit", junit_path}});
  if (!csv_path.empty()) {
    hn::RefuseToOverwriteInputs(csv_path, inputs, "--csv");
    csv.emplace(csv_path);
    csv->stream() << hn::kTrajectoryCsvHeader << "\n";
  }
  if (!junit_path.empty()) {
    hn::RefuseToOverwriteInputs(junit_path, inputs, "--junit");
    junit.emplace(junit_path);
  }
  // Interrupted (Ctrl-C): one line on stderr saying so and what was (not) written, exit 130.
  const auto pending = [&]() {
    std::string left;
    for (const std::optional<hn::AtomicFile>* file : {&csv, &junit})
      if (*file) left += std::string(left.empty() ? "" : " and ") + (file == &csv ? "--csv " : "--junit ") + (*file)->path();
    return left.empty() ? std::string("no file was asked for") : left + " left as " + (left.find(" and ") != std::string::npos ? "they were" : "it was");
  };
  // Until a scene's table is out (flushed after each), nothing was printed: the note says so.
  hn::ReportInterrupts("run", "nothing was printed yet and nothing written (" + pending() + ")");
  std::vector<hn::JunitCase> junit_cases;
  bool all_ok = true, any_invalid = false;
  // Runs that fail the gate (gate.h), by kind, named "scene: method" when several scenes run.
  std::vector<std::string> outside, stopped, errors, stale;
  std::vector<std::string> known_failures;  // "scenario: method" outside but listed in tolerances.yaml
  std::vector<std::string> alone;           // scenes where no two methods were compared, and why
  std::vector<std::string> not_judged;      // "method q̈ 3.0": measured, no bound, shown
  for (const std::string& f : files) {
    const mb::Model m = mb::references::LoadScenarioValidated(f);
    const hn::RunReport rep =
        hn::RunScenario(m, methods, run_options, hn::LoadTolerances(m), MethodIsolation(in_process, budget));
    any_invalid = any_invalid || rep.invalid;
    const std::string prefix = files.size() > 1 ? m.name + ": " : "";
    bool scene_ok = rep.ok;
    for (const mb::Result& r : rep.results) {
      const hn::MethodVerdict v = hn::VerdictOf(rep, r.method);
      const hn::Gate g = hn::GateOf(mb::ToString(r.status), v.within, v.known, v.stale);
      scene_ok = scene_ok && !hn::GateFails(g);
      if (g == hn::Gate::kOutside) outside.push_back(prefix + r.method);
      if (g == hn::Gate::kStoppedByBudget) stopped.push_back(prefix + r.method);
      if (g == hn::Gate::kError && r.status != mb::Status::kInvalidScenario) errors.push_back(prefix + r.method);
      if (g == hn::Gate::kKnownNoLongerFails)
        stale.push_back(prefix + r.method + " (" + (v.known_where.empty() ? "its entry" : v.known_where) + ")");
    }
    all_ok = all_ok && scene_ok;
    for (const std::string& k : hn::KnownFailures(rep)) known_failures.push_back(files.size() > 1 ? m.name + ": " + k : k);
    // A scene where no two methods were compared (one ran, the others n/a): nothing agrees or
    // disagrees there, and the summary says so instead of "all methods agree".
    if (rep.pairs.empty() && rep.free.empty() && !rep.invalid) {
      std::vector<std::string> ran, stopped_here;
      for (const mb::Result& r : rep.results) {
        if (r.ok()) ran.push_back(r.method);
        if (r.status == mb::Status::kOverBudget) stopped_here.push_back(r.method);
      }
      const std::string to_the_end = stopped_here.empty() ? "" : " to the end";
      std::string what = ran.empty() ? "no method ran it" + to_the_end + " (each n/a or stopped; see its row)"
                                     : "only " + Join(ran) + " ran" + to_the_end + "; nothing to compare against";
      if (!stopped_here.empty()) what += " (" + Join(stopped_here) + " stopped by the CPU budget)";
      if (!m.book.empty())
        what += " (its " + std::to_string(m.book.size()) + " printed value" + (m.book.size() > 1 ? "s" : "") +
                ": mechbench check " + f + ")";
      alone.push_back(files.size() > 1 ? m.name + ": " + what : what);
    }
    for (const hn::PairComparison& p : rep.pairs)
      if (!p.not_judged.empty())
        not_judged.push_back((files.size() > 1 ? m.name + ": " : std::string()) + p.method + " " + Join(p.not_judged));
    json js = {{"scenario", m.name}, {"section", m.section}, {"ok", rep.ok}, {"problems", rep.problems}, {"known", rep.known},
               {"samples", m.analysis.samples}, {"t0", m.analysis.t0},
               {"tolerances", {{"q", rep.tolerances.q}, {"qd", rep.tolerances.qd}, {"qdd", rep.tolerances.qdd}, {"instant", rep.tolerances.instant},
                               {"residual", rep.tolerances.residual}}}};
    json jm = json::array();
    for (const auto& r : rep.results) {
      json e = {{"method", r.method}, {"status", mb::ToString(r.status)}, {"reason", r.reason},
                {"cpu_seconds", r.cpu_seconds}, {"cpu", hn::CpuJson(r.cpu, r.steps)}, {"wall_seconds", r.wall_seconds},
                {"samples", r.trajectory.size()}, {"settings", r.settings}, {"messages", r.messages}};
      if (const auto it = rep.startup.find(r.method); it != rep.startup.end() && it->second.done)
        e["startup"] = {{"first", it->second.first}, {"again", it->second.again}, {"runs", it->second.runs},
                        {"one_time", it->second.one_time()}};
      if (auto it = rep.max_residual.find(r.method); it != rep.max_residual.end()) e["max_residual"] = it->second;
      jm.push_back(e);
    }
    if (csv) hn::WriteTrajectoryCsv(csv->stream(), m, rep);
    if (junit)
      for (hn::JunitCase& c : hn::JunitCases(rep)) junit_cases.push_back(std::move(c));
    js["methods"] = jm;
    json jp = json::array();
    for (const auto& p : rep.pairs)
      jp.push_back({{"reference", p.reference}, {"method", p.method}, {"samples", p.samples}, {"q", p.q},
                    {"qd", p.qd}, {"qdd", p.qdd}, {"worst", p.worst_slot}, {"quantities", p.quantities},
                    {"quantity", p.quantity}, {"worst_quantity", p.worst_quantity},
                    {"acceleration_quantity", p.acceleration_quantity},
                    {"worst_acceleration_quantity", p.worst_acceleration_quantity}, {"not_judged", p.not_judged},
                    {"within", p.within}, {"known", p.known}});
    js["comparisons"] = jp;
    if (!rep.free.empty() || !rep.reference.empty()) {
      json jf = json::array();
      for (const auto& c : rep.free) {
        jf.push_back({{"method", c.method}, {"position", c.position}, {"worst", c.worst_slot}, {"t", c.worst_t},
                      {"tolerance", c.tolerance}, {"within", c.within}, {"problem", c.problem}, {"known", c.known},
                      {"first_outside_t", JsonNumber(c.first_outside_t)}, {"energy_drift", JsonNumber(c.energy_drift)},
                      {"reached_t", JsonNumber(c.reached_t)}});
        if (c.criteria && m.criteria)
          jf.back()["criteria"] = {{"point", m.criteria->name}, {"error", JsonNumber(c.criteria->error)},
                                   {"t", JsonNumber(c.criteria->t)}, {"levels", m.criteria->levels}, {"met", c.criteria->met},
                                   {"complete", c.criteria->complete}, {"verdict", c.criteria->Verdict(*m.criteria)}};
      }
      js["reference"] = {{"description", rep.reference}, {"confirmed", rep.reference_confirmed},
                         {"from_cache", rep.reference_from_cache}, {"comparisons", jf}};
      if (const std::string note = hn::EnergyDriftNote(m); !note.empty()) js["reference"]["energy_drift_note"] = note;
    }
    json jr = json::array();
    for (const auto& c : rep.reactions)
      jr.push_back({{"reference", c.reference}, {"method", c.method}, {"components", c.components},
                    {"relative", JsonNumber(c.relative)}, {"absolute", JsonNumber(c.absolute)}, {"worst", c.worst}});
    js["reactions"] = jr;
    out.push_back(js);
    if (as_json) continue;
    PrintHeading(m);
    if (m.analysis.HasMotion())
      std::printf("  motion: %d samples over t = %s … %s s\n", m.analysis.samples, Num(m.analysis.t0, 4).c_str(),
                  Num(m.analysis.t1, 6).c_str());
    else
      std::printf("  instant t = %s s\n", Num(m.analysis.t0, 4).c_str());
    // A scene that cannot be set up stops every method on the same bad input: said once (the
    // numeric solver's words, else the first method's), not once per method.
    std::string invalid_reason;
    std::set<std::string> invalid_lines;
    for (const mb::Result& r : rep.results)
      if (r.status == mb::Status::kInvalidScenario) {
        if (invalid_reason.empty() || r.method == "numeric") invalid_reason = r.reason;
        invalid_lines.insert(r.method + ": " + r.reason);
      }
    // Bad input is said once, below, not as a row per method.
    const bool any_row = std::any_of(rep.results.begin(), rep.results.end(),
                                     [](const mb::Result& r) { return r.status != mb::Status::kInvalidScenario; });
    if (any_row)
      std::printf("  %-28s %-16s %10s %10s %9s  %s\n", "method", "status", "set-up[ms]", "run [ms]", "max ‖Φ‖",
                  "largest relative difference (q / qd / qdd)");
    for (const auto& r : rep.results) {
      if (r.status == mb::Status::kInvalidScenario) continue;
      const bool base = std::any_of(rep.pairs.begin(), rep.pairs.end(), [&](const hn::PairComparison& p) { return p.reference == r.method; });
      std::string diff = base ? "base of the comparison" : "";
      for (const auto& p : rep.pairs)
        if (p.method == r.method)
          // A free scene's methods start from one assembled state: their q, q̇ at t0 agree by
          // construction, the motions are judged against the reference below.
          // A figure without a bound is in brackets and named after the verdict: not judged.
          diff = (p.instant_only ? "at t0 only (motion: below) vs " : "vs ") + p.reference + ": " + Num(p.q, 2) + " / " +
                 Num(p.qd, 2) + " / " +
                 (!p.qdd_compared ? std::string("—")
                  : std::isinf(rep.tolerances.For(p.method).qdd) ? "[" + Num(p.qdd, 2) + "]"
                                                                 : Num(p.qdd, 2)) +
                 "; " + std::to_string(p.quantities) + " quantities at t0: " + Num(p.quantity, 2) +
                 (p.worst_acceleration_quantity.empty()
                      ? std::string()
                      : std::string(", accelerations ") +
                            (std::isinf(rep.tolerances.For(p.method).AccelerationAtT0())
                                 ? "[" + Num(p.acceleration_quantity, 2) + "]"
                                 : Num(p.acceleration_quantity, 2)) +
                            " (" + p.worst_acceleration_quantity + ")") +
                 (p.within ? (r.ok() ? "  within tolerance" : "  within tolerance at t0; the run " + std::string(mb::ToString(r.status)))
                           : std::string(p.known.empty() ? "  OUTSIDE" : "  KNOWN, outside") + " tolerance (" +
                                 Join(OutsideItems(p, rep.tolerances.For(p.method))) + ")") +
                 (p.not_judged.empty() ? std::string()
                                       : (p.within ? " where bounded" : std::string()) + "; n/a (not judged, no bound in "
                                         "harness/tolerances.yaml): " + Join(p.not_judged));
      const auto res = rep.max_residual.find(r.method);
      std::printf("  %-28s %-16s %10.3f %10.3f %9s  %s\n", r.method.c_str(), mb::ToString(r.status), r.cpu.setup * 1e3,
                  (r.cpu.integration + r.cpu.observation) * 1e3,
                  res != rep.max_residual.end() ? Num(res->second, 2).c_str() : "—", diff.c_str());
      if (!r.ok() && r.status != mb::Status::kInvalidScenario) std::printf("  %-28s   %s\n", "", r.reason.c_str());
      if (verbose) {
        std::string timing = "cpu " + Num(r.cpu_seconds * 1e3, 3) + " ms = set-up " + Num(r.cpu.setup * 1e3, 3) +
                             " + integration " + Num(r.cpu.integration * 1e3, 3) + " + observation " +
                             Num(r.cpu.observation * 1e3, 3) + " ms";
        if (r.steps > 0)
          timing += "; " + std::to_string(r.steps) + " steps, " + Num(r.cpu.integration / static_cast<double>(r.steps) * 1e6, 3) + " µs each";
        if (const auto it = rep.startup.find(r.method); it != rep.startup.end() && it->second.done)
          timing += "; one-time start-up paid before the run: " + Num(it->second.one_time() * 1e3, 3) + " ms";
        std::printf("  %-28s   %s\n", "", timing.c_str());
        for (const auto& msg : r.messages) std::printf("  %-28s   note: %s\n", "", msg.c_str());
        // What does not apply to this scene is left out of the text (--json keeps every setting):
        // drivers in a free scene, loop closures where there are none ("0 × …").
        for (const auto& [k, v] : r.settings) {
          if ((k == "drivers" && m.IsFree()) || v.rfind("0 ×", 0) == 0) continue;
          std::printf("  %-28s   setting %s: %s\n", "", k.c_str(), v.c_str());
        }
      }
    }
    if (!rep.reference.empty())
      std::printf("  reference%s: %s\n", rep.reference_from_cache ? " (cached)" : "", rep.reference.c_str());
    for (const auto& c : rep.free) {
      std::string where = c.within ? "within" : (c.known.empty() ? "OUTSIDE" : "KNOWN, outside");
      if (!c.problem.empty()) where += ": " + c.problem;
      if (!std::isnan(c.first_outside_t)) where += ", first at t = " + Num(c.first_outside_t, 4) + " s";
      if (!std::isnan(c.reached_t)) where += " (over budget: judged up to t = " + Num(c.reached_t, 4) + " s)";
      std::printf("  %-28s position error vs reference %-9s (relative to the coordinates' range; tolerance %s, at q.%s t = %s s)  energy drift %s J  %s\n",
                  c.method.c_str(), Num(c.position, 2).c_str(), Num(c.tolerance, 2).c_str(), c.worst_slot.c_str(),
                  Num(c.worst_t, 4).c_str(), std::isnan(c.energy_drift) ? "—" : Num(c.energy_drift, 2).c_str(), where.c_str());
      if (c.criteria && m.criteria)
        std::printf("  %-28s criteria: max |%s − reference| over %d output steps %s %s (t = %s s): %s\n", c.method.c_str(),
                    m.criteria->name.c_str(), m.criteria->output_steps, Num(c.criteria->error, 2).c_str(),
                    m.length_unit.c_str(), Num(c.criteria->t, 4).c_str(), c.criteria->Verdict(*m.criteria).c_str());
    }
    if (!rep.free.empty() && m.criteria && !m.criteria->source.empty())
      std::printf("  criteria levels: %s\n", m.criteria->source.c_str());
    if (!rep.free.empty())
      if (const std::string note = hn::EnergyDriftNote(m); !note.empty()) std::printf("  energy drift: %s\n", note.c_str());
    for (const auto& c : rep.reactions)
      std::printf("  %-28s reactions at t0 vs %s: %s of the largest (%s N; %d components; worst %s)\n", c.method.c_str(),
                  c.reference.c_str(), Num(c.relative, 2).c_str(), Num(c.absolute, 2).c_str(), c.components, c.worst.c_str());
    if (!rep.reactions.empty())
      std::printf("  reactions: shown, not judged (no bound in harness/tolerances.yaml; an engine's constraint forces of its "
                  "first step: a few %% off for an iterative solver at its default iterations; README, Engines and dynamics)\n");
    if (!invalid_reason.empty()) std::printf("  INVALID SCENE (bad input): %s\n", invalid_reason.c_str());
    for (const auto& p : rep.problems)
      if (!invalid_lines.count(p)) std::printf("  PROBLEM: %s\n", p.c_str());
    for (const auto& k : rep.known) std::printf("  known: %s\n", k.c_str());
    // One verdict per method: ok / outside / diverged / known failure / n/a, with the reason.
    if (invalid_reason.empty()) {
      std::printf("  verdict:\n");
      const int n_ok = static_cast<int>(
          std::count_if(rep.results.begin(), rep.results.end(), [](const mb::Result& r) { return r.ok(); }));
      const int n_run = static_cast<int>(std::count_if(rep.results.begin(), rep.results.end(), [](const mb::Result& r) {
        return r.ok() || r.status == mb::Status::kOverBudget;
      }));
      // Methods that cannot do the scene: named on one line, their reasons being in the table above.
      std::vector<std::string> not_applicable;
      for (const auto& r : rep.results) {
        const hn::MethodVerdict v = hn::VerdictOf(rep, r.method);
        std::string text;
        if (r.status == mb::Status::kNotApplicable) {
          not_applicable.push_back(r.method);
          continue;
        } else if (!v.within && !v.known.empty())
          text = std::string("known failure") + (r.ok() ? "" : std::string(" (") + mb::ToString(r.status) + ")") + " — " + v.known +
                 (v.known_where.empty() ? "" : " (" + v.known_where + ")");
        else if (r.status == mb::Status::kDiverged) text = "diverged — " + r.reason;
        else if (r.status == mb::Status::kOverBudget)
          text = "stopped by its CPU budget (not judged past where it got: not a pass) — " + r.reason;
        else if (!r.ok()) text = std::string(mb::ToString(r.status)) + " — " + r.reason;
        else if (!v.within) text = "OUTSIDE its tolerance — " + (v.problems.empty() ? std::string("see above") : v.problems.front());
        else if (!v.compared)
          text = "ran alone: nothing to compare against (" + std::string(n_ok > 1 ? "not compared" : n_ok < n_run ? "no other method ran to the end" : "no other method ran") + ")";
        else if (!v.not_judged.empty())
          // Never "ok" beside a figure that was not judged: within on what has a bound, n/a for the rest.
          text = "within its tolerance where bounded; n/a (not judged, no bound in harness/tolerances.yaml) for its "
                 "difference from " + v.base + ": " + Join(v.not_judged);
        else
          text = "ok";
        if (!v.stale.empty())
          text += " — known failure no longer fails: remove the entry (" +
                  (v.known_where.empty() ? std::string("its tolerances file") : v.known_where) + ": " + v.stale + ")";
        std::printf("    %-28s %s\n", r.method.c_str(), text.c_str());
        // A failed run on a light body the engines added (engine_method.cc): said here, not only
        // under --verbose (a known failure's entry says its own cause).
        if (const auto light = r.settings.find("light_bodies");
            light != r.settings.end() && (!r.ok() || !v.within) && v.known.empty())
          std::printf("    %-28s note: %s\n", "", light->second.c_str());
      }
      if (!not_applicable.empty())
        std::printf("    %-28s %s (each one's reason is in the table above)\n", "n/a", Join(not_applicable).c_str());
    }
    std::fflush(stdout);
    hn::SetInterruptNote("the results printed so far are partial; nothing written (" + pending() + ")");
  }
  if (junit) hn::WriteJunit(junit->stream(), junit_cases);
  // Bad input (a scene that cannot be set up, exit 2) writes nothing, as a refusal at load does:
  // an existing --csv or --junit file is left as it was, never replaced by a header alone.
  if (any_invalid)
    for (std::optional<hn::AtomicFile>* file : {&csv, &junit})
      if (*file) std::fprintf(stderr, "not written: %s left as it was (a scene could not be set up)\n", (*file)->path().c_str());
  for (std::optional<hn::AtomicFile>* file : {&csv, &junit}) {
    if (!*file || any_invalid) continue;
    (*file)->Commit();
    std::fflush(stdout);  // the table first: with 2>&1 the note must not land inside a line of it
    std::cout.flush();
    std::fprintf(stderr, "wrote %s\n", (*file)->path().c_str());
    hn::SetInterruptNote("the results are complete; wrote " + (*file)->path() +
                         (file == &csv && junit ? " (--junit " + junit->path() + " left as it was)" : std::string()));
  }
  if (as_json) std::cout << out.dump(2) << "\n";
  else if (any_invalid)
    std::printf("\nbad input: a scene cannot be set up (the INVALID SCENE line says why and how to fix it)\n");
  else if (!all_ok) {
    // What failed the gate, each kind named (gate.h): a run stopped by the budget judged nothing
    // past where it got, so it is neither a pass nor outside its tolerance.
    const std::string budget_words = std::to_string(stopped.size()) + " stopped by the CPU budget (--budget " +
                                     Num(budget, 6) + " s) before the end of the motion: " + Join(stopped) +
                                     "; not judged past where they got, so not a pass (raise --budget; 0: no limit)";
    const bool only_budget = outside.empty() && errors.empty() && !stopped.empty() &&
                             std::none_of(out.begin(), out.end(), [](const json& js) {
                               return std::any_of(js["problems"].begin(), js["problems"].end(), [](const json& p) {
                                 return p.get<std::string>().rfind("reference trajectory: ", 0) == 0;
                               });
                             });
    if (only_budget) std::printf("\n%s\n", budget_words.c_str());
    else {
      std::printf("\nsome methods disagree or failed (see PROBLEM lines)");
      if (!outside.empty()) std::printf("; outside their tolerance: %s", Join(outside).c_str());
      if (!errors.empty()) std::printf("; crashed or timed out: %s", Join(errors).c_str());
      if (!stopped.empty()) std::printf("; %s", budget_words.c_str());
      std::printf("\n");
    }
    if (!outside.empty())
      std::printf("tolerances: %s; the project's defaults are each method's accuracy at its default settings on "
                  "the built-in scenes; a scene of your own that is faster or stiffer may need its own entry or known "
                  "failure: --tolerances FILE (README: Gating a CI job on mechbench)\n",
                  hn::TolerancesFilesText().c_str());
  } else {
    std::string except;
    for (size_t k = 0; k < known_failures.size(); ++k) except += (k ? ", " : "") + known_failures[k];
    if (!except.empty())
      except = " except " + std::to_string(known_failures.size()) + " known failure" + (known_failures.size() > 1 ? "s" : "") +
               " (" + except + ")";
    if (alone.size() == files.size())
      std::printf("\nnothing to compare: %s\n", Join(alone).c_str());
    else {
      std::printf("\nall methods agree within tolerance%s", except.c_str());
      std::printf("%s\n", alone.empty() ? "" : ("; nothing to compare on " + Join(alone)).c_str());
    }
    if (!not_judged.empty())
      std::printf("not judged (no bound in harness/tolerances.yaml; shown, not counted as agreement): %s\n",
                  Join(not_judged).c_str());
  }
  // A listed known failure that passes: said (the entry is stale), not failing the gate.
  if (!as_json && !any_invalid && !stale.empty())
    std::printf("known failure no longer fails: remove the entry: %s\n", Join(stale).c_str());
  if (any_invalid) return kExitBadInput;
  return all_ok ? kExitAgree : kExitDisagree;
}

// ---- sweep, stress, report, merge ------------------------------------------------------------

std::string Cell(const json& v, int digits = 2) {
  return v.is_number() ? Num(v.get<double>(), digits) : std::string("—");
}

void PrintSweep(const json& results) {
  std::string scenario;
  for (const json& r : results["records"]) {
    if (r["kind"] != "sweep") continue;
    if (r["scenario"] != scenario) {
      scenario = r["scenario"].get<std::string>();
      std::printf("\n%s — work–precision (error relative to the motion's scale, max over the run)\n", scenario.c_str());
      std::printf("  %-28s %-9s %10s %-10s %11s %9s %9s %9s %9s\n", "method", "control", "value", "status", "cpu [ms]",
                  "q max", "q rms", "qd max", "max ‖Φ‖");
    }
    const json e = r.value("error", json::object());
    std::printf("  %-28s %-9s %10s %-10s %11.3f %9s %9s %9s %9s\n", r["method"].get<std::string>().c_str(),
                r["control"].get<std::string>().c_str(), Cell(r["value"], 4).c_str(), r["status"].get<std::string>().c_str(),
                r["cpu_seconds"].get<double>() * 1e3, Cell(e.value("q_max", json())).c_str(),
                Cell(e.value("q_rms", json())).c_str(), Cell(e.value("qd_max", json())).c_str(),
                Cell(r["max_residual"]).c_str());
  }
  // The observed order of a fixed-step method; an error-controlled one's rungs vary its tolerance,
  // and what is printed for it is its error's slope against the tolerance ("tol 0.93"), no order.
  std::printf("\n%-28s %-28s %12s %12s %14s %14s\n", "scenario", "method", "cpu→1e-3 [ms]", "cpu→1e-6 [ms]",
              "order/tol slope", "stable h [s]");
  for (const json& d : results["derived"]) {
    auto ms = [](const json& v) { return v.is_number() ? Num(v.get<double>() * 1e3, 3) : std::string("not reached"); };
    const json slope = d.value("tolerance_slope", json());
    const std::string convergence = slope.is_number() ? "tol " + Cell(slope, 2) : Cell(d["order"], 2);
    std::printf("%s %s %12s %12s %14s %14s\n", Pad(d["scenario"].get<std::string>(), 28).c_str(),
                Pad(d["method"].get<std::string>(), 28).c_str(), ms(d["cpu_to_1e-3"]).c_str(),
                ms(d["cpu_to_1e-6"]).c_str(), convergence.c_str(), Cell(d["largest_stable"], 3).c_str());
  }
}

void PrintStress(const json& results) {
  std::map<std::string, int> counts;
  std::string group;
  for (const json& r : results["records"]) {
    if (r["kind"] == "stress") {
      const std::string g = r["scenario"].get<std::string>() + "@" + r["case"].get<std::string>();
      if (g != group) {
        group = g;
        std::printf("\n%s — %s\n", g.c_str(), r["description"].get<std::string>().c_str());
      }
      ++counts[r["outcome"].get<std::string>()];
      std::printf("  %-28s %-16s %s\n", r["method"].get<std::string>().c_str(), r["outcome"].get<std::string>().c_str(),
                  r["detail"].get<std::string>().substr(0, 150).c_str());
    } else if (r["kind"] == "stable_step") {
      std::printf("  largest stable step %-28s %-10s first unstable %-10s %s\n", r["method"].get<std::string>().c_str(),
                  Cell(r["largest_stable"], 3).c_str(), Cell(r["first_unstable"], 3).c_str(),
                  r["limit"].get<std::string>().c_str());
    }
  }
  std::printf("\noutcomes:");
  for (const auto& [k, v] : counts) std::printf("  %s %d", k.c_str(), v);
  std::printf("\n");
}

// A run record's gate (gate.h), as `run` decides it.
hn::Gate RecordGate(const json& r) {
  return hn::GateOf(r.value("status", ""), r.value("within", false), r.value("known", ""), r.value("known_stale", ""));
}

// 0 when every run passes the gate (inside its tolerance, n/a, or a listed known failure; not
// stopped by its budget, crashed or timed out) and the exact methods agree on every book value, 1
// otherwise. Stress outcomes are findings, not failures.
int ReportExit(const json& results) {
  // A scene that cannot be assembled is bad input, as `run` and `check` say with exit code 2.
  for (const json& r : results["records"])
    if (r["kind"] == "run" && r.value("status", "") == "invalid-scenario") {
      std::fprintf(stderr, "error: %s: %s\n", r.value("scenario", "").c_str(), r.value("reason", "").c_str());
      return kExitBadInput;
    }
  for (const json& r : results["records"]) {
    if (r["kind"] == "run" && hn::GateFails(RecordGate(r))) return kExitDisagree;
    if (r["kind"] == "check")
      for (const json& row : r["rows"])
        if (!row["methods_agree"].get<bool>()) return kExitDisagree;
  }
  return kExitAgree;
}

void PrintReportSummary(const json& results, const std::string& dir, const hn::ReportWriter::Info& info) {
  std::map<std::string, int> kinds, verdicts, outcomes;
  std::map<hn::Gate, std::vector<std::string>> gates;  // run records by gate (gate.h): "scene: method"
  for (const json& r : results["records"]) {
    ++kinds[r["kind"].get<std::string>()];
    if (r["kind"] == "check")
      for (const json& row : r["rows"]) ++verdicts[row["verdict"].get<std::string>()];
    if (r["kind"] == "stress") ++outcomes[r["outcome"].get<std::string>()];
    if (r["kind"] == "run")
      gates[RecordGate(r)].push_back(r.value("scenario", "") + ": " + r.value("method", "") +
                                     (r.contains("known_entry") ? " (" + r.value("known_entry", "") + ")" : ""));
  }
  std::printf("mechbench report: %zu records (", results["records"].size());
  for (const auto& [k, v] : kinds) std::printf(" %s %d", k.c_str(), v);
  std::printf(" )\n");
  // Only the lines that have something to say (no empty "book values:").
  if (!verdicts.empty()) {
    std::printf("  book values:");
    for (const auto& [k, v] : verdicts) std::printf(" %s %d", k.c_str(), v);
    std::printf("\n");
  }
  if (kinds.count("run")) {
    const auto count = [&](hn::Gate g) { return gates.count(g) ? gates[g].size() : size_t{0}; };
    std::printf("  runs outside their tolerance (not known): %zu\n", count(hn::Gate::kOutside));
    const std::pair<hn::Gate, const char*> lines[] = {
        {hn::Gate::kStoppedByBudget, "runs stopped by their CPU budget (not judged to the end: failing)"},
        {hn::Gate::kError, "runs that crashed or timed out"},
        {hn::Gate::kKnownFailure, "runs that are a known failure"},
        {hn::Gate::kKnownNoLongerFails, "known failures that no longer fail (remove the entry)"}};
    for (const auto& [g, words] : lines)
      if (count(g))
        std::printf("  %s: %zu%s\n", words, count(g), g == hn::Gate::kKnownFailure ? "" : (" (" + Join(gates[g]) + ")").c_str());
  }
  if (!outcomes.empty()) {
    std::printf("  stress outcomes:");
    for (const auto& [k, v] : outcomes) std::printf(" %s %d", k.c_str(), v);
    std::printf("\n");
  }
  std::string tolerances = "harness/tolerances.yaml";  // the files the report was judged by
  if (results.contains("options") && results["options"].contains("tolerances"))
    for (const json& f : results["options"]["tolerances"]) tolerances += ", then " + f.get<std::string>();
  std::printf("  tolerances: %s\n", tolerances.c_str());
  std::printf("  plots: %d%s\n", info.plots, info.gnuplot ? "" : " (gnuplot not found: install gnuplot-nox)");
  for (const char* f : {"report.html", "results.json", "results.csv", "summary.md"})
    std::printf("  wrote %s/%s\n", dir.c_str(), f);
}

// The user's tolerance files a command uses: MECHBENCH_TOLERANCES's (colon-separated), then those
// given with --tolerances (later files win), so that an environment set for a CI job is honoured
// by run, sweep, stress and report alike, as it is by check and the test suites.
std::vector<std::string> WithEnvironmentFiles(const std::vector<std::string>& given) {
  std::vector<std::string> files = hn::EnvironmentTolerancesFiles();
  files.insert(files.end(), given.begin(), given.end());
  return files;
}

// A user file's scenario entry that names none of the scenes given nor a built-in one: a warning
// on stderr (it may be a scene of the user's not given this time; a misspelt name applies to nothing).
void WarnUnmatchedScenarios(const std::vector<std::string>& stems) {
  for (const std::string& w : hn::UnmatchedScenarioNames(stems)) std::fprintf(stderr, "warning: %s\n", w.c_str());
}

// --tolerances FILE (repeatable): the user's tolerances and known failures, merged over
// harness/tolerances.yaml, read strictly before any work (bad input: exit 2 with file and line).
void AddTolerancesOption(CLI::App* cmd, std::vector<std::string>& files) {
  cmd->add_option("--tolerances", files,
                  "A tolerances file (harness/tolerances.yaml's format) merged over the project's: tolerances and "
                  "known failures for your own scenarios (repeatable; later files win)");
}

struct CampaignCli {
  hn::CampaignOptions o;
  std::string shard;  // "K/N"
  std::string out, junit;
  bool json_out = false;
  bool no_check = false, no_run = false, no_sweep = false, no_stress = false, no_precision = false, no_chains = false;

  void Add(CLI::App* cmd, bool kinds) {
    cmd->add_option("scenario", o.scenarios, "Scenarios (default: all built-in; --quick: a small set)");
    cmd->add_option("--method", o.methods, "Only these methods");
    cmd->add_flag("--quick", o.quick, "Fewer scenarios, rungs and repeats (well under a minute)");
    cmd->add_option("--jobs,-j", o.jobs, "Worker processes at once")->capture_default_str()->check(CLI::Range(1, 256));
    cmd->add_option("--repeats", o.repeats, "Sweep: runs per rung for the CPU median")->capture_default_str()->check(CLI::Range(1, 100));
    cmd->add_option("--timeout", o.timeout, "Per case [s]: killed and reported as timed_out after this")
        ->capture_default_str()
        ->check(FiniteNumber(0, false, "--timeout"));
    cmd->add_flag("--in-process", [this](int64_t) { o.isolate = false; }, "Run cases in this process (debugging; a crash ends the run)");
    cmd->add_flag("--json", json_out, "Print the results object (schema harness/report/results.schema.json)");
    AddTolerancesOption(cmd, o.tolerances);
    if (kinds) {
      cmd->add_option("--out,-o", out, "Folder for report.html, results.json, results.csv, summary.md")->required();
      cmd->add_option("--junit", junit, "Also write JUnit XML here: a test case per (scenario, method) run and per book value");
      cmd->add_option("--shard", shard, "K/N: run the K-th of N deterministic slices and write DIR/shard-K-of-N.jsonl");
      cmd->add_flag("--no-check", no_check, "Leave out the book checks");
      cmd->add_flag("--no-run", no_run, "Leave out the runs against the reference");
      cmd->add_flag("--no-sweep", no_sweep, "Leave out the work–precision sweeps");
      cmd->add_flag("--no-stress", no_stress, "Leave out the stress cases and stable-step searches");
      cmd->add_flag("--no-precision", no_precision,
                    "Leave out the published benchmarks' precision levels (CPU time to meet each)");
      cmd->add_flag("--no-chains", no_chains,
                    "Leave out the long-chains table (every integrating method on the N-four-bar as N grows)");
    }
  }
  void ParseShard() {
    if (shard.empty()) return;
    int k = 0, n = 0;
    char extra = 0;
    if (std::sscanf(shard.c_str(), "%d/%d%c", &k, &n, &extra) != 2 || n < 1 || k < 1 || k > n)
      throw mb::ScenarioError({"--shard", 0}, "bad shard '" + shard + "'", "write K/N with 1 ≤ K ≤ N, e.g. --shard 2/4");
    o.shard = k;
    o.shards = n;
  }
};

json OptionsJson(const hn::CampaignOptions& o) {
  return {{"quick", o.quick}, {"repeats", o.repeats}, {"timeout", o.timeout}, {"jobs", o.jobs},
          {"scenarios", o.scenarios}, {"methods", o.methods}, {"check", o.check}, {"run", o.run},
          {"sweep", o.sweep}, {"stress", o.stress}, {"precision", o.precision}, {"chains", o.chains},
          {"tolerances", o.tolerances}};
}

int CmdCampaign(CampaignCli& cli, const std::string& what) {
  hn::CampaignOptions& o = cli.o;
  if (what == "sweep") o.check = o.run = o.stress = o.precision = o.chains = false;
  if (what == "stress") o.check = o.run = o.sweep = o.precision = o.chains = false;
  if (what == "report") {
    o.check = !cli.no_check;
    o.run = !cli.no_run;
    o.sweep = !cli.no_sweep;
    o.stress = !cli.no_stress;
    o.precision = !cli.no_precision;
    o.chains = !cli.no_chains;
    cli.ParseShard();
  }
  // MECHBENCH_TOLERANCES's files, then --tolerances': recorded in results.json's options.
  o.tolerances = WithEnvironmentFiles(o.tolerances);
  hn::SetUserTolerancesFiles(o.tolerances);
  const std::vector<hn::Case> cases = hn::EnumerateCases(o);
  {
    std::set<std::string> stems;
    for (const hn::Case& c : cases) stems.insert(c.scenario);
    WarnUnmatchedScenarios({stems.begin(), stems.end()});
  }
  if (o.progress)
    std::fprintf(stderr, "mechbench %s: %zu cases%s, %d job(s), time limit %s s per case\n", what.c_str(), cases.size(),
                 o.shards > 1 ? (" (shard " + std::to_string(o.shard) + "/" + std::to_string(o.shards) + ")").c_str() : "",
                 o.jobs, Num(o.timeout, 4).c_str());
  // The outputs are checked before any case runs (an unwritable --out used to fail after the work).
  std::optional<hn::AtomicFile> shard_file;
  if (what == "report" && o.shards > 1) {
    hn::CreateOutputFolder(cli.out);
    shard_file.emplace(cli.out + "/shard-" + std::to_string(o.shard) + "-of-" + std::to_string(o.shards) + ".jsonl");
  }
  std::optional<hn::ReportWriter> report_writer;
  std::optional<hn::AtomicFile> junit;
  if (what == "report" && o.shards == 1) {
    report_writer.emplace(cli.out);
    if (!cli.junit.empty()) {
      std::vector<std::pair<std::string, std::string>> outputs;
      for (const char* f : {"results.json", "results.csv", "summary.md", "report.html"})
        outputs.emplace_back(std::string("the report's ") + f, (std::filesystem::path(report_writer->dir()) / f).string());
      outputs.emplace_back("--junit", cli.junit);
      hn::RefuseClashingOutputs(outputs);
      std::vector<std::string> inputs = hn::UserTolerancesFiles();
      for (const std::string& f : o.scenarios)
        if (std::filesystem::exists(f)) inputs.push_back(f);
      hn::RefuseToOverwriteInputs(cli.junit, inputs, "--junit");
      junit.emplace(cli.junit);
    }
  }
  // Interrupted (Ctrl-C): one line on stderr saying so and what was (not) written, exit 130.
  if (shard_file)
    hn::ReportInterrupts(what, "nothing written (" + shard_file->path() + " left as it was)");
  else if (report_writer)
    hn::ReportInterrupts(what, "nothing written (the report in " + report_writer->dir() + " is as it was" +
                                   (junit ? ", --junit " + junit->path() + " too" : std::string()) + ")");
  else
    hn::ReportInterrupts(what, "the results are lost (nothing is written before the end)");
  std::vector<json> records = hn::ExecuteCases(cases, o);
  if (shard_file) {
    // A shard names its campaign and counts its records, so that merge refuses a mixture of two
    // campaigns and a shard that lost its last lines.
    size_t total = 0;
    const std::string id = hn::CampaignId(o, &total);
    shard_file->stream() << json{{"mechbench_shard", {{"shard", o.shard}, {"shards", o.shards}, {"cases", cases.size()},
                                                      {"records", records.size()}, {"total_cases", total},
                                                      {"campaign", id}, {"options", OptionsJson(o)}}}}.dump()
                         << "\n";
    for (const json& r : records) shard_file->stream() << r.dump() << "\n";
    shard_file->Commit();
    hn::SetInterruptNote("wrote " + shard_file->path());
    std::printf("wrote %s (%zu records of %zu cases)\n", shard_file->path().c_str(), records.size(), cases.size());
    return kExitAgree;
  }
  const json results = hn::Assemble(std::move(records), o);
  if (what == "report") {
    const hn::ReportWriter::Info info = report_writer->Write(results);
    hn::SetInterruptNote("the report was written whole to " + report_writer->dir() +
                         (junit ? " (--junit " + junit->path() + " left as it was)" : std::string()));
    if (junit) {
      hn::WriteJunit(junit->stream(), hn::JunitCases(results));
      junit->Commit();
      hn::SetInterruptNote("the report was written whole to " + report_writer->dir() + ", and " + junit->path());
    }
    if (cli.json_out) std::cout << results.dump(2) << "\n";
    else PrintReportSummary(results, cli.out, info);
    return ReportExit(results);
  }
  if (cli.json_out) {
    std::cout << results.dump(2) << "\n";
    return kExitAgree;
  }
  if (what == "sweep") PrintSweep(results);
  else PrintStress(results);
  return kExitAgree;
}

// Joins shard files into one report, with the options the shards were run with (shards.h refuses
// anything but the whole of one campaign, naming the file and line).
int CmdMerge(const std::vector<std::string>& files, const std::string& out, const std::string& junit_path) {
  hn::ReportWriter writer(out);  // an unusable --out is reported before the shards are read
  std::optional<hn::AtomicFile> junit;
  if (!junit_path.empty()) {
    hn::RefuseToOverwriteInputs(junit_path, files, "--junit");
    junit.emplace(junit_path);
  }
  hn::ShardSet set;
  std::vector<int> seen;
  for (const std::string& f : files) {
    std::ifstream in(f);
    if (!in) throw mb::ScenarioError({f, 0}, "cannot read the shard file", "pass the .jsonl files that `report --shard K/N` wrote");
    hn::ReadShard(in, f, set, seen);
  }
  hn::FinishShards(set, seen, files.empty() ? "merge" : files[0]);
  hn::CampaignOptions o;
  const json& op = set.options;
  o.quick = op["quick"].get<bool>();
  o.repeats = op["repeats"].get<int>();
  o.timeout = op["timeout"].get<double>();
  o.jobs = op["jobs"].get<int>();
  o.scenarios = op["scenarios"].get<std::vector<std::string>>();
  o.methods = op["methods"].get<std::vector<std::string>>();
  if (op.contains("tolerances")) o.tolerances = op["tolerances"].get<std::vector<std::string>>();
  o.shards = set.shards;
  const json results = hn::Assemble(std::move(set.records), o);
  const hn::ReportWriter::Info info = writer.Write(results);
  if (junit) {
    hn::WriteJunit(junit->stream(), hn::JunitCases(results));
    junit->Commit();
  }
  PrintReportSummary(results, out, info);
  return ReportExit(results);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"mechbench — cross-validation of mechanism solvers on textbook scenarios"};
  app.require_subcommand(1);
  app.footer("Exit codes: 0 methods agree, 1 some disagree, a run failed or its CPU budget stopped it, 2 bad input.\n"
             "SCENARIO is a name from `mechbench list` or a path to a scenario file.");

  bool json_out = false;
  std::vector<std::string> names, method_names;
  std::string csv;

  auto* list = app.add_subcommand("list", "List the built-in scenarios, their kind and the methods that apply");
  list->add_flag("--json", json_out, "Machine-readable output");
  list->add_option("scenario", names, "Scenario names or files (default: every built-in scenario)");

  auto* check = app.add_subcommand("check", "Every printed book value beside each method's value, with a verdict");
  check->add_option("scenario", names, "Scenarios to check (default: all built-in)");
  check->add_option("--method", method_names, "These methods (default: analytic and numeric)");
  check->add_flag("--json", json_out, "Records {scenario, section, quantity, unit, book, <method>..., verdict}");
  bool in_process = false;
  check->add_flag("--in-process", in_process, "Run the methods in this process (debugging; a crash ends the command)");
  check->footer("Exit code 0 when the methods agree with each other, even where a printed value `differs` (a book's "
                "errata are reported, not failed); 1 when the methods disagree or a value is not computed (not judged: "
                "a method's run went wrong, the reference is not confirmed, no method gives it); 2 bad input.");

  auto* run = app.add_subcommand("run", "Run the scenarios' motion through every applicable method and compare");
  run->add_option("scenario", names, "Scenarios to run (default: all built-in)");
  run->add_option("--method", method_names, "Only these methods");
  run->add_flag("--json", json_out, "Machine-readable output");
  run->add_option("--csv", csv, "Write every method's trajectory to this CSV file (long format)");
  std::string run_junit;
  run->add_option("--junit", run_junit, "Write JUnit XML here: a test case per (scenario, method)");
  bool verbose = false;
  run->add_flag("--verbose,-v", verbose, "Also print each method's settings");
  run->add_flag("--in-process", in_process,
                "Run the methods in this process (debugging; a crash ends the command). By default each runs in its "
                "own, and an engine that aborts or hangs is a crashed or timed_out row");
  std::vector<std::string> tolerance_files;
  AddTolerancesOption(run, tolerance_files);
  double budget = 60;
  run->add_option("--budget", budget,
                  "CPU seconds per method and scenario; a method still stepping then stops as over-budget, a row "
                  "judged up to the time it reached, which fails the gate (exit 1: not judged to the end; 0: no limit)")
      ->capture_default_str()
      ->check(FiniteNumber(0, true, "--budget"));

  // generate nfourbar N: the IFToMM A02 N-four-bar as a scenario file (stdout or -o FILE).
  auto* generate = app.add_subcommand("generate", "Write a generated scenario file (nfourbar N: IFToMM A02)");
  std::string gen_kind, gen_out;
  mb::references::NFourBarOptions gen;
  generate->add_option("kind", gen_kind, "nfourbar")->required()->check(CLI::IsMember({"nfourbar"}));
  generate->add_option("N", gen.n, "number of four-bars")->required()->check(CLI::Range(1, 100000));
  generate->add_option("--t1", gen.t1, "end of the motion [s]")->capture_default_str()->check(FiniteNumber(0, false, "--t1"));
  generate->add_option("--samples", gen.samples, "output samples over [0, t1]")->capture_default_str()->check(CLI::Range(2, 100000000));
  generate->add_option("-o,--output", gen_out, "write to this file instead of stdout");
  generate->add_flag("--criteria", gen.criteria,
                     "add the benchmark's precision criteria (P0 within 1e-3 / 1e-1 m over the output steps; A02: --samples 401)");

  CampaignCli sweep_cli, stress_cli, report_cli;
  auto* sweep = app.add_subcommand("sweep", "Work–precision: each method over a ladder of steps or tolerances, error against the reference and CPU time");
  sweep_cli.Add(sweep, false);
  auto* stress = app.add_subcommand("stress", "Stiff and extreme variants of each family, an outcome per method, and each method's largest stable step");
  stress_cli.Add(stress, false);
  auto* report = app.add_subcommand("report", "check + run + sweep + stress over everything: report.html, results.json, results.csv, summary.md");
  report_cli.Add(report, true);
  auto* merge = app.add_subcommand("merge", "Join the shard files of `report --shard K/N` into one report");
  std::vector<std::string> merge_files;
  std::string merge_out;
  merge->add_option("files", merge_files, "shard-K-of-N.jsonl files")->required();
  merge->add_option("--out,-o", merge_out, "Folder for the report files")->required();
  std::string merge_junit;
  merge->add_option("--junit", merge_junit, "Also write JUnit XML here");

  auto* diff = app.add_subcommand("diff", "What changed between two reports (folders or results.json): statuses, errors past a "
                                          "factor, new failures, CPU ratios; exit 1 on a regression");
  std::string diff_old, diff_new;
  hn::DiffOptions diff_options;
  bool diff_markdown = false;
  diff->add_option("old", diff_old, "The baseline: a report folder or its results.json")->required();
  diff->add_option("new", diff_new, "The report to judge against it")->required();
  diff->add_option("--factor", diff_options.error_factor, "An error in q that grows by more than this factor is a regression")
      ->capture_default_str()
      ->check(FiniteNumber(1, false, "--factor"));
  diff->add_flag("--markdown", diff_markdown, "Markdown, for a CI job summary");

  // An unknown or missing command is named as such, with the commands (CLI11 would only say that
  // a subcommand is required), and the nearest one when it is a slip of a few letters.
  std::string known, nearest;
  size_t nearest_distance = 3;  // suggest within two edits
  bool found = false;
  const std::string first = argc > 1 ? argv[1] : "";
  for (const CLI::App* sub : app.get_subcommands({})) {
    known += (known.empty() ? "" : ", ") + sub->get_name();
    found = found || sub->get_name() == first;
    if (const size_t d = EditDistance(first, sub->get_name()); d < nearest_distance) nearest_distance = d, nearest = sub->get_name();
  }
  const bool wants_help = std::any_of(argv + 1, argv + argc, [](const char* a) {
    return std::string(a) == "-h" || std::string(a) == "--help" || std::string(a) == "--help-all";
  });
  if (argc == 1 || (first[0] == '-' && !wants_help && std::none_of(argv + 1, argv + argc, [](const char* a) { return a[0] != '-'; }))) {
    std::cerr << "error: no command given (fix: use one of " << known << "; mechbench --help)\n";
    return kExitBadInput;
  }
  if (first[0] != '-' && !found) {
    std::cerr << "error: unknown command '" << first << "' (fix: "
              << (nearest.empty() ? "use one of " : "did you mean '" + nearest + "'? The commands are ") << known
              << "; mechbench --help)\n";
    return kExitBadInput;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : kExitBadInput;
  }
  try {
    if (*run) {
      hn::SetUserTolerancesFiles(WithEnvironmentFiles(tolerance_files));
      std::vector<std::string> stems;
      for (const std::string& f : ResolveAll(names)) stems.push_back(std::filesystem::path(f).stem().string());
      WarnUnmatchedScenarios(stems);
    }
    if (*list) return CmdList(names, json_out);
    if (*check) return CmdCheck(names, method_names, json_out, in_process);
    if (*run) return CmdRun(names, method_names, json_out, csv, verbose, budget, in_process, run_junit);
    if (*sweep) return CmdCampaign(sweep_cli, "sweep");
    if (*stress) return CmdCampaign(stress_cli, "stress");
    if (*report) return CmdCampaign(report_cli, "report");
    if (*merge) return CmdMerge(merge_files, merge_out, merge_junit);
    if (*diff) {
      const hn::DiffResult d = hn::Diff(hn::LoadResults(diff_old), hn::LoadResults(diff_new), diff_options);
      hn::PrintDiff(std::cout, d, diff_markdown);
      return d.regressions ? kExitDisagree : kExitAgree;
    }
    if (*generate) {
      const std::string text = mb::references::NFourBarYaml(gen);
      if (gen_out.empty()) {
        std::cout << text;
        return kExitAgree;
      }
      std::ofstream out(gen_out);
      if (!(out << text)) throw mb::ScenarioError({gen_out, 0}, "cannot write the scenario file");
      return kExitAgree;
    }
  } catch (const mb::ScenarioError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return kExitBadInput;
  }
  return kExitBadInput;
}
