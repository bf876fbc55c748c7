// The value a time-integrating method runs with: its own step or tolerance (Method::control(),
// default_control()), or the RunOptions override of a work–precision sweep. Shared by the
// numeric formulations and the engine adapters, so that every one records it the same way:
//   settings["control"]        "step" | "tolerance"
//   settings["control_value"]  the plain number used (%.17g): the step h [s] after the cap below,
//                              or the relative tolerance / accuracy
// and describes it in its own settings with ControlText(), e.g.
//   "0.002 s (sweep override; default 0.001 s)".
// A fixed-step method shortens its steps evenly to land on every sample time, so a step larger
// than the sample interval becomes the sample interval: the value used is then the interval, and
// ControlText() says "capped by the sample interval".
#pragma once

#include "mechbench/format.h"
#include "mechbench/method.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <stdexcept>
#include <string>

namespace mechbench {

struct ControlValue {
  Control kind = Control::kNone;
  double value = kNaN;          // what the run uses (kStep: the largest step, after the cap)
  double requested = kNaN;      // the override, or the default when there is none
  double default_value = kNaN;  // Method::default_control()
  bool overridden = false;      // from RunOptions::step / ::tolerance
  bool capped = false;          // kStep: requested > the largest sample interval, which it became
  double interval = kNaN;       // kStep: the largest sample interval [s] (NaN without a motion)
};

// `largest_interval`: the largest time between two samples [s], NaN (or ≤ 0) for no motion.
// Throws std::invalid_argument (Method::Run reports it as a failed run) for an override that is
// not a positive finite number. The override that does not match `kind` is ignored.
inline ControlValue EffectiveControl(Control kind, double default_value, const RunOptions& options,
                                     double largest_interval = kNaN) {
  ControlValue c;
  c.kind = kind;
  c.default_value = default_value;
  if (kind == Control::kNone) return c;
  const double o = kind == Control::kStep ? options.step : options.tolerance;
  c.requested = default_value;
  if (!std::isnan(o)) {
    if (!std::isfinite(o) || o <= 0)
      throw std::invalid_argument(std::string("RunOptions::") + (kind == Control::kStep ? "step" : "tolerance") +
                                  " must be a positive number, not " + Fmt(o));
    c.requested = o;
    c.overridden = true;
  }
  c.value = c.requested;
  if (kind == Control::kStep && largest_interval > 0) {
    c.interval = largest_interval;
    // A step within round-off of the interval is the interval (Substeps allows 1e-9 of slack).
    if (c.requested > largest_interval * (1 + 1e-9)) {
      c.value = largest_interval;
      c.capped = true;
    }
  }
  return c;
}

// The largest interval between consecutive sample times (NaN for fewer than two).
template <class Times>
double LargestInterval(const Times& times) {
  double out = kNaN;
  for (size_t k = 1; k < times.size(); ++k) {
    const double dt = times[k] - times[k - 1];
    if (!(out >= dt)) out = dt;
  }
  return out;
}
inline double LargestInterval(const Analysis& a) {
  if (!a.HasMotion()) return kNaN;
  double out = 0;
  for (int k = 1; k < a.samples; ++k) out = std::max(out, a.TimeAt(k) - a.TimeAt(k - 1));
  return out;
}

// The one fixed-step schedule of every stepping method (the natural-coordinate formulations and
// the engines): from t to the next sample time t_next in n equal steps of h ≤ h_max, n =
// ⌈(t_next − t)/h_max⌉ with 1e-9 of slack, so that a step dividing the interval up to round-off
// is not one step more. Every sample is landed on exactly.
struct Substeps {
  long n = 1;      // steps
  double h = 0;    // [s] each
};
inline Substeps StepsTo(double t, double t_next, double h_max) {
  const double span = t_next - t;
  const double steps = std::ceil(span / h_max - 1e-9);
  // More steps than a count holds (an interval of 1e16 s at 1 ms) would never end: say so, rather
  // than convert out of range. Method::Run reports it as the run's failure.
  if (!(steps < 1e18))
    throw std::range_error("the interval from t = " + Fmt(t) + " to " + Fmt(t_next) + " s is " + Fmt(steps, 3) +
                           " steps of " + Fmt(h_max) + " s, more than a run can take (a shorter motion, or more samples)");
  Substeps s;
  s.n = std::max(1L, static_cast<long>(steps));
  s.h = span / static_cast<double>(s.n);
  return s;
}

inline std::string FullPrecision(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

// "0.001 s", "0.002 s (sweep override; default 0.001 s)", "0.01 s (the requested 0.05 s (sweep
// override; default 0.001 s) capped by the sample interval 0.01 s)". `unit` is " s" or "".
inline std::string ControlText(const ControlValue& c, const std::string& unit) {
  const std::string origin =
      c.overridden ? "sweep override; default " + Fmt(c.default_value) + unit : "";
  if (c.capped)
    return Fmt(c.value) + unit + " (the requested " + Fmt(c.requested) + unit + (c.overridden ? " (" + origin + ")" : "") +
           " capped by the sample interval " + Fmt(c.interval) + unit + ")";
  return Fmt(c.value) + unit + (c.overridden ? " (" + origin + ")" : "");
}

// settings["control"] and settings["control_value"]; nothing for Control::kNone.
inline void RecordControl(const ControlValue& c, std::map<std::string, std::string>& settings) {
  if (c.kind == Control::kNone) return;
  settings["control"] = ToString(c.kind);
  settings["control_value"] = FullPrecision(c.value);
}

}  // namespace mechbench
