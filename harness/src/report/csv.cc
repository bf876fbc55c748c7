// results.csv
#include "writers.h"

#include "access.h"
#include "text.h"
#include "mechbench/harness/output.h"

#include <sstream>
#include <vector>

namespace mechbench::harness::report {

std::string RenderCsv(const json& results) {
  std::ostringstream o;
  o << "kind,scenario,case,method,control,value,status,cpu_seconds,cpu_setup,cpu_integration,cpu_observation,steps,"
       "step_us,q_max,q_rms,qd_max,qdd_max,max_residual,energy_drift,reason\n";
  auto row = [&o](const std::vector<std::string>& cells) {
    for (size_t i = 0; i < cells.size(); ++i) o << (i ? "," : "") << CsvField(cells[i]);
    o << "\n";
  };
  for (const auto& r : Arr(At(results, "records"))) {
    const std::string kind = Str(r, "kind");
    const json& err = At(r, "error");
    if (kind == "run" || kind == "sweep" || kind == "stress") {
      const bool stress = kind == "stress";
      row({kind, Str(r, "scenario"), stress ? Str(r, "case") : "", Str(r, "method"),
           kind == "sweep" ? Str(r, "control") : "", kind == "sweep" ? CsvNum(At(r, "value")) : "",
           stress ? Str(r, "outcome") : Str(r, "status"), CsvNum(At(r, "cpu_seconds")), CsvNum(At(At(r, "cpu"), "setup")),
           CsvNum(At(At(r, "cpu"), "integration")), CsvNum(At(At(r, "cpu"), "observation")), CsvNum(At(At(r, "cpu"), "steps")),
           CsvNum(At(At(r, "cpu"), "step_us")), CsvNum(At(err, "q_max")),
           CsvNum(At(err, "q_rms")), CsvNum(At(err, "qd_max")), CsvNum(At(err, "qdd_max")),
           CsvNum(At(r, "max_residual")), CsvNum(At(r, "energy_drift")),
           stress ? Str(r, "detail") : Str(r, "reason")});
    } else if (kind == "stable_step") {
      for (const auto& t : Arr(At(r, "tried"))) {
        row({kind, Str(r, "scenario"), "", Str(r, "method"), "step", CsvNum(At(t, "step")), Str(t, "outcome"), "", "", "",
             "", "", "", "", "", "", "", "", "", Str(t, "detail")});
      }
    }
  }
  return o.str();
}

}  // namespace mechbench::harness::report
