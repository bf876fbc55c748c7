#include "mechbench/harness/junit.h"

#include "mechbench/format.h"
#include "mechbench/harness/gate.h"

#include <cstdio>
#include <map>

namespace mechbench::harness {

namespace {

using nlohmann::json;

// XML text: the five entities escaped, and the characters XML 1.0 cannot hold dropped.
std::string Xml(const std::string& s) {
  std::string out;
  out.reserve(s.size());
  for (unsigned char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default:
        if (c < 0x20 && c != '\t' && c != '\n' && c != '\r') continue;
        out += static_cast<char>(c);
    }
  }
  return out;
}

std::string SecondsText(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6f", s > 0 ? s : 0.0);
  return buf;
}

std::string Lines(const std::vector<std::string>& lines) {
  std::string out;
  for (const std::string& l : lines) out += l + "\n";
  return out;
}

// One case's state and message from its gate (gate.h), alike for `run` and the report: `what`
// "status: reason", `first` the first line saying why it is outside, `why` and `where` a known
// failure's reason and its entry's file:line.
void JudgeCase(JunitCase& c, Gate g, const std::string& what, const std::string& first, const std::string& why,
               const std::string& where) {
  const std::string entry = "(" + (where.empty() ? std::string("tolerances file") : where) + "): " + why;
  switch (g) {
    case Gate::kPass: return;
    case Gate::kNotApplicable:
      c.state = JunitCase::State::kSkipped;
      c.message = "not applicable: " + what.substr(what.find(": ") + 2);
      return;
    case Gate::kKnownFailure:
      c.state = JunitCase::State::kSkipped;
      c.message = "known failure " + entry;
      return;
    case Gate::kKnownNoLongerFails:
      // Passed, and said: the entry is stale (not failing the job).
      c.output += "known failure no longer fails: remove the entry " + entry + "\n";
      return;
    case Gate::kStoppedByBudget:
      c.state = JunitCase::State::kError;
      c.message = "stopped by its CPU budget (not judged past where it got): " + what.substr(what.find(": ") + 2);
      return;
    case Gate::kError:
      c.state = JunitCase::State::kError;
      c.message = what;
      return;
    case Gate::kOutside:
      c.state = JunitCase::State::kFailed;
      c.message = first.empty() ? what : first;
      return;
  }
}

}  // namespace

void WriteJunit(std::ostream& out, const std::vector<JunitCase>& cases) {
  std::map<std::string, std::vector<const JunitCase*>> suites;
  std::vector<std::string> order;
  int failures = 0, errors = 0, skipped = 0;
  double total = 0;
  for (const JunitCase& c : cases) {
    if (!suites.count(c.suite)) order.push_back(c.suite);
    suites[c.suite].push_back(&c);
    failures += c.state == JunitCase::State::kFailed;
    errors += c.state == JunitCase::State::kError;
    skipped += c.state == JunitCase::State::kSkipped;
    total += c.seconds;
  }
  out << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      << "<testsuites name=\"mechbench\" tests=\"" << cases.size() << "\" failures=\"" << failures << "\" errors=\""
      << errors << "\" skipped=\"" << skipped << "\" time=\"" << SecondsText(total) << "\">\n";
  for (const std::string& name : order) {
    const auto& list = suites[name];
    int f = 0, e = 0, sk = 0;
    double t = 0;
    for (const JunitCase* c : list) {
      f += c->state == JunitCase::State::kFailed;
      e += c->state == JunitCase::State::kError;
      sk += c->state == JunitCase::State::kSkipped;
      t += c->seconds;
    }
    out << "  <testsuite name=\"" << Xml(name) << "\" tests=\"" << list.size() << "\" failures=\"" << f << "\" errors=\""
        << e << "\" skipped=\"" << sk << "\" time=\"" << SecondsText(t) << "\">\n";
    for (const JunitCase* c : list) {
      out << "    <testcase classname=\"mechbench." << Xml(name) << "\" name=\"" << Xml(c->name) << "\" time=\""
          << SecondsText(c->seconds) << "\"";
      if (c->state == JunitCase::State::kPassed && c->output.empty()) {
        out << "/>\n";
        continue;
      }
      out << ">\n";
      const char* tag = c->state == JunitCase::State::kFailed  ? "failure"
                        : c->state == JunitCase::State::kError ? "error"
                        : c->state == JunitCase::State::kSkipped ? "skipped"
                                                                 : nullptr;
      if (tag) out << "      <" << tag << " message=\"" << Xml(c->message) << "\"/>\n";
      if (!c->output.empty()) out << "      <system-out>" << Xml(c->output) << "</system-out>\n";
      out << "    </testcase>\n";
    }
    out << "  </testsuite>\n";
  }
  out << "</testsuites>\n";
}

std::vector<JunitCase> JunitCases(const RunReport& rep) {
  std::vector<JunitCase> out;
  for (const Result& r : rep.results) {
    JunitCase c;
    c.suite = "run." + rep.scenario;
    c.name = r.method;
    c.seconds = r.cpu_seconds;
    const MethodVerdict v = VerdictOf(rep, r.method);
    c.output = Lines(v.problems);
    JudgeCase(c, GateOf(ToString(r.status), v.within, v.known, v.stale), std::string(ToString(r.status)) + ": " + r.reason,
              v.problems.empty() ? std::string() : v.problems.front(), v.known.empty() ? v.stale : v.known, v.known_where);
    out.push_back(std::move(c));
  }
  return out;
}

std::vector<JunitCase> JunitCases(const json& results) {
  std::vector<JunitCase> out;
  if (!results.is_object() || !results.contains("records") || !results["records"].is_array()) return out;
  for (const json& r : results["records"]) {
    const std::string kind = r.value("kind", "");
    const std::string scenario = r.value("scenario", "");
    if (kind == "run") {
      JunitCase c;
      c.suite = "run." + scenario;
      c.name = r.value("method", "");
      c.seconds = r.value("cpu_seconds", 0.0);
      const std::string status = r.value("status", ""), known = r.value("known", ""), stale = r.value("known_stale", "");
      const bool within = r.value("within", false);
      if (r.contains("problems") && r["problems"].is_array())
        for (const json& p : r["problems"])
          if (p.is_string()) c.output += p.get<std::string>() + "\n";
      JudgeCase(c, GateOf(status, within, known, stale), status + ": " + r.value("reason", ""),
                c.output.substr(0, c.output.find('\n')), known.empty() ? stale : known, r.value("known_entry", ""));
      out.push_back(std::move(c));
    } else if (kind == "check" && r.contains("rows") && r["rows"].is_array()) {
      for (const json& row : r["rows"]) {
        JunitCase c;
        c.suite = "book." + scenario;
        c.name = row.value("quantity", "") + " (" + row.value("where", "") + ")";
        const std::string verdict = row.value("verdict", "");
        std::string computed;
        if (row.contains("computed") && row["computed"].is_object())
          for (const auto& [method, v] : row["computed"].items())
            computed += "; " + method + " " + (v.is_number() ? Fmt(v.get<double>(), 10) : std::string("n/a"));
        c.output = "book " + row.value("printed", "") + " " + row.value("unit", "") + computed + "; verdict " + verdict +
                   (row.contains("note") ? "; " + row.value("note", "") : "");
        if (!row.value("methods_agree", true)) {
          c.state = JunitCase::State::kFailed;
          c.message = "the methods disagree on " + row.value("quantity", "") + computed;
        }
        out.push_back(std::move(c));
      }
    }
  }
  return out;
}

}  // namespace mechbench::harness
