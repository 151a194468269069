// What the sequential test's tests share: references drawn through a fixed mixing matrix, the
// alarms over unchanged blocks, and a two-sided count of them at the watch's default sizes.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>

#include <Eigen/Core>

#include "vibid/oma/sequential_test.hpp"

namespace vibid::oma::testing {

// A reference of m observations N(0, mix mixᵀ) drawn from rng.
inline Eigen::MatrixXd DrawReference(const Eigen::MatrixXd& mix, int m, std::mt19937_64& rng) {
  std::normal_distribution<double> normal;
  Eigen::MatrixXd ref(mix.rows(), m);
  for (int j = 0; j < m; ++j)
    for (int i = 0; i < mix.rows(); ++i) ref(i, j) = normal(rng);
  return mix * ref;
}

inline Eigen::MatrixXd Mix(int p) {
  Eigen::MatrixXd mix = Eigen::MatrixXd::Identity(p, p) + 0.7 * Eigen::MatrixXd::Ones(p, p);
  mix(0, p - 1) = 2.0;
  return mix;
}

// Alarms of one test over `blocks` unchanged blocks.
inline int Alarms(SequentialTest& test, const Eigen::MatrixXd& mix, long blocks,
                  std::mt19937_64& rng) {
  std::normal_distribution<double> normal;
  Eigen::VectorXd z(mix.rows());
  int alarms = 0;
  for (long b = 0; b < blocks; ++b) {
    for (int i = 0; i < z.size(); ++i) z(i) = normal(rng);
    alarms += test.Add(mix * z).alarm;
  }
  return alarms;
}

// The watch's default sizes: p = 8 residuals, m = 144 reference blocks (30 minutes of 10 s
// blocks), onsets up to 60 blocks back.
constexpr int kP = 8;
constexpr int kM = 144;
constexpr int kL = 60;

// `refs` references each watched `hours` of unchanged 10 s blocks at `per_hour` asked: alarms
// counted, and the count expected from the calibration (the references' mean rate) with its
// spread (Poisson's and the references' own, from the band), 3.3 standard deviations each side.
inline void CountTwoSided(double per_hour, int refs, double hours, std::uint64_t seed) {
  const double asked = per_hour * 10.0 / 3600.0;
  const SequentialCalibration c = CalibrateSequential(kP, kM, kL, asked);
  const long blocks = std::lround(hours * 360.0);
  std::mt19937_64 rng(seed);
  const Eigen::MatrixXd mix = Mix(kP);
  int alarms = 0;
  for (int r = 0; r < refs; ++r) {
    SequentialTest test(DrawReference(mix, kM, rng), kL, asked);
    alarms += Alarms(test, mix, blocks, rng);
  }
  const double n = static_cast<double>(blocks);
  const double expected = c.mean * refs * n;
  const double spread = (c.high - c.low) / 4.0 * n;
  const double sd = std::sqrt(expected + refs * spread * spread);
  std::printf(
      "%.0f h at %g/h asked (%.1f alarms): %d, %.1f expected (%.1f … %.1f); h %.2f (exact %.2f), "
      "band %.2g … %.2g per hour, mean %.2g; at the exact h %.2g … %.2g\n",
      refs * hours, per_hour, per_hour * refs * hours, alarms, expected, expected - 3.3 * sd,
      expected + 3.3 * sd, c.threshold, c.exact_threshold, c.low * 360.0, c.high * 360.0,
      c.mean * 360.0, c.exact_low * 360.0, c.exact_high * 360.0);
  EXPECT_GE(alarms, expected - 3.3 * sd);
  EXPECT_LE(alarms, expected + 3.3 * sd);
  EXPECT_GT(expected - 3.3 * sd, 0.0);                      // the lower bound can fail
  EXPECT_LT(expected + 3.3 * sd, per_hour * refs * hours);  // the upper lies below the rate asked
}

}  // namespace vibid::oma::testing
