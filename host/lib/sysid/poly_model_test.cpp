// Polynomial models: ARX against octave-control, PEM recovery of ARMAX/OE/BJ systems, OE against
// ARX under output noise, k-step prediction identities, order selection, bad orders.
#include "vibid/sysid/poly_model.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "testing_systems.hpp"
#include "vibid/common/csv.hpp"
#include "vibid/common/error.hpp"
#include "vibid/common/json_file.hpp"
#include "vibid/numerics/polynomial.hpp"
#include "vibid/sysid/fit.hpp"
#include "vibid/sysid/greybox.hpp"
#include "vibid/sysid/pem.hpp"

namespace vibid::sysid {
namespace {

Eigen::VectorXd Vec(const nlohmann::json& j) {
  const auto v = j.get<std::vector<double>>();
  return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}

double MaxAbs(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  EXPECT_EQ(a.size(), b.size());
  return a.size() == b.size() ? (a - b).cwiseAbs().maxCoeff() : 1e300;
}

TEST(Arx, MatchesOctaveControl) {
  // Golden: scripts/golden/sysid_arx_octave.m (octave-control 3.4.0 arx; its nk is ours minus one).
  const Recording rec = LoadRecording(VIBID_SOURCE_DIR "/host/lib/sysid/testdata/arx_data.csv");
  const IoData data =
      MakeIoData(rec.Signal(ParseColumnSpec("u")), rec.Signal(ParseColumnSpec("y")), rec.dt_s());
  const auto golden = ReadJsonFile(VIBID_SOURCE_DIR "/host/lib/sysid/testdata/arx_octave.json");
  ASSERT_GE(golden["cases"].size(), 5u);
  for (const auto& c : golden["cases"]) {
    const PolyOrders o{c["na"].get<int>(), c["nb"].get<int>(), 0, 0, 0, c["nk"].get<int>()};
    SCOPED_TRACE("na=" + std::to_string(o.na) + " nb=" + std::to_string(o.nb) +
                 " nk=" + std::to_string(o.nk));
    const ArxResult r = EstimateArx(data, o);
    EXPECT_LT(MaxAbs(r.model.a, Vec(c["A"])), 1e-8);
    EXPECT_LT(MaxAbs(r.model.b, Vec(c["B"])), 1e-8);
  }
}

TEST(Arx, RecoversNoiseFreeArxSystemExactly) {
  // y = B/A u exactly: ARX with the right orders has zero equation error.
  const Eigen::Vector3d a(1.0, -1.5, 0.7);
  Eigen::VectorXd b(4);
  b << 0.0, 0.0, 1.0, 0.5;  // nk = 2, nb = 2
  const Eigen::VectorXd u = testing::WhiteNoise(500, 1.0, 7);
  const IoData data = MakeIoData(u, numerics::Filter(b, a, u), 1.0);
  const ArxResult r = EstimateArx(data, PolyOrders{2, 2, 0, 0, 0, 2});
  EXPECT_LT(MaxAbs(r.model.a, a), 1e-12);
  EXPECT_LT(MaxAbs(r.model.b, b), 1e-12);
  EXPECT_LT(r.loss, 1e-24);
}

TEST(Arx, CovarianceMatchesMonteCarloSpread) {
  // Equation-error data: the LS covariance σ²(ΦᵀΦ)⁻¹ predicts the spread over noise realisations.
  const Eigen::Vector3d a(1.0, -1.2, 0.5);
  const Eigen::Vector2d b(0.0, 1.0);
  const Eigen::VectorXd u = testing::WhiteNoise(1000, 1.0, 3);
  const int runs = 200;
  Eigen::MatrixXd estimates(runs, 3);
  Eigen::VectorXd mean_std = Eigen::VectorXd::Zero(3);
  for (int run = 0; run < runs; ++run) {
    const Eigen::VectorXd e = testing::WhiteNoise(1000, 0.3, 100 + static_cast<std::uint32_t>(run));
    const IoData data = MakeIoData(
        u, numerics::Filter(b, a, u) + numerics::Filter(Eigen::VectorXd::Ones(1), a, e), 1.0);
    const ArxResult r = EstimateArx(data, PolyOrders{2, 1, 0, 0, 0, 1});
    estimates.row(run) = r.model.Parameters().transpose();
    mean_std += r.model.covariance.diagonal().cwiseSqrt() / runs;
  }
  const Eigen::RowVectorXd mean = estimates.colwise().mean();
  const Eigen::VectorXd spread =
      ((estimates.rowwise() - mean).cwiseAbs2().colwise().sum() / (runs - 1))
          .cwiseSqrt()
          .transpose();
  for (Eigen::Index i = 0; i < 3; ++i) {
    // 200 runs: the sample std is within ±15 % of the true one with probability > 0.97.
    EXPECT_NEAR(spread[i] / mean_std[i], 1.0, 0.15) << "parameter " << i;
  }
}

/// The one-cart model's ZOH discretization as an OE system (nb = 2, nf = 2, nk = 1).
PolyModel OneCartOe(double dt_s) {
  const DiscreteTf d = C2dZoh(testing::OneCartTf(), dt_s);
  PolyModel m;
  m.structure = Structure::kOe;
  m.orders = PolyOrders{0, 2, 0, 0, 2, 1};
  m.dt_s = dt_s;
  m.b = d.num;  // [0, b1, b2]
  m.f = d.den;
  return m;
}

TEST(Pem, OeBeatsArxWhenTheNoiseIsNotEquationError) {
  const double dt = 0.02;
  const PolyModel truth = OneCartOe(dt);
  const Eigen::VectorXd u = testing::WhiteNoise(3000, 0.01, 11);
  const Eigen::VectorXd y0 = SimulatePoly(truth, u);
  const Eigen::VectorXd y = y0 + testing::WhiteNoise(3000, 0.1 * testing::Rms(y0), 12);
  const IoData data = MakeIoData(u, y, dt);
  const ArxResult arx = EstimateArx(data, PolyOrders{2, 2, 0, 0, 0, 1});
  const PemResult oe = EstimatePem(data, Structure::kOe, PolyOrders{0, 2, 0, 0, 2, 1});
  ASSERT_TRUE(oe.summary.Converged()) << oe.summary.message;
  const double fit_arx = FitPercent(y0, SimulatePoly(arx.model, u));
  const double fit_oe = FitPercent(y0, SimulatePoly(oe.model, u));
  const double err_arx = (arx.model.a - truth.f).cwiseAbs().maxCoeff();
  const double err_oe = (oe.model.f - truth.f).cwiseAbs().maxCoeff();
  std::printf(
      "fit vs noise-free output: ARX %.2f %%, OE %.2f %%; max |pole poly error| ARX %.2e, OE "
      "%.2e\n",
      fit_arx, fit_oe, err_arx, err_oe);
  EXPECT_GT(fit_oe, 99.0);
  EXPECT_LT(fit_arx, fit_oe - 5.0);
  EXPECT_LT(err_oe * 10.0, err_arx);
  // The OE estimate is consistent: within 4 of its own standard deviations.
  const Eigen::VectorXd err = oe.model.Parameters() - truth.Parameters();
  const Eigen::VectorXd sd = oe.model.covariance.diagonal().cwiseSqrt();
  for (Eigen::Index i = 0; i < err.size(); ++i)
    EXPECT_LT(std::abs(err[i]), 4.0 * sd[i]) << "parameter " << i;
}

TEST(Pem, OeOfAFastSampledFourthOrderSystem) {
  // Two-cart model at 200 Hz: the discrete poles sit within 0.01 of z = 1 (one on it: the carts are
  // free), where the ARX start is useless and lagged regressors are collinear to working precision.
  // The IV passes, written in backward differences, converge to the OE stationary point, noise-free
  // and with 1 % output noise alike.
  const double dt = 0.005;
  const TransferFunction tf =
      Normalized(CartTf(CartConfig{2, CartInput::kForce}, testing::TwoCartValues().head(5)));
  const DiscreteTf d = C2dZoh(tf, dt);
  Eigen::VectorXd u = Eigen::VectorXd::Zero(6000);
  for (Eigen::Index i = 0; i < u.size(); ++i) u[i] = ((i / 150) % 2 == 0) ? 5.0 : -5.0;
  const Eigen::VectorXd y0 = numerics::Filter(d.num, d.den, u);
  const PemResult r =
      EstimatePem(MakeIoData(u, y0, dt), Structure::kOe, PolyOrders{0, 4, 0, 0, 4, 1});
  ASSERT_TRUE(r.summary.Converged()) << r.summary.message;
  EXPECT_LT((r.model.f - d.den).cwiseAbs().maxCoeff(), 1e-9);
  // B is the weak direction at this rate: a relative change of 1e-8 in B, with F following it by
  // 1e-12, moves the simulated output by 1e-9 of its RMS (the criterion cannot resolve it further).
  EXPECT_LT((r.model.b - d.num).cwiseAbs().maxCoeff(), 1e-7 * d.num.cwiseAbs().maxCoeff());
  EXPECT_LT((y0 - SimulatePoly(r.model, u)).norm(), 1e-8 * y0.norm());
  const Eigen::VectorXd y = y0 + testing::WhiteNoise(y0.size(), 0.01 * testing::Rms(y0), 91);
  const PemResult noisy =
      EstimatePem(MakeIoData(u, y, dt), Structure::kOe, PolyOrders{0, 4, 0, 0, 4, 1});
  ASSERT_TRUE(noisy.summary.Converged()) << noisy.summary.message;
  EXPECT_EQ(noisy.initialization, "instrumental-variable");
  EXPECT_GT(FitPercent(y0, SimulatePoly(noisy.model, u)), 99.5);
  const Eigen::VectorXd truth = (Eigen::VectorXd(8) << d.num.tail(4), d.den.tail(4)).finished();
  const Eigen::VectorXd err = noisy.model.Parameters() - truth;
  const Eigen::VectorXd sd = noisy.model.covariance.diagonal().cwiseSqrt();
  for (Eigen::Index i = 0; i < err.size(); ++i)
    EXPECT_LT(std::abs(err[i]), 4.0 * sd[i]) << "parameter " << i;
  const ArxResult arx = EstimateArx(MakeIoData(u, y, dt), PolyOrders{4, 4, 0, 0, 0, 1});
  EXPECT_LT(FitPercent(y0, SimulatePoly(arx.model, u)), 90.0);
}

TEST(Pem, RecoversArmaxAndBoxJenkinsSystems) {
  const Eigen::Index n = 8000;
  const Eigen::VectorXd u = testing::WhiteNoise(n, 1.0, 21);
  const Eigen::VectorXd e = testing::WhiteNoise(n, 0.2, 22);
  {
    PolyModel truth;
    truth.structure = Structure::kArmax;
    truth.orders = PolyOrders{2, 2, 1, 0, 0, 1};
    truth.SetParameters((Eigen::VectorXd(5) << -1.5, 0.7, 1.0, 0.5, 0.6).finished());
    const Eigen::VectorXd y =
        numerics::Filter(truth.b, truth.a, u) + numerics::Filter(truth.c, truth.a, e);
    const PemResult r = EstimatePem(MakeIoData(u, y, 1.0), Structure::kArmax, truth.orders);
    ASSERT_TRUE(r.summary.Converged()) << r.summary.message;
    const Eigen::VectorXd err = r.model.Parameters() - truth.Parameters();
    const Eigen::VectorXd sd = r.model.covariance.diagonal().cwiseSqrt();
    for (Eigen::Index i = 0; i < err.size(); ++i)
      EXPECT_LT(std::abs(err[i]), 4.0 * sd[i]) << "armax parameter " << i;
    EXPECT_NEAR(r.model.noise_variance, 0.04, 0.04 * 0.05);
  }
  {
    PolyModel truth;
    truth.structure = Structure::kBj;
    truth.orders = PolyOrders{0, 2, 1, 1, 2, 1};
    truth.SetParameters((Eigen::VectorXd(6) << 1.0, 0.5, 0.4, -0.8, -1.2, 0.5).finished());
    const Eigen::VectorXd y =
        numerics::Filter(truth.b, truth.f, u) + numerics::Filter(truth.c, truth.d, e);
    const PemResult r = EstimatePem(MakeIoData(u, y, 1.0), Structure::kBj, truth.orders);
    ASSERT_TRUE(r.summary.Converged()) << r.summary.message;
    const Eigen::VectorXd err = r.model.Parameters() - truth.Parameters();
    const Eigen::VectorXd sd = r.model.covariance.diagonal().cwiseSqrt();
    for (Eigen::Index i = 0; i < err.size(); ++i)
      EXPECT_LT(std::abs(err[i]), 4.0 * sd[i]) << "bj parameter " << i;
  }
}

TEST(Pem, KStepPredictionIdentities) {
  PolyModel m;
  m.structure = Structure::kArmax;
  m.orders = PolyOrders{2, 2, 1, 0, 0, 1};
  m.SetParameters((Eigen::VectorXd(5) << -1.5, 0.7, 1.0, 0.5, 0.6).finished());
  const Eigen::VectorXd u = testing::WhiteNoise(400, 1.0, 5);
  const Eigen::VectorXd y =
      numerics::Filter(m.b, m.a, u) + numerics::Filter(m.c, m.a, testing::WhiteNoise(400, 0.1, 6));
  const IoData data = MakeIoData(u, y, 1.0);
  // k = 1: the one-step predictor, ŷ = y − e.
  EXPECT_LT((PredictKStep(m, data, 1) - (y - PredictionErrors(m, data))).cwiseAbs().maxCoeff(),
            1e-12);
  // k = N: nothing measured is recent enough, the prediction is the simulation.
  EXPECT_LT((PredictKStep(m, data, 400) - SimulatePoly(m, u)).cwiseAbs().maxCoeff(), 1e-10);
}

TEST(Arx, AicAndFpePickTheTrueOrder) {
  const Eigen::Vector4d a(1.0, -1.8, 1.3, -0.38);  // 3rd order, stable
  const Eigen::Vector4d b(0.0, 1.0, 0.4, 0.2);
  const Eigen::VectorXd u = testing::WhiteNoise(4000, 1.0, 31);
  const Eigen::VectorXd y =
      numerics::Filter(b, a, u) +
      numerics::Filter(Eigen::VectorXd::Ones(1), a, testing::WhiteNoise(4000, 0.1, 32));
  const IoData data = MakeIoData(u, y, 1.0);
  for (const auto criterion : {OrderCriterion::kAic, OrderCriterion::kFpe}) {
    const OrderSelection s = SelectArxOrder(data, 1, 8, 1, criterion);
    EXPECT_EQ(s.candidates[s.best].orders.na, 3);
  }
  // Closed forms (Ljung eq. 16.31, 16.33).
  EXPECT_DOUBLE_EQ(Aic(0.5, 4, 100), 100.0 * std::log(0.5) + 8.0);
  EXPECT_DOUBLE_EQ(Fpe(0.5, 4, 100), 0.5 * 1.04 / 0.96);
}

TEST(Arx, RejectsOrdersTooHighAndNonExcitingInput) {
  const Eigen::VectorXd u = testing::WhiteNoise(50, 1.0, 1);
  const IoData data = MakeIoData(u, u, 1.0);
  try {
    EstimateArx(data, PolyOrders{30, 30, 0, 0, 0, 1});
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("orders too high"), std::string::npos) << e.what();
  }
  // A single step: lagged copies of the input differ in one row only, enough for nb = 2 but a
  // constant-after-sample-0 input cannot support nb = 3 from row 2 on.
  Eigen::VectorXd step = Eigen::VectorXd::Ones(60);
  step[0] = 0.0;
  const IoData stepped = MakeIoData(step, testing::WhiteNoise(60, 1.0, 2), 1.0);
  try {
    EstimateArx(stepped, PolyOrders{1, 3, 0, 0, 0, 1});
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("not persistently exciting"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(ValidateOrders(Structure::kOe, PolyOrders{1, 2, 0, 0, 2, 1}, 100), InputError);
}

}  // namespace
}  // namespace vibid::sysid
