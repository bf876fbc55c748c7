// Joint reactions at t0 (issue 4; convention in numeric/reactions.h): a pendulum by hand (in m
// and in mm, at rest and turning), the four formulations against each other and against
// Newton–Euler body by body on the free scenes, and every engine variant against
// dyn-baumgarte-rk4's within a tolerance measured per variant and scene (on §5.1 against the
// scene with the slider block the engines' graph adds; the plain scene's difference is a finding
// below, as are the reasons for each engine's error). MECHBENCH_VERBOSE=1 prints the figures.
#include "mechbench/harness/registry.h"
#include "mechbench/loader.h"
#include "mechbench/numeric/dynamics_methods.h"
#include "mechbench/numeric/forward_dynamics.h"
#include "mechbench/numeric/natural_model.h"
#include "mechbench/references/nfourbar.h"
#include "mechbench/numeric/reactions.h"

#ifdef MECHBENCH_WITH_SIMBODY
#include "mechbench/engines/simbody.h"
#endif
#ifdef MECHBENCH_WITH_ODE
#include "mechbench/engines/ode.h"
#endif
#ifdef MECHBENCH_WITH_BULLET
#include "mechbench/engines/bullet.h"
#endif
#ifdef MECHBENCH_WITH_MUJOCO
#include "mechbench/engines/mujoco.h"
#endif

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <tuple>
#include <vector>

