// The opening of report.html: work–precision across the scenes, as one figure (gnuplot data and
// script) and the table beside it, both from reach.h.
#pragma once

#include "reach.h"

#include <string>

namespace mechbench::harness::report {

struct PlotSpec {
  std::string data, script;  // the script reads its data as `datafile` (Gnuplot::Plot)
  int width = 0, height = 0;
};

// A dot plot: a row per swept method, a panel per level (1e-3, 1e-6); on each row a marker per
// scene at the integration CPU that reached the level (log axis), an open marker in the panel's
// "not reached" band where the method was swept on the scene but never got there, and a bar at
// the median over the scenes reached. Methods never swept have no row (the table lists them).
// Empty `script` when no method was swept.
PlotSpec ReachFigure(const Reach& reach);

// Per method: on how many of the scenes it was swept on it reached each level, and the median
// integration CPU over those (or "never" with its best error).
std::string ReachTableHtml(const Reach& reach);

}  // namespace mechbench::harness::report
