// One way to measure how far a motion is from a reference motion. `run` (driven pairs and free
// scenes), `sweep`, `stress`, the report, the reference's own confirmation, the benchmark and the
// tests all call CompareMotion, so that a number in one means the same in the others.
//
// Samples are matched by index; their times must agree to 1e-12 (relative to 1 + |t|), and a run
// that stopped early is compared over the samples it has, with `problem` saying so.
//
// Every coordinate is of one of two kinds: lengths (points' coordinates, distances) and angles
// (relative angles, rotations). Each kind has its own scale, taken from the reference motion:
//  - q:  the largest range (max − min) any coordinate of that kind covers over the motion, and at
//        least kScaleFloor × the kind's size (lengths: the scene's length scale, Model::LengthScale;
//        angles: 1 rad), so that a coordinate that hardly moves, or a single instant, is judged
//        against the mechanism's own size and not against round-off;
//  - q̇:  the largest |q̇| of the kind, and at least its q scale / T;
//  - q̈:  the largest |q̈| of the kind, and at least its q̇ scale / T;
// with T the motion's duration (t1 − t0; 1 s for an instant). A constant-speed crank has θ̈ = 0
// and a slider at rest x = const: their errors count against the motion of their kind as a whole.
// The error of a kind is the largest |Δ| / scale over its coordinates and the samples (NaN counts
// as infinite), and its RMS over the same.
#pragma once

#include "mechbench/method.h"
#include "mechbench/model.h"

#include <array>
#include <string>
#include <vector>

namespace mechbench {

inline constexpr double kScaleFloor = 1e-3;

// 0: lengths, 1: angles.
int SlotKind(const Model& model, int slot);

struct MotionScale {
  std::array<double, 2> q{1, 1}, qd{1, 1}, qdd{1, 1};  // [lengths, angles], in their units (/s, /s²)
};
MotionScale ScaleOfMotion(const Model& model, const std::vector<Sample>& reference);

struct KindError {
  double max = kNaN;  // largest |Δ| / scale (NaN: the kind was not compared, e.g. no q̈ on one side)
  double rms = kNaN;  // over every coordinate and sample compared
  std::string slot;   // where the largest is
  double t = kNaN;    // when [s]
};

struct MotionError {
  int samples = 0;       // compared
  std::string problem;   // sample times or counts differ
  KindError q, qd, qdd;
  std::vector<double> q_per_sample;  // the largest relative |Δq| at each compared sample
  MotionScale scale;                 // what the differences were divided by
};

// `other` against `reference`, scaled by the reference's own motion.
MotionError CompareMotion(const Model& model, const std::vector<Sample>& reference, const std::vector<Sample>& other);
// The same with a given scale: e.g. a whole run's, when only some of its samples are compared.
MotionError CompareMotion(const Model& model, const MotionScale& scale, const std::vector<Sample>& reference,
                          const std::vector<Sample>& other);

}  // namespace mechbench
