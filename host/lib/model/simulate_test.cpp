// Time simulation against closed-form responses, scipy.signal.lsim, convergence orders, and
// hand-derived Coulomb friction cases.
#include "vibid/model/simulate.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <string>

#include "test_support.hpp"
#include "vibid/common/error.hpp"
#include "vibid/model/frf.hpp"

namespace vibid::model {
namespace {

using testing::Golden;
using testing::JsonMatrix;
using testing::JsonVector;

constexpr double kPi = std::numbers::pi;

// m = 2 kg, k = 5000 N/m, c = 4 N·s/m: ωn = 50 rad/s, ζ = 0.02.
Model OneDof() {
  return MakeChain(Eigen::VectorXd::Constant(1, 2.0), Eigen::VectorXd::Constant(1, 5000.0),
                   Eigen::VectorXd::Constant(1, 4.0));
}
constexpr double kWn = 50.0;
constexpr double kZeta = 0.02;
constexpr double kK = 5000.0;

// Free response from (x0, v0): e^{−ζωt}(x0 cos ωd t + (v0 + ζω x0)/ωd sin ωd t).
double FreeResponse(double t, double x0, double v0) {
  const double wd = kWn * std::sqrt(1.0 - kZeta * kZeta);
  return std::exp(-kZeta * kWn * t) *
         (x0 * std::cos(wd * t) + (v0 + kZeta * kWn * x0) / wd * std::sin(wd * t));
}

ForceInput Shapes(std::initializer_list<const char*> specs) {
  ForceInput input;
  for (const char* s : specs) input.shapes.push_back(ParseForceShape(s));
  return input;
}

SimulationOptions Options(Method method, double dt_s, double t_end_s) {
  SimulationOptions o;
  o.method = method;
  o.dt_s = dt_s;
  o.t_end_s = t_end_s;
  return o;
}

TEST(Simulate, ExactMatchesTheAnalyticStepResponseToOneInABillion) {
  // x(t) = F/k [1 − e^{−ζωt}(cos ωd t + ζ/√(1−ζ²) sin ωd t)], v(t) = F/k ωn/√(1−ζ²) e^{−ζωt} sin ωd
  // t.
  const double force = 5.0;
  const SimulationResult r =
      Simulate(OneDof(), Shapes({"step:dof=1,amp=5"}), Options(Method::kExact, 1e-3, 2.0));
  ASSERT_EQ(r.t_s.size(), 2001);
  const double wd = kWn * std::sqrt(1.0 - kZeta * kZeta);
  double worst_x = 0.0, worst_v = 0.0;
  for (Eigen::Index i = 0; i < r.t_s.size(); ++i) {
    const double t = r.t_s[i];
    const double decay = std::exp(-kZeta * kWn * t);
    const double x = force / kK *
                     (1.0 - decay * (std::cos(wd * t) +
                                     kZeta / std::sqrt(1.0 - kZeta * kZeta) * std::sin(wd * t)));
    const double v = force / kK * kWn / std::sqrt(1.0 - kZeta * kZeta) * decay * std::sin(wd * t);
    worst_x = std::max(worst_x, std::abs(r.x_m(i, 0) - x));
    worst_v = std::max(worst_v, std::abs(r.v_m_s(i, 0) - v));
  }
  EXPECT_LT(worst_x, 1e-9 * force / kK);
  EXPECT_LT(worst_v, 1e-9 * force / kK * kWn);
  // a from the equation of motion: (F − c v − k x)/m.
  EXPECT_NEAR(r.a_m_s2(100, 0), (5.0 - 4.0 * r.v_m_s(100, 0) - kK * r.x_m(100, 0)) / 2.0, 1e-12);
  EXPECT_EQ(r.force_n(0, 0), 5.0);
}

TEST(Simulate, FreeResponseExactAndRk4) {
  SimulationOptions o = Options(Method::kExact, 1e-3, 1.0);
  o.x0_m = Eigen::VectorXd::Constant(1, 0.01);
  o.v0_m_s = Eigen::VectorXd::Constant(1, -0.2);
  for (const Method method : {Method::kExact, Method::kRk4}) {
    o.method = method;
    const SimulationResult r = Simulate(OneDof(), ForceInput{}, o);
    double worst = 0.0;
    for (Eigen::Index i = 0; i < r.t_s.size(); ++i)
      worst = std::max(worst, std::abs(r.x_m(i, 0) - FreeResponse(r.t_s[i], 0.01, -0.2)));
    // RK4 at ωn dt = 0.05: global error ~ (ωn dt)^4 / 120 per radian of phase.
    EXPECT_LT(worst, method == Method::kExact ? 1e-13 : 1e-7) << MethodName(method);
  }
}

TEST(Simulate, ForcedSineSettlesToTheFrfAmplitudeAndPhase) {
  // Steady state x = |H| F sin(ωt + ∠H); transients decay as e^{−ζωn t} (1/s time constant).
  const double f_hz = 6.0, amp = 3.0, w = 2.0 * kPi * f_hz;
  const SimulationResult r =
      Simulate(OneDof(), Shapes({"sine:dof=1,amp=3,freq_hz=6"}), Options(Method::kRk4, 2e-4, 30.0));
  const std::complex<double> h =
      Frf(OneDof(), 0, 0, FrfKind::kReceptance, Eigen::VectorXd::Constant(1, w))[0];
  double worst = 0.0;
  for (Eigen::Index i = r.t_s.size() - 5000; i < r.t_s.size(); ++i) {
    worst = std::max(
        worst, std::abs(r.x_m(i, 0) - amp * std::abs(h) * std::sin(w * r.t_s[i] + std::arg(h))));
  }
  EXPECT_LT(worst, 1e-7 * amp * std::abs(h));
}

// Largest deviation from the closed-form free response over one second.
double MaxError(Method method, double dt) {
  SimulationOptions o = Options(method, dt, 1.0);
  o.x0_m = Eigen::VectorXd::Constant(1, 0.01);
  const SimulationResult r = Simulate(OneDof(), ForceInput{}, o);
  EXPECT_NEAR(r.t_s[r.t_s.size() - 1], 1.0, 1e-12);
  double worst = 0.0;
  for (Eigen::Index i = 0; i < r.t_s.size(); ++i)
    worst = std::max(worst, std::abs(r.x_m(i, 0) - FreeResponse(r.t_s[i], 0.01, 0.0)));
  return worst;
}

TEST(Simulate, Rk4IsFourthOrder) {
  // Halving dt divides the error by 2^4 = 16.
  const double e1 = MaxError(Method::kRk4, 4e-3);
  const double e2 = MaxError(Method::kRk4, 2e-3);
  const double e3 = MaxError(Method::kRk4, 1e-3);
  EXPECT_NEAR(e1 / e2, 16.0, 1.0);
  EXPECT_NEAR(e2 / e3, 16.0, 0.5);
}

TEST(Simulate, EulerIsFirstOrder) {
  // Halving dt halves the error.
  const double e1 = MaxError(Method::kEuler, 1e-4);
  const double e2 = MaxError(Method::kEuler, 5e-5);
  EXPECT_NEAR(e1 / e2, 2.0, 0.1);
}

TEST(Simulate, ExactMatchesScipyLsimWithAForceTable) {
  const auto& g = Golden().at("lsim");  // scipy.signal.lsim(interp=False), model_golden.py
  const Model m = testing::JsonModel(g);
  ForceInput input;
  input.table.t_s = JsonVector(g.at("t_s"));
  input.table.force_n = JsonMatrix(g.at("force_n"));
  const double dt = g.at("dt_s").get<double>();
  SimulationOptions o = Options(Method::kExact, dt, input.table.t_s[input.table.t_s.size() - 1]);
  o.x0_m = JsonVector(g.at("x0_m"));
  o.v0_m_s = JsonVector(g.at("v0_m_s"));
  const SimulationResult r = Simulate(m, input, o);
  const Eigen::MatrixXd expected = JsonMatrix(g.at("x_m"));
  ASSERT_EQ(r.x_m.rows(), expected.rows());
  EXPECT_LT((r.x_m - expected).cwiseAbs().maxCoeff(), 1e-9 * expected.cwiseAbs().maxCoeff());
}

TEST(Simulate, ExactAndRk4AgreeOverRandomSystems) {
  // Pulses on the time grid are constant over every step, so ZOH is exact and RK4 converges to it.
  std::mt19937 rng(3);
  for (int trial = 0; trial < 12; ++trial) {
    const Eigen::Index n = 1 + trial % 4;
    const Model m = testing::RandomModel(rng, n, trial % 2 == 0);
    ForceInput force;
    force.shapes.push_back(ParseForceShape("pulse:dof=1,amp=3,t0=0.01,width=0.05"));
    force.shapes.push_back(ParseForceShape("step:dof=" + std::to_string(n) + ",amp=-1,t0=0.1"));
    const SimulationResult exact = Simulate(m, force, Options(Method::kExact, 2e-4, 0.5));
    const SimulationResult rk4 = Simulate(m, force, Options(Method::kRk4, 2e-4, 0.5));
    const double scale = exact.x_m.cwiseAbs().maxCoeff();
    EXPECT_LT((rk4.x_m - exact.x_m).cwiseAbs().maxCoeff(), 1e-6 * scale) << "trial " << trial;
    EXPECT_TRUE(exact.a_m_s2.row(50).isApprox(rk4.a_m_s2.row(50), 1e-5)) << "trial " << trial;
  }
}

TEST(Simulate, DisturbanceAddsToTheForceAndIsRecorded) {
  const Model m = MakeChain(Eigen::Vector2d(2.0, 1.5), Eigen::Vector2d(4000.0, 3000.0),
                            Eigen::Vector2d(2.0, 1.0));
  const SimulationOptions o = Options(Method::kExact, 1e-3, 0.5);
  const SimulationResult split =
      Simulate(m, Shapes({"step:dof=1,amp=2"}), Shapes({"pulse:dof=2,amp=1,width=0.1"}), o);
  const SimulationResult joint =
      Simulate(m, Shapes({"step:dof=1,amp=2", "pulse:dof=2,amp=1,width=0.1"}), o);
  EXPECT_EQ(split.x_m, joint.x_m);
  EXPECT_EQ(split.disturbance_n(50, 1), 1.0);
  EXPECT_EQ(split.force_n(50, 1), 0.0);
  EXPECT_EQ(split.disturbance_n(200, 1), 0.0);
}

TEST(Simulator, StepByStepEqualsSimulate) {
  const Model m = MakeChain(Eigen::Vector2d(2.0, 1.5), Eigen::Vector2d(4000.0, 3000.0),
                            Eigen::Vector2d(2.0, 1.0));
  for (const Method method : {Method::kExact, Method::kRk4, Method::kEuler}) {
    const SimulationOptions o = Options(method, 1e-3, 0.3);
    const SimulationResult r = Simulate(m, Shapes({"step:dof=2,amp=4"}), o);
    Simulator sim(m, o);
    for (Eigen::Index k = 1; k < r.t_s.size(); ++k) {
      sim.Step(Eigen::Vector2d(0.0, 4.0));
      ASSERT_NEAR(sim.time_s(), r.t_s[k], 1e-12);
      ASSERT_EQ(sim.position_m(), r.x_m.row(k).transpose()) << MethodName(method) << " step " << k;
      ASSERT_EQ(sim.acceleration_m_s2(), r.a_m_s2.row(k).transpose());
    }
  }
}

TEST(Friction, StaticFrictionLargerThanTheForceHoldsTheBlock) {
  // μs m g = 0.5 · 1 · 9.80665 = 4.90 N > 4 N applied (spring at rest): nothing moves, exactly.
  const Model m = MakeChain(Eigen::VectorXd::Constant(1, 1.0), Eigen::VectorXd::Constant(1, 100.0));
  for (const Method method : {Method::kRk4, Method::kEuler}) {
    SimulationOptions o = Options(method, 1e-3, 1.0);
    o.friction = {{0.5, 0.3}};
    const SimulationResult r = Simulate(m, Shapes({"step:dof=1,amp=4"}), o);
    EXPECT_TRUE(r.x_m.isZero(0.0)) << MethodName(method);
    EXPECT_TRUE(r.v_m_s.isZero(0.0));
    EXPECT_TRUE(r.a_m_s2.isZero(0.0));
  }
  // 5 N > 4.90 N: it moves.
  SimulationOptions o = Options(Method::kRk4, 1e-3, 1.0);
  o.friction = {{0.5, 0.3}};
  EXPECT_GT(Simulate(m, Shapes({"step:dof=1,amp=5"}), o).x_m(1000, 0), 0.0);
}

TEST(Friction, PushedBlockSlidesAndSticksWhereHandDerived) {
  // No spring. F = 5 N for T = 0.1 s on m = 0.57 kg, μs = μd = 0.2 (friction f = μ m g):
  //   a1 = (F − f)/m, v1 = a1 T, x1 = a1 T²/2; then decelerates at μ g: stops after v1/(μ g) at
  //   x = x1 + v1²/(2 μ g), and stays there (no force left).
  const double mass = 0.57, force = 5.0, width = 0.1, mu = 0.2, g = kStandardGravity_m_s2;
  Model m;
  m.m_kg = Eigen::MatrixXd::Constant(1, 1, mass);
  m.k_n_per_m = Eigen::MatrixXd::Zero(1, 1);
  m.c_ns_per_m = Eigen::MatrixXd::Zero(1, 1);
  const double a1 = (force - mu * mass * g) / mass;
  const double v1 = a1 * width;
  const double x_stop = a1 * width * width / 2.0 + v1 * v1 / (2.0 * mu * g);
  const double t_stop = width + v1 / (mu * g);
  SimulationOptions o = Options(Method::kRk4, 1e-3, 1.0);
  o.friction = {{mu, mu}};
  const SimulationResult r = Simulate(m, Shapes({"pulse:dof=1,amp=5,width=0.1"}), o);
  const Eigen::Index last = r.t_s.size() - 1;
  EXPECT_NEAR(r.x_m(last, 0), x_stop, 1e-12);
  EXPECT_EQ(r.v_m_s(last, 0), 0.0);
  EXPECT_NEAR(r.v_m_s(100, 0), v1, 1e-12);
  const auto stop_index = static_cast<Eigen::Index>(std::ceil(t_stop / 1e-3));
  EXPECT_EQ(r.v_m_s(stop_index, 0), 0.0);
  EXPECT_GT(r.v_m_s(stop_index - 1, 0), 0.0);
}

TEST(Friction, SpringMassAmplitudeDecaysLinearlyAndSticksInsideTheDeadBand) {
  // m = 1, k = 100 (ω = 10 rad/s), μs = μd = 0.05: δ = μ m g/k. Released from 5.5 δ, each half
  // cycle (π/ω) ends 2δ closer to 0 on the other side: −3.5 δ, +1.5 δ, then from 1.5 δ the centre
  // is +δ and the swing ends at +0.5 δ, inside |x| ≤ δ, where static friction holds it for good.
  const double mu = 0.05, k = 100.0, w = 10.0;
  const double delta = mu * 1.0 * kStandardGravity_m_s2 / k;
  const Model m = MakeChain(Eigen::VectorXd::Constant(1, 1.0), Eigen::VectorXd::Constant(1, k));
  SimulationOptions o = Options(Method::kRk4, 1e-3, 2.0);
  o.friction = {{mu, mu}};
  o.x0_m = Eigen::VectorXd::Constant(1, 5.5 * delta);
  const SimulationResult r = Simulate(m, ForceInput{}, o);
  // The turning point falls between samples: the nearest sample is within ½ a (dt/2)², a ≤ ω² 2.5
  // δ.
  EXPECT_NEAR(r.x_m.col(0).minCoeff(), -3.5 * delta, 0.5 * w * w * 2.5 * delta * 0.25e-6);
  EXPECT_NEAR(r.x_m(r.t_s.size() - 1, 0), 0.5 * delta, 1e-9);
  const auto after_stop = static_cast<Eigen::Index>(std::ceil(3.0 * kPi / w / 1e-3)) + 1;
  EXPECT_TRUE(r.v_m_s.col(0).tail(r.t_s.size() - after_stop).isZero(0.0));
  EXPECT_GT(std::abs(r.v_m_s(after_stop - 10, 0)), 0.0);
}

TEST(Friction, MethodsSection10CartCheckMovesRoughlyThirtyCentimetres) {
  // Source check (methods §10): carts 0.57/0.56 kg, springs 15 N/m, μ = 0.01, 5 N on cart 1 for
  // 0.1 s: cart 1 ranges over "roughly 0.3 m". Impulse 0.5 N·s → 0.88 m/s; the first swing is
  // about v/ω with ω ≈ √(2k/M) plus the coupled mode: asserted within a factor of 1.5.
  const Model m = MakeCartTrack(Eigen::Vector2d(0.57, 0.56), 15.0);
  SimulationOptions o = Options(Method::kRk4, 1e-3, 10.0);
  o.friction = {{0.01, 0.01}};
  const SimulationResult r = Simulate(m, Shapes({"pulse:dof=1,amp=5,width=0.1"}), o);
  const double range = r.x_m.col(0).maxCoeff() - r.x_m.col(0).minCoeff();
  EXPECT_GT(range, 0.2);
  EXPECT_LT(range, 0.45);
}

TEST(SimulateOptions, AreValidatedUpFront) {
  const Model m = OneDof();
  const ForceInput none;
  EXPECT_THROW(Simulate(m, none, Options(Method::kRk4, 0.0, 1.0)), InputError);
  EXPECT_THROW(Simulate(m, none, Options(Method::kRk4, -1e-3, 1.0)), InputError);
  EXPECT_THROW(Simulate(m, none, Options(Method::kRk4, 1e-3, 1e-3)), InputError);
  EXPECT_THROW(Simulate(m, Shapes({"step:dof=2,amp=1"}), Options(Method::kRk4, 1e-3, 1.0)),
               InputError);
  SimulationOptions o = Options(Method::kExact, 1e-3, 1.0);
  o.friction = {{0.1, 0.1}};
  EXPECT_THROW(Simulate(m, none, o), InputError);
  o.method = Method::kRk4;
  o.friction = {{0.1, 0.2}};  // μd > μs
  EXPECT_THROW(Simulate(m, none, o), InputError);
  o.friction = {{0.2, 0.1}, {0.2, 0.1}};  // two entries for one DOF
  EXPECT_THROW(Simulate(m, none, o), InputError);
  o = Options(Method::kRk4, 1e-3, 1.0);
  o.x0_m = Eigen::Vector2d(0.0, 0.0);
  EXPECT_THROW(Simulate(m, none, o), InputError);
  EXPECT_THROW(Simulate(m, none, Options(Method::kRk4, 1e-9, 1e3)), InputError);  // 1e12 samples
  Model full = MakeChain(Eigen::Vector2d(2.0, 1.5), Eigen::Vector2d(4000.0, 3000.0));
  full.m_kg(0, 1) = full.m_kg(1, 0) = 0.1;
  o = Options(Method::kRk4, 1e-3, 1.0);
  o.friction = {{0.1, 0.1}};
  EXPECT_THROW(Simulate(full, none, o), InputError);
  EXPECT_THROW(ParseMethod("leapfrog"), InputError);
  EXPECT_EQ(ParseMethod("exact"), Method::kExact);
}

}  // namespace
}  // namespace vibid::model
