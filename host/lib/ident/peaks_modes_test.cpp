// Peak picking, Eq. 10 shapes and the modal curve fit on closed-form FRFs of 1- and 2-DOF systems.
#include <cmath>
#include <complex>
#include <numbers>

#include <gtest/gtest.h>

#include "test_support.hpp"
#include "vibid/common/error.hpp"
#include "vibid/ident/modes.hpp"
#include "vibid/ident/peaks.hpp"

namespace vibid::ident {
namespace {

using testing::ChainFrf;
using testing::ChainModesOf;

Eigen::VectorXd SdofMagnitude(const Eigen::VectorXd& f_hz, double m, double k, double zeta) {
  const double c = 2 * zeta * std::sqrt(k * m);
  Eigen::VectorXd mag(f_hz.size());
  for (Eigen::Index i = 0; i < f_hz.size(); ++i) {
    const double w = 2 * std::numbers::pi * f_hz[i];
    mag[i] = 1.0 / std::abs(std::complex<double>(k - m * w * w, c * w));
  }
  return mag;
}

TEST(PeakPicking, SdofHalfPowerDampingAndCubicPeak) {
  // m = 2, k = 8000: f_n = sqrt(4000)/(2 pi) = 10.066 Hz; zeta 0.01.
  const double m = 2.0, k = 8000.0, zeta = 0.01;
  const double wn = std::sqrt(k / m);
  const Eigen::VectorXd f = Eigen::VectorXd::LinSpaced(2001, 0.0, 40.0);  // 0.02 Hz lines
  const PeakResult r = PickPeaks(f, SdofMagnitude(f, m, k, zeta), {});
  ASSERT_EQ(r.peaks.size(), 1u);
  const Peak& p = r.peaks[0];
  // |H| peaks at omega_n sqrt(1 - 2 zeta^2) (closed form); the cubic through 5 lines finds it.
  EXPECT_NEAR(p.omega_rad_s, wn * std::sqrt(1 - 2 * zeta * zeta), 1e-4 * wn);
  EXPECT_NEAR(p.magnitude, 1.0 / (2 * zeta * std::sqrt(1 - zeta * zeta) * k),
              2e-3 / (2 * zeta * k));
  EXPECT_NEAR(p.zeta, zeta, 0.005 * zeta);
  EXPECT_FALSE(p.resolution_warning);
  EXPECT_TRUE(r.warnings.empty());
}

TEST(PeakPicking, WarnsWhenTheHalfPowerBandSpansFewLines) {
  const Eigen::VectorXd f =
      Eigen::VectorXd::LinSpaced(101, 0.0, 40.0);  // 0.4 Hz lines, band 0.2 Hz
  const PeakResult r = PickPeaks(f, SdofMagnitude(f, 2.0, 8000.0, 0.01), {});
  ASSERT_EQ(r.peaks.size(), 1u);
  EXPECT_TRUE(r.peaks[0].resolution_warning);
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_NE(r.warnings[0].find("half-power band"), std::string::npos);
}

TEST(PeakPicking, IgnoresRipplesAndHonoursThresholdAndCount) {
  const Eigen::VectorXd f = Eigen::VectorXd::LinSpaced(2001, 0.0, 40.0);
  Eigen::VectorXd mag = SdofMagnitude(f, 2.0, 8000.0, 0.01);
  // A ripple on the flank: a local maximum that never falls to half power before the main peak.
  mag[400] *= 1.02;
  mag[401] *= 1.0;
  const PeakResult r = PickPeaks(f, mag, {});
  EXPECT_EQ(r.peaks.size(), 1u);
  EXPECT_THROW(PickPeaks(f, mag, {.threshold_fraction = 1.5}), InputError);
  EXPECT_THROW(PickPeaks(f.head(3), mag.head(3), {}), InputError);
}

struct Truth {
  const char* name;
  double m1, m2, k1, k2, beta;  // proportional damping C = beta K
};

// Separated modes with light damping, and closer modes with moderate damping.
const Truth kTruths[] = {
    {"separated_light", 1.2, 0.8, 3000.0, 2000.0, 2e-4},
    {"close_moderate", 1.0, 0.1, 4000.0, 400.0, 6e-4},
};

class ChainModes2 : public ::testing::TestWithParam<Truth> {};

TEST_P(ChainModes2, PeakPicksAndCurveFitRecoverTheModes) {
  const Truth t = GetParam();
  const auto modes = ChainModesOf(t.m1, t.m2, t.k1, t.k2);
  const Frf frf = ChainFrf(t.m1, t.m2, t.k1, t.k2, t.beta * t.k1, t.beta * t.k2, 1, 0.01, 4000);
  const Eigen::VectorXd mag = PickingMagnitude(frf, -1);
  const PeakResult picks = PickPeaks(frf.freq_hz, mag, {});
  ASSERT_EQ(picks.peaks.size(), 2u) << t.name;
  // Eq. 10 estimates: close, not exact (neighbouring mode's contribution).
  const auto quick = ShapesFromPeaks(frf, 1, picks.peaks);
  for (int i = 0; i < 2; ++i) {
    const double zeta_true = t.beta * modes.omega[i] / 2;  // C = beta K: zeta_i = beta omega_i / 2
    EXPECT_NEAR(quick[static_cast<std::size_t>(i)].omega_rad_s, modes.omega[i],
                2e-3 * modes.omega[i])
        << t.name;
    EXPECT_NEAR(quick[static_cast<std::size_t>(i)].zeta, zeta_true, 0.1 * zeta_true) << t.name;
    EXPECT_NEAR(quick[static_cast<std::size_t>(i)].ratio, modes.ratio[i],
                0.05 * std::abs(modes.ratio[i]))
        << t.name;
  }
  const CurveFitResult fit = FitModes(frf, picks.peaks, {});
  ASSERT_TRUE(fit.summary.Converged()) << fit.summary.message;
  EXPECT_LT(fit.summary.final_cost, fit.summary.initial_cost);
  const auto shapes = ShapesFromResidues(fit, 1);
  ASSERT_EQ(shapes.size(), 2u);
  for (int i = 0; i < 2; ++i) {
    const auto& s = shapes[static_cast<std::size_t>(i)];
    const double zeta_true = t.beta * modes.omega[i] / 2;
    EXPECT_NEAR(s.omega_rad_s, modes.omega[i] * std::sqrt(1.0), 1e-6 * modes.omega[i]) << t.name;
    EXPECT_NEAR(s.zeta, zeta_true, 1e-5 * zeta_true) << t.name;
    EXPECT_NEAR(s.ratio, modes.ratio[i], 1e-5 * std::abs(modes.ratio[i])) << t.name;
    // Mass normalisation: phi^T M phi = 1 with the true masses.
    EXPECT_NEAR(t.m1 * s.shape[0] * s.shape[0] + t.m2 * s.shape[1] * s.shape[1], 1.0, 1e-5)
        << t.name;
  }
  EXPECT_LT(fit.rms_relative_error, 1e-6);
}

INSTANTIATE_TEST_SUITE_P(Truths, ChainModes2, ::testing::ValuesIn(kTruths),
                         [](const auto& param_info) { return std::string(param_info.param.name); });

TEST(CurveFit, RejectsNonReceptanceAndEmptyStart) {
  Frf frf = ChainFrf(1, 1, 1000, 1000, 0.1, 0.1, 1, 0.05, 400);
  EXPECT_THROW(FitModes(frf, {}, {}), InputError);
  frf.quantity = Quantity::kAcceleration;
  Peak p;
  p.omega_rad_s = 20;
  p.freq_hz = 20 / (2 * std::numbers::pi);
  p.zeta = 0.01;
  EXPECT_THROW(FitModes(frf, {p}, {}), InputError);
}

}  // namespace
}  // namespace vibid::ident
