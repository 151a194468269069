// Continuous-time estimation (SRIVC + output error) on the cart-track models of methods §10.
#include "vibid/sysid/tfest.hpp"

#include <string>

#include <gtest/gtest.h>

#include "testing_systems.hpp"
#include "vibid/common/error.hpp"
#include "vibid/sysid/fit.hpp"

namespace vibid::sysid {
namespace {

using testing::MaxRelativeError;

constexpr double kDt = 0.005;  // 200 Hz, the ECP rig's logging rate

struct Case {
  std::string name;
  TransferFunction truth;
  Eigen::VectorXd u;
  Eigen::VectorXd y;  ///< Noise-free output.
};

/// Force-driven records simulated by the model core (exact ZOH), and position-input records of the
/// methods §10 TFs X1/Xi simulated here. 15 s at 200 Hz: several periods of the slowest mode.
std::vector<Case> Cases() {
  std::vector<Case> cases;
  for (const int carts : {1, 2}) {
    const std::string tag = carts == 1 ? "one-cart" : "two-cart";
    // 5 N on cart 1 from t = 0.1 s, held or for 0.1 s (the pulse of methods §10).
    for (const auto& [kind, shape] : {std::pair{"step", "step:dof=1,amp=5,t0=0.1"},
                                      std::pair{"pulse", "pulse:dof=1,amp=5,width=0.1,t0=0.1"}}) {
      const testing::ModelCoreRecord r = testing::SimulateCartTrack(carts, shape, kDt, 15.0);
      cases.push_back({tag + " force " + kind, r.truth, r.force_n, r.x1_m});
    }
    const TransferFunction tf = carts == 1 ? testing::OneCartTf() : testing::TwoCartTf();
    const Eigen::Index n = 3000;
    for (const auto& [kind, u] : {std::pair{"step", testing::Step(n, 20, 0.01)},
                                  std::pair{"pulse", testing::Pulse(n, 20, 20, 0.01)}}) {
      cases.push_back({tag + " position " + kind, tf, u, Simulate(tf, u, kDt)});
    }
  }
  return cases;
}

TEST(Tfest, RecoversNoiseFreeCartModels) {
  for (const Case& c : Cases()) {
    SCOPED_TRACE(c.name);
    const Eigen::VectorXd& y = c.y;
    TfestOptions o;
    o.np = static_cast<int>(c.truth.Order());
    o.nz = static_cast<int>(c.truth.num.size() - 1);
    const TfestResult r = EstimateTf(MakeIoData(c.u, y, kDt), o);
    const double err = MaxRelativeError(r.tf, c.truth);
    std::printf("%s: max rel coef error %.3e, fit %.6f %%, %s, %d iterations, init %s\n",
                c.name.c_str(), err, r.fit_percent,
                numerics::TerminationName(r.summary.termination), r.summary.iterations,
                r.initialization.c_str());
    EXPECT_TRUE(r.summary.Converged()) << r.summary.message;
    EXPECT_LT(err, 1e-3);
    EXPECT_GE(FitPercent(y, Simulate(r.tf, c.u, kDt)), 99.9);
  }
}

TEST(Tfest, OnePercentOutputNoise) {
  // White output noise at 1 % of the output RMS. Force inputs (step and pulse) and position pulses
  // meet 2 % in every coefficient. A position step carries little information on the small
  // numerator term b0 = Bi·M2/(M1·M2) (the (Bi/M)·s feed-through): its own standard deviation is
  // 1.2–2.4 % of its value there, so for those two records the test asserts every coefficient
  // within 3 of its standard deviations instead (the standard deviations themselves are checked
  // against a Monte Carlo spread below).
  std::uint32_t seed = 1;
  for (const Case& c : Cases()) {
    SCOPED_TRACE(c.name);
    const bool held_step = c.name.ends_with("position step");
    const Eigen::VectorXd& y0 = c.y;
    const Eigen::VectorXd y = y0 + testing::WhiteNoise(y0.size(), 0.01 * testing::Rms(y0), seed++);
    TfestOptions o;
    o.np = static_cast<int>(c.truth.Order());
    o.nz = static_cast<int>(c.truth.num.size() - 1);
    const TfestResult r = EstimateTf(MakeIoData(c.u, y, kDt), o);
    const double err = MaxRelativeError(r.tf, c.truth);
    const double fit = FitPercent(y0, Simulate(r.tf, c.u, kDt));
    std::printf("%s + 1%% noise: max rel coef error %.3e, fit vs noise-free %.4f %%\n",
                c.name.c_str(), err, fit);
    EXPECT_GE(fit, 98.0);
    if (!held_step) {
      EXPECT_LT(err, 0.02);
      continue;
    }
    for (Eigen::Index i = 1; i < c.truth.den.size(); ++i) {
      EXPECT_LT(std::abs(r.tf.den[i] - c.truth.den[i]), 3.0 * r.den_std[i]) << "a" << i;
    }
    for (Eigen::Index i = 0; i < c.truth.num.size(); ++i) {
      EXPECT_LT(std::abs(r.tf.num[i] - c.truth.num[i]), 3.0 * r.num_std[i]) << "b" << i;
    }
  }
}

TEST(Tfest, StandardDeviationsMatchMonteCarloSpread) {
  const TransferFunction truth = testing::OneCartTf();
  const Eigen::VectorXd u = testing::Pulse(2000, 20, 20, 0.01);
  const Eigen::VectorXd y0 = Simulate(truth, u, kDt);
  const int runs = 40;
  Eigen::MatrixXd est(runs, 4);
  Eigen::VectorXd mean_std = Eigen::VectorXd::Zero(4);
  for (int run = 0; run < runs; ++run) {
    const Eigen::VectorXd y = y0 + testing::WhiteNoise(y0.size(), 0.01 * testing::Rms(y0),
                                                       500 + static_cast<std::uint32_t>(run));
    TfestOptions o;
    o.np = 2;
    o.nz = 1;
    const TfestResult r = EstimateTf(MakeIoData(u, y, kDt), o);
    est.row(run) << r.tf.den[1], r.tf.den[2], r.tf.num[0], r.tf.num[1];
    mean_std +=
        (Eigen::Vector4d() << r.den_std[1], r.den_std[2], r.num_std[0], r.num_std[1]).finished() /
        runs;
  }
  const Eigen::RowVectorXd mean = est.colwise().mean();
  const Eigen::VectorXd spread =
      ((est.rowwise() - mean).cwiseAbs2().colwise().sum() / (runs - 1)).cwiseSqrt().transpose();
  for (Eigen::Index i = 0; i < 4; ++i) {
    // 40 runs: the sample std is within ±30 % of the true one with probability ≈ 0.99.
    EXPECT_NEAR(spread[i] / mean_std[i], 1.0, 0.3) << "coefficient " << i;
  }
}

TEST(Tfest, EstimatesInitialConditions) {
  // The record starts mid-motion: a free response P/A is added (P = 0.02 s + 0.5 in X1 units).
  const TransferFunction truth = testing::OneCartTf();
  const Eigen::VectorXd u = testing::Pulse(2000, 200, 20, 0.01);
  const Eigen::VectorXd p = Eigen::Vector2d(0.002, 0.05);
  const Eigen::VectorXd y = SimulateWithIc(truth, p, u, kDt);
  TfestOptions o;
  o.np = 2;
  o.nz = 1;
  o.ic = InitialCondition::kEstimate;
  const TfestResult r = EstimateTf(MakeIoData(u, y, kDt), o);
  EXPECT_LT(MaxRelativeError(r.tf, truth), 1e-6);
  EXPECT_LT((r.ic_num - p).cwiseAbs().maxCoeff(), 1e-8);
  EXPECT_GT(r.fit_percent, 99.999);
  o.ic = InitialCondition::kZero;
  EXPECT_LT(EstimateTf(MakeIoData(u, y, kDt), o).fit_percent, r.fit_percent);
  // FitInitialCondition recovers P for the true TF by linear least squares.
  EXPECT_LT((FitInitialCondition(truth, MakeIoData(u, y, kDt)) - p).cwiseAbs().maxCoeff(), 1e-10);
}

TEST(Tfest, RejectsBadOrders) {
  const Eigen::VectorXd u = testing::Pulse(100, 5, 5, 1.0);
  const IoData data = MakeIoData(u, Simulate(testing::OneCartTf(), u, kDt), kDt);
  TfestOptions o;
  o.np = 2;
  o.nz = 2;
  EXPECT_THROW(EstimateTf(data, o), InputError);
  o.np = 8;
  o.nz = 3;
  try {
    EstimateTf(data, o);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("orders too high"), std::string::npos);
  }
}

}  // namespace
}  // namespace vibid::sysid