namespace mechbench {
namespace reactions_test {  // this file's own names (the tests build in unity batches)
namespace {

constexpr double kPi = 3.14159265358979323846;

bool Verbose() { return std::getenv("MECHBENCH_VERBOSE") != nullptr; }

Model Load(const std::string& name) { return LoadScenario(ResolveScenario(name)); }

Quantities Reactions(const Result& r) {
  Quantities out;
  for (const auto& [k, v] : r.quantities)
    if (k.rfind("reaction.", 0) == 0) out[k] = v;
  return out;
}

Eigen::Vector2d Get(const Quantities& q, const std::string& point, const std::string& body) {
  const auto x = q.find(numeric::ReactionName(point, body, 0)), y = q.find(numeric::ReactionName(point, body, 1));
  if (x == q.end() || y == q.end()) {
    ADD_FAILURE() << "no reaction at " << point << " on " << body;
    return {kNaN, kNaN};
  }
  return {x->second, y->second};
}

// ---- a pendulum by hand ------------------------------------------------------------------------

// A uniform bar of mass m and length L pinned at O, released at angle θ with rate ω under gravity
// g. About O: I_O α = −m g (L/2) cos θ, I_O = m L²/3, so α = −3 g cos θ / (2 L), whatever ω. Its
// centre of mass accelerates by a_G = α k × r_G − ω² r_G, r_G = (L/2)(cos θ, sin θ), and the pin
// gives R = m a_G − m g.
Eigen::Vector2d PendulumReaction(double m, double L, double th, double w, double g) {
  const double alpha = -3 * g * std::cos(th) / (2 * L);
  const Eigen::Vector2d rG = L / 2 * Eigen::Vector2d(std::cos(th), std::sin(th));
  const Eigen::Vector2d aG = alpha * Eigen::Vector2d(-rG.y(), rG.x()) - w * w * rG;
  return m * aG - m * Eigen::Vector2d(0, -g);
}

// The same pendulum as a scene (m = 3 kg, L = 2 m), at θ = 30° or −110° ("30deg", "minus110deg"),
// lengths in m or mm: tests/data/scenes/pendulum_bar_<angle>[_mm].yaml, released at rate ω.
Model Pendulum(const std::string& angle, const std::string& unit, double w) {
  Model model = LoadScenario(std::string(MECHBENCH_TEST_DATA) + "/scenes/pendulum_bar_" + angle +
                             (unit == "mm" ? "_mm" : "") + ".yaml");
  model.initial.at(0).velocity = w;  // [rad/s]
  return model;
}

TEST(ReactionsNumeric, PendulumByHand) {
  const double m = 3, L = 2, g = 9.81;
  for (const auto& [unit, k] : {std::pair{std::string("m"), 1.0}, std::pair{std::string("mm"), 1e3}})
    for (const auto& [angle, th_deg] :
         {std::pair{std::string("30deg"), 30.0}, std::pair{std::string("minus110deg"), -110.0}})
      for (const double w : {0.0, 2.5}) {
        SCOPED_TRACE(unit + " θ = " + std::to_string(th_deg) + " ω = " + std::to_string(w));
        const Model model = Pendulum(angle, unit, w);
        // The file holds the pendulum the formula is given.
        ASSERT_EQ(model.length_unit, unit);
        ASSERT_EQ(model.bodies.size(), 1u);
        ASSERT_EQ(model.bodies[0].mass, m);
        ASSERT_NEAR(model.bodies[0].Length(), k * L, 1e-12 * k);
        ASSERT_NEAR(model.gravity.y(), -g * k, 1e-12 * k);
        ASSERT_NEAR(model.initial.at(0).value, th_deg * kPi / 180, 1e-15);
        const Eigen::Vector2d expect = PendulumReaction(m, L, th_deg * kPi / 180, w, g);
        for (const auto& meth : {numeric::MakeBaumgarteRk4Method(), numeric::MakeAli3pMethod()}) {
          const Result r = meth->Run(model, {.motion = false});
          ASSERT_TRUE(r.ok()) << r.reason;
          const Quantities q = Reactions(r);
          EXPECT_EQ(q.size(), 2u) << "only the pin O: point 1 is a free end";
          const Eigen::Vector2d got = Get(q, "O", "bar");
          EXPECT_LT((got - expect).norm(), 1e-10 * expect.norm()) << got.transpose() << " vs " << expect.transpose();
        }
      }
}

// ---- the formulations on the free scenes -------------------------------------------------------

std::vector<std::unique_ptr<Method>> Formulations() {
  std::vector<std::unique_ptr<Method>> out;
  out.push_back(numeric::MakeBaumgarteRk4Method());
  out.push_back(numeric::MakeBaumgarteDopri5Method());
  out.push_back(numeric::MakeAli3pMethod());
  out.push_back(numeric::MakeCoordinatePartitioningMethod());
  return out;
}

// Newton–Euler on each body from the t0 state (q, q̈ of the result): Σ pin forces + weight +
// applied forces = m a_G, and their moments about G = I_G α. `unknown` [body] is the direction of
// an unreported force (a slider guide's normal): the balance is then checked across it only, and
// the moments not at all. Returns the largest residual over the scale of the forces.
double NewtonEulerResidual(const Model& model, const Result& r, const std::map<std::string, Eigen::Vector2d>& unknown) {
  const numeric::NaturalModel nm = numeric::Compile(model);
  Eigen::VectorXd q(nm.n), qdd(nm.n);
  for (int s = 0; s < nm.n; ++s) {
    q[s] = r.quantities.at("q." + model.q_layout[s].name);
    qdd[s] = r.quantities.at("qdd." + model.q_layout[s].name);
  }
  auto point = [&](const Eigen::VectorXd& v, int p, bool acc) {
    Eigen::Vector2d out;
    for (int a = 0; a < 2; ++a) {
      const int s = nm.point_slot[p][a];
      out[a] = s >= 0 ? v[s] : (acc ? 0.0 : nm.point_const[p][a]);
    }
    return out;
  };
  const double u = nm.meters_per_unit;
  const Quantities reac = Reactions(r);
  double scale = 0, worst = 0;
  for (const auto& [k, v] : reac) scale = std::max(scale, std::fabs(v));
  for (const Body& b : model.bodies) {
    const Eigen::Vector2d r0 = point(q, b.points[0], false), r1 = point(q, b.points[1], false);
    const Eigen::Vector2d a0 = point(qdd, b.points[0], true), a1 = point(qdd, b.points[1], true);
    const Eigen::Vector2d d = r1 - r0, ex = d / b.Length(), ey(-ex.y(), ex.x());
    const Eigen::Vector2d rG = r0 + b.com_B.x() * ex + b.com_B.y() * ey;
    const double alpha = (d.x() * (a1 - a0).y() - d.y() * (a1 - a0).x()) / d.squaredNorm();
    const double cx = b.com_B.x() / b.Length(), cy = b.com_B.y() / b.Length();
    // a_G = C(com) [a0; a1] (dynamics.h)
    const Eigen::Vector2d aG((1 - cx) * a0.x() + cy * a0.y() + cx * a1.x() - cy * a1.y(),
                             -cy * a0.x() + (1 - cx) * a0.y() + cy * a1.x() + cx * a1.y());
    Eigen::Vector2d F = b.mass * model.gravity * u;
    double M = 0;
    for (int p : b.points) {
      Eigen::Vector2d f = Eigen::Vector2d::Zero();
      const std::string name = numeric::ReactionName(model.points[p].name, b.name, 0);
      if (reac.count(name)) f += Get(reac, model.points[p].name, b.name);
      for (const PointForce& pf : model.forces)
        if (pf.point == p) {
          // An applied force on a shared point acts on the first body that holds it (reactions.h).
          for (const Body& first : model.bodies)
            if (std::find(first.points.begin(), first.points.end(), p) != first.points.end()) {
              if (&first == &b) f += pf.f_W;
              break;
            }
        }
      F += f;
      const Eigen::Vector2d arm = (point(q, p, false) - rG) * u;
      M += arm.x() * f.y() - arm.y() * f.x();
    }
    const Eigen::Vector2d lin = F - b.mass * aG * u;
    const double rot = M - b.inertia_com * u * u * alpha;
    double res;
    if (const auto it = unknown.find(b.name); it != unknown.end()) {
      const Eigen::Vector2d n = it->second.normalized();
      res = std::fabs(lin.dot(Eigen::Vector2d(-n.y(), n.x())));
    } else {
      res = std::max(lin.norm(), std::fabs(rot) / (b.Length() * u));
    }
    worst = std::max(worst, res / scale);
    if (Verbose()) std::printf("  %s: Newton–Euler residual %.3g N (scale %.3g N)\n", b.name.c_str(), res, scale);
  }
  return worst;
}

class ReactionsFree : public ::testing::TestWithParam<std::string> {};

// The four formulations start from the same index-1 q̈ and λ (dynamics_methods.cc), so their
// reactions are the same numbers; the pin forces balance every body (Newton–Euler, 1e-12 of the
// largest reaction), and the pair at a shared pin is equal and opposite.
TEST_P(ReactionsFree, FormulationsAgreeAndBalance) {
  const Model model = Load(GetParam());
  Quantities first;
  for (const auto& meth : Formulations()) {
    SCOPED_TRACE(meth->name());
    const Result r = meth->Run(model, {.motion = false});
    ASSERT_TRUE(r.ok()) << r.reason;
    const Quantities q = Reactions(r);
    ASSERT_FALSE(q.empty()) << r.settings.at("reactions");
    if (first.empty()) {
      first = q;
      // s5_1's bar: the bushing's guide (y = const) pushes along y, which no pin reports.
      const double res = NewtonEulerResidual(model, r, {{"bar", Eigen::Vector2d(0, 1)}});
      EXPECT_LT(res, 1e-12);
      if (Verbose()) {
        std::printf("%s %s: Newton–Euler %.3g\n", GetParam().c_str(), meth->name().c_str(), res);
        for (const auto& [k, v] : q) std::printf("  %s = %.12g\n", k.c_str(), v);
      }
    } else {
      ASSERT_EQ(q.size(), first.size());
      for (const auto& [k, v] : first) EXPECT_EQ(q.at(k), v) << k;
    }
  }
  // Equal and opposite at every pin two bodies share.
  double scale = 0;
  for (const auto& [k, v] : first) scale = std::max(scale, std::fabs(v));
  for (size_t p = 0; p < model.points.size(); ++p) {
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    int n = 0;
    for (const Body& b : model.bodies)
      if (first.count(numeric::ReactionName(model.points[p].name, b.name, 0))) {
        sum += Get(first, model.points[p].name, b.name);
        ++n;
      }
    if (n >= 2 && !model.points[p].fixed) {
      EXPECT_LT(sum.norm(), 1e-12 * scale) << model.points[p].name;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Scenes, ReactionsFree, ::testing::Values("fourbar_free", "s5_1_disc_bar_bushing"));

// The pins the convention reports on the two scenes, and what it leaves out.
TEST(ReactionsNumeric, PinsOfTheFreeScenes) {
  const Result four = numeric::MakeBaumgarteRk4Method()->Run(Load("fourbar_free"), {.motion = false});
  std::vector<std::string> keys;
  for (const auto& [k, v] : Reactions(four)) keys.push_back(k);
  EXPECT_EQ(keys, (std::vector<std::string>{"reaction.1.coupler.x", "reaction.1.coupler.y", "reaction.1.crank.x",
                                            "reaction.1.crank.y", "reaction.2.coupler.x", "reaction.2.coupler.y",
                                            "reaction.2.rocker.x", "reaction.2.rocker.y", "reaction.A.crank.x",
                                            "reaction.A.crank.y", "reaction.B.rocker.x", "reaction.B.rocker.y"}));
  const Result disc = numeric::MakeBaumgarteRk4Method()->Run(Load("s5_1_disc_bar_bushing"), {.motion = false});
  keys.clear();
  for (const auto& [k, v] : Reactions(disc)) keys.push_back(k);
  // Point 2 is the bushing's: a slider point, left out (it is no pin of two model bodies anyway).
  EXPECT_EQ(keys, (std::vector<std::string>{"reaction.1.bar.x", "reaction.1.bar.y", "reaction.1.disc.x",
                                            "reaction.1.disc.y", "reaction.O2.disc.x", "reaction.O2.disc.y"}));
}

// ---- engines -----------------------------------------------------------------------------------

std::vector<MethodPtr> EngineVariants() { return harness::EngineMethods(); }

// A rack coupling's tooth force (tests/data/scenes/rack_pinion_spring_user.yaml): by hand the
// pinion's pin carries its weight 19.62 N and the tooth force m_rack (g + a) = 4.905 N. Natural
// coordinates have no pitch point (the coupling row ties θ to the rack's travel: its force is no
// pin's) and every engine couples two joint coordinates (Simbody's CoordinateCoupler, MuJoCo's
// joint equality, btMultiBodyGearConstraint), so none can tell the tooth force apart from the
// pin's reaction: each leaves the pin out with its reason, instead of Simbody and MuJoCo giving
// 19.62 N and btMultiBody 24.525 N as before.
TEST(ReactionsCoupling, APinOfACoupledBodyIsLeftOutByEveryMethodWithItsReason) {
  const Model m = LoadScenario(std::string(MECHBENCH_TEST_DATA) + "/scenes/rack_pinion_spring_user.yaml");
  ASSERT_FALSE(m.couplings.empty());
  std::vector<MethodPtr> methods;
  methods.push_back(numeric::MakeBaumgarteRk4Method());
  for (auto& e : EngineVariants()) methods.push_back(std::move(e));
  int engines = 0;
  for (const MethodPtr& meth : methods) {
    if (meth->Applicability(m)) continue;  // no rack in ODE, Bullet's btRigidBody
    SCOPED_TRACE(meth->name());
    const Result r = meth->Run(m, {.motion = false});
    ASSERT_TRUE(r.ok()) << r.reason;
    EXPECT_EQ(r.quantities.count("reaction.O.pinion.y"), 0u) << r.quantities.at("reaction.O.pinion.y");
    EXPECT_EQ(r.quantities.count("reaction.O.pinion.x"), 0u);
    const auto text = r.settings.find("reactions");
    ASSERT_NE(text, r.settings.end());
    const bool engine = meth->name() != "dyn-baumgarte-rk4";
    engines += engine;
    EXPECT_NE(text->second.find(engine ? "left out: body pinion at O: rack yR1 by theta" : "left out: rack yR1 by theta"),
              std::string::npos)
        << text->second;
    // The rack's slider point is no pin: no reaction, and the reason (numeric; engines not yet
    // asserted: a translating link's second slider is dropped as redundant and names no point).
    if (!engine) {
      EXPECT_EQ(r.quantities.count("reaction.R1.rack.x"), 0u);
      EXPECT_NE(text->second.find("left out: point R1: a slider's point (sliders are left out"), std::string::npos)
          << text->second;
    }
  }
  if (engines == 0) GTEST_SKIP() << "no engine with couplings is built";
}

std::vector<std::string> VariantNames() {
  std::vector<std::string> out;
  for (const auto& m : EngineVariants()) out.push_back(m->name());
  return out;
}

// Largest |Δ| over the reference's reactions ÷ the largest reference reaction; NaN when a key is
// missing on either side.
double RelativeError(const Quantities& ref, const Quantities& got) {
  double diff = 0, scale = 0;
  for (const auto& [k, v] : ref) {
    const auto it = got.find(k);
    if (it == got.end()) return kNaN;
    diff = std::max(diff, std::fabs(it->second - v));
    scale = std::max(scale, std::fabs(v));
  }
  return got.size() == ref.size() ? diff / scale : kNaN;
}

// §5.1 as the engines simulate it (tests/data/scenes/s5_1_disc_bar_bushing_with_block.yaml): the
// graph gives the bushing a slider block of 1e-2 × the lightest link's mass
// (graph.block_mass_ratio: 0.01 kg) at point 2, which the natural-coordinate scene does not have.
// Here it is a body of two points on the guide (so that it only slides); its points are slider
// points, so it adds no reaction quantity.
Model BushingWithBlock() {
  return LoadScenario(std::string(MECHBENCH_TEST_DATA) + "/scenes/s5_1_disc_bar_bushing_with_block.yaml");
}

// The formulations' reactions of the scene the engines simulate.
Result EngineReference(const std::string& scene) {
  const Model m = scene == "s5_1_disc_bar_bushing" ? BushingWithBlock() : Load(scene);
  return numeric::MakeBaumgarteRk4Method()->Run(m, {.motion = false});
}

// Relative tolerance on the largest reaction, per (variant, scene), measured (RelWithDebInfo) at
// the variants' own settings from t0 (Method::Run with motion = false; ODE and Bullet take their
// first step for the forces). Filled in below.
double Tolerance(const std::string& variant, const std::string& scene);

class ReactionsEngine : public ::testing::TestWithParam<std::tuple<std::string, std::string>> {};

TEST_P(ReactionsEngine, AgreesWithTheFormulations) {
  const std::string& scene = std::get<0>(GetParam());
  const std::string& variant = std::get<1>(GetParam());  // a plain reference: a lambda captures it
  const Model model = Load(scene);
  const Result ref = EngineReference(scene);
  ASSERT_TRUE(ref.ok()) << ref.reason;
  const auto all = EngineVariants();
  const auto it = std::find_if(all.begin(), all.end(), [&](const MethodPtr& m) { return m->name() == variant; });
  ASSERT_NE(it, all.end());
  const Method& meth = **it;
  if (auto why = meth.Applicability(model)) GTEST_SKIP() << *why;
  const Result r = meth.Run(model, {.motion = false});
  ASSERT_TRUE(r.ok()) << r.reason;
  ASSERT_TRUE(r.settings.count("reactions")) << "no settings[\"reactions\"]";
  const Quantities got = Reactions(r);
  const double e = RelativeError(Reactions(ref), got);
  if (Verbose()) {
    std::printf("%s %s: relative error %.3g\n  %s\n", scene.c_str(), variant.c_str(), e, r.settings.at("reactions").c_str());
    for (const auto& [k, v] : got)
      std::printf("  %s = %.10g (ref %.10g)\n", k.c_str(), v, ref.quantities.count(k) ? ref.quantities.at(k) : kNaN);
  }
  ASSERT_TRUE(std::isfinite(e)) << "the reported reactions differ in their pins: " << r.settings.at("reactions");
  EXPECT_LE(e, Tolerance(variant, scene));
  // The full motion reports the same t0 forces (ODE and Bullet: of the same first step, whose h may
  // differ in its last bit: it is the sample interval over the number of steps).
  const Result full = meth.Run(model);
  ASSERT_TRUE(full.ok()) << full.reason;
  EXPECT_LE(RelativeError(got, Reactions(full)), 1e-9);
}

// A point load is given in newtons whatever the scene's length unit; an engine works in kg and the
// scene's length, so the graph hands it over as N / meters_per_unit. The same loaded pendulum in
// m and in mm must swing alike (before this was fixed the mm load was 1000× too weak).
TEST(EngineUnits, APointLoadInNewtonsActsAlikeInMetresAndMillimetres) {
  const auto loaded = [](const std::string& unit) {
    Model model = Pendulum("30deg", unit, 0);
    // [N] on point 1, about 1.4 × the weight's moment: a load the tests add to the scene.
    PointForce load;
    load.point = model.PointIndex("1");
    load.f_W = {-40, 0};
    model.forces.push_back(load);
    return model;
  };
  const Model m = loaded("m"), mm = loaded("mm");
  int checked = 0;
  for (const MethodPtr& meth : EngineVariants()) {
    SCOPED_TRACE(meth->name());
    if (meth->Applicability(m)) continue;
    const Result a = meth->Run(m), b = meth->Run(mm);
    ASSERT_TRUE(a.ok() && b.ok()) << a.reason << b.reason;
    const int th = m.SlotIndex("theta");
    ASSERT_GE(th, 0);
    const double swing = a.trajectory.back().q[th] - a.trajectory.front().q[th];
    EXPECT_GT(std::fabs(swing), 1e-3);  // the load moves it
    EXPECT_NEAR(b.trajectory.back().q[th], a.trajectory.back().q[th], 1e-6 * std::fabs(swing));
    ++checked;
  }
  if (checked == 0) GTEST_SKIP() << "no engine built";
}

// FINDING (understood, kept visible): on §5.1 the engines' reactions differ from the
// formulations' by 1.5e-4 of the largest reaction, Simbody's exact ones included (measured
// 1.48e-4): the slider block the graph adds (BushingWithBlock). With that block in the formulations'
// scene, Simbody agrees to round-off (measured 1.4e-16).
#ifdef MECHBENCH_WITH_SIMBODY
TEST(ReactionsEngineFinding, SliderBlockExplainsTheBushingDifference) {
  const auto all = EngineVariants();
  const auto it = std::find_if(all.begin(), all.end(), [](const MethodPtr& m) { return m->name() == "simbody-rkmerson-tuned"; });
  ASSERT_NE(it, all.end());
  const Result simbody = (*it)->Run(Load("s5_1_disc_bar_bushing"), {.motion = false});
  ASSERT_TRUE(simbody.ok()) << simbody.reason;
  const Result plain = numeric::MakeBaumgarteRk4Method()->Run(Load("s5_1_disc_bar_bushing"), {.motion = false});
  const Result block = EngineReference("s5_1_disc_bar_bushing");
  ASSERT_TRUE(plain.ok() && block.ok());
  const double e_plain = RelativeError(Reactions(plain), Reactions(simbody));
  const double e_block = RelativeError(Reactions(block), Reactions(simbody));
  if (Verbose()) std::printf("s5_1: Simbody against the formulations %.3g, with the slider block %.3g\n", e_plain, e_block);
  EXPECT_GT(e_plain, 1e-4);
  EXPECT_LT(e_plain, 2e-4);
  EXPECT_LE(e_block, 1e-12);
}
#endif

#ifdef MECHBENCH_WITH_ODE
// ODE's forces are its first step's, and its rows are softened by CFM: (J M⁻¹ Jᵀ + CFM/h) λ = …,
// an error ∝ CFM/h (measured 1.07e-6 at h = 1 ms, 1.07e-5 at 0.1 ms with ODE's CFM 1e-10). With
// CFM 0 the first step from rest gives the t0 forces but for ERP × the assembly residual / h²
// (measured 2.6e-12 at 1 ms, 2.6e-10 at 0.1 ms).
TEST(ReactionsEngineFinding, OdeErrorIsItsCfm) {
  const Model m = Load("fourbar_free");
  const Result ref = EngineReference("fourbar_free");
  for (const double h : {1e-3, 1e-4}) {
    engines::OdeOptions o;
    o.name = "ode-worldstep-cfm0";
    o.step = h;
    o.cfm = 0;
    const Result r = engines::MakeOdeMethod(o)->Run(m, {.motion = false});
    ASSERT_TRUE(r.ok()) << r.reason;
    const double e = RelativeError(Reactions(ref), Reactions(r));
    if (Verbose()) std::printf("ode-worldstep CFM 0, h = %g: %.3g\n", h, e);
    EXPECT_LE(e, 1e-9);
  }
}
#endif

#ifdef MECHBENCH_WITH_BULLET
// btRigidBody's forces are the first step's sequential-impulse (PGS) result: on §5.1 (disc 10 kg,
// bar 1 kg, block 0.01 kg) 100 iterations leave 2.45e-3, 1000 converge (measured 3.3e-14).
TEST(ReactionsEngineFinding, BulletRigidBodyErrorIsItsIterations) {
  const Model m = Load("s5_1_disc_bar_bushing");
  const Result ref = EngineReference("s5_1_disc_bar_bushing");
  engines::BulletOptions o{"bullet-rigidbody-1000", false, 1e-3, 1000, -1, -1};
  const Result r = engines::MakeBulletMethod(o)->Run(m, {.motion = false});
  ASSERT_TRUE(r.ok()) << r.reason;
  const double e = RelativeError(Reactions(ref), Reactions(r));
  if (Verbose()) std::printf("bullet-rigidbody 1000 iterations on s5_1: %.3g\n", e);
  EXPECT_LE(e, 1e-12);
}

// btMultiBody's tree-joint forces come from btMultiBodyJointFeedback, whose constraint pass runs
// the articulated-body recursion again at the step's unconstrained velocities v0 + h a (O(h)),
// with their velocity-product terms (btMultiBody.cpp: zeroAccSpatFrc from spatVel in either
// pass): an error that falls as h² and does not depend on the iterations. Measured on §5.1:
// 1.65e-5 at 1 ms (10 or 100 iterations alike), 1.65e-7 at 0.1 ms.
TEST(ReactionsEngineFinding, BulletMultiBodyErrorIsSecondOrderInH) {
  const Model m = Load("s5_1_disc_bar_bushing");
  const Result ref = EngineReference("s5_1_disc_bar_bushing");
  auto error = [&](double h, int iterations) {
    engines::BulletOptions o{"bullet-multibody-x", true, h, iterations, -1, -1};
    const Result r = engines::MakeBulletMethod(o)->Run(m, {.motion = false});
    EXPECT_TRUE(r.ok()) << r.reason;
    return RelativeError(Reactions(ref), Reactions(r));
  };
  const double e10 = error(1e-3, 10), e100 = error(1e-3, 100), e_half = error(1e-4, 10);
  if (Verbose()) std::printf("bullet-multibody on s5_1: %.3g (10 it.), %.3g (100 it.), %.3g at 0.1 ms\n", e10, e100, e_half);
  EXPECT_NEAR(e100 / e10, 1.0, 0.05);
  EXPECT_GT(e10 / e_half, 80);
  EXPECT_LT(e10 / e_half, 120);
}
#endif

#ifdef MECHBENCH_WITH_MUJOCO
// MuJoCo's connect equality is soft: impedance d (solimp) leaves a regularisation (1 − d)/d of the
// constraint's inertia, and the forces' error follows 1 − d (measured on the four-bar, RK4 at
// 0.1 ms: 1.14e-3 at d = 0.99, 1.13e-4 at 0.999) down to MuJoCo's largest impedance mjMAXIMP =
// 0.9999 (1.13e-5; any larger d is clamped to it: the tuned variant's floor).
TEST(ReactionsEngineFinding, MujocoErrorIsItsImpedance) {
  const Model m = Load("fourbar_free");
  const Result ref = EngineReference("fourbar_free");
  auto error = [&](double d) {
    engines::MujocoOptions o;
    o.name = "mujoco-rk4-d";
    o.integrator = "RK4";
    o.step = 1e-4;
    o.solref = {2e-4, 1.0};
    o.solimp = {d, d, 0.001, 0.5, 2.0};
    o.tolerance = 1e-12;
    const Result r = engines::MakeMujocoMethod(o)->Run(m, {.motion = false});
    EXPECT_TRUE(r.ok()) << r.reason;
    return RelativeError(Reactions(ref), Reactions(r));
  };
  const double e2 = error(0.99), e3 = error(0.999), e4 = error(0.9999), e5 = error(0.99999);
  if (Verbose()) std::printf("mujoco impedance 0.99 … 0.99999: %.3g %.3g %.3g %.3g\n", e2, e3, e4, e5);
  EXPECT_NEAR(e2 / e3, 10, 1);
  EXPECT_NEAR(e3 / e4, 10, 1);
  EXPECT_NEAR(e5 / e4, 1.0, 1e-6);
}
#endif

// A moving start: the N-four-bar (N = 3) with P0 at 1 m/s, its vertical bars turning at 1 rad/s.
// The formulations balance every body (velocity terms included) and Simbody, which realizes t0
// exactly, agrees to round-off (measured 9.8e-17 and 2.0e-16). FINDING (understood, kept
// visible): an engine whose forces are its first step's (ODE, Bullet) enforces J v_1 = 0 at the
// velocity level, which leaves out the J̇ q̇ part of the constraint forces (here the bars'
// centripetal pull): measured 8.3e-2 for ode-worldstep-default, 4.1e-2 for bullet-multibody-default
// (its tree joints' articulated-body pass has them, its loop closure not), 8.3e-2 for
// bullet-rigidbody-tuned. Their settings["reactions"] say whether the scene starts at rest.
TEST(ReactionsEngineFinding, MovingStart) {
  references::NFourBarOptions o;
  o.n = 3;
  const Model m = references::NFourBar(o);
  const Result ref = numeric::MakeBaumgarteRk4Method()->Run(m, {.motion = false});
  ASSERT_TRUE(ref.ok()) << ref.reason;
  EXPECT_EQ(Reactions(ref).size(), 28u);  // 7 bars, each pinned at both ends
  EXPECT_LT(NewtonEulerResidual(m, ref, {}), 1e-12);
  const std::map<std::string, std::pair<double, double>> expect{{"simbody-rkmerson-tuned", {0, 1e-13}},
                                                                {"ode-worldstep-default", {0.06, 0.11}},
                                                                {"bullet-multibody-default", {0.03, 0.06}},
                                                                {"bullet-rigidbody-tuned", {0.06, 0.11}}};
  for (const auto& meth : EngineVariants()) {
    const auto it = expect.find(meth->name());
    if (it == expect.end()) continue;
    const Result r = meth->Run(m, {.motion = false});
    ASSERT_TRUE(r.ok()) << r.reason;
    const double e = RelativeError(Reactions(ref), Reactions(r));
    if (Verbose()) std::printf("N-four-bar (moving start) %s: %.3g\n", meth->name().c_str(), e);
    EXPECT_GE(e, it->second.first) << meth->name();
    EXPECT_LE(e, it->second.second) << meth->name();
  }
}

std::string SceneVariantName(const ::testing::TestParamInfo<std::tuple<std::string, std::string>>& info) {
  std::string s = std::get<0>(info.param) + "_" + std::get<1>(info.param);
  std::replace(s.begin(), s.end(), '-', '_');
  return s;
}

INSTANTIATE_TEST_SUITE_P(Scenes, ReactionsEngine,
                         ::testing::Combine(::testing::Values("fourbar_free", "s5_1_disc_bar_bushing"),
                                            ::testing::ValuesIn(VariantNames())),
                         SceneVariantName);
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(ReactionsEngine);


// Measured relative error on the largest reaction (RelWithDebInfo; fourbar_free | §5.1 against
// the scene with the engines' slider block) and the bound kept, about 3× above:
//   simbody-rkmerson-*        1.8e-16 | 1.4e-16   exact (Acceleration stage, not integrated)
//   ode-worldstep-default     1.07e-6 | 1.03e-6   CFM 1e-10 softens the first step's rows ∝ CFM/h
//   ode-worldstep-tuned       1.07e-5 | 1.03e-5   the same at h = 0.1 ms (OdeErrorIsItsCfm)
//   ode-quickstep-default     3.5e-3  | 1.5e-2    20 QuickStep iterations do not converge
//   ode-quickstep-tuned       1.07e-5 | 1.21e-5   200 iterations: CFM/h again
//   bullet-multibody-default  4.5e-7  | 1.65e-5   joint-feedback pass at O(h) velocities (BulletMultiBody…)
//   bullet-multibody-tuned    4.3e-9  | 1.65e-7   the same at h = 0.1 ms
//   bullet-rigidbody-default  6.6e-2  | 3.1e-2    10 sequential-impulse iterations do not converge
//   bullet-rigidbody-tuned    5.5e-10 | 2.4e-3    100 do on the four-bar, not on §5.1's 1000:1 masses
//   mujoco-euler-default      1.2e-2  | 2.2e-2    soft connect equality, impedance 0.9 (solimp)
//   mujoco-rk4-tuned          1.13e-5 | 4.55e-5   impedance 0.9999, MuJoCo's largest (mjMAXIMP)
double Tolerance(const std::string& variant, const std::string& scene) {
  static const std::map<std::string, std::pair<double, double>> kBound{
      {"simbody-rkmerson-default", {1e-13, 1e-13}}, {"simbody-rkmerson-tuned", {1e-13, 1e-13}},
      {"ode-worldstep-default", {3e-6, 3e-6}},      {"ode-worldstep-tuned", {3e-5, 3e-5}},
      {"ode-quickstep-default", {1e-2, 5e-2}},      {"ode-quickstep-tuned", {3e-5, 4e-5}},
      {"bullet-multibody-default", {1.5e-6, 5e-5}}, {"bullet-multibody-tuned", {1.5e-8, 5e-7}},
      {"bullet-rigidbody-default", {0.2, 0.1}},     {"bullet-rigidbody-tuned", {2e-9, 1e-2}},
      {"mujoco-euler-default", {4e-2, 6e-2}},       {"mujoco-rk4-tuned", {3e-5, 1.5e-4}}};
  const auto it = kBound.find(variant);
  if (it == kBound.end()) {
    ADD_FAILURE() << "no tolerance measured for " << variant;
    return 0;
  }
  return scene == "fourbar_free" ? it->second.first : it->second.second;
}

}  // namespace
}  // namespace reactions_test
}  // namespace mechbench
