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

#include <Simbody.h>

#include <utility>
#include <vector>

namespace mechbench::engines {

// A driver's joint coordinate as prescribed motion, q(t) = scale·(law(t) − law(t0)), zero at t0
// where the graph's frames put the joint; `Map` is the planar DriverMap or the SpatialDriverMap
// (both give Position, Rate and Acceleration at (t, t0)).
template <class Map>
class PrescribedLaw : public SimTK::Motion::Custom::Implementation {
 public:
  PrescribedLaw(Map d, double t0) : d_(std::move(d)), t0_(t0) {}
  Implementation* clone() const override { return new PrescribedLaw(*this); }
  SimTK::Motion::Level getLevel(const SimTK::State&) const override { return SimTK::Motion::Position; }
  void calcPrescribedPosition(const SimTK::State& s, int nq, SimTK::Real* q) const override {
    if (nq == 1) q[0] = d_.Position(s.getTime(), t0_);
  }
  void calcPrescribedPositionDot(const SimTK::State& s, int nq, SimTK::Real* qd) const override {
    if (nq == 1) qd[0] = d_.Rate(s.getTime(), t0_);
  }
  void calcPrescribedPositionDotDot(const SimTK::State& s, int nq, SimTK::Real* qdd) const override {
    if (nq == 1) qdd[0] = d_.Acceleration(s.getTime(), t0_);
  }

 private:
  Map d_;
  double t0_;
};

// `accuracy` > 0: the integrator's accuracy and constraint tolerance; <= 0: Simbody's defaults
// (left unset). `control` is the run's control as EngineMethod::SimulateSpatial gets it (for the
// settings' text only).
void SimulateSimbodySpatial(const SpatialGraph& g, const std::vector<double>& times, double accuracy,
                            const ControlValue& control, const SpatialRecorder& record, const RunOptions& options,
                            Result& result);

}  // namespace mechbench::engines
