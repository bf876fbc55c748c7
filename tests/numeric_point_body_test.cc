// One-point bodies (a point mass, a slider block, a piston; Body::IsPointBody) in the natural-
// coordinate dynamics: a point mass moves exactly as a bar whose mass sits at the same point, M
// and Q agree with the analytic method's energy polarisation (a block on a turning guide with its
// com off its point and an inertia), a driven piston's power follows the closed form of the
// slider-crank, and the free scenes conserve energy in every formulation.
#include "mechbench/analytic/energy.h"
#include "mechbench/loader.h"
#include "mechbench/numeric/dynamics.h"
#include "mechbench/numeric/dynamics_methods.h"
#include "mechbench/numeric/forward_dynamics.h"
#include "mechbench/numeric/natural_data.h"
#include "mechbench/numeric/natural_model.h"
#include "mechbench/numeric/numeric_method.h"
#include "formulations.h"
#include "quantity.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace mechbench::numeric {
namespace numeric_point_body_test {  // this file's own names (the tests build in unity batches)
namespace {

using test::Formulation;
using test::Formulations;
using test::Scene;

// Largest |q − q'| and |q̇ − q̇'| over two runs of scenes with one q layout.
double TrajectoryDifference(const Result& a, const Result& b) {
  EXPECT_EQ(a.trajectory.size(), b.trajectory.size());
  double worst = 0;
  for (size_t k = 0; k < std::min(a.trajectory.size(), b.trajectory.size()); ++k) {
    worst = std::max(worst, (a.trajectory[k].q - b.trajectory[k].q).cwiseAbs().maxCoeff());
    worst = std::max(worst, (a.trajectory[k].qd - b.trajectory[k].qd).cwiseAbs().maxCoeff());
  }
  return worst;
}

TEST(NumericPointBody, LoadsWithTheFramesOfItsGuide) {
  const Model bob = Scene("pendulum_point_mass.yaml");
  const Body& b = bob.bodies[bob.BodyIndex("bob")];
  EXPECT_TRUE(b.IsPointBody());
  EXPECT_EQ(b.guide, -1);
  EXPECT_EQ(b.mass, 3.0);
  EXPECT_EQ(b.com_B, Eigen::Vector2d(0, 0));  // `mass` alone: the point mass of a point body
  EXPECT_EQ(b.inertia_com, 0.0);
  const Model piston = Scene("slider_crank_piston_free.yaml");
  const Body& p = piston.bodies[piston.BodyIndex("piston")];
  ASSERT_GE(p.guide, 0);
  EXPECT_EQ(piston.joints[p.guide].point, p.points[0]);
  const Model inverted = Scene("inverted_slider_crank_block_free.yaml");
  const Body& k = inverted.bodies[inverted.BodyIndex("block")];
  ASSERT_GE(k.guide, 0);
  EXPECT_EQ(inverted.joints[k.guide].type, JointType::kPointOnBody);
}

// (1) A massless rod with a 3 kg point body at its tip against one bar with its 3 kg at the tip
// (com at the tip, inertia 0), and a 1 kg bar with the point body against the bar merged by hand:
// the same M and Q, and the same motion in every formulation. Measured: the first pair identical
// to the last bit (both give 3 I on the tip's slots), the merged pair within 1e-15 in M and
// 2e-15 in q, q̇ over 1 s.
TEST(NumericPointBody, PointMassMovesLikeTheBarThatCarriesItsMass) {
  const std::pair<const char*, const char*> pairs[] = {{"pendulum_point_mass.yaml", "pendulum_tip_mass_bar.yaml"},
                                                       {"pendulum_bar_point_mass.yaml", "pendulum_bar_point_mass_merged.yaml"}};
  for (const auto& [with_point, as_bar] : pairs) {
    const Model a = Scene(with_point), b = Scene(as_bar);
    ASSERT_EQ(a.q_layout.size(), b.q_layout.size());
    for (bool sparse : {false, true}) {
      const NaturalModel na = Compile(a), nb = Compile(b);
      NaturalData da(na), db(nb);
      da.sparse = db.sparse = sparse;
      MassMatrix(na, da);
      MassMatrix(nb, db);
      GeneralizedForces(na, da);
      GeneralizedForces(nb, db);
      const Eigen::MatrixXd Ma = sparse ? Eigen::MatrixXd(da.M_sparse) : da.M;
      const Eigen::MatrixXd Mb = sparse ? Eigen::MatrixXd(db.M_sparse) : db.M;
      EXPECT_LT((Ma - Mb).cwiseAbs().maxCoeff(), 1e-14 * Mb.cwiseAbs().maxCoeff()) << with_point << " sparse " << sparse;
      EXPECT_LT((da.Q - db.Q).cwiseAbs().maxCoeff(), 1e-14 * db.Q.cwiseAbs().maxCoeff()) << with_point;
    }
    for (const Formulation& f : Formulations()) {
      const Result ra = f.make()->Run(a), rb = f.make()->Run(b);
      ASSERT_EQ(ra.status, Status::kOk) << with_point << " " << f.name << ": " << ra.reason;
      ASSERT_EQ(rb.status, Status::kOk) << as_bar << " " << f.name << ": " << rb.reason;
      const double d = TrajectoryDifference(ra, rb);
      std::printf("  %-34s %-24s max |Δq|, |Δq̇| = %.2e\n", with_point, f.name.c_str(), d);
      EXPECT_LT(d, 1e-12) << with_point << " " << f.name;
    }
  }
}

// (2) M and Q against the analytic method's polarisation of the kinetic energy and the power of
// the weights (analytic/energy.h), dense and sparse both ways: a block with com off its point and
// an inertia on the turning rocker (its M couples the block's point with the rocker's two), and a
// piston on a fixed guide.
TEST(NumericPointBody, MassMatrixAgreesWithTheEnergyOfTheBlock) {
  for (const char* file : {"inverted_slider_crank_block_free.yaml", "slider_crank_piston_free.yaml",
                           "pendulum_bar_point_mass.yaml"}) {
    const Model model = Scene(file);
    const NaturalModel nm = Compile(model);
    for (bool sparse : {false, true}) {
      NaturalData data(nm);
      data.sparse = sparse;
      MassMatrix(nm, data);
      GeneralizedForces(nm, data);
      const Eigen::MatrixXd M = sparse ? Eigen::MatrixXd(data.M_sparse) : data.M;
      for (int from : {0, 1000}) {
        const analytic::MassAndForces e = analytic::MassAndForcesByEnergy(model, from);
        const Eigen::MatrixXd Me = e.sparse ? Eigen::MatrixXd(e.M_sparse) : e.M;
        const double dM = (M - Me).cwiseAbs().maxCoeff() / M.cwiseAbs().maxCoeff();
        const double dQ = (data.Q - e.Q).cwiseAbs().maxCoeff() / data.Q.cwiseAbs().maxCoeff();
        EXPECT_LT(dM, 1e-13) << file << " sparse " << sparse << " from " << from;
        EXPECT_LT(dQ, 1e-13) << file << " sparse " << sparse << " from " << from;
      }
    }
  }
  // The block's part: the rocker's slots see its inertia and offset com (the M of the scene
  // without the block differs there, not only on A's slots).
  Model without = Scene("inverted_slider_crank_block_free.yaml");
  without.bodies[without.BodyIndex("block")].mass = 0;
  without.bodies[without.BodyIndex("block")].com_B.setZero();
  without.bodies[without.BodyIndex("block")].inertia_com = 0;
  const Model with = Scene("inverted_slider_crank_block_free.yaml");
  const NaturalModel n0 = Compile(without), n1 = Compile(with);
  NaturalData d0(n0), d1(n1);
  MassMatrix(n0, d0);
  MassMatrix(n1, d1);
  const int xD = with.SlotIndex("xD");
  EXPECT_GT(std::fabs(d1.M(xD, xD) - d0.M(xD, xD)), 1e-4);
}

// (3) A piston of m = 2 kg on the vertical guide, crank driven at ω = 10 rad/s: the power the
// driver supplies, q̇ᵀ(M q̈ − Q), exceeds the massless piston's by m (ÿ_B + g) ẏ_B, with
// y_B = f(θ) = r sin θ + S, S = sqrt(l² − r² cos² θ): ẏ_B = ω f', ÿ_B = ω² f'',
// f' = r cos θ + r² sin θ cos θ / S, f'' = −r sin θ + r² cos 2θ / S − r⁴ sin² θ cos² θ / S³.
// Measured: within 8.9e-15 W of the closed form over the 21 samples (peak 11.8 W).
TEST(NumericPointBody, DrivenPistonAddsItsInertiaForceToTheDrivingPower) {
  const Model heavy = Scene("slider_crank_piston_driven.yaml"), light = Scene("slider_crank_massless_piston_driven.yaml");
  const Result rh = MakeNumericMethod()->Run(heavy), rl = MakeNumericMethod()->Run(light);
  ASSERT_EQ(rh.status, Status::kOk) << rh.reason;
  ASSERT_EQ(rl.status, Status::kOk) << rl.reason;
  ASSERT_EQ(rh.trajectory.size(), rl.trajectory.size());
  const auto power = [](const Model& m, const Sample& s) {
    const NaturalModel nm = Compile(m);
    NaturalData d(nm);
    MassMatrix(nm, d);
    GeneralizedForces(nm, d);
    return s.qd.dot(d.M * s.qdd - d.Q);
  };
  const double r = 0.1, l = 0.4, w = 10, m = 2, g = 9.81, th0 = 30 * 3.14159265358979323846 / 180;
  double worst = 0, peak = 0;
  for (size_t k = 0; k < rh.trajectory.size(); ++k) {
    const double t = rh.trajectory[k].t, th = th0 + w * t, c = std::cos(th), s = std::sin(th);
    const double S = std::sqrt(l * l - r * r * c * c);
    const double f1 = r * c + r * r * s * c / S;
    const double f2 = -r * s + r * r * std::cos(2 * th) / S - std::pow(r, 4) * s * s * c * c / (S * S * S);
    const double expect = m * (w * w * f2 + g) * (w * f1);
    const double got = power(heavy, rh.trajectory[k]) - power(light, rl.trajectory[k]);
    worst = std::max(worst, std::fabs(got - expect));
    peak = std::max(peak, std::fabs(expect));
  }
  std::printf("  driven piston: max |ΔP − m (ÿ_B + g) ẏ_B| = %.2e W (peak %.3g W)\n", worst, peak);
  EXPECT_GT(peak, 10.0);
  EXPECT_LT(worst, 1e-10 * peak);
}

// (4) The free scenes with a piston or a block on a turning guide conserve energy in every
// formulation, and the piston's mass changes the motion (it is not left out). Measured over 1 s
// (piston / inverted; dense and sparse alike): RK4 at 1 ms 4.5e-10 / 1.9e-10 J, DOPRI5 5.1e-8 /
// 1.5e-8, ALI3-P 5.8e-5 / 3.2e-5 (the trapezoidal rule's dissipation), partitioning 5.1e-10 /
// 1.9e-10 J. Bounds leave about a factor 5.
double EnergyBound(const std::string& formulation) {
  if (formulation.rfind("rk4", 0) == 0) return 3e-9;
  if (formulation.rfind("dopri5", 0) == 0) return 3e-7;
  if (formulation.rfind("ali3p", 0) == 0) return 3e-4;
  return 3e-9;
}

TEST(NumericPointBody, FreeScenesWithBlocksConserveEnergy) {
  for (const char* file : {"slider_crank_piston_free.yaml", "inverted_slider_crank_block_free.yaml"}) {
    const Model model = Scene(file);
    for (const Formulation& f : Formulations()) {
      const Result r = f.make()->Run(model);
      ASSERT_EQ(r.status, Status::kOk) << file << " " << f.name << ": " << r.reason;
      const double drift = Get(r, "energy_drift");
      std::printf("  %-40s %-24s energy drift %.2e J\n", file, f.name.c_str(), drift);
      EXPECT_LT(drift, EnergyBound(f.name)) << file << " " << f.name;
    }
  }
  const Result heavy = MakeBaumgarteRk4Method()->Run(Scene("slider_crank_piston_free.yaml"));
  const Result light = MakeBaumgarteRk4Method()->Run(Scene("slider_crank_massless_piston_free.yaml"));
  ASSERT_EQ(heavy.status, Status::kOk);
  ASSERT_EQ(light.status, Status::kOk);
  EXPECT_GT(TrajectoryDifference(heavy, light), 1e-2);
}

}  // namespace
}  // namespace numeric_point_body_test
}  // namespace mechbench::numeric
