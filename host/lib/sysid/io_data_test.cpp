// Record handling (checks, detrending, ranges, decimation) and the fit and residual statistics.
#include "vibid/sysid/io_data.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

#include "testing_systems.hpp"
#include "vibid/common/error.hpp"
#include "vibid/numerics/polynomial.hpp"
#include "vibid/sysid/fit.hpp"

namespace vibid::sysid {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

TEST(IoData, RejectsBadRecordsWithClearMessages) {
  const Eigen::VectorXd ten = Eigen::VectorXd::LinSpaced(10, 0.0, 1.0);
  Eigen::VectorXd nan = ten;
  nan[4] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THAT([&] { MakeIoData(ten, Eigen::VectorXd::Ones(9), 0.1, "V", "X"); },
              ThrowsMessage<InputError>(HasSubstr("lengths must match")));
  EXPECT_THAT(
      [&] { MakeIoData(ten, nan, 0.1, "V", "X"); },
      ThrowsMessage<InputError>(HasSubstr("output 'X' is not finite (NaN or Inf) at sample 4")));
  EXPECT_THAT([&] { MakeIoData(Eigen::VectorXd::Constant(10, 3.0), ten, 0.1, "V", "X"); },
              ThrowsMessage<InputError>(HasSubstr("not persistently exciting")));
  EXPECT_THAT([&] { MakeIoData(ten.head(4), ten.head(4), 0.1); },
              ThrowsMessage<InputError>(HasSubstr("too short")));
  EXPECT_THROW(MakeIoData(ten, ten, 0.0), InputError);
}

TEST(IoData, DetrendRemovesMeanAndLine) {
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(100, 0.0, 99.0);
  const Eigen::VectorXd s = (0.3 * t.array()).sin().matrix();
  const IoData d{s, (2.0 + 0.5 * t.array()).matrix() + s, 1.0};
  const DetrendResult lin = Detrend(d, Trend::kLinear);
  EXPECT_NEAR(lin.data.y.mean(), 0.0, 1e-12);
  // What is left is the sine minus its own (small) least-squares line.
  EXPECT_NEAR(lin.y_trend[1], 0.5, 0.01);
  const DetrendResult mean = Detrend(d, Trend::kMean);
  EXPECT_NEAR(mean.data.u.mean(), 0.0, 1e-14);
  EXPECT_DOUBLE_EQ(mean.y_trend[0], d.y.mean());
}

TEST(IoData, RangesAndSplit) {
  const IoData d{Eigen::VectorXd::LinSpaced(20, 0.0, 19.0),
                 Eigen::VectorXd::LinSpaced(20, 0.0, 19.0), 0.5};
  const SampleRange r = ParseSampleRange("5:", 20);
  EXPECT_EQ(r.first, 5);
  EXPECT_EQ(r.last, 20);
  EXPECT_THROW(ParseSampleRange("5:30", 20), InputError);
  EXPECT_THROW(ParseSampleRange("8:8", 20), InputError);
  EXPECT_THROW(ParseSampleRange("-1:4", 20), InputError);
  EXPECT_THROW(ParseSampleRange("4", 20), InputError);
  const SplitData s = Split(d, 0.5);
  EXPECT_EQ(s.estimation.samples(), 10);
  EXPECT_EQ(s.validation.u[0], 10.0);
}

TEST(IoData, DecimationKeepsTheBandAndRejectsAliases) {
  // 1 kHz record decimated by 5: new Nyquist 100 Hz. 20 Hz passes; 150 Hz would alias to 50 Hz.
  const double fs = 1000.0;
  const Eigen::Index n = 5000;
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(n, 0.0, static_cast<double>(n - 1)) / fs;
  constexpr double kTwoPi = 2.0 * std::numbers::pi;
  const Eigen::VectorXd pass = (kTwoPi * 20.0 * t.array()).sin().matrix();
  const Eigen::VectorXd stop = (kTwoPi * 150.0 * t.array()).sin().matrix();
  const IoData out = Decimate(IoData{pass, stop, 1.0 / fs}, 5);
  EXPECT_DOUBLE_EQ(out.dt_s, 0.005);
  ASSERT_EQ(out.samples(), 1000);
  // Away from the edges: the 20 Hz sine is kept in amplitude and phase (linear-phase FIR, delay
  // compensated), the 150 Hz one is gone (Blackman stop band).
  double pass_err = 0.0;
  double stop_amp = 0.0;
  for (Eigen::Index i = 50; i < 950; ++i) {
    pass_err = std::max(
        pass_err, std::abs(out.u[i] - std::sin(kTwoPi * 20.0 * 0.005 * static_cast<double>(i))));
    stop_amp = std::max(stop_amp, std::abs(out.y[i]));
  }
  EXPECT_LT(pass_err, 2e-3);
  EXPECT_LT(stop_amp, 1e-3);  // below −60 dB
  // A constant passes unchanged everywhere, edges included (the kernel is renormalised there).
  const IoData c = Decimate(
      IoData{Eigen::VectorXd::Constant(100, 2.0), Eigen::VectorXd::Constant(100, -1.0), 1.0}, 4);
  EXPECT_LT((c.u.array() - 2.0).abs().maxCoeff(), 1e-12);
  EXPECT_NEAR(LowPassFir(81, 0.1).sum(), 1.0, 1e-15);
}

TEST(Fit, FitPercentClosedForms) {
  const Eigen::Vector4d y(1.0, 2.0, 3.0, 4.0);
  EXPECT_DOUBLE_EQ(FitPercent(y, y), 100.0);
  EXPECT_NEAR(FitPercent(y, Eigen::Vector4d::Constant(2.5)), 0.0, 1e-12);  // the mean: 0 %
  // ‖y − ŷ‖ = 1, ‖y − ȳ‖ = √5: 100 (1 − 1/√5).
  EXPECT_NEAR(FitPercent(y, Eigen::Vector4d(1.0, 2.0, 3.0, 5.0)),
              100.0 * (1.0 - 1.0 / std::sqrt(5.0)), 1e-12);
  EXPECT_THROW(FitPercent(y, Eigen::Vector3d::Zero()), InputError);
}

TEST(Fit, QuantilesMatchTables) {
  // Standard normal and chi-square tables (Abramowitz & Stegun 26.2, 26.4).
  EXPECT_NEAR(NormalQuantileTwoSided(0.95), 1.959964, 1e-6);
  EXPECT_NEAR(NormalQuantileTwoSided(0.99), 2.575829, 1e-6);
  EXPECT_NEAR(ChiSquareQuantile(0.99, 25), 44.314, 0.05);
  EXPECT_NEAR(ChiSquareQuantile(0.95, 10), 18.307, 0.05);
}

TEST(Fit, ResidualTestsSeparateWhiteFromColouredAndCorrelated) {
  const Eigen::Index n = 4000;
  const Eigen::VectorXd u = testing::WhiteNoise(n, 1.0, 41);
  const Eigen::VectorXd e = testing::WhiteNoise(n, 1.0, 42);
  const ResidualTests white = TestResiduals(e, u);
  EXPECT_TRUE(white.white);
  EXPECT_TRUE(white.independent);
  EXPECT_NEAR(white.autocorrelation_bound, 2.575829 / std::sqrt(4000.0), 1e-6);
  // AR(1) residuals, ρ(1) = 0.3: the Ljung–Box test rejects whiteness.
  const ResidualTests coloured =
      TestResiduals(numerics::Filter(Eigen::VectorXd::Ones(1), Eigen::Vector2d(1.0, -0.3), e), u);
  EXPECT_FALSE(coloured.white);
  EXPECT_NEAR(coloured.autocorrelation[0], 0.3, 0.05);
  // Residuals that still contain the input two samples back: the cross-correlation test rejects.
  Eigen::VectorXd leak = e;
  leak.tail(n - 2) += 0.2 * u.head(n - 2);
  const ResidualTests correlated = TestResiduals(leak, u);
  EXPECT_FALSE(correlated.independent);
  EXPECT_NEAR(correlated.cross_correlation[25 + 2], 0.2 / std::sqrt(1.04), 0.05);
}

}  // namespace
}  // namespace vibid::sysid
