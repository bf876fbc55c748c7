// Simbody adapter (no Simbody headers here): a MobilizedBody tree (Pin about z, Slider) from the
// graph's spanning tree, loop closures as Constraint::PointOnLine along z (the planar coincidence
// of two points, two equations), gears as Constraint::CoordinateCoupler, drivers as prescribed
// Motion::Custom at position level, integrated by RK-Merson with error control. Spatial scenes
// (the engines' spatial graph): src/simbody_spatial.h.
#pragma once

#include "mechbench/method.h"

#include <vector>

namespace mechbench::engines {

// "simbody-rkmerson-default" (Simbody's default accuracy 1e-3) and "simbody-rkmerson-tuned"
// (accuracy and constraint tolerance 1e-10).
std::vector<MethodPtr> MakeSimbodyMethods();

}  // namespace mechbench::engines
