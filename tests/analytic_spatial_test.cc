// The spatial closed forms (analytic/src/spatial.cc) on the fixture files: the RSSR four-bar driven
// by a point slot (rssr_fourbar.yaml) and by its input angle (rssr_fourbar_angles.yaml), and the
// spatial slider-crank (spatial_slider_crank.yaml), each against a closed form written here from
// the file's constants alone, with rates and accelerations from that closed form's central
// differences (independent of the solver's differentiation); and the reasons it gives where it
// does not apply. The comparison with the numeric method is in numeric_spatial_test.cc.
#include "mechbench/analytic/analytic_method.h"
#include "mechbench/loader.h"

#include <gtest/gtest.h>

#include <Eigen/Core>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <numbers>
#include <string>

namespace mechbench::analytic {
namespace analytic_spatial_test {  // this file's own names (the tests build in unity batches)
namespace {

using V3 = Eigen::Vector3d;
constexpr double kPi = std::numbers::pi;

std::string Scene(const std::string& name) { return std::string(MECHBENCH_TEST_DATA) + "/scenes/" + name + ".yaml"; }

// f', f'' by central differences at h and h/2 extrapolated (Richardson): truncation ~h⁴ f⁽⁵⁾/30
// and ~h⁴ f⁽⁶⁾/360, rounding ~ε f/h ≈ 2e-13 and ~ε f/h² ≈ 2e-10 for f of order 1 (h = 1e-3).
double D1(const std::function<double(double)>& f, double x) {
  const auto c = [&](double h) { return (f(x + h) - f(x - h)) / (2 * h); };
  return (4 * c(5e-4) - c(1e-3)) / 3;
}
double D2(const std::function<double(double)>& f, double x) {
  const auto c = [&](double h) { return (f(x + h) - 2 * f(x) + f(x - h)) / (h * h); };
  return (4 * c(5e-4) - c(1e-3)) / 3;
}

struct Worst {
  double q = 0, qd = 0, qdd = 0;
  void Add(double dq, double dqd, double dqdd) {
    q = std::max(q, std::fabs(dq)), qd = std::max(qd, std::fabs(dqd)), qdd = std::max(qdd, std::fabs(dqdd));
  }
};

// The RSSR's output angle φ(θ): B = a (cos θ, sin θ, 0), C = D + c (0, cos φ, sin φ), |C − B| = b,
// so with d = D − B: d₂ cos φ + d₃ sin φ = K = (b² − c² − |d|²) / (2c) (the files' branch: +acos).
double RssrPhi(const Model& m, double th) {
  const double a = m.constants.at("a"), b = m.constants.at("b"), c = m.constants.at("c");
  const V3 D = m.spatial.entities[m.spatial.EntityIndex("D")].r_W;
  const V3 d = D - a * V3(std::cos(th), std::sin(th), 0);
  const double K = (b * b - c * c - d.squaredNorm()) / (2 * c);
  return std::atan2(d.z(), d.y()) + std::acos(K / std::hypot(d.y(), d.z()));
}

// Over the motion: θ(t) = th0 + w t; the output crank's φ from C's slots, or from q.phi.
Worst RssrAgainstClosedForm(const Model& m, const Result& r) {
  const double th0 = m.constants.at("th0"), w = m.constants.at("w");
  const V3 D = m.spatial.entities[m.spatial.EntityIndex("D")].r_W;
  const double c = m.constants.at("c");
  const int yC = m.SlotIndex("yC"), zC = m.SlotIndex("zC"), phi = m.SlotIndex("phi");
  const auto f = [&](double th) { return RssrPhi(m, th); };
  Worst worst;
  for (const Sample& s : r.trajectory) {
    const double th = th0 + w * s.t;
    const double py = s.q[yC] - D.y(), pz = s.q[zC] - D.z();
    const double ph = std::atan2(pz, py), phd = (py * s.qd[zC] - pz * s.qd[yC]) / (c * c);
    const double phdd = (py * s.qdd[zC] - pz * s.qdd[yC]) / (c * c);
    worst.Add(std::remainder(ph - f(th), 2 * kPi), phd - D1(f, th) * w, phdd - D2(f, th) * w * w);
    if (phi >= 0) worst.Add(s.q[phi] - f(th), s.qd[phi] - D1(f, th) * w, s.qdd[phi] - D2(f, th) * w * w);
  }
  return worst;
}

void Print(const char* what, const Result& r, const Worst& w) {
  if (std::getenv("MECHBENCH_VERBOSE"))
    std::printf("%s over %zu samples: q %.2g, qd %.2g, qdd %.2g\n", what, r.trajectory.size(), w.q, w.qd, w.qdd);
}

TEST(AnalyticSpatial, RssrDrivenByAPointSlotMatchesItsClosedForm) {
  const Model m = LoadScenario(Scene("rssr_fourbar"));
  const auto method = MakeAnalyticMethod();
  ASSERT_FALSE(method->Applicability(m)) << *method->Applicability(m);
  const Result r = method->Run(m);
  ASSERT_TRUE(r.ok()) << r.reason;
  ASSERT_EQ(static_cast<int>(r.trajectory.size()), m.analysis.samples);
  EXPECT_NE(r.settings.at("decomposition").find("RSSR four-bar"), std::string::npos) << r.settings.at("decomposition");
  // The driven slot follows its law exactly; every slot of q is there.
  const int xB = m.SlotIndex("xB");
  for (const Sample& s : r.trajectory) {
    ASSERT_EQ(s.q.size(), static_cast<int>(m.q_layout.size()));
    EXPECT_NEAR(s.q[xB], m.drivers[0].At(s.t, 0), 1e-15);
    EXPECT_NEAR(s.qd[xB], m.drivers[0].RateAt(s.t, 0), 1e-14);
    EXPECT_NEAR(s.qdd[xB], m.drivers[0].AccelerationAt(s.t, 0), 1e-14);
  }
  const Worst w = RssrAgainstClosedForm(m, r);
  Print("RSSR (slot xB)", r, w);
  EXPECT_LT(w.q, 1e-13);    // the same equation in another arrangement: rounding only (measured 0)
  EXPECT_LT(w.qd, 1e-11);   // the differences' own error (above); measured 1.7e-12
  EXPECT_LT(w.qdd, 1e-7);   // measured 9e-9: the second difference's rounding
}

TEST(AnalyticSpatial, RssrDrivenByItsInputAngleMatchesItsClosedForm) {
  const Model m = LoadScenario(Scene("rssr_fourbar_angles"));
  const Result r = MakeAnalyticMethod()->Run(m);
  ASSERT_TRUE(r.ok()) << r.reason;
  const Worst w = RssrAgainstClosedForm(m, r);
  Print("RSSR (angle theta)", r, w);
  EXPECT_LT(w.q, 1e-13);  // measured 4.4e-16
  EXPECT_LT(w.qd, 1e-11);  // 1.7e-12
  EXPECT_LT(w.qdd, 1e-7);  // 9e-9
  // The unit vector across the output crank turns with it: w3 = (0, −sin φ, cos φ).
  const Sample& last = r.trajectory.back();
  const double phi = last.q[m.SlotIndex("phi")];
  EXPECT_NEAR(last.q[m.SlotIndex("yw3")], -std::sin(phi), 1e-14);
  EXPECT_NEAR(last.q[m.SlotIndex("zw3")], std::cos(phi), 1e-14);
}

// s(θ) = −d·h + √((d·h)² − |h|² + L²), h = F − B(θ), B = a (cos θ, sin θ, 0): the file's description.
TEST(AnalyticSpatial, SliderCrankMatchesItsClosedFormOverAFullTurn) {
  const Model m = LoadScenario(Scene("spatial_slider_crank"));
  const Result r = MakeAnalyticMethod()->Run(m);
  ASSERT_TRUE(r.ok()) << r.reason;
  ASSERT_EQ(static_cast<int>(r.trajectory.size()), m.analysis.samples);
  EXPECT_NE(r.settings.at("decomposition").find("spatial slider-crank"), std::string::npos);
  const double a = m.constants.at("a"), L = m.constants.at("L"), th0 = m.constants.at("th0"), w = 2 * kPi;
  const V3 F = m.spatial.entities[m.spatial.EntityIndex("F")].r_W, d = m.spatial.entities[m.spatial.EntityIndex("d")].r_W;
  const auto f = [&](double th) {
    const V3 h = F - a * V3(std::cos(th), std::sin(th), 0);
    return -d.dot(h) + std::sqrt(d.dot(h) * d.dot(h) - h.squaredNorm() + L * L);
  };
  const int s = m.SlotIndex("s"), xC = m.SlotIndex("xC"), theta = m.SlotIndex("theta");
  Worst worst;
  for (const Sample& x : r.trajectory) {
    const double th = th0 + w * x.t;
    EXPECT_NEAR(x.q[theta], th, 1e-14);
    worst.Add(x.q[s] - f(th), x.qd[s] - D1(f, th) * w, x.qdd[s] - D2(f, th) * w * w);
    // C's slots are the slider's: C = F + s d.
    worst.Add(x.q[xC] - (F.x() + f(th) * d.x()), x.qd[xC] - D1(f, th) * w * d.x(), 0);
  }
  Print("slider-crank", r, worst);
  EXPECT_LT(worst.q, 1e-13);   // measured 1.3e-15
  EXPECT_LT(worst.qd, 5e-11);  // 5.8e-12; w = 2π: the differences' errors times w and w²
  EXPECT_LT(worst.qdd, 1e-6);  // 2.1e-7: the second difference's rounding, ε s/h² w² ≈ 1e-7
}

// A spatial scene that is not a loop of two cranks or sliders and a bar: the reason, not a run.
TEST(AnalyticSpatial, OtherSpatialScenesGetTheReason) {
  const auto method = MakeAnalyticMethod();
  for (const char* name : {"spatial_rotor_driven", "spherical_pendulum"}) {
    SCOPED_TRACE(name);
    const Model m = LoadScenario(Scene(name));
    const std::optional<std::string> why = method->Applicability(m);
    ASSERT_TRUE(why);
    EXPECT_EQ(why->rfind("no closed form for this spatial mechanism (RSSR and spatial slider-crank only): ", 0), 0u) << *why;
    const Result r = method->Run(m);
    EXPECT_EQ(r.status, Status::kNotApplicable);
    EXPECT_EQ(r.reason, *why);
  }
}

// A point slot gives the crank's turn only where it is monotonic: rssr_fourbar.yaml's xB = a cos θ
// driven past θ = π (t1 = 2.5 s: θ up to 4.3 rad) turns back at the end of its range.
TEST(AnalyticSpatial, APointSlotDriverThatIsNotMonotonicGetsAReason) {
  Model m = LoadScenario(Scene("rssr_fourbar"));
  m.analysis.t1 = 2.5;
  m.analysis.samples = 26;
  const std::optional<std::string> why = MakeAnalyticMethod()->Applicability(m);
  ASSERT_TRUE(why);
  EXPECT_NE(why->find("driver on xB: "), std::string::npos) << *why;
  EXPECT_NE(why->find("drive an angle coordinate instead"), std::string::npos) << *why;
}

// An RSSR whose crank cannot turn fully, driven round (rssr_claim_beyond_reach.yaml, newuser8): the
// bar cannot reach the output crank's circle at t = 0.4 s, bad input on the driver's line (28) as
// numeric says it, not a row's reason without a file and line.
TEST(AnalyticSpatial, ADriverPastItsReachDuringTheMotionIsBadInputOnItsLine) {
  const Result r = MakeAnalyticMethod()->Run(LoadScenario(Scene("rssr_claim_beyond_reach")));
  EXPECT_EQ(r.status, Status::kInvalidScenario);
  EXPECT_NE(r.reason.find("rssr_claim_beyond_reach.yaml:28: the driven theta at t = 0.4 s is out of the mechanism's reach: "
                          "the loop cannot close there (the bar cannot reach the output crank's circle"),
            std::string::npos)
      << r.reason;
}

// Its reason for a loop of the wrong make-up counts in the singular where there is one (it said
// "1 cranks and sliders"; newuser9).
TEST(AnalyticSpatial, TheLoopReasonCountsCranksAndSliders) {
  const std::optional<std::string> why = MakeAnalyticMethod()->Applicability(LoadScenario(Scene("spatial_block_pendulum")));
  ASSERT_TRUE(why);
  EXPECT_NE(why->find("only): 0 cranks and 1 slider (the loop has two"), std::string::npos) << *why;
}

}  // namespace
}  // namespace analytic_spatial_test
}  // namespace mechbench::analytic
