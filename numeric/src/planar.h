// Internal: the small planar vector helpers numeric's sources share (one definition each, so that
// the sources also build as one translation unit: CMake's unity build in CI).
#pragma once

#include <Eigen/Core>

namespace mechbench::numeric::planar {

// a × b, the z-component of the cross product of two plane vectors.
inline double Cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }
// P v with P = [0 −1; 1 0], the +90° rotation ("perp" in the book's linear rows).
inline Eigen::Vector2d Perp(const Eigen::Vector2d& v) { return {-v.y(), v.x()}; }
// C(ξ, η) of dynamics.h: r = C [r_i; r_j] for the material point at body-frame (ξ, η) of a body of
// length L, i.e. (1 − a) I − b P | a I + b P with a = ξ/L, b = η/L.
inline Eigen::Matrix<double, 2, 4> Interpolation(double L, const Eigen::Vector2d& xi) {
  const double a = xi.x() / L, b = xi.y() / L;
  Eigen::Matrix<double, 2, 4> C;
  C << 1 - a, b, a, -b,
       -b, 1 - a, b, a;
  return C;
}

}  // namespace mechbench::numeric::planar
