#include "vibid/dob/design.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "test_support.hpp"
#include "vibid/common/error.hpp"
#include "vibid/dob/chain_plant.hpp"
#include "vibid/dob/compare.hpp"
#include "vibid/dob/lowpass.hpp"
#include "vibid/dob/model_plant.hpp"
#include "vibid/model/simulate.hpp"

namespace vibid::dob {
namespace {

constexpr double kFs = 5000.0;

model::Model Rig() {
  return model::MakeChain(Eigen::Vector2d(2.5, 2.0), Eigen::Vector2d(4000, 3000),
                          Eigen::Vector2d(3, 3));
}

// The sensor path Q G_A^-1 against scipy (bilinear_zpk of the same zeros and poles, pre-warped).
TEST(DobDesign, SisoSensorPathMatchesScipy) {
  const auto& ref = test::Golden()["siso_path"];
  const DobDesign d = DesignObserver(ChainPlantForceOnM2({}), DobOptions{});
  ASSERT_TRUE(d.stable) << d.message;
  ASSERT_EQ(d.paths.size(), 2u);
  EXPECT_EQ(d.plant_relative_degree, 2);
  for (std::size_t i = 0; i < ref["freqs_hz"].size(); ++i) {
    const double f = ref["freqs_hz"][i].get<double>();
    const Complex z = std::exp(Complex(0.0, 2.0 * std::numbers::pi * f / kFs));
    const Complex want = test::AsComplex(ref["tustin_response"][i]);
    EXPECT_LE(std::abs(EvaluateSos(d.paths[0].sos, z) - want), 1e-8 * std::abs(want)) << f;
  }
  // The force path is -Q: -1 at DC.
  EXPECT_NEAR(EvaluateSos(d.paths[1].sos, 1.0).real(), -1.0, 1e-12);
}

TEST(DobDesign, RealizabilityNamesBothNumbers) {
  DobOptions o;
  o.relative_degree = 1;
  try {
    static_cast<void>(DesignObserver(ChainPlantForceOnM2({}), o));
    FAIL() << "r = 1 accepted";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("r = 1"), std::string::npos) << msg;
    EXPECT_NE(msg.find("relative degree 2"), std::string::npos) << msg;
  }
  // Velocity sensing lowers G_A's relative degree to 1, acceleration to 0: r = 1 and 0 then work.
  o.sensor = SensorKind::kVelocity;
  EXPECT_TRUE(DesignObserver(ChainPlantForceOnM2({}), o).stable);
  o.sensor = SensorKind::kAcceleration;
  o.relative_degree = 0;
  EXPECT_TRUE(DesignObserver(ChainPlantForceOnM2({}), o).stable);
  // MIMO with displacement sensors: M x'' needs r >= 2.
  o = DobOptions{};
  o.form = ObserverForm::kMimo;
  o.relative_degree = 1;
  EXPECT_THROW(DesignObserver(ChainPlantForceOnM2({}), o), InputError);
}

TEST(DobDesign, UndampedNominalModelIsRefusedWithTheReason) {
  ChainParameters p;
  p.c1_ns_per_m = 0.0;
  p.c2_ns_per_m = 0.0;
  const DobDesign d = DesignObserver(ChainPlantForceOnM2(p), DobOptions{});
  EXPECT_FALSE(d.stable);
  EXPECT_NE(d.message.find("undamped"), std::string::npos) << d.message;
  // sqrt((k1 + k2) / m1) = sqrt(7000 / 2.5) rad/s: the anti-resonance of m2, named in Hz.
  EXPECT_NE(d.message.find(
                std::to_string(std::sqrt(7000.0 / 2.5) / (2.0 * std::numbers::pi)).substr(0, 5)),
            std::string::npos)
      << d.message;
}

TEST(DobDesign, UpperBandEdgeIsWhereQLeavesTenPercent) {
  const DobDesign d = DesignObserver(ChainPlantForceOnM2({}), DobOptions{});
  const Complex s(0.0, 2.0 * std::numbers::pi * d.valid_band_hi_hz);
  EXPECT_NEAR(
      std::abs(numerics::EvaluatePolynomial(d.q.num, s) / numerics::EvaluatePolynomial(d.q.den, s) -
               1.0),
      0.1, 1e-9);
  DobOptions acc;
  acc.sensor = SensorKind::kAcceleration;
  acc.relative_degree = 2;
  acc.leak_hz = 0.05;
  EXPECT_DOUBLE_EQ(DesignObserver(ChainPlantForceOnM2({}), acc).valid_band_lo_hz, 0.5);
}

struct Sim {
  model::SimulationResult r;
  Eigen::VectorXd push;
};

Sim Simulate(const std::string& push_spec, double t_end_s) {
  model::ForceInput shaker;
  shaker.shapes.push_back(model::ParseForceShape("sine:dof=2,amp=40,freq_hz=16"));
  model::ForceInput push;
  push.shapes.push_back(model::ParseForceShape(push_spec));
  model::SimulationOptions o;
  o.method = model::Method::kExact;
  o.dt_s = 1.0 / kFs;
  o.t_end_s = t_end_s;
  Sim s{model::Simulate(Rig(), shaker, push, o), {}};
  s.push = s.r.disturbance_n.col(1);
  return s;
}

double FitAfterLowpass(const Eigen::VectorXd& d_hat, const Eigen::VectorXd& truth, double skip_s) {
  const Eigen::VectorXd lp = FiltFilt(ButterworthLowpass(4, 4.0, kFs), d_hat);
  const auto skip = static_cast<Eigen::Index>(skip_s * kFs);
  const Eigen::Index n = truth.size() - 2 * skip;
  return CompareSignals(lp.segment(skip, n), truth.segment(skip, n), kFs).fit_percent;
}

// The multi-input form Q[M x'' + C x' + K x - F] with both masses' encoders, and the ZOH variant.
TEST(DobDesign, MimoFormAndZeroOrderHoldRecoverThePush) {
  const Sim s = Simulate("chirp:dof=2,amp=10,f0_hz=0.2,f1_hz=2,t1=8", 8.0);
  DobOptions o;
  o.form = ObserverForm::kMimo;
  const DobDesign mimo = DesignObserver(PlantFromModel(Rig(), 1, 1), o);
  ASSERT_TRUE(mimo.stable) << mimo.message;
  ASSERT_EQ(mimo.paths.size(), 3u);
  EXPECT_EQ(mimo.paths[0].dof, 0);
  EXPECT_EQ(mimo.paths[1].dof, 1);
  const std::vector<Eigen::VectorXd> in = {s.r.x_m.col(0), s.r.x_m.col(1), s.r.force_n.col(1)};
  EXPECT_GE(FitAfterLowpass(RunFloat(mimo.paths, in), s.push, 1.0), 99.0);
  const FixedRun fixed = RunFixed(mimo.fixed.description, in);
  EXPECT_EQ(fixed.saturations, 0u);
  EXPECT_GE(FitAfterLowpass(fixed.d_hat_n, s.push, 1.0), 99.0);

  DobOptions z;
  z.discretization = Discretization::kZeroOrderHold;
  const DobDesign zoh = DesignObserver(PlantFromModel(Rig(), 1, 1), z);
  ASSERT_TRUE(zoh.stable) << zoh.message;
  EXPECT_GE(FitAfterLowpass(RunFloat(zoh.paths, {s.r.x_m.col(1), s.r.force_n.col(1)}), s.push, 1.0),
            99.0);
}

// Which sensor serves which band: a 0.5-1.3 Hz push seen through accelerometers (0.01 m/s^2 rms
// noise) drowns in the twice-integrated noise; the encoder (1/560 cm quantization) recovers it.
TEST(DobDesign, AccelerometersLoseASlowPushThatEncodersRecover) {
  const Sim s = Simulate("chirp:dof=2,amp=10,f0_hz=0.5,f1_hz=1.3,t1=20", 20.0);
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.01);
  Eigen::VectorXd acc = s.r.a_m_s2.col(1);
  for (Eigen::Index k = 0; k < acc.size(); ++k) acc[k] += noise(rng);
  const double lsb = 0.01 / 560.0;
  const Eigen::VectorXd enc = (s.r.x_m.col(1) / lsb).array().round() * lsb;
  DobOptions a;
  a.sensor = SensorKind::kAcceleration;
  a.relative_degree = 2;
  a.leak_hz = 0.02;
  const DobDesign with_acc = DesignObserver(PlantFromModel(Rig(), 1, 1), a);
  ASSERT_TRUE(with_acc.stable) << with_acc.message;
  const DobDesign with_enc = DesignObserver(PlantFromModel(Rig(), 1, 1), DobOptions{});
  const double fit_acc =
      FitAfterLowpass(RunFloat(with_acc.paths, {acc, s.r.force_n.col(1)}), s.push, 5.0);
  const double fit_enc =
      FitAfterLowpass(RunFloat(with_enc.paths, {enc, s.r.force_n.col(1)}), s.push, 5.0);
  EXPECT_LT(fit_acc, 90.0);
  EXPECT_GE(fit_enc, 99.0);
  std::printf("0.5-1.3 Hz push: fit %.1f %% with accelerometers, %.2f %% with the encoder\n",
              fit_acc, fit_enc);
}

TEST(DobDesign, BinomialPrototypeHasNoOvershoot) {
  DobOptions o;
  o.prototype = QPrototype::kBinomial;
  o.relative_degree = 5;
  const DobDesign d = DesignObserver(ChainPlantForceOnM2({}), o);
  ASSERT_TRUE(d.stable);
  const Eigen::VectorXd step = -FilterSos(d.paths.back().sos, Eigen::VectorXd::Ones(2000));
  EXPECT_LE(step.maxCoeff(), 1.0 + 1e-9);
  EXPECT_NEAR(step[1999], 1.0, 1e-6);
}

}  // namespace
}  // namespace vibid::dob
