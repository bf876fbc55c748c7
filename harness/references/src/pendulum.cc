#include "mechbench/references/pendulum.h"

#include "mechbench/errors.h"
#include "mechbench/references/cranks.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace mechbench::references {
namespace {

constexpr int kMaxAgm = 40;  // the AGM converges quadratically: 5 or 6 steps for k < 0.999

}  // namespace

double EllipticK(double k) {
  MB_ASSERT(k >= 0 && k < 1, "EllipticK needs 0 ≤ k < 1");
  double a = 1, b = std::sqrt((1 - k) * (1 + k));
  for (int i = 0; i < kMaxAgm && std::fabs(a - b) > 1e-16 * a; ++i) {
    const double an = 0.5 * (a + b);
    b = std::sqrt(a * b);
    a = an;
  }
  return std::numbers::pi / (a + b);  // π / (2 AGM), with AGM = (a + b) / 2 at convergence
}

Jacobi JacobiElliptic(double u, double k) {
  MB_ASSERT(k >= 0 && k < 1, "JacobiElliptic needs 0 ≤ k < 1");
  if (k == 0) return {std::sin(u), std::cos(u), 1.0};
  const double period = 4 * EllipticK(k);
  u -= period * std::round(u / period);
  // Descending Landen by the AGM: a_n, c_n until c_N is negligible; then φ_N = 2^N a_N u and
  // back down φ_{n−1} = (φ_n + asin(c_n / a_n · sin φ_n)) / 2; sn = sin φ_0, cn = cos φ_0,
  // dn = √(1 − k² sn²) (A&S 16.4.3, 16.9.1).
  double a[kMaxAgm + 1], c[kMaxAgm + 1];
  a[0] = 1, c[0] = k;
  double b = std::sqrt((1 - k) * (1 + k));
  int n = 0;
  while (n < kMaxAgm && std::fabs(c[n]) > 1e-17) {
    const double an = 0.5 * (a[n] + b);
    c[n + 1] = 0.5 * (a[n] - b);
    b = std::sqrt(a[n] * b);
    a[++n] = an;
  }
  double phi = std::ldexp(a[n] * u, n);
  for (int i = n; i > 0; --i) {
    phi = 0.5 * (phi + std::asin(c[i] / a[i] * std::sin(phi)));
  }
  const double sn = std::sin(phi), cn = std::cos(phi);
  // dn from sn: A&S's cos φ_0 / cos(φ_1 − φ_0) is 0/0 where cn vanishes (u = K, the turning points).
  return {sn, cn, std::sqrt((1 - k * sn) * (1 + k * sn))};
}

numeric::ExactSolution PendulumExact(const Model& model, const std::vector<double>& extra_times, std::string& why) {
  numeric::ExactSolution out;
  ParallelCranks pc;
  MB_ASSERT(AnalyzeParallelCranks(model, pc, why) && pc.couplers == 0, "PendulumExact needs one crank");
  const double w0 = std::sqrt(pc.g * pc.K / pc.J);
  const double phi0 = std::remainder(pc.theta0 + std::numbers::pi / 2, 2 * std::numbers::pi);
  const double rate0 = pc.omega0;
  const double half = std::sin(phi0 / 2), r = rate0 / (2 * w0);
  const double k = std::sqrt(half * half + r * r);
  if (!(k < 1)) {
    why = "it turns over (k = " + std::to_string(k) + " ≥ 1): only the swinging pendulum's closed form is written";
    return out;
  }
  const double K = EllipticK(k);
  // u0: sn(u0) = sin(φ0/2) / k, cn(u0) of the sign of φ̇0 (sn(2K − u) = sn u, cn(2K − u) = −cn u).
  const double s0 = k > 0 ? std::clamp(half / k, -1.0, 1.0) : 0.0;
  double u0 = std::fabs(s0) >= 1 ? std::copysign(K, s0) : (k > 0 ? std::ellint_1(k, std::asin(s0)) : 0.0);
  if (rate0 < 0) u0 = 2 * K - u0;
  const Eigen::Vector2d G = model.points[pc.ground[0]].p_W;
  const double L = pc.L, t0 = model.analysis.t0;
  const int n = static_cast<int>(model.q_layout.size());
  const auto at = [&](double t) {
    const Jacobi j = JacobiElliptic(w0 * (t - t0) + u0, k);
    const double sin_phi = 2 * k * j.sn * j.dn, cos_phi = 1 - 2 * k * k * j.sn * j.sn;
    const double w = 2 * k * w0 * j.cn, a = -w0 * w0 * sin_phi;
    Sample s;
    s.t = t;
    s.q = Eigen::VectorXd::Zero(n), s.qd = Eigen::VectorXd::Zero(n), s.qdd = Eigen::VectorXd::Zero(n);
    s.q[pc.x[0]] = G.x() + L * sin_phi;
    s.q[pc.y[0]] = G.y() - L * cos_phi;
    s.qd[pc.x[0]] = L * cos_phi * w;
    s.qd[pc.y[0]] = L * sin_phi * w;
    s.qdd[pc.x[0]] = L * (cos_phi * a - sin_phi * w * w);
    s.qdd[pc.y[0]] = L * (sin_phi * a + cos_phi * w * w);
    if (pc.angle_slot >= 0) {  // the crank's angle as a coordinate: φ = 2 asin(k sn) (|φ| < π), θ̇ = φ̇
      s.q[pc.angle_slot] = pc.angle0 + (2 * std::asin(std::clamp(k * j.sn, -1.0, 1.0)) - phi0);
      s.qd[pc.angle_slot] = w;
      s.qdd[pc.angle_slot] = a;
    }
    s.residual = 0;
    return s;
  };
  const Analysis& an = model.analysis;
  out.trajectory.reserve(an.samples);
  for (int i = 0; i < an.samples; ++i) out.trajectory.push_back(at(an.TimeAt(i)));
  for (double t : extra_times) out.extra.push_back(at(t));
  out.quantities["k"] = k;
  out.quantities["period"] = 4 * K / w0;
  out.quantities["energy"] = 0.5 * pc.J * rate0 * rate0 + pc.g * pc.K * std::sin(pc.theta0);
  why.clear();
  return out;
}

}  // namespace mechbench::references
