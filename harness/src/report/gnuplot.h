// gnuplot as a child process: a data file and a script in a private temporary folder, an SVG out.
// It runs with -d (--default-settings), so a ~/.gnuplot of whoever renders cannot change the plots.
#pragma once

#include <cstddef>
#include <filesystem>
#include <memory>
#include <string>

namespace mechbench::harness::report {

// Gives every id in a gnuplot SVG (gnuplot_canvas, gpPt0, textbox, …) and every reference to it
// (href="#…", url(#…)) the prefix, so several SVGs can live in one page. gnuplot itself repeats
// some ids within one SVG (gnuplot_plot_1 for a plot's key sample and its error bars): a repeat
// gets a "-2", "-3", … suffix, and references keep pointing at the first.
std::string PrefixSvgIds(const std::string& svg, const std::string& prefix);

struct PlotResult {
  bool ok = false;
  std::string svg;        // inline-ready: no prolog, ids prefixed
  std::string id_prefix;  // the prefix given to its ids ("p3-"): gnuplot's plot N is <g id="p3-gnuplot_plot_N">
  std::string why;        // when not ok
};

// The i-th of ten distinguishable colours (Tableau 10), "#1f77b4".
const char* Colour(size_t i);
// Line style for the i-th curve: the colour, then the point shape and the dash pattern change,
// so a dozen curves stay apart.
std::string LineStyle(size_t i, bool vary_points = true);

// Finds gnuplot on PATH and asks its version; each Plot writes into a private temporary folder
// that the destructor removes.
class Gnuplot {
 public:
  Gnuplot();
  ~Gnuplot();
  Gnuplot(const Gnuplot&) = delete;
  Gnuplot& operator=(const Gnuplot&) = delete;

  bool available() const { return available_; }
  const std::string& version() const { return version_; }
  const std::string& why_missing() const { return why_; }

  // `body` refers to its data as the gnuplot variable `datafile`.
  PlotResult Plot(const std::string& name, const std::string& title, int width, int height,
                  const std::string& data, const std::string& body);

 private:
  std::string exe_, version_, why_;
  std::filesystem::path tmp_;
  std::shared_ptr<void> on_interrupt_;  // removes tmp_ if an interrupt ends the process (output.h)
  bool available_ = false;
  int count_ = 0;
};

}  // namespace mechbench::harness::report
