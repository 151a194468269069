// The modal model's confidence intervals: coverage over seeded synthetic hammer tests, and the
// model itself on an exact FRF. Truth: the simulated rig's state-matrix eigenvalues (model core)
// and its undamped shapes in closed form (test_support.hpp).
#include "vibid/ident/modal_model.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "test_support.hpp"
#include "vibid/common/error.hpp"
#include "vibid/ident/impact.hpp"
#include "vibid/ident/modes.hpp"
#include "vibid/ident/testing/hammer_test.hpp"
#include "vibid/model/modal.hpp"

namespace vibid::ident {
namespace {

bool Inside(const std::array<double, 2>& ci, double v) { return ci[0] <= v && v <= ci[1]; }

// Over 120 seeded hammer tests (3 hits of 5 s at 200 Hz, 0.5 % noise on force and responses,
// the default path: impact FRF, lscf) the 95 % intervals must hold the true omega and zeta in
// 90-99 % of the cases, and the a1/a2 intervals the closed-form ratio (both modes pooled: 240
// intervals each, so a true rate of 95 % lands in that range with a probability above 0.999). Short
// records keep the test cheap enough for the sanitizer build.
TEST(ModalModel, IntervalsCoverTheTruthAtTheirRate) {
  const double m1 = 1.0, m2 = 0.5, k1 = 4000.0, k2 = 2000.0, beta = 1e-3, fs = 200.0;
  const model::Model truth = model::MakeChain(Eigen::Vector2d(m1, m2), Eigen::Vector2d(k1, k2),
                                              Eigen::Vector2d(beta * k1, beta * k2));
  const model::ComplexModes cm = model::ComplexModalDamping(truth);
  const auto tm = testing::ChainModesOf(m1, m2, k1, k2);
  constexpr int kTests = 120;
  int omega_in[2] = {0, 0}, zeta_in[2] = {0, 0}, ratio_in[2] = {0, 0}, done = 0;
  double omega_hw[2] = {0, 0}, zeta_hw[2] = {0, 0};
  const auto t0 = std::chrono::steady_clock::now();
  for (int seed = 1; seed <= kTests; ++seed) {
    HammerTestSpec spec{.hammer_dof = 1,
                        .fs_hz = fs,
                        .hits = 3,
                        .pulse_width_s = 0.004,
                        .spacing_min_s = 5.0,
                        .spacing_max_s = 5.5,
                        .lead_s = 0.2,
                        .force_noise = 0.005,
                        .response_noise = 0.005,
                        .seed = static_cast<std::uint64_t>(5000 + seed)};
    const HammerTestRecord rec = SimulateHammerTest(truth, spec);
    ASSERT_TRUE(ClassifyExcitation(rec.force_n, fs).impact);
    const ImpactResult r = EstimateImpactFrf(rec.force_n, rec.response, fs, {}, Estimator::kH1,
                                             Quantity::kAcceleration);
    const ModeIdentification id = IdentifyModes(ConvertFrf(r.frf, Quantity::kDisplacement), 1, {});
    ASSERT_TRUE(id.has_model) << "seed " << seed;
    ASSERT_EQ(id.modes.size(), 2u) << "seed " << seed;
    for (int i = 0; i < 2; ++i) {
      const ModeEstimate& m = id.modes[static_cast<std::size_t>(i)];
      ASSERT_TRUE(m.HasIntervals());
      omega_in[i] += Inside(m.omega_ci95_rad_s, cm.omega_rad_s[i]);
      zeta_in[i] += Inside(m.zeta_ci95, cm.zeta[i]);
      ratio_in[i] += Inside(m.ratio_ci95, tm.ratio[i]);
      omega_hw[i] += 0.5 * (m.omega_ci95_rad_s[1] - m.omega_ci95_rad_s[0]) / cm.omega_rad_s[i];
      zeta_hw[i] += 0.5 * (m.zeta_ci95[1] - m.zeta_ci95[0]) / cm.zeta[i];
    }
    ++done;
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const auto rate = [&](const int* in) {
    return static_cast<double>(in[0] + in[1]) / (2.0 * done);
  };
  for (int i = 0; i < 2; ++i) {
    std::printf(
        "mode %d (%.3f Hz, zeta %.4f): omega in 95 %% interval %d/%d (mean half-width %.4f %%), "
        "zeta %d/%d "
        "(%.2f %%), a1/a2 %d/%d\n",
        i + 1, cm.omega_rad_s[i] / (2 * std::numbers::pi), cm.zeta[i], omega_in[i], done,
        100 * omega_hw[i] / done, zeta_in[i], done, 100 * zeta_hw[i] / done, ratio_in[i], done);
  }
  std::printf("coverage over %d tests (%.1f s): omega %.1f %%, zeta %.1f %%, a1/a2 %.1f %%\n", done,
              seconds, 100 * rate(omega_in), 100 * rate(zeta_in), 100 * rate(ratio_in));
  EXPECT_GE(rate(omega_in), 0.90);
  EXPECT_LE(rate(omega_in), 0.99);
  EXPECT_GE(rate(zeta_in), 0.90);
  EXPECT_LE(rate(zeta_in), 0.99);
  EXPECT_GE(rate(ratio_in), 0.90);
  EXPECT_LE(rate(ratio_in), 0.99);
}

// Noise-free receptance of the chain at uniform lines (no truncation: pretrigger 0): the fit
// returns the exact poles and the closed-form shape ratios, with vanishing intervals.
TEST(ModalModel, ExactFrfGivesTheExactModes) {
  const double m1 = 1.2, m2 = 0.8, k1 = 3000, k2 = 2000, c1 = 1.2, c2 = 0.8;
  const Frf frf = testing::ChainFrf(m1, m2, k1, k2, c1, c2, 1, 0.05, 600);
  const model::ComplexModes cm = model::ComplexModalDamping(
      model::MakeChain(Eigen::Vector2d(m1, m2), Eigen::Vector2d(k1, k2), Eigen::Vector2d(c1, c2)));
  const auto tm = testing::ChainModesOf(m1, m2, k1, k2);
  // Start 0.3 % and 20 % off the truth.
  std::vector<std::complex<double>> start;
  for (int i = 0; i < 2; ++i) {
    const double w = 1.003 * cm.omega_rad_s[i], z = 1.2 * cm.zeta[i];
    start.emplace_back(-z * w, w * std::sqrt(1 - z * z));
  }
  const ModalModelFit fit = FitModalModel(frf, start, {});
  ASSERT_TRUE(fit.summary.Converged()) << fit.summary.message;
  for (Eigen::Index i = 0; i < 2; ++i) {
    EXPECT_NEAR(fit.omega_rad_s[i], cm.omega_rad_s[i], 1e-8 * cm.omega_rad_s[i]);
    EXPECT_NEAR(fit.zeta[i], cm.zeta[i], 1e-6 * cm.zeta[i]);
    // Stiffness-proportional damping: real modes, so the undamped ratio is exact.
    EXPECT_NEAR(fit.ShapeRatio(i, 0, 1), tm.ratio[i], 1e-6 * std::abs(tm.ratio[i]));
    EXPECT_LT(fit.omega_sd_rad_s[i], 1e-8 * cm.omega_rad_s[i]);
  }
}

TEST(ModalModel, BadInputsAreInputErrors) {
  const Frf frf = testing::ChainFrf(1, 1, 1000, 1000, 1, 1, 1, 0.1, 200);
  EXPECT_THROW(FitModalModel(frf, {}, {}), InputError);
  EXPECT_THROW(FitModalModel(frf, {{0.1, 30.0}}, {}), InputError);  // unstable start pole
  EXPECT_THROW(FitModalModel(frf, {{-0.1, 30.0}}, {.max_iterations = -1}), InputError);
  EXPECT_THROW(FitModalModel(frf, {{-0.1, 30.0}}, {.freq_min_hz = 5.0, .freq_max_hz = 4.0}),
               InputError);
  Frf acc = frf;
  acc.quantity = Quantity::kAcceleration;
  EXPECT_THROW(FitModalModel(acc, {{-0.1, 30.0}}, {}), InputError);
}

}  // namespace
}  // namespace vibid::ident
