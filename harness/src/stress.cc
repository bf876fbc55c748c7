// Stress variants: each derived from a family's base scenario by changing what the family
// stresses (a mass, a tooth count, a speed, a link length, the horizon), so that the variant is
// still a plain Model that every method consumes unchanged.
#include "mechbench/harness/campaign.h"

#include "mechbench/errors.h"
#include "mechbench/format.h"
#include "mechbench/references/nfourbar.h"

#include <cmath>
#include <numbers>

namespace mechbench::harness {
namespace {

// "1e3", "1e-6" for powers of ten, else a short decimal.
std::string PowerOfTenText(double v) {
  const double e = std::log10(v);
  if (std::fabs(e - std::round(e)) < 1e-12) return "1e" + std::to_string(static_cast<int>(std::round(e)));
  return Fmt(v, 6);
}

Body& BodyNamed(Model& m, const std::string& name) {
  const int i = m.BodyIndex(name);
  MB_ASSERT(i >= 0, ("stress variant: base scenario " + m.name + " has no body " + name).c_str());
  return m.bodies[i];
}

// The variant keeps the base's geometry and data but none of its book values (they are the
// base's claims, not the variant's).
Model Renamed(const Model& base, const std::string& id) {
  Model m = base;
  m.name = base.name + "@" + id;
  m.book.clear();
  m.synthesis.reset();
  return m;
}

// A mass ratio: `body` gets `ratio` × the mass of `other` (inertia scaled alike).
StressVariant MassRatio(const std::string& base, const std::string& body, const std::string& other, double ratio,
                        const std::string& words) {
  StressVariant v;
  v.id = "mass_ratio=" + PowerOfTenText(ratio);
  v.family = "mass ratio";
  v.base = base;
  v.description = words + ": " + body + " is " + PowerOfTenText(ratio) + " × the mass of " + other +
                  " (inertia scaled with it)";
  v.tolerance = 1e-3;
  v.derive = [=](const Model& b) {
    Model m = Renamed(b, v.id);
    Body& heavy = BodyNamed(m, body);
    const double factor = ratio * BodyNamed(m, other).mass / heavy.mass;
    heavy.mass *= factor;
    heavy.inertia_com *= factor;
    return m;
  };
  return v;
}

// The last mesh's driven wheel gets `factor` × its teeth.
StressVariant GearRatio(const std::string& base, int factor, const std::string& label) {
  StressVariant v;
  v.id = "gear_ratio=" + label;
  v.family = "gear ratio";
  v.base = base;
  v.description = "the last mesh's driven wheel has " + std::to_string(factor) + " × its teeth (overall ratio about " +
                  label + ":1)";
  v.tolerance = 1e-6;
  v.derive = [=](const Model& b) {
    Model m = Renamed(b, v.id);
    for (auto it = m.joints.rbegin(); it != m.joints.rend(); ++it)
      if (it->type == JointType::kGear) {
        it->teeth[1] *= factor;
        break;
      }
    return m;
  };
  return v;
}

// The input turns at `rpm`, over one turn with the base's samples.
StressVariant InputSpeed(const std::string& base, double rpm) {
  StressVariant v;
  v.id = "input_speed=" + Fmt(rpm, 6) + "rpm";
  v.family = "input speed";
  v.base = base;
  v.description = "the driven input at " + Fmt(rpm, 6) + " rpm over one turn";
  v.tolerance = 1e-2;
  v.derive = [=](const Model& b) {
    Model m = Renamed(b, v.id);
    const double omega = rpm * 2 * std::numbers::pi / 60;  // [rad/s]
    m.drivers.at(0).velocity = omega;
    m.analysis.t1 = m.analysis.t0 + 2 * std::numbers::pi / omega;
    return m;
  };
  return v;
}

// The rocker of the crank-rocker made `length` long (uniform 1 kg/m as the base).
StressVariant RockerLength(const std::string& base, const std::string& id, const std::string& family, double length,
                           const std::string& words) {
  StressVariant v;
  v.id = id;
  v.family = family;
  v.base = base;
  v.description = words;
  v.tolerance = 1e-2;
  v.derive = [=](const Model& b) {
    Model m = Renamed(b, v.id);
    Body& rocker = BodyNamed(m, "rocker");
    rocker.p_B.at(1).x() = length;
    rocker.mass = length;
    rocker.com_B = {length / 2, 0};
    rocker.inertia_com = length * length * length / 12;
    return m;
  };
  return v;
}

}  // namespace

const std::vector<StressVariant>& StressVariants() {
  static const std::vector<StressVariant> variants = [] {
    std::vector<StressVariant> v;
    v.push_back(MassRatio("s5_1_disc_bar_bushing", "disc", "bar", 1e3, "heavy disc, light bar"));
    v.push_back(MassRatio("s5_1_disc_bar_bushing", "disc", "bar", 1e6, "heavy disc, light bar"));
    v.push_back(MassRatio("fourbar_free", "crank", "coupler", 1e-3, "near-massless crank"));
    v.push_back(MassRatio("fourbar_free", "crank", "coupler", 1e-6, "near-massless crank"));
    v.push_back(GearRatio("s6_3_compound_train", 5, "99"));
    v.push_back(GearRatio("s6_3_compound_train", 50, "990"));
    v.push_back(InputSpeed("fourbar_crank_rocker", 1000));
    v.push_back(InputSpeed("fourbar_crank_rocker", 10000));
    // Grashof: s + l = 2 + 10 = 12 against p + q = 8 + L. L = 5 is the base crank-rocker.
    v.push_back(RockerLength("fourbar_crank_rocker", "toggle=1e-3", "toggle", 4.001,
                             "rocker 4.001 m: each turn passes within 1 mm of the coupler–rocker dead centre "
                             "(s + l = 12, p + q = 12.001)"));
    v.push_back(RockerLength("fourbar_crank_rocker", "change_point", "change point", 4.0,
                             "rocker 4 m: s + l = p + q = 12, a Grashof change point; at θ = 180° all bars are "
                             "collinear and the linkage can switch assembly"));
    {
      StressVariant s;
      s.id = "nfourbar=1";
      s.family = "singular crossing";
      s.base = "";  // generated: the IFToMM A02 N-four-bar with N = 1
      s.description = "IFToMM A02 N-four-bar, N = 1 (a parallelogram), 5 s: passes the horizontal, where Φ_q loses "
                      "rank and the motion may bifurcate";
      s.tolerance = 1e-2;
      s.derive = [](const Model&) {
        Model m = references::NFourBar({.n = 1, .t1 = 5.0, .samples = 51});
        m.name = "nfourbar_1";
        return m;
      };
      v.push_back(s);
    }
    for (const auto& [base, h] : {std::pair<std::string, double>{"s5_1_disc_bar_bushing", 0.01}, {"fourbar_free", 0.05}}) {
      StressVariant s;
      s.id = "step=" + Fmt(h * 1e3, 3) + "ms";
      s.family = "large step";
      s.base = base;
      s.description = "every fixed-step method at h = " + Fmt(h * 1e3, 3) + " ms (10 to 50 × its default)";
      s.tolerance = 1e-2;
      s.step = h;
      s.derive = [id = s.id](const Model& b) { return Renamed(b, id); };
      v.push_back(s);
    }
    {
      StressVariant s;
      s.id = "horizon=30s";
      s.family = "long horizon";
      s.base = "fourbar_free";
      s.description = "released from rest and followed for 30 s (301 samples): energy and phase drift";
      s.tolerance = 1e-2;
      s.derive = [id = s.id](const Model& b) {
        Model m = Renamed(b, id);
        m.analysis.t1 = 30;
        m.analysis.samples = 301;
        return m;
      };
      v.push_back(s);
    }
    return v;
  }();
  return variants;
}

}  // namespace mechbench::harness
