// report.html
#include "writers.h"

#include "access.h"
#include "chains_view.h"
#include "precision_view.h"
#include "reach.h"
#include "results_view.h"
#include "summary_html.h"
#include "text.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <vector>

namespace mechbench::harness::report {

namespace {

// A record's CPU phases as five table cells: set-up, integration, observation, steps, µs per step.
std::string CpuCells(const json& r) {
  const json& c = At(r, "cpu");
  const auto steps = Num(At(c, "steps"));
  const auto step_us = Num(At(c, "step_us"));
  std::string out;
  for (const char* k : {"setup", "integration", "observation"})
    out += "<td class=\"num\">" + Html(FmtSeconds(Num(At(c, k)))) + "</td>";
  out += "<td class=\"num\">" + (steps ? Fmt("g8", *steps) : std::string(kDash)) + "</td>";
  out += "<td class=\"num\">" + (step_us ? Fmt("g3", *step_us) : std::string(kDash)) + "</td>";
  return out;
}

const char* kCss = R"(
:root { --ok:#e3f4e6; --warn:#fff1cc; --bad:#fde0de; --na:#eeeeee; --line:#d8dce2; --head:#f4f6f8; }
* { box-sizing: border-box; }
body { font-family: "DejaVu Sans", "Liberation Sans", Arial, Helvetica, sans-serif; font-size: 14px;
       line-height: 1.4; color: #1d232b; margin: 0; background: #fafbfc; }
main { max-width: 1320px; margin: 0 auto; padding: 16px 24px 48px; background: #fff; }
h1 { font-size: 24px; margin: 8px 0 4px; }
h2 { font-size: 19px; margin: 36px 0 6px; padding-top: 10px; border-top: 3px solid #3b6ea5; }
h3 { font-size: 15px; margin: 20px 0 6px; color: #2b4d73; }
p.meta, p.note { color: #4c5560; margin: 4px 0 8px; }
p.note { font-style: italic; }
code, .mono { font-family: "DejaVu Sans Mono", "Liberation Mono", Consolas, monospace; font-size: 12.5px; }
table { border-collapse: collapse; margin: 6px 0 12px; font-size: 13px; }
th, td { border: 1px solid var(--line); padding: 3px 7px; vertical-align: top; text-align: left; }
th { background: var(--head); font-weight: 600; }
td.num { text-align: right; font-family: "DejaVu Sans Mono", "Liberation Mono", Consolas, monospace;
         font-size: 12.5px; white-space: nowrap; }
td.wrap { max-width: 420px; overflow-wrap: anywhere; white-space: pre-line; }
td.st { white-space: nowrap; }
table.kv th { width: 11em; }
.grid { display: flex; flex-wrap: wrap; gap: 12px 28px; align-items: flex-start; }
.grid > div { flex: 0 1 auto; }
.ok { background: var(--ok); } .warn { background: var(--warn); } .bad { background: var(--bad); }
.na { background: var(--na); color: #555; }
.totals { background: var(--head); border: 1px solid var(--line); padding: 8px 12px; margin: 12px 0; }
figure { margin: 8px 0 14px; max-width: 100%; }
figure.plot svg { display: block; width: 100%; height: auto; background: #fff; border: 1px solid var(--line); }
figure.missing { border: 1px dashed #b55; background: var(--bad); padding: 12px; color: #6b1f1f; }
figcaption { font-size: 12.5px; color: #4c5560; margin-top: 3px; }
details { margin: 4px 0; } summary { cursor: pointer; font-weight: 600; }
details table { margin-left: 18px; }
nav ol { columns: 2; margin: 4px 0; }
small { color: #5c6570; }
table.reach td.never { color: #7a2020; font-size: 12px; max-width: 190px; }
table.reach td.na { font-style: italic; }
.summary-grid { display: flex; flex-wrap: wrap; gap: 8px 24px; align-items: flex-start; }
.summary-grid > figure { flex: 1 1 520px; max-width: 660px; }
.summary-grid > div { flex: 0 0 auto; }
form.pick { margin: 4px 0 6px; line-height: 1.9; }
form.pick .grp { display: inline-block; min-width: 5.5em; color: #4c5560; font-size: 12.5px; }
form.pick input { position: absolute; opacity: 0; width: 1px; height: 1px; margin: 0; }
form.pick label { font-family: "DejaVu Sans Mono", "Liberation Mono", Consolas, monospace; font-size: 12px;
                  white-space: nowrap; cursor: pointer; margin-left: 12px; display: inline-block; }
form.pick label::before { content: "✓"; display: inline-block; width: 13px; height: 13px; line-height: 13px;
                          margin: 0 5px 1px 0; vertical-align: middle; text-align: center; font-size: 11px;
                          color: #fff; background: #3b6ea5; border: 1px solid #3b6ea5; border-radius: 2px; }
form.pick input:not(:checked) + label::before { content: ""; background: #fff; border-color: #9aa0a6; }
form.pick input:focus-visible + label { outline: 2px solid #3b6ea5; outline-offset: 1px; }
form.pick .sw { display: inline-block; width: 16px; height: 4px; margin: 0 4px 2px 0; vertical-align: middle; }
form.pick input:not(:checked) + label { color: #9aa0a6; text-decoration: line-through; }
form.pick input:not(:checked) + label .sw { opacity: 0.35; }
form.pick button { margin-left: 14px; font-size: 12px; cursor: pointer; }
.wp { display: flex; flex-wrap: wrap; gap: 4px 24px; align-items: flex-start; }
)";

// A frame's time for its label: four significant digits, never an exponent below 1e5 s.
std::string FrameTime(double t) {
  char b[32];
  if (std::fabs(t) >= 1000 && std::fabs(t) < 1e5) std::snprintf(b, sizeof b, "%.0f", t);
  else std::snprintf(b, sizeof b, "%.4g", t);
  return b;
}

std::string Cls(const std::string& c) { return c.empty() ? "" : " class=\"" + c + "\""; }

std::string VerdictClass(const std::string& v) {
  if (v == "agrees") return "ok";
  if (v == "last-digit") return "warn";
  if (v == "differs") return "bad";
  return "na";
}
std::string StatusClass(const std::string& s) {
  if (s == "ok") return "ok";
  if (s == "not-applicable") return "na";
  return "bad";
}
std::string OutcomeClass(const std::string& s) {
  if (s == "ok") return "ok";
  if (s == "inaccurate") return "warn";
  if (s == "not_applicable") return "na";
  return "bad";
}

// The picker's sample of line style i (LineStyle): its colour, dashed from the eleventh on.
std::string Swatch(size_t i) {
  const std::string colour = Colour(i);
  return i < 10 ? "background:" + colour : "height:0;border-top:4px dashed " + colour;
}

struct Figure {
  std::string kind, scenario;
  int width = 600, height = 400;
};

// How a drawing puts the mechanism's points on the page: a planar scene's x and y as they are; a
// spatial scene's in an isometric view (orthographic, looking from (1, 1, 1) towards the origin, z
// up: x points to the lower left, y to the lower right) or one of its three projections.
struct View {
  enum class Plane { kXY, kXZ, kYZ, kIsometric };
  Plane plane = Plane::kXY;
  int dim = 2;                // components per point in the records
  std::string kind;           // the figure's kind (its data-plot tag's first part)
  std::string title, caption;  // added to the figure's title and caption
  // The page coordinates of the point whose components start at a[at], or nullopt.
  std::optional<std::pair<double, double>> Project(const json& a, size_t at) const {
    if (a.size() < at + static_cast<size_t>(dim)) return std::nullopt;
    double c[3] = {0, 0, 0};
    for (int i = 0; i < dim; ++i) {
      const auto v = Num(a[at + static_cast<size_t>(i)]);
      if (!v) return std::nullopt;
      c[i] = *v;
    }
    switch (plane) {
      case Plane::kXY: return std::make_pair(c[0], c[1]);
      case Plane::kXZ: return std::make_pair(c[0], c[2]);
      case Plane::kYZ: return std::make_pair(c[1], c[2]);
      case Plane::kIsometric:
        return std::make_pair((c[1] - c[0]) / std::sqrt(2.0), (2 * c[2] - c[0] - c[1]) / std::sqrt(6.0));
    }
    return std::nullopt;
  }
  // The isometric view's axes as a small triad of arrows x, y, z from (x0, y0) on the page, `len`
  // long (gnuplot lines; nothing in the other views, whose axes are labelled).
  std::string Triad(double x0, double y0, double len) const {
    if (plane != Plane::kIsometric) return "";
    std::string out;
    const char* names[3] = {"x", "y", "z"};
    for (int i = 0; i < 3; ++i) {
      json e = json::array({0.0, 0.0, 0.0});
      e[i] = len;
      const auto d = Project(e, 0);
      out += "set arrow from " + Fmt("full", x0) + "," + Fmt("full", y0) + " to " + Fmt("full", x0 + d->first) + "," +
             Fmt("full", y0 + d->second) + " head size screen 0.012,25 lw 1.2 lc rgb '#777777'\n";
      out += "set label " + GpStr(names[i]) + " at " + Fmt("full", x0 + 1.25 * d->first) + "," +
             Fmt("full", y0 + 1.25 * d->second) + " center font ',9' tc rgb '#555555'\n";
    }
    return out;
  }
  // The gnuplot lines for the axes: labels in the scene's unit, or none in the isometric view
  // (whose page axes are no coordinate's).
  std::string Axes(const std::string& unit) const {
    const char* names[4][2] = {{"x", "y"}, {"x", "z"}, {"y", "z"}, {"", ""}};
    const int k = static_cast<int>(plane);
    if (plane == Plane::kIsometric) return "unset xtics\nunset ytics\nunset border\n";
    return "set xlabel " + GpStr(std::string(names[k][0]) + " [" + unit + "]") + " noenhanced\nset ylabel " +
           GpStr(std::string(names[k][1]) + " [" + unit + "]") + " noenhanced\nset grid lc rgb '#e4e4e4'\n";
  }
};
const View kPlanarView{View::Plane::kXY, 2, "drawing", "", ""};
const View kSpatialViews[4] = {
    {View::Plane::kIsometric, 3, "drawing", " (isometric)",
     " in an isometric view (looking from (1, 1, 1) towards the origin; z up, x to the lower left, y to the "
     "lower right)"},
    {View::Plane::kXY, 3, "drawing-top", " (top: x–y)", " seen from above (its projection on the x–y plane)"},
    {View::Plane::kXZ, 3, "drawing-front", " (front: x–z)", " seen from the front (its projection on the x–z plane)"},
    {View::Plane::kYZ, 3, "drawing-side", " (side: y–z)", " seen from the side (its projection on the y–z plane)"},
};

class HtmlWriter {
 public:
  HtmlWriter(const json& results, Gnuplot& gp) : r_(results), gp_(gp) {}

  std::string Render() {
    std::ostringstream& o = o_;
    const std::string created = Str(r_, "created");
    Title();
    Summary();
    Benchmarks();
    Chains();
    Context();
    const auto scenarios = Scenarios(r_);
    std::set<std::string> used;
    for (const auto& s : scenarios) {
      std::string id = "sc-" + Slug(s.name);
      while (!used.insert(id).second) id += "-2";
      anchors_.push_back(id);
    }
    Overview(scenarios);
    for (size_t i = 0; i < scenarios.size(); ++i) Scenario(scenarios[i], anchors_[i]);
    o << "<p class=\"meta\">Written by mechbench";
    if (gp_.available()) o << "; plots by " << Html(gp_.version());
    o << ".</p>\n</main>\n</body>\n</html>\n";
    // The head last: it carries the rules of the method pickers, known once the plots are drawn.
    std::ostringstream page;
    page << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
         << "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
         << "<title>mechbench report " << Html(created) << "</title>\n<style>" << kCss << pick_css_.str()
         << AnimationCss() << "</style>\n</head>\n<body>\n<main>\n"
         << o.str();
    return page.str();
  }
  int plots() const { return plots_; }

 private:
  // The motion figures' rules: each frame's items shown for their share of the cycle (one keyframes
  // rule per frame count), paused while the pointer is over the figure, still when the reader asks
  // for reduced motion (the first frame stays).
  std::string AnimationCss() const {
    if (anim_frames_.empty()) return "";
    std::ostringstream css;
    for (const size_t n : anim_frames_)
      css << "@keyframes mb-frames-" << n << " { 0% { visibility: visible; } " << Fmt("g6", 100.0 / static_cast<double>(n))
          << "% { visibility: hidden; } 100% { visibility: hidden; } }\n";
    css << anim_css_.str()
        << "figure.plot:hover g[id] { animation-play-state: paused !important; }\n"
        << "@media (prefers-reduced-motion: reduce) { figure.plot g[id] { animation: none !important; } }\n";
    return css.str();
  }

  void KvTable(const std::vector<std::pair<std::string, std::string>>& rows) {
    o_ << "<table class=\"kv\">";
    for (const auto& [k, v] : rows) o_ << "<tr><th>" << Html(k) << "</th><td>" << Html(v) << "</td></tr>";
    o_ << "</table>\n";
  }

  // The title, what ran where in one line, and the totals.
  void Title() {
    std::ostringstream& o = o_;
    const json& m = At(r_, "machine");
    const json& build = At(r_, "build");
    std::string where = Str(m, "cpu");
    if (!Str(m, "cores").empty()) where += (where.empty() ? "" : ", ") + Str(m, "cores") + " cores";
    if (!Str(build, "build_type").empty()) where += (where.empty() ? "" : " · ") + Str(build, "build_type");
    o << "<h1>mechbench report</h1>\n<p class=\"meta\">created " << Html(Str(r_, "created"))
      << (where.empty() ? "" : " · " + Html(where)) << " · schema " << Html(Str(r_, "schema")) << "</p>\n";
    const Counts all = Count(At(r_, "records"), nullptr);
    o << "<div class=\"totals\"><b>Totals</b> — book values: " << Html(JoinCounts(Ordered(all.verdicts, kVerdicts)))
      << " · runs: " << Html(RunsText(all.runs)) << " · sweep rungs: " << all.sweeps_ok << " of " << all.sweeps
      << " ok · stress: " << Html(JoinCounts(Ordered(all.outcomes, kOutcomes))) << " · stable-step searches: "
      << all.stable_steps << "</div>\n";
    if (!gp_.available()) {
      o << "<p class=\"note\">Plots are missing from this page: " << Html(gp_.why_missing()) << ".</p>\n";
    }
  }

  // The answer first: per method, the integration CPU to reach 1e-3 and 1e-6 on each scene, and
  // on how many scenes it got there.
  void Summary() {
    const Reach reach = ReachAcrossScenes(r_);
    std::ostringstream& o = o_;
    o << "<section id=\"summary\">\n<h2>Work–precision across the scenes</h2>\n";
    if (reach.empty()) {
      o << "<p class=\"note\">No work–precision sweeps in these results, so no summary across the scenes.</p>\n"
        << "</section>\n";
      return;
    }
    o << "<p class=\"meta\">" << reach.scenes.size() << " scene" << (reach.scenes.size() == 1 ? "" : "s")
      << " swept. For each method and scene: the integration CPU (the method's own work, median of the repeats; one "
      << "run when it takes 50 ms or more; a run two variants share — the same computation, such as Simbody's default "
      << "and tuned accuracy at a swept accuracy — is done once for both) of "
      << "the cheapest sweep rung whose error in q (max over the run, relative to the motion's scale) is within "
      << "1e-3, and within 1e-6. Per scene below: the work–precision plots they come from.</p>\n";
    o << "<div class=\"summary-grid\">\n";
    const PlotSpec f = ReachFigure(reach);
    EmitFigure({"summary", "work-precision", f.width, f.height}, "Work–precision across the scenes",
               "A row per method, a marker per scene (colour and shape: the scene). Filled: the CPU at which it "
               "reached the level; open, in the grey band: swept on that scene, never within the level. Black bar: "
               "the median over the scenes reached. Methods that reach different scenes are compared on different "
               "work: read the counts beside.",
               f.data, f.script);
    o << "<div>" << ReachTableHtml(reach)
      << "<p class=\"meta\" style=\"max-width:520px\">Scenes: reached of those the method was swept on (it "
      << "is not applicable on the others). Median: over the scenes it reached, so a median to 1e-6 below the "
      << "one to 1e-3 means fewer, cheaper scenes got there. Never: no rung within the level, with the smallest "
      << "q error any of its rungs got.</p></div>\n</div>\n</section>\n";
  }

  // The published benchmarks' precision levels: per method, the CPU time of the coarsest run that
  // met each level (precision_view.h).
  void Benchmarks() {
    const std::vector<PrecisionTable> tables = PrecisionTables(r_);
    if (tables.empty()) return;
    std::ostringstream& o = o_;
    o << "<section id=\"benchmarks\">\n<h2>Published benchmarks: CPU time to each precision level</h2>\n"
      << "<p class=\"meta\">As the IFToMM library of multibody benchmarks compares solvers: the error is the "
      << "largest distance of the benchmark's point from the reference over its output steps, and each method's "
      << "figure is the CPU time (the method's own work; median of the repeats, one run when it takes 50 ms or more; "
      << "two variants whose walks are the same computation share one) of the coarsest run that meets "
      << "the level: the fewest steps or the loosest tolerance, so the least work, though on runs of a few "
      << "milliseconds the clock's noise can make a finer rung look cheaper. Each method walks its steps or "
      << "tolerances from coarse to fine until every level is met or its CPU budget is spent.</p>\n";
    for (const PrecisionTable& t : tables) {
      std::string unit;
      for (const auto& s : Arr(At(r_, "scenarios")))
        if (Str(s, "scenario") == t.scenario) unit = Str(At(s, "drawing"), "unit");
      o << "<h3><code>" << Html(t.scenario) << "</code>: point " << Html(t.point) << ", " << t.output_steps
        << " output steps</h3>\n"
        << (t.source.empty() ? std::string() : "<p class=\"meta\">Levels: " + Html(t.source) + ".</p>\n")
        << "<table><tr><th>method</th><th>status</th>";
      for (size_t l = 0; l < t.levels.size(); ++l)
        o << "<th>" << Html(LevelText(t.levels[l], unit)) << (l == 0 && t.levels.size() > 1 ? " (high)" : "")
          << (l + 1 == t.levels.size() && t.levels.size() > 1 ? " (low)" : "") << "</th>";
      o << "<th>runs</th><th>reason</th></tr>\n";
      for (const PrecisionRow& row : t.rows) {
        o << "<tr><td><code>" << Html(row.method) << "</code></td><td class=\"st " << StatusClass(row.status) << "\">"
          << Html(row.status) << "</td>";
        for (const PrecisionCell& c : row.cells)
          o << "<td class=\"num" << (row.status != "ok" ? "" : c.met ? " ok" : " bad") << "\">" << Html(c.cpu)
            << (c.detail.empty() ? "" : "<br><small>" + Html(c.detail) + "</small>") << "</td>";
        o << "<td class=\"num\">" << row.rungs << "</td><td class=\"wrap\">" << Html(row.reason) << "</td></tr>\n";
      }
      o << "</table>\n";
    }
    o << "</section>\n";
  }

  // The long chains (chains_view.h): per method and N, the integration CPU per step and the
  // position error against the exact motion, the growth exponent, and why the ladder stopped.
  void Chains() {
    const ChainTable t = ChainTableOf(r_);
    if (t.empty()) return;
    std::ostringstream& o = o_;
    o << "<section id=\"chains\">\n<h2>Long chains: the N-four-bar as N grows</h2>\n"
      << "<p class=\"meta\">Every integrating method on the generated N-four-bar (IFToMM A02's mechanism, "
      << "<code>mechbench generate nfourbar N</code>) over its first " << Html(FmtSeconds(t.t1)) << " ("
      << t.samples << " samples, before the first singular position), each N a fresh run at the method's "
      << "own settings, in the method's case process once its one-time costs are paid. Each cell: the "
      << "integration CPU per step (the method's own work; one run, or the median of the repeats for a rung "
      << "under 5 ms) and the position error (q, max over the samples, relative to the motion's scale) against the exact "
      << "motion the scene names (<code>reference: {exact: nfourbar}</code>). A method climbs the ladder until a "
      << "rung fails or loses the motion (error above 0.1 or scaled ‖Φ‖ above 1e-2), or its CPU budget of "
      << Html(FmtSeconds(t.budget)) << " for all its rungs is spent: a rung whose cost, extrapolated from the "
      << "last two, would not fit in what is left is not started. Growth: the log–log slope of the integration "
      << "CPU per simulated second against N over the rungs from N = 10 on (all rungs when fewer than two got "
      << "there). All rungs together: " << Html(FmtSeconds(t.cpu_seconds)) << " of CPU.</p>\n";
    std::ostringstream data, plot;
    std::vector<std::string> items;
    for (size_t i = 0; i < t.rows.size(); ++i) {
      const ChainRow& row = t.rows[i];
      std::ostringstream block;
      int points = 0;
      for (size_t k = 0; k < t.ladder.size(); ++k)
        if (row.cells[k].step_us && *row.cells[k].step_us > 0)
          block << t.ladder[k] << " " << Fmt("full", *row.cells[k].step_us) << "\n", ++points;
      if (!points) continue;
      data << "# " << GpDataStr(row.method) << ": N us_per_step\n" << block.str() << "\n\n";
      items.push_back("datafile index " + std::to_string(items.size()) + " using 1:2 with linespoints lw 1.4 " +
                      LineStyle(i) + " ps 0.7 title " + GpStr(row.method) + " noenhanced");
    }
    if (!items.empty()) {
      plot << "set title 'Long chains: integration CPU per step'\n"
           << "set xlabel 'N (four-bars in the chain)'\nset ylabel 'integration CPU per step [µs]'\n"
           << "set logscale xy 10\nset format y '10^{%L}'\n"
           << "set grid xtics ytics lc rgb '#dddddd'\n"
           << "set key outside right top Left reverse noenhanced samplen 2\nplot ";
      for (size_t i = 0; i < items.size(); ++i) plot << (i ? ", \\\n     " : "") << items[i];
      plot << "\n";
      EmitFigure({"chains", "nfourbar", 820, 440}, "Long chains: integration CPU per step",
                 "One line per method through the rungs it ran (a rung stopped by its budget is drawn with the "
                 "steps it took).",
                 data.str(), plot.str());
    }
    o << "<table><tr><th>method</th>";
    for (int n : t.ladder) o << "<th>N = " << n << "</th>";
    o << "<th>growth</th><th>CPU</th><th>ladder stopped</th></tr>\n";
    for (const ChainRow& row : t.rows) {
      o << "<tr><td><code>" << Html(row.method) << "</code></td>";
      for (const ChainCell& c : row.cells) {
        if (!c.ran) {
          o << "<td class=\"num\">" << kDash << "</td>";
          continue;
        }
        o << "<td class=\"num" << (c.ok ? " ok" : " bad") << "\">" << Html(c.text) << "<br><small>" << Html(c.detail)
          << "</small></td>";
      }
      o << "<td class=\"num\">" << Html(FmtExponent(row.exponent));
      if (row.exponent) o << "<br><small>" << Html(row.exponent_range) << ", " << row.exponent_points << " rungs</small>";
      o << "</td><td class=\"num\">" << Html(FmtSeconds(row.cpu_seconds)) << "</td><td class=\"wrap\">"
        << Html(row.stop.empty() ? row.status : row.stop) << (row.stop_detail.empty() ? "" : ": " + Html(row.stop_detail))
        << "</td></tr>\n";
    }
    o << "</table>\n<p class=\"meta\">— : not run (the ladder stopped below). A red cell: the rung that stopped "
      << "the ladder (over its budget, failed, or the motion lost).</p>\n</section>\n";
  }

  // Build, engines, machine, options and the methods.
  void Context() {
    std::ostringstream& o = o_;
    o << "<h2 id=\"context\">Build, machine and scenes</h2>\n";
    o << "<div class=\"grid\">\n<div><h3>Build</h3>";
    std::vector<std::pair<std::string, std::string>> kv;
    const json& build = At(r_, "build");
    for (const char* k : {"version", "build_type", "compiler"}) kv.emplace_back(k, Str(build, k));
    if (build.is_object())
      for (const auto& [k, v] : build.items())
        if (k != "version" && k != "build_type" && k != "compiler") kv.emplace_back(k, Str(v));
    KvTable(kv);
    o << "</div>\n<div><h3>Engines</h3>";
    kv.clear();
    if (At(r_, "engines").is_object())
      for (const auto& [k, v] : At(r_, "engines").items()) kv.emplace_back(k, Str(v));
    if (kv.empty()) o << "<p class=\"note\">no engines built in</p>";
    else KvTable(kv);
    o << "</div>\n<div><h3>Machine</h3>";
    kv.clear();
    const json& m = At(r_, "machine");
    kv.emplace_back("cpu", Str(m, "cpu"));
    kv.emplace_back("cores", Str(m, "cores"));
    kv.emplace_back("memory", Num(At(m, "memory_gib")) ? Fmt("g3", *Num(At(m, "memory_gib"))) + " GiB" : "");
    kv.emplace_back("os", Str(m, "os"));
    if (!Str(m, "hostname").empty()) kv.emplace_back("hostname", Str(m, "hostname"));
    KvTable(kv);
    o << "</div>\n<div><h3>Options</h3>";
    kv.clear();
    const json& opt = At(r_, "options");
    for (const char* k : {"quick", "shards", "jobs", "repeats"}) kv.emplace_back(k, Str(opt, k));
    kv.emplace_back("timeout", Num(At(opt, "timeout_seconds")) ? Str(opt, "timeout_seconds") + " s" : "");
    std::string sel;
    for (const auto& s : Arr(At(opt, "selection"))) sel += (sel.empty() ? "" : ", ") + Str(s);
    kv.emplace_back("selection", sel.empty() ? "all" : sel);
    KvTable(kv);
    o << "</div>\n</div>\n";

    const json& methods = At(r_, "methods");
    if (!Arr(methods).empty()) {
      o << "<details><summary>Methods (" << Arr(methods).size() << ")</summary>\n<table><tr><th>method</th>"
        << "<th>control</th><th>default</th><th>description</th></tr>\n";
      for (const auto& m2 : Arr(methods)) {
        const std::string control = Str(m2, "control");
        o << "<tr><td><code>" << Html(Str(m2, "method")) << "</code></td><td>" << Html(control) << "</td><td class=\"num\">"
          << Html(Num(At(m2, "default")) ? FmtRung(control, Num(At(m2, "default"))) : "")
          << "</td><td class=\"wrap\">" << Html(Str(m2, "description")) << "</td></tr>\n";
      }
      o << "</table>\n</details>\n";
    }
  }

  void Overview(const std::vector<ScenarioRef>& scenarios) {
    std::ostringstream& o = o_;
    o << "<h3>Scenarios</h3>\n<table><tr><th>section</th><th>scenario</th><th>kind</th><th>book values</th>"
      << "<th>runs</th><th>sweep rungs</th><th>stress not ok</th></tr>\n";
    const json& records = At(r_, "records");
    for (size_t i = 0; i < scenarios.size(); ++i) {
      const auto& s = scenarios[i];
      const Counts c = Count(records, &s.name);
      int bad = 0, total = 0;
      for (const auto& [k, n] : c.outcomes) {
        total += n;
        if (k != "ok") bad += n;
      }
      const bool runs_bad = c.runs.not_ok() > 0;
      const bool book_bad = c.verdicts.count("differs") && c.verdicts.at("differs") > 0;
      o << "<tr><td>" << Html(s.info ? Str(*s.info, "section") : "") << "</td><td><a href=\"#" << anchors_[i]
        << "\"><code>" << Html(s.name) << "</code></a></td><td>" << Html(s.info ? Str(*s.info, "kind") : "")
        << "</td><td" << Cls(c.verdicts.empty() ? "" : (book_bad ? "bad" : "ok")) << ">"
        << Html(c.verdicts.empty() ? kDash : JoinCounts(Ordered(c.verdicts, kVerdicts))) << "</td><td"
        << Cls(runs_bad ? "bad" : "") << ">"
        << Html(c.runs.ok + c.runs.not_ok() + c.runs.not_applicable ? RunsText(c.runs) : kDash) << "</td><td>"
        << (c.sweeps ? std::to_string(c.sweeps_ok) + " of " + std::to_string(c.sweeps) + " ok" : kDash) << "</td><td"
        << Cls(bad ? "bad" : "") << ">" << (total ? std::to_string(bad) + " of " + std::to_string(total) : kDash)
        << "</td></tr>\n";
    }
    o << "</table>\n";
  }

  // A plot or its placeholder: always a <figure class="plot…" data-plot="KIND-SCENARIO">. Returns
  // the prefix of the plot's SVG ids, empty for a placeholder.
  std::string EmitFigure(const Figure& f, const std::string& title, const std::string& caption, const std::string& data,
                  const std::string& body) {
    const std::string tag = f.kind + "-" + f.scenario;
    PlotResult p = gp_.Plot(tag, title, f.width, f.height, data, body);
    if (p.ok) {
      ++plots_;
      o_ << "<figure class=\"plot\" data-plot=\"" << Html(tag) << "\" style=\"width:" << f.width << "px\">\n"
         << p.svg << "\n<figcaption>" << caption << "</figcaption></figure>\n";
      return p.id_prefix;
    }
    o_ << "<figure class=\"plot missing\" data-plot=\"" << Html(tag) << "\" style=\"width:" << f.width
       << "px\"><b>Plot missing:</b> " << Html(title) << ". " << Html(p.why) << "</figure>\n";
    return "";
  }

  void Drawing(const ScenarioRef& s) {
    const json& d = s.info ? At(*s.info, "drawing") : Null();
    if (!d.is_object()) {
      const bool gears = s.info && Str(*s.info, "kind") == "gear_train";
      o_ << "<p class=\"note\">No drawing: "
         << (gears ? "a gear train is described by its ratios, not by points in the plane."
                   : "the results give no drawing for this scenario.")
         << "</p>\n";
      return;
    }
    // A spatial scene (dim 3) is drawn four times: an isometric view and its three projections.
    if (Num(At(d, "dim")).value_or(2) == 3) {
      for (const View& v : kSpatialViews) DrawingView(s, d, v);
    } else {
      DrawingView(s, d, kPlanarView);
    }
  }

  void DrawingView(const ScenarioRef& s, const json& d, const View& view) {
    std::ostringstream data, plot;
    double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
    auto extend = [&](double x, double y) {
      xmin = std::min(xmin, x);
      xmax = std::max(xmax, x);
      ymin = std::min(ymin, y);
      ymax = std::max(ymax, y);
    };
    auto point = [&view](const json& p) { return view.Project(Arr(p), 0); };
    int index = 0;
    std::vector<std::string> items;
    for (const auto& b : Arr(At(d, "bodies"))) {
      std::ostringstream block;
      int n = 0;
      for (const auto& p : Arr(At(b, "points"))) {
        if (auto xy = point(p)) {
          block << Fmt("full", xy->first) << " " << Fmt("full", xy->second) << "\n";
          extend(xy->first, xy->second);
          ++n;
        }
      }
      if (!n) continue;
      data << "# body " << GpDataStr(Str(b, "name")) << "\n" << block.str() << "\n\n";
      items.push_back("datafile index " + std::to_string(index) + " using 1:2 with linespoints lw 3.5 " +
                      LineStyle(static_cast<size_t>(index), false) + " ps 0.55 title " + GpStr(Str(b, "name")) +
                      " noenhanced");
      ++index;
    }
    // Labels once per name: fixed points first, then the other named points.
    std::set<std::string> labelled;
    auto named_block = [&](const json& list, const char* key, const char* what, const std::string& style,
                           const std::string& title, const std::string& label_style) {
      std::ostringstream block;
      int n = 0;
      for (const auto& e : Arr(list)) {
        auto xy = point(At(e, key));
        if (!xy) continue;
        const std::string name = Str(e, "name");
        const bool first = labelled.insert(name).second;
        block << Fmt("full", xy->first) << " " << Fmt("full", xy->second) << " " << GpDataStr(first ? name : "")
              << "\n";
        extend(xy->first, xy->second);
        ++n;
      }
      if (!n) return;
      data << "# " << what << "\n" << block.str() << "\n\n";
      items.push_back("datafile index " + std::to_string(index) + " using 1:2 with points " + style + " " + title);
      items.push_back("datafile index " + std::to_string(index) + " using 1:2:3 with labels " + label_style +
                      " noenhanced notitle");
      ++index;
    };
    named_block(At(d, "fixed"), "p", "fixed points", "pt 9 ps 1.7 lc rgb '#222222'", "title 'fixed'",
                "offset char 0,-1.3 font ',10' tc rgb '#111111'");
    named_block(At(d, "points"), "p", "points", "pt 6 ps 0.9 lc rgb '#555555'", "notitle",
                "offset char 0.9,0.8 font ',9' tc rgb '#333333'");
    if (items.empty()) {
      o_ << "<p class=\"note\">No drawing: the drawing in the results has no points.</p>\n";
      return;
    }
    const double span = std::max({xmax - xmin, ymax - ymin, 1e-12});
    const double pad = 0.12 * span;
    // Equal axes: the picture's height follows the mechanism's aspect (about 90 px of the width
    // go to the y tics and label, about 110 px of the height to the x tics, label and the key).
    const int width = 560;
    const double aspect = (ymax - ymin + 2 * pad) / (xmax - xmin + 2 * pad);
    const int height = static_cast<int>(std::clamp((width - 90) * aspect + 110, 220.0, 520.0));
    const std::string unit = Str(d, "unit");
    plot << "set size ratio -1\n"
         << "set xrange [" << Fmt("full", xmin - pad) << ":" << Fmt("full", xmax + pad) << "]\n"
         << "set yrange [" << Fmt("full", ymin - pad) << ":" << Fmt("full", ymax + pad) << "]\n"
         << view.Axes(unit) << view.Triad(xmin - 0.5 * pad, ymin - 0.5 * pad, 0.5 * pad)
         << "set key below horizontal noenhanced samplen 2\n"
         << "plot ";
    for (size_t i = 0; i < items.size(); ++i) plot << (i ? ", \\\n     " : "") << items[i];
    plot << "\n";
    EmitFigure({view.kind, s.name, width, height}, "Drawing of " + s.name + " at t0" + view.title,
               "The mechanism at t0" + view.caption + ": bodies as lines through their points, ▲ fixed points.",
               data.str(), plot.str());
  }

  // The motion, animated: the reference mechanism (wide, grey) and each method's (coloured) at
  // the frames of the run records (frames.h), one plot item per frame and kind, shown in turn by
  // a CSS animation of the items' visibility (no script). Hovering pauses it; with reduced motion
  // asked for, the first frame stays. Default settings and tuned variants are two figures, as in
  // the work–precision plots.
  void Motion(const ScenarioRef& s) {
    const json& d = s.info ? At(*s.info, "drawing") : Null();
    if (!d.is_object() || !At(d, "order").is_array()) return;
    const size_t n_points = Arr(At(d, "order")).size();
    std::vector<std::vector<int>> bodies;
    for (const auto& b : Arr(At(d, "bodies"))) {
      std::vector<int> idx;
      for (const auto& i : Arr(At(b, "index")))
        if (i.is_number_integer() && i.get<int>() >= 0 && static_cast<size_t>(i.get<int>()) < n_points)
          idx.push_back(i.get<int>());
      if (!idx.empty()) bodies.push_back(idx);
    }
    // A spatial scene's motion is drawn in the isometric view of its drawing (kSpatialViews[0]).
    const bool solid = Num(At(d, "dim")).value_or(2) == 3;
    const View& view = solid ? kSpatialViews[0] : kPlanarView;
    const size_t dim = solid ? 3 : 2;
    // A frame set is usable when every frame has every point (in the drawing's dimension).
    auto usable = [&](const json& f) {
      if (!f.is_object() || Arr(At(f, "t")).size() < 2 || Arr(At(f, "t")).size() != Arr(At(f, "p")).size()) return false;
      if (Num(At(f, "dim")).value_or(2) != static_cast<double>(dim)) return false;
      for (const auto& p : Arr(At(f, "p")))
        if (Arr(p).size() != dim * n_points) return false;
      return true;
    };
    std::vector<std::string> order;
    std::map<std::string, const json*> frames;
    const json* reference = nullptr;
    std::string against;
    for (const json* r : RecordsOf(r_, s.name, "run")) {
      if (!usable(At(*r, "frames"))) continue;
      const std::string m = Str(*r, "method");
      if (!frames.count(m)) order.push_back(m);
      frames[m] = &At(*r, "frames");
      // The reference most runs were judged against (the analytic method's own run is judged
      // against numeric's motion).
      if (usable(At(*r, "reference_frames")) && (!reference || Str(*r, "reference_against") != "numeric")) {
        reference = &At(*r, "reference_frames");
        against = Str(*r, "reference_against");
      }
    }
    if (!reference || bodies.empty()) return;
    order = OrderMethods(r_, order);
    const auto& times = Arr(At(*reference, "t"));
    const size_t n_frames = times.size();
    o_ << "<h3>Motion</h3>\n";

    std::vector<std::string> groups[2];
    for (const auto& m : order) groups[IsTuned(m) ? 1 : 0].push_back(m);
    // One extent for both figures: every point of every frame drawn.
    double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
    std::set<int> drawn;  // the points on some body: what the figure shows
    for (const auto& idx : bodies) drawn.insert(idx.begin(), idx.end());
    auto extend = [&](const json& f) {
      for (const auto& p : Arr(At(f, "p")))
        for (const int i : drawn) {
          const auto xy = view.Project(Arr(p), dim * static_cast<size_t>(i));
          if (!xy) continue;
          const auto [x, y] = *xy;
          xmin = std::min(xmin, x), xmax = std::max(xmax, x), ymin = std::min(ymin, y), ymax = std::max(ymax, y);
        }
    };
    extend(*reference);
    for (const auto& [m, f] : frames) extend(*f);
    if (!(xmax >= xmin) || !(ymax >= ymin)) return;
    // A method far off the reference (a run that diverged) should not shrink the mechanism to a dot:
    // the view is the reference's, widened by at most its own size.
    double rx0 = INFINITY, rx1 = -INFINITY, ry0 = INFINITY, ry1 = -INFINITY;
    std::swap(rx0, xmin), std::swap(rx1, xmax), std::swap(ry0, ymin), std::swap(ry1, ymax);
    extend(*reference);
    std::swap(rx0, xmin), std::swap(rx1, xmax), std::swap(ry0, ymin), std::swap(ry1, ymax);
    const double rspan = std::max({rx1 - rx0, ry1 - ry0, 1e-12});
    xmin = std::max(xmin, rx0 - rspan), xmax = std::min(xmax, rx1 + rspan);
    ymin = std::max(ymin, ry0 - rspan), ymax = std::min(ymax, ry1 + rspan);
    const double span = std::max({xmax - xmin, ymax - ymin, 1e-12});
    const double pad = 0.1 * span;
    const double x0 = xmin - pad, x1 = xmax + pad, y0 = ymin - pad, y1 = ymax + 1.6 * pad;

    const double t_first = Num(times.front()).value_or(0), t_last = Num(times.back()).value_or(0);
    const double cycle = 6.0;  // [s] of playback for the whole motion
    for (int g = 0; g < 2; ++g) {
      const auto& methods = groups[g];
      if (methods.empty()) continue;
      std::ostringstream data, plot;
      std::vector<std::string> items;
      auto polylines = [&](std::ostringstream& block, const json& p, const char* colour) {
        for (const auto& idx : bodies) {
          for (int i : idx) {
            const auto xy = view.Project(Arr(p), dim * static_cast<size_t>(i));
            if (!xy) continue;
            block << Fmt("g10", xy->first) << " " << Fmt("g10", xy->second) << (colour ? std::string(" ") + colour : "") << "\n";
          }
          block << "\n";
        }
      };
      int block = 0;
      for (size_t k = 0; k < n_frames; ++k) {
        const auto tk = Num(times[k]);
        // The reference at frame k.
        std::ostringstream ref;
        polylines(ref, Arr(At(*reference, "p"))[k], nullptr);
        data << "# reference, t = " << Fmt("g10", tk.value_or(0)) << "\n" << ref.str() << "\n\n";
        items.push_back("datafile index " + std::to_string(block++) + " using 1:2 with lines lw 7 lc rgb '#c8ccd2' notitle");
        // Every method's mechanism at the same time, each in its colour.
        std::ostringstream meth;
        int lines = 0;
        for (size_t i = 0; i < methods.size(); ++i) {
          const json& f = *frames[methods[i]];
          const auto& ft = Arr(At(f, "t"));
          for (size_t j = 0; j < ft.size(); ++j)
            if (tk && Num(ft[j]) && std::fabs(*Num(ft[j]) - *tk) <= 1e-9 * std::max(1.0, std::fabs(*tk))) {
              const std::string c = std::to_string(std::stoul(std::string(Colour(i)).substr(1), nullptr, 16));
              polylines(meth, Arr(At(f, "p"))[j], c.c_str());
              ++lines;
              break;
            }
        }
        if (!lines) meth << Fmt("full", x0) << " " << Fmt("full", y0) << " 0\n\n";  // an empty frame keeps its place
        data << "# methods\n" << meth.str() << "\n\n";
        items.push_back("datafile index " + std::to_string(block++) +
                        (lines ? " using 1:2:3 with lines lw 1.8 lc rgb variable notitle"
                               : " using 1:2 with dots lc rgb '#ffffff' notitle"));
        data << "# time\n" << Fmt("full", x0 + 0.02 * (x1 - x0)) << " " << Fmt("full", y1 - 0.04 * (y1 - y0)) << " "
             << GpDataStr("t = " + FrameTime(tk.value_or(0)) + " s") << "\n\n\n";
        items.push_back("datafile index " + std::to_string(block++) + " using 1:2:3 with labels left font ',10' notitle");
      }
      // The grey mechanism is the reference: "reference (analytic)" when it is a method's motion,
      // so that the method's name is not in the key twice.
      const std::string ref_title = against.empty()                      ? std::string("reference")
                                    : against.rfind("reference", 0) == 0 ? against
                                                                         : "reference (" + against + ")";
      items.push_back("keyentry with lines lw 7 lc rgb '#c8ccd2' title " + GpStr(ref_title) + " noenhanced");
      for (size_t i = 0; i < methods.size(); ++i)
        items.push_back(std::string("keyentry with lines lw 1.8 lc rgb '") + Colour(i) + "' title " + GpStr(methods[i]) +
                        " noenhanced");
      const std::string unit = Str(d, "unit");
      const std::string which = !groups[0].empty() && !groups[1].empty() ? (g ? " · tuned variants" : " · default settings") : "";
      plot << "set size ratio -1\n"
           << "set xrange [" << Fmt("full", x0) << ":" << Fmt("full", x1) << "]\n"
           << "set yrange [" << Fmt("full", y0) << ":" << Fmt("full", y1) << "]\n"
           << view.Axes(unit) << view.Triad(x0 + 0.5 * pad, y0 + 0.5 * pad, 0.4 * pad)
           << "set key below horizontal Left reverse noenhanced samplen 2 width -2\n"
           << "set title " << GpStr("Motion · " + s.name + which) << " noenhanced\n"
           << "plot ";
      for (size_t i = 0; i < items.size(); ++i) plot << (i ? ", \\\n     " : "") << items[i];
      plot << "\n";
      const int width = 560;
      const double aspect = (y1 - y0) / (x1 - x0);
      const size_t key_rows = (methods.size() + 3) / 3;
      const int height = static_cast<int>(std::clamp((width - 90) * aspect + 110 + 16.0 * key_rows, 240.0, 620.0));
      const std::string caption =
          "The motion from t = " + Html(Fmt("g6", t_first)) + " s to " + Html(Fmt("g6", t_last)) + " s in " +
          std::to_string(n_frames) + " frames, played over " + Fmt("g3", cycle) +
          " s (hover to pause)" + view.caption + ": the motion each method was judged against (<code>" +
          Html(against) +
          "</code>, wide grey) and each method's mechanism, bodies as lines through their points. A method that "
          "stopped early is drawn up to where it stopped.";
      const std::string prefix = EmitFigure({g && !groups[0].empty() ? "motion-tuned" : "motion", s.name, width, height},
                                            "Motion of " + s.name + which, caption, data.str(), plot.str());
      if (prefix.empty()) continue;
      // Frame k's three items are plots 3k+1 … 3k+3; each is visible for its 1/n of the cycle.
      const double dt = cycle / static_cast<double>(n_frames);
      for (size_t k = 0; k < n_frames; ++k)
        for (int item = 1; item <= 3; ++item) {
          const std::string id = prefix + "gnuplot_plot_" + std::to_string(3 * k + item);
          anim_css_ << "[id=\"" << id << "\"] { animation: mb-frames-" << n_frames << " " << Fmt("g6", cycle) << "s step-end "
                    << Fmt("g6", dt * static_cast<double>(k)) << "s infinite;" << (k ? " visibility: hidden;" : "")
                    << " }\n";
        }
      anim_frames_.insert(n_frames);
    }
  }

  void CheckTable(const std::string& scenario) {
    const auto checks = RecordsOf(r_, scenario, "check");
    o_ << "<h3>Book values</h3>\n";
    std::vector<const json*> rows;
    std::vector<std::string> seen;
    for (const json* c : checks)
      for (const auto& row : Arr(At(*c, "rows"))) {
        rows.push_back(&row);
        if (At(row, "computed").is_object())
          for (const auto& [m, v] : At(row, "computed").items())
            if (std::find(seen.begin(), seen.end(), m) == seen.end()) seen.push_back(m);
      }
    if (rows.empty()) {
      o_ << "<p class=\"note\">No book values for this scenario.</p>\n";
      return;
    }
    const auto methods = OrderMethods(r_, seen);
    // Claims at a time of the motion (a published solution's values at t): when, and the
    // uncertainty each is judged within (half its last digit, its stated precision or the
    // reference's own agreement, whichever is largest).
    const bool timed = std::any_of(rows.begin(), rows.end(), [](const json* row) { return Num(At(*row, "at")).has_value(); });
    o_ << "<table><tr><th>quantity</th><th>where</th>" << (timed ? "<th>at t</th>" : "") << "<th>unit</th><th>printed</th>"
       << (timed ? "<th title=\"judged within ± this\">allowed</th>" : "");
    for (const auto& m : methods) o_ << "<th><code>" << Html(m) << "</code></th>";
    o_ << "<th>verdict</th><th>note</th></tr>\n";
    for (const json* row : rows) {
      const std::string verdict = Str(*row, "verdict");
      const bool agree = !At(*row, "methods_agree").is_boolean() || At(*row, "methods_agree").get<bool>();
      o_ << "<tr><td><code>" << Html(Str(*row, "quantity")) << "</code></td><td>" << Html(Str(*row, "where")) << "</td>";
      if (timed) {
        const auto at = Num(At(*row, "at"));
        o_ << "<td class=\"num\">" << (at ? Html(Fmt("g6", *at) + " s") : kDash) << "</td>";
      }
      o_ << "<td>" << Html(Str(*row, "unit")) << "</td><td class=\"num\">" << Html(Str(*row, "printed")) << "</td>";
      if (timed) {
        const auto allowed = Num(At(*row, "allowed"));
        o_ << "<td class=\"num\">" << (allowed ? Html("± " + Fmt("g2", *allowed)) : kDash) << "</td>";
      }
      for (const auto& m : methods) {
        const json& v = At(At(*row, "computed"), m.c_str());
        o_ << "<td class=\"num\">" << (Num(v) ? Html(Fmt("g10", *Num(v))) : kDash) << "</td>";
      }
      o_ << "<td class=\"st " << VerdictClass(verdict) << "\">" << Html(verdict)
         << (agree ? "" : "<br><small>methods disagree</small>") << "</td><td class=\"wrap\">"
         << Html(Str(*row, "note")) << (Str(*row, "reason").empty() ? "" : Str(*row, "note").empty() ? "" : "<br>")
         << Html(Str(*row, "reason")) << "</td></tr>\n";
    }
    o_ << "</table>\n";
  }

  void RunTable(const std::string& scenario) {
    const auto runs = RecordsOf(r_, scenario, "run");
    o_ << "<h3>Runs</h3>\n";
    if (runs.empty()) {
      o_ << "<p class=\"note\">No runs for this scenario.</p>\n";
      return;
    }
    std::string against;
    for (const json* r : runs)
      if (!Str(At(*r, "error"), "against").empty()) against = Str(At(*r, "error"), "against");
    o_ << "<table><tr><th>method</th><th>status</th><th title=\"building the method's model and start state\">set-up</th>"
       << "<th title=\"the method's own work over the motion\">integration</th><th title=\"reading samples back\">observation</th>"
       << "<th>steps</th><th>µs / step</th><th>error q max</th><th>error q̇ max</th>"
       << "<th>error q̈ max</th><th>max ‖Φ‖</th><th>within tolerance</th><th>reason</th></tr>\n";
    for (const json* r : runs) {
      const std::string status = Str(*r, "status");
      const json& err = At(*r, "error");
      const bool has_within = At(*r, "within").is_boolean();
      const bool within = has_within && At(*r, "within").get<bool>();
      const std::string known = Str(*r, "known");
      const bool judged = has_within && status != "not-applicable";
      const std::string entry = Str(*r, "known_entry").empty() ? "" : " (" + Str(*r, "known_entry") + ")";
      std::string within_text = !judged ? kDash : within ? "yes" : known.empty() ? "no" : "no — known" + entry + ": " + known;
      if (judged && within && !Str(*r, "known_stale").empty())
        within_text = "yes — known failure no longer fails: remove the entry" + entry;
      // Never a bare "yes" beside a figure without a bound, nor for a run compared with nothing.
      if (judged && At(*r, "compared").is_boolean() && !At(*r, "compared").get<bool>())
        within_text = "not judged: nothing to compare against";
      else if (judged && within && At(*r, "not_judged").is_array()) {
        within_text = "yes where bounded; not judged (no bound):";
        for (const auto& n : Arr(At(*r, "not_judged"))) within_text += " " + Str(n) + ";";
        within_text.pop_back();
      }
      std::string within_cls = !has_within || status != "ok" ? "" : within ? "ok" : known.empty() ? "bad" : "warn";
      std::string why = Str(*r, "reason");
      if (!Str(err, "against").empty() && Str(err, "against") != against)
        why += (why.empty() ? "" : "; ") + std::string("error against ") + Str(err, "against");
      o_ << "<tr><td><code>" << Html(Str(*r, "method")) << "</code></td><td class=\"st " << StatusClass(status) << "\">"
         << Html(status) << "</td>" << CpuCells(*r) << "<td class=\"num\">" << FmtErr(Num(At(err, "q_max")))
         << "</td><td class=\"num\">"
         << FmtErr(Num(At(err, "qd_max"))) << "</td><td class=\"num\">" << FmtErr(Num(At(err, "qdd_max")))
         << "</td><td class=\"num\">" << FmtErr(Num(At(*r, "max_residual"))) << "</td><td" << Cls(within_cls)
         << " style=\"max-width:300px\">" << Html(within_text) << "</td><td class=\"wrap\">" << Html(why)
         << "</td></tr>\n";
    }
    o_ << "</table>\n";
    if (!against.empty())
      o_ << "<p class=\"meta\">Errors are relative to the motion's scale, against <code>" << Html(against)
         << "</code>; ‖Φ‖ is the scaled constraint residual.</p>\n";
  }

  struct Rung {
    double value, err, cpu, lo, hi;
  };

  // Colours stay with a method from scene to scene: its place among the methods of its group
  // (default settings, or tuned) over the whole report.
  size_t StyleIndex(const std::string& method) {
    if (style_.empty()) {
      std::vector<std::string> seen;
      for (const auto& r : Arr(At(r_, "records")))
        if (Str(r, "kind") == "sweep" && std::find(seen.begin(), seen.end(), Str(r, "method")) == seen.end())
          seen.push_back(Str(r, "method"));
      size_t next[2] = {0, 0};
      for (const auto& m : OrderMethods(r_, seen)) style_[m] = next[IsTuned(m) ? 1 : 0]++;
    }
    auto it = style_.find(method);
    return it == style_.end() ? 0 : it->second;
  }

  void WorkPrecision(const ScenarioRef& s) {
    const auto sweeps = RecordsOf(r_, s.name, "sweep");
    o_ << "<h3>Work–precision</h3>\n";
    if (sweeps.empty()) {
      o_ << "<p class=\"note\">No work–precision sweeps for this scenario, so no plot.</p>\n";
      return;
    }
    std::vector<std::string> order;
    std::map<std::string, std::vector<Rung>> rungs;
    std::map<std::string, std::map<std::string, int>> skipped;
    for (const json* r : sweeps) {
      const std::string m = Str(*r, "method");
      if (std::find(order.begin(), order.end(), m) == order.end()) order.push_back(m);
      const auto err = Num(At(At(*r, "error"), "q_max"));
      // Integration time; a record from before the phases were measured has its whole run only.
      const bool phases = At(*r, "cpu").is_object();
      const auto cpu = phases ? Num(At(At(*r, "cpu"), "integration")) : Num(At(*r, "cpu_seconds"));
      const std::string status = Str(*r, "status");
      if (status != "ok" || !err || *err <= 0 || !cpu || *cpu <= 0) {
        ++skipped[m][status != "ok" ? status : "no finite error"];
        continue;
      }
      const double lo = Num(phases ? At(At(*r, "cpu"), "integration_min") : At(*r, "cpu_min")).value_or(*cpu);
      const double hi = Num(phases ? At(At(*r, "cpu"), "integration_max") : At(*r, "cpu_max")).value_or(*cpu);
      rungs[m].push_back({Num(At(*r, "value")).value_or(0), *err, *cpu, lo > 0 ? std::min(lo, *cpu) : *cpu,
                          std::max(hi, *cpu)});
    }
    order = OrderMethods(r_, order);
    // Two groups, each its own plot when both are there: default settings (and the formulations,
    // which have no other), and the engines' tuned variants.
    std::vector<std::string> groups[2];
    for (const auto& m : order)
      if (!rungs[m].empty()) groups[IsTuned(m) ? 1 : 0].push_back(m);
    std::string skipped_text[2];
    for (const auto& m : order) {
      if (!skipped.count(m)) continue;
      std::string parts;
      for (const auto& [why, n] : skipped[m]) parts += (parts.empty() ? "" : ", ") + std::to_string(n) + " " + why;
      std::string& text = skipped_text[IsTuned(m) ? 1 : 0];
      text += (text.empty() ? "" : "; ") + m + ": " + parts;
    }
    if (groups[0].empty() && groups[1].empty()) {
      const std::string both = skipped_text[0] + (skipped_text[0].empty() || skipped_text[1].empty() ? "" : "; ") +
                               skipped_text[1];
      o_ << "<p class=\"note\">No plot: no sweep rung finished ok with a finite error (" << Html(both) << ").</p>\n";
      return;
    }
    const bool split = !groups[0].empty() && !groups[1].empty();
    // Both plots on the same axes, so a tuned line and its default compare by eye.
    double e0 = INFINITY, e1 = 0, c0 = INFINITY, c1 = 0;
    for (const auto& [m, v] : rungs)
      for (const Rung& g : v) e0 = std::min(e0, g.err), e1 = std::max(e1, g.err), c0 = std::min(c0, g.lo), c1 = std::max(c1, g.hi);
    auto padded = [](double a, double b) {  // an eighth of a decade beyond the data, at least one decade
      const double lo = std::log10(a) - 0.125, hi = std::max(std::log10(b) + 0.125, lo + 1);
      return "[" + Fmt("g6", std::pow(10.0, lo)) + ":" + Fmt("g6", std::pow(10.0, hi)) + "]";
    };
    const std::string ranges = split ? "set xrange " + padded(e0, e1) + "\nset yrange " + padded(c0, c1) + "\n" : "";

    // The picker: a checkbox per method, before the plots (a checkbox hides a line by a CSS rule
    // on the later siblings); "show all" resets the form. No script.
    const std::string pick = "pick" + std::to_string(++pickers_);
    o_ << "<form class=\"pick\" autocomplete=\"off\" aria-label=\"methods shown in the work–precision plot"
       << (split ? "s" : "") << "\">\n";
    std::map<std::string, std::string> box;
    for (int g = 0; g < 2; ++g) {
      if (groups[g].empty()) continue;
      o_ << (g && split ? "<br>" : "") << "<span class=\"grp\">" << (g ? "tuned" : "defaults") << "</span>";
      for (const auto& m : groups[g]) {
        const std::string id = pick + "-" + std::to_string(box.size());
        box[m] = id;
        o_ << "<input type=\"checkbox\" id=\"" << id << "\" checked><label for=\"" << id << "\"><span class=\"sw\" "
           << "style=\"" << Swatch(StyleIndex(m)) << "\"></span>" << Html(m) << "</label>\n";
      }
    }
    o_ << "<button type=\"reset\">show all</button>\n<div class=\"wp\">\n";
    for (int g = 0; g < 2; ++g) {
      const auto& methods = groups[g];
      if (methods.empty()) continue;
      std::ostringstream data, plot;
      std::vector<std::string> items;
      for (const auto& m : methods) {
        auto& v = rungs[m];
        std::stable_sort(v.begin(), v.end(), [](const Rung& a, const Rung& b) { return a.value > b.value; });
        data << "# " << GpDataStr(m) << ": q_max cpu cpu_min cpu_max value\n";
        for (const auto& r : v)
          data << Fmt("full", r.err) << " " << Fmt("full", r.cpu) << " " << Fmt("full", r.lo) << " "
               << Fmt("full", r.hi) << " " << Fmt("full", r.value) << "\n";
        data << "\n\n";
        items.push_back("datafile index " + std::to_string(items.size()) + " using 1:2:3:4 with yerrorlines lw 1.6 " +
                        LineStyle(StyleIndex(m)) + " ps 0.6 title " + GpStr(m) + " noenhanced");
      }
      const std::string which = !split ? "" : g ? " · tuned variants" : " · default settings";
      plot << "set title " << GpStr("Work–precision · " + s.name + which) << " noenhanced\n"
           << "set xlabel 'error in q, max over the run (relative)'\n"
           << "set ylabel 'integration CPU [s] (median; bars min–max)'\n"
           << "set logscale xy 10\n"
           << ranges
           << "set format x '10^{%L}'\nset format y '10^{%L}'\n"
           << "set grid xtics ytics lc rgb '#dddddd'\n"
           // A few methods: the key inside, top right (where a work–precision plot has no data); more:
           // beside the plot.
           << (items.size() <= 4 ? "set key top right box opaque noenhanced samplen 2\n"
               : split           ? "set key below Left reverse noenhanced samplen 2 width -2 height 1\n"
                                 : "set key outside right top Left reverse noenhanced samplen 2\n")
           << "set bars small\n"
           << "plot ";
      for (size_t i = 0; i < items.size(); ++i) plot << (i ? ", \\\n     " : "") << items[i];
      plot << "\n";
      std::string caption = std::string(split ? (g ? "The engines' tuned variants. " :
                                                     "The formulations and the engines at their default settings. ")
                                              : "") +
                            "One line per method through its sweep rungs; only rungs that finished ok with a finite "
                            "error. Time is the method's own integration (set-up and observation apart: see the runs "
                            "table).";
      if (split) caption += " Same axes as the plot beside.";
      if (!skipped_text[g].empty()) caption += " Not plotted: " + skipped_text[g] + ".";
      // Side by side, each with its key below (the key's rows: about three names to a row).
      const int width = split ? 620 : items.size() <= 4 ? 640 : 800;
      const size_t key_rows = split && methods.size() > 4 ? (methods.size() + 2) / 3 : 0;
      const int height = 420 + static_cast<int>(key_rows) * 16;
      const std::string prefix = EmitFigure({g && split ? "work-precision-tuned" : "work-precision", s.name, width, height},
                                            "Work–precision of " + s.name + which, Html(caption), data.str(), plot.str());
      // gnuplot's n-th plot is <g id="PREFIX-gnuplot_plot_n">; its error bars repeat the id ("…-2").
      if (!prefix.empty())
        for (size_t i = 0; i < methods.size(); ++i) {
          const std::string sel = "#" + box[methods[i]] + ":not(:checked) ~ .wp ";
          const std::string id = prefix + "gnuplot_plot_" + std::to_string(i + 1);
          pick_css_ << sel << "[id=\"" << id << "\"], " << sel << "[id^=\"" << id << "-\"] { display: none; }\n";
        }
    }
    o_ << "</div>\n</form>\n";
  }

  void DerivedTable(const std::string& scenario) {
    std::vector<const json*> rows;
    for (const auto& d : Arr(At(r_, "derived")))
      if (Str(d, "scenario") == scenario) rows.push_back(&d);
    if (rows.empty()) return;
    o_ << "<table><tr><th>method</th><th>integration CPU to q error 1e-3</th><th>its set-up</th><th>to 1e-6</th>"
       << "<th>its set-up</th><th>observed order (fixed step) / error slope against the tolerance</th><th>largest stable step</th></tr>\n";
    for (const json* d : rows) {
      o_ << "<tr><td><code>" << Html(Str(*d, "method")) << "</code></td><td class=\"num\">"
         << Html(FmtLevelCpu(*d, "1e-3")) << "</td><td class=\"num\">"
         << Html(FmtSeconds(Num(At(*d, "setup_at_1e-3")))) << "</td><td class=\"num\">"
         << Html(FmtLevelCpu(*d, "1e-6")) << "</td><td class=\"num\">"
         << Html(FmtSeconds(Num(At(*d, "setup_at_1e-6")))) << "</td><td class=\"num\">"
         << Html(FmtConvergence(*d)) << "</td><td class=\"num\">"
         << Html(FmtSeconds(Num(At(*d, "largest_stable")))) << "</td></tr>\n";
    }
    o_ << "</table>\n<p class=\"meta\">— : not reached or not measured. CPU time is the integration time (the "
       << "method's own work, median over the repeats) of the cheapest rung whose q error is within the target, with "
       << "that rung's set-up beside it; a cell marked (X's run) is X's run, shared because both methods do the same "
       << "computation (the same engine settings at that rung): one measurement shown twice, not two; the observed order is the slope of log error against log step of a fixed-step method; "
       << "an error-controlled method (DOPRI5, Simbody's integrators …) chooses its own steps, so what its rungs vary is "
       << "the tolerance, and its cell gives the slope of log error against log tolerance instead (near 0: the error does "
       << "not follow the tolerance, e.g. when the output samples bound the step).</p>\n";
  }

  void Stability(const std::string& scenario) {
    const auto stress = RecordsOf(r_, scenario, "stress");
    const auto steps = RecordsOf(r_, scenario, "stable_step");
    o_ << "<h3>Stability</h3>\n";
    if (stress.empty() && steps.empty()) {
      o_ << "<p class=\"note\">No stress cases for this scenario.</p>\n";
      return;
    }
    if (!stress.empty()) {
      o_ << "<table><tr><th>case</th><th>family</th><th>method</th><th>outcome</th><th>detail</th><th>t fail</th>"
         << "<th>error q max</th><th>max ‖Φ‖</th><th>CPU</th></tr>\n";
      for (const json* r : stress) {
        const std::string outcome = Str(*r, "outcome");
        auto t = Num(At(*r, "t_fail"));
        o_ << "<tr><td title=\"" << Html(Str(*r, "description")) << "\"><code>" << Html(Str(*r, "case"))
           << "</code></td><td>" << Html(Str(*r, "family")) << "</td><td><code>" << Html(Str(*r, "method"))
           << "</code></td><td class=\"st " << OutcomeClass(outcome) << "\">" << Html(outcome) << "</td><td class=\"wrap\">"
           << Html(Str(*r, "detail")) << "</td><td class=\"num\">" << (t ? Html(Fmt("g6", *t) + " s") : kDash)
           << "</td><td class=\"num\">" << FmtErr(Num(At(At(*r, "error"), "q_max"))) << "</td><td class=\"num\">"
           << FmtErr(Num(At(*r, "max_residual"))) << "</td><td class=\"num\">"
           << Html(FmtSeconds(Num(At(*r, "cpu_seconds")))) << "</td></tr>\n";
      }
      o_ << "</table>\n";
    }
    if (!steps.empty()) {
      o_ << "<table><tr><th>method</th><th>largest stable step</th><th>first unstable step</th><th>limit</th>"
         << "<th>steps tried</th></tr>\n";
      for (const json* r : steps) {
        std::string tried;
        for (const auto& t : Arr(At(*r, "tried"))) {
          const std::string outcome = Str(t, "outcome");
          tried += std::string(tried.empty() ? "" : ", ") + "<span" + Cls(OutcomeClass(outcome)) + " title=\"" +
                   Html(Str(t, "detail")) + "\">" + Html(FmtSeconds(Num(At(t, "step")))) + " " + Html(outcome) +
                   "</span>";
        }
        auto unstable = Num(At(*r, "first_unstable"));
        o_ << "<tr><td><code>" << Html(Str(*r, "method")) << "</code></td><td class=\"num\">"
           << Html(FmtSeconds(Num(At(*r, "largest_stable")))) << "</td><td class=\"num\">"
           << (unstable ? Html(FmtSeconds(unstable)) : "none found") << "</td><td class=\"wrap\">"
           << Html(Str(*r, "limit")) << "</td><td class=\"wrap\">" << tried << "</td></tr>\n";
      }
      o_ << "</table>\n";
    }
  }

  void Settings(const std::string& scenario) {
    std::vector<std::string> methods;
    std::map<std::string, std::vector<std::pair<std::string, std::vector<std::string>>>> settings;
    std::map<std::string, std::vector<std::string>> messages;
    for (const auto& r : Arr(At(r_, "records"))) {
      const std::string kind = Str(r, "kind");
      if (Str(r, "scenario") != scenario || (kind != "run" && kind != "sweep")) continue;
      const std::string m = Str(r, "method");
      if (std::find(methods.begin(), methods.end(), m) == methods.end()) methods.push_back(m);
      auto& list = settings[m];
      if (At(r, "settings").is_object()) {
        for (const auto& item : At(r, "settings").items()) {
          const std::string k = item.key();
          const auto& v = item.value();
          auto it = std::find_if(list.begin(), list.end(), [&k](const auto& e) { return e.first == k; });
          if (it == list.end()) {
            list.push_back({k, {}});
            it = list.end() - 1;
          }
          const std::string value = Str(v);
          if (std::find(it->second.begin(), it->second.end(), value) == it->second.end()) it->second.push_back(value);
        }
      }
      for (const auto& msg : Arr(At(r, "messages"))) messages[m].push_back(Str(msg));
    }
    if (methods.empty()) return;
    o_ << "<h3>Settings</h3>\n";
    for (const auto& m : methods) {
      o_ << "<details><summary><code>" << Html(m) << "</code></summary>\n";
      if (settings[m].empty()) o_ << "<p class=\"note\">no settings recorded</p>\n";
      else {
        o_ << "<table>";
        for (const auto& [k, values] : settings[m]) {
          std::string v;
          for (size_t i = 0; i < values.size() && i < 12; ++i) v += (i ? " | " : "") + values[i];
          if (values.size() > 12) v += " | …";
          o_ << "<tr><th>" << Html(k) << "</th><td class=\"wrap\">" << Html(v)
             << (values.size() > 1 ? " <small>(varies over the sweep)</small>" : "") << "</td></tr>";
        }
        o_ << "</table>\n";
      }
      if (!messages[m].empty()) {
        o_ << "<ul>";
        for (const auto& msg : messages[m]) o_ << "<li>" << Html(msg) << "</li>";
        o_ << "</ul>\n";
      }
      o_ << "</details>\n";
    }
  }

  void Scenario(const ScenarioRef& s, const std::string& anchor) {
    std::ostringstream& o = o_;
    const std::string section = s.info ? Str(*s.info, "section") : "";
    const std::string title = s.info ? Str(*s.info, "title") : "";
    o << "<section id=\"" << anchor << "\">\n<h2>" << (section.empty() ? "" : Html(section) + " · ") << "<code>"
      << Html(s.name) << "</code>" << (title.empty() ? "" : " — " + Html(title)) << "</h2>\n";
    if (s.info) {
      const std::string kind = Str(*s.info, "kind");
      const bool free = At(*s.info, "free").is_boolean() && At(*s.info, "free").get<bool>();
      o << "<p class=\"meta\">" << Html(kind == "gear_train" ? "gear train" : kind) << " · "
        << (free ? "free (forward dynamics)" : "driven") << " · <code>" << Html(Str(*s.info, "file"))
        << "</code></p>\n";
    } else {
      o << "<p class=\"note\">This scenario is not in the results' scenario list.</p>\n";
    }
    Drawing(s);
    // A published benchmark in a report comes for its book checks and precision levels alone.
    if (RecordsOf(r_, s.name, "run").empty() && RecordsOf(r_, s.name, "sweep").empty() &&
        RecordsOf(r_, s.name, "stress").empty()) {
      CheckTable(s.name);
      o << "<p class=\"note\">No runs of this scene in the report";
      if (!RecordsOf(r_, s.name, "precision").empty())
        o << " (a published benchmark: its precision levels are in <a href=\"#benchmarks\">the benchmarks' table</a>)";
      o << "; <code>mechbench run " << Html(s.info ? Str(*s.info, "file") : s.name)
        << "</code> runs it against its reference.</p>\n</section>\n";
      return;
    }
    Motion(s);
    CheckTable(s.name);
    RunTable(s.name);
    WorkPrecision(s);
    DerivedTable(s.name);
    Stability(s.name);
    Settings(s.name);
    o << "</section>\n";
  }

  const json& r_;
  Gnuplot& gp_;
  std::ostringstream o_;
  std::vector<std::string> anchors_;
  int plots_ = 0;
  std::ostringstream pick_css_;  // rules of the method pickers, into the head
  std::ostringstream anim_css_;  // the motion figures' frame rules, into the head
  std::set<size_t> anim_frames_;  // the frame counts that need a keyframes rule
  int pickers_ = 0;
  std::map<std::string, size_t> style_;  // method -> its line style (StyleIndex)
};

}  // namespace

HtmlPage RenderHtml(const json& results, Gnuplot& gp) {
  HtmlWriter html(results, gp);
  HtmlPage page;
  page.text = html.Render();
  page.plots = html.plots();
  return page;
}

}  // namespace mechbench::harness::report
