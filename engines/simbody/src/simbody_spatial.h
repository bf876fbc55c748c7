// The Simbody adapter's spatial path (issue 13), apart from the planar one in simbody_method.cc:
// the engines' spatial graph (spatial_graph.h) as a MobilizedBody tree (Ball, Pin about the
// graph's axis, Free), loop closures as Constraint::Ball (a revolute closure: Constraint::Ball at
// its point and two Constraint::ConstantAngle at 90° keeping the axes parallel), Simbody's own
// gravity, constant forces and torques and two-point spring–dampers, drivers as prescribed
// Motion::Custom on their pins, integrated by RK-Merson as the planar path is.
#pragma once

#include "mechbench/engines/engine_method.h"
#include "mechbench/engines/spatial_graph.h"
#include "mechbench/method.h"
#include "mechbench/run_control.h"

#include <vector>

namespace mechbench::engines {

// `accuracy` > 0: the integrator's accuracy and constraint tolerance; <= 0: Simbody's defaults
// (left unset). `control` is the run's control as EngineMethod::SimulateSpatial gets it (for the
// settings' text only).
void SimulateSimbodySpatial(const SpatialGraph& g, const std::vector<double>& times, double accuracy,
                            const ControlValue& control, const SpatialRecorder& record, const RunOptions& options,
                            Result& result);

}  // namespace mechbench::engines
