#include "summary_html.h"

#include "gnuplot.h"
#include "text.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

namespace mechbench::harness::report {

namespace {

// Filled point types for the scenes; gnuplot's open variant of each is one less.
constexpr int kFilled[] = {7, 5, 9, 11, 13, 15};
int FilledPoint(size_t j) { return kFilled[j % 6]; }
int OpenPoint(size_t j) { return kFilled[j % 6] - 1; }

std::string Px(double v) { return Fmt("g6", v); }

// The median CPU, or "never" over the best error on a second line.
std::string NeverOrMedian(const MethodReach& m, int level) {
  if (m.reached(level)) return Html(MedianCpuText(m, level));
  const auto best = BestError(m);
  if (!best && m.not_judged()) return "not judged<br><small>" + Html(NotJudgedNote(m)) + "</small>";
  return "never<br><small>" + std::string(best ? "best q error " + Html(FmtErr(best)) : "no rung finished") +
         "</small>";
}

}  // namespace

PlotSpec ReachFigure(const Reach& reach) {
  PlotSpec spec;
  std::vector<const MethodReach*> rows;
  for (const MethodReach& m : reach.methods)
    if (!m.scenes.empty()) rows.push_back(&m);
  if (rows.empty()) return spec;
  const size_t n = rows.size(), scenes = reach.scenes.size();
  auto row_y = [n](size_t i) { return static_cast<double>(n - i); };
  auto scene_index = [&reach](const std::string& s) {
    return static_cast<size_t>(std::find(reach.scenes.begin(), reach.scenes.end(), s) - reach.scenes.begin());
  };
  // Markers of one row spread over its height, a fixed offset per scene, so scenes at the same
  // CPU do not hide each other.
  const double step = scenes > 1 ? std::min(0.3, 0.7 / static_cast<double>(scenes - 1)) : 0.0;
  auto offset = [&](size_t j) { return (static_cast<double>(j) - 0.5 * static_cast<double>(scenes - 1)) * step; };

  // The CPU axis: whole decades around every CPU reached, then the "not reached" band.
  double vmin = INFINITY, vmax = -INFINITY;
  for (const MethodReach* m : rows)
    for (const SceneReach& s : m->scenes)
      for (const auto& c : s.cpu)
        if (c && *c > 0) vmin = std::min(vmin, *c), vmax = std::max(vmax, *c);
  if (!std::isfinite(vmin)) vmin = 1e-4, vmax = 1e-2;
  const int d0 = static_cast<int>(std::floor(std::log10(vmin) - 0.15));  // no marker on the left border
  int d1 = static_cast<int>(std::ceil(std::log10(vmax) + 0.02));
  if (d1 <= d0) d1 = d0 + 1;
  const double lo = std::pow(10.0, d0), hi = std::pow(10.0, d1);
  const double band = hi * std::pow(10.0, 0.25), not_reached = hi * std::pow(10.0, 0.7),
               axis_end = hi * std::pow(10.0, 1.15);
  const int tic_step = d1 - d0 > 7 ? 2 : 1;
  std::string xtics;
  for (int d = d0; d <= d1; d += tic_step)
    xtics += (xtics.empty() ? "" : ", ") + GpStr(FmtSeconds(std::pow(10.0, d))) + " " + Fmt("full", std::pow(10.0, d));

  // Data: per level, per scene, the reached and the not-reached markers; then per level the
  // medians. Empty blocks are left out (gnuplot warns on them).
  std::ostringstream data;
  int index = 0;
  std::vector<std::string> items[2];
  for (int k = 0; k < 2; ++k) {
    for (size_t j = 0; j < scenes; ++j) {
      std::ostringstream reached, missed;
      for (size_t i = 0; i < n; ++i)
        for (const SceneReach& s : rows[i]->scenes) {
          if (scene_index(s.scenario) != j) continue;
          const double y = row_y(i) + offset(j);
          if (s.cpu[k]) reached << Fmt("full", std::max(*s.cpu[k], lo)) << " " << Fmt("full", y) << "\n";
          else missed << Fmt("full", not_reached) << " " << Fmt("full", y) << "\n";
        }
      const std::string colour = std::string("lc rgb '") + Colour(j) + "'";
      if (!reached.str().empty()) {
        data << "# " << GpDataStr(reach.scenes[j]) << " reached " << kLevels[k].label << "\n" << reached.str() << "\n\n";
        items[k].push_back("datafile index " + std::to_string(index++) + " using 1:2 with points pt " +
                           std::to_string(FilledPoint(j)) + " ps 0.95 " + colour + " notitle");
      }
      if (!missed.str().empty()) {
        data << "# " << GpDataStr(reach.scenes[j]) << " not reached " << kLevels[k].label << "\n" << missed.str()
             << "\n\n";
        items[k].push_back("datafile index " + std::to_string(index++) + " using 1:2 with points pt " +
                           std::to_string(OpenPoint(j)) + " ps 0.95 lw 1.3 " + colour + " notitle");
      }
    }
    std::ostringstream medians;
    for (size_t i = 0; i < n; ++i)
      if (auto m = rows[i]->median_cpu(k))
        medians << Fmt("full", std::max(*m, lo)) << " " << Fmt("full", row_y(i) - 0.4) << "\n";
    if (!medians.str().empty()) {
      data << "# medians " << kLevels[k].label << "\n" << medians.str() << "\n\n";
      items[k].push_back("datafile index " + std::to_string(index++) +
                         " using 1:2:(0):(0.8) with vectors nohead lw 2.5 lc rgb '#222222' notitle");
    }
  }
  // The key, once, below both panels: a sample per scene, the open marker, the median bar.
  std::vector<std::string> key;
  for (size_t j = 0; j < scenes; ++j)
    key.push_back("1/0 with points pt " + std::to_string(FilledPoint(j)) + " ps 0.95 lc rgb '" + Colour(j) +
                  "' title " + GpStr(reach.scenes[j]));
  key.push_back("1/0 with points pt 6 ps 0.95 lw 1.3 lc rgb '#555555' title 'open: swept there, not reached'");
  key.push_back("1/0 with lines lw 2.5 lc rgb '#222222' title 'median of the scenes reached'");

  // Geometry in pixels: method names on the left, two panels, the key under them.
  size_t longest = 0;
  for (const MethodReach* m : rows) longest = std::max(longest, m->method.size());
  const double width = 660, left = std::clamp(24.0 + 6.4 * static_cast<double>(longest), 110.0, 250.0);
  // Rows grow with the scenes, so more markers per row stay apart.
  const double gap = 16, right = 12, top = 40, row_px = std::clamp(8 + 4.5 * static_cast<double>(scenes), 24.0, 40.0);
  // The key's columns: as many as fit the width at its longest title (about 5.5 px a character
  // at 9 pt, the sample and the gap beside).
  size_t longest_title = 30;
  for (const auto& s : reach.scenes) longest_title = std::max(longest_title, s.size());
  const int key_cols = static_cast<int>(std::clamp((width - 24) / (5.5 * static_cast<double>(longest_title) + 44), 1.0, 4.0));
  const int key_rows = static_cast<int>((key.size() + static_cast<size_t>(key_cols) - 1) / static_cast<size_t>(key_cols));
  const double bottom = 62 + 16 * key_rows + 14;
  const double height = top + row_px * static_cast<double>(n) + 8 + bottom;
  const double panel = (width - left - gap - right) / 2;
  auto sx = [width](double px) { return Px(px / width); };
  auto sy = [height](double px_from_top) { return Px(1.0 - px_from_top / height); };

  std::ostringstream gp;
  gp << "set multiplot\n"
     << "set logscale x 10\n"
     << "set xrange [" << Fmt("full", lo) << ":" << Fmt("full", axis_end) << "]\n"
     << "set yrange [0.4:" << Fmt("full", static_cast<double>(n) + 0.6) << "]\n"
     << "set xtics (" << xtics << ") nomirror noenhanced font ',9'\n"
     << "set grid xtics ytics lc rgb '#e4e4e4' lw 1\n"
     << "set object 1 rect from first " << Fmt("full", band) << ", graph 0 to graph 1, graph 1 behind fc rgb '#eeeeee' "
     << "fs solid 1.0 noborder\n"
     << "set label 1 'not reached' at first " << Fmt("full", not_reached) << ", graph 1 center offset 0,0.7 "
     << "font ',8' tc rgb '#555555'\n"
     << "set xlabel 'integration CPU (cheapest rung within the level)' font ',9'\n"
     << "set tmargin at screen " << sy(top) << "\nset bmargin at screen " << sy(top + row_px * n + 8) << "\n";
  std::string names, blanks;
  for (size_t i = 0; i < n; ++i) {
    names += (i ? ", " : "") + GpStr(rows[i]->method) + " " + Fmt("full", row_y(i));
    blanks += std::string(i ? ", " : "") + "'' " + Fmt("full", row_y(i));
  }
  for (int k = 0; k < 2; ++k) {
    const double x0 = left + k * (panel + gap);
    gp << "set lmargin at screen " << sx(x0) << "\nset rmargin at screen " << sx(x0 + panel) << "\n"
       << "set title " << GpStr(std::string("q error ≤ ") + kLevels[k].label) << " font ',11'\n"
       << "set ytics (" << (k == 0 ? names : blanks) << ") nomirror noenhanced\n";
    if (k == 0)
      gp << "set key at screen 0.5, screen " << Px(6 / height) << " center bottom vertical maxrows " << key_rows
         << " Left reverse samplen 1.5 spacing 1.05 width 1 noenhanced font ',9'\n";
    else
      gp << "unset key\n";
    std::vector<std::string> all = items[k];
    if (k == 0) all.insert(all.end(), key.begin(), key.end());
    // A panel with nothing to draw still draws its axes.
    if (all.empty()) all.push_back("1/0 notitle");
    gp << "plot ";
    for (size_t i = 0; i < all.size(); ++i) gp << (i ? ", \\\n     " : "") << all[i];
    gp << "\n";
  }
  gp << "unset multiplot\n";
  spec.data = data.str();
  spec.script = gp.str();
  spec.width = static_cast<int>(width);
  spec.height = static_cast<int>(std::lround(height));
  return spec;
}

std::string ReachTableHtml(const Reach& reach) {
  std::ostringstream o;
  o << "<table class=\"reach\"><tr><th rowspan=\"2\">method</th>";
  for (const auto& level : kLevels)
    o << "<th colspan=\"2\">q error ≤ " << level.label << "</th>";
  o << "</tr>\n<tr>";
  for (size_t k = 0; k < 2; ++k)
    o << "<th title=\"scenes it reached the level on, of the scenes it was swept on\">scenes</th>"
      << "<th title=\"median integration CPU over the scenes it reached\">median CPU</th>";
  o << "</tr>\n";
  for (const MethodReach& m : reach.methods) {
    o << "<tr><td><code>" << Html(m.method) << "</code></td>";
    if (m.scenes.empty()) {
      o << "<td colspan=\"4\" class=\"na\">not swept on any scene</td></tr>\n";
      continue;
    }
    for (int k = 0; k < 2; ++k) {
      const int r = m.reached(k);
      const bool all = r == static_cast<int>(m.scenes.size());
      std::string scenes;  // where, on hover (the figure shows it)
      for (const SceneReach& s : m.scenes)
        if (s.cpu[k]) scenes += (scenes.empty() ? "reached on " : ", ") + s.scenario;
      o << "<td class=\"num" << (r == 0 ? " bad" : all ? " ok" : "") << "\""
        << (scenes.empty() ? "" : " title=\"" + Html(scenes) + "\"") << ">" << Html(ReachedOf(m, k)) << "</td>"
        << "<td class=\"" << (r ? "num" : "never") << "\">" << NeverOrMedian(m, k) << "</td>";
    }
    o << "</tr>\n";
  }
  o << "</table>\n";
  return o.str();
}

}  // namespace mechbench::harness::report
