// Vector algebra of the book's Part I (§1.2–§1.4): moduli, unit vectors, dot and cross products,
// the skew matrix [r]x of eq. 1.12, triple products, and the planar shortcuts used by the linkage
// solver (k × r and the scalar cross product of two in-plane vectors).
#pragma once

#include <Eigen/Core>

namespace mechbench::analytic {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

// Unit vector along r (eq. 1.3); r must be nonzero.
Vec3 Unit(const Vec3& r);
Vec2 Unit(const Vec2& r);

// Angle between two vectors in [0, π] (eq. 1.9), computed as atan2(|a×b|, a·b) so that it stays
// accurate near 0 and π where acos loses digits.
double AngleBetween(const Vec3& a, const Vec3& b);

// a × b by the determinant rule (eq. 1.11).
Vec3 Cross(const Vec3& a, const Vec3& b);
// [r]x, the matrix with [r]x b = r × b (eq. 1.12).
Mat3 Skew(const Vec3& r);
// a × (b × c) (eq. 1.14); the parentheses matter (eq. 1.15).
Vec3 TripleCross(const Vec3& a, const Vec3& b, const Vec3& c);
// a · (b × c), the signed volume of the parallelepiped on a, b, c.
double TripleScalar(const Vec3& a, const Vec3& b, const Vec3& c);

// Planar helpers (vectors in the mechanism's plane, k its normal).
// Scalar cross product a_x b_y − a_y b_x = (a × b)·k.
inline double Cross2(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }
// k × r: r turned +90° in the plane. ω k × r is the velocity term of a planar rigid body.
inline Vec2 Perp(const Vec2& r) { return Vec2(-r.y(), r.x()); }
// Unit vector at angle phi [rad] from the x axis.
Vec2 Direction(double phi);
// Solves [c1 c2] (x1, x2)ᵀ = rhs by Cramer's rule; returns false when the columns are parallel
// (relative determinant below `tol`), which is a singular (toggle) position of the dyad.
bool SolveCramer2(const Vec2& c1, const Vec2& c2, const Vec2& rhs, double& x1, double& x2,
                  double tol = 1e-12);

}  // namespace mechbench::analytic
