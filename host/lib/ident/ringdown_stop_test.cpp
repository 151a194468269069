// Ring-downs that friction stops within a few envelope samples: too short to fit, they still count
// for the early-stop test. Built in closed form (displacements), two modes on two responses:
// mode A viscous and long, mode B with Coulomb friction alone, whose envelope falls linearly to
// zero in kStopS (dA/dt = -r: a relay's amplitude loss per cycle is constant), where an FRF
// reads a damping (kZetaFrfB) whose decay to 2 % takes ln(50) / (zeta omega) = 0.94 s.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "vibid/ident/modes.hpp"
#include "vibid/ident/ringdown.hpp"
#include "ringdown_test_support.hpp"

namespace vibid::ident {
namespace {

using testing::Mode;
using testing::Omega;

constexpr double kFs = 200.0;
constexpr double kFA = 4.4, kZetaA = 0.02;  // mode A: viscous, rings for 10 s
constexpr double kFB = 11.0;                // mode B: Coulomb friction alone
constexpr double kStopS = 0.5;              // mode B's ring-down ends here
constexpr double kZetaFrfB = 0.06;          // mode B's damping as its FRF peak reads it

const Eigen::Vector2d kPhiA(0.5, 0.7);
const Eigen::Vector2d kPhiB(0.7, -0.5);

// Five hits of 12 s of different strengths; mode B's stop time does not depend on the strength
// here (its rate scales with it), as the 0.3 N study's ring-downs ended after about 0.5 s
// whatever the hit.
RingDowns MakeRingDowns() {
  RingDowns rd;
  rd.fs_hz = kFs;
  rd.sensor = Quantity::kDisplacement;
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0.0, 2e-7);
  const double sa = kZetaA * Omega(kFA);
  const double wda = Omega(kFA) * std::sqrt(1.0 - kZetaA * kZetaA);
  for (int h = 0; h < 5; ++h) {
    const double scale = 1.0 + 0.1 * (h - 2);
    Eigen::MatrixXd hit(2400, 2);
    for (Eigen::Index k = 0; k < hit.rows(); ++k) {
      const double t = static_cast<double>(k) / kFs;
      const double qa = scale * 1e-3 * std::exp(-sa * t) * std::cos(wda * t);
      const double qb = scale * 1e-3 * std::max(0.0, 1.0 - t / kStopS) * std::cos(Omega(kFB) * t);
      hit.row(k) = (kPhiA * qa + kPhiB * qb).transpose();
      hit(k, 0) += noise(rng);
      hit(k, 1) += noise(rng);
    }
    rd.hits.push_back(hit);
  }
  return rd;
}

// Mode B found: every hit's ring-down falls to 2 % of its start long before its FRF damping lets
// it (the envelope, smoothed over 0.55 s, reads it gone after about 0.5 s of the 0.94 s), too fast
// for the envelope fit's eight samples: stopped early in 5 of 5 hits, every interval withheld,
// friction named. Mode A, viscous, is left alone.
TEST(RingDownStop, RingDownsTooShortToFitStillCountForTheEarlyStop) {
  ModeIdentification mi;
  mi.modes.push_back(Mode(kFA, kZetaA, kPhiA));
  mi.modes.push_back(Mode(kFB, kZetaFrfB, kPhiB));
  ApplyAmplitudeCheck(MakeRingDowns(), mi);
  const AmplitudeDamping& b = mi.modes[1].amplitude;
  ASSERT_TRUE(b.stops_early) << b.note;
  EXPECT_TRUE(b.amplitude_dependent);
  EXPECT_EQ(b.hits, 5u);
  const double expected_s = std::log(50.0) / (kZetaFrfB * Omega(kFB));  // 0.943 s
  EXPECT_NEAR(b.expected_stop_s, expected_s, 1e-9);
  EXPECT_LT(b.stop_s, 0.7 * expected_s);
  EXPECT_GT(b.stop_s, 0.25);  // not before the envelope's smoothing lets it fall
  EXPECT_FALSE(std::isfinite(mi.modes[1].zeta_ci95[0]));
  EXPECT_FALSE(mi.modes[0].amplitude.amplitude_dependent) << mi.modes[0].amplitude.note;
  // Friction that stops one mode's ring-downs moves the others beyond their own ring-downs'
  // reach: mode A keeps its values, not its intervals.
  EXPECT_FALSE(std::isfinite(mi.modes[0].omega_ci95_rad_s[0]));
  EXPECT_DOUBLE_EQ(mi.modes[0].zeta, kZetaA);
  EXPECT_NE(mi.modes[0].caution.find("strong enough to stop the ring-downs at 11 Hz"),
            std::string::npos)
      << mi.modes[0].caution;
  EXPECT_NE(FrictionShownBy(mi).find("at 11 Hz they die in"), std::string::npos)
      << FrictionShownBy(mi);
}

// Mode B lost (a clear peak with no mode): read in what mode A's shape leaves of the responses,
// against the peak's own half-power damping, its ring-downs stop early and friction is named as
// the likely cause. Without the peak's damping there is nothing to stop early against, and the
// ring-downs are too short for the amplitude rule: nothing is named.
TEST(RingDownStop, ALostPeakWhoseRingDownsStopEarlyNamesFriction) {
  for (const bool with_zeta : {true, false}) {
    ModeIdentification mi;
    mi.modes.push_back(Mode(kFA, kZetaA, kPhiA));
    mi.peaks_without_mode_hz = {kFB};
    if (with_zeta) mi.peaks_without_mode_zeta = {kZetaFrfB};
    ApplyAmplitudeCheck(MakeRingDowns(), mi);
    const std::string shown = FrictionShownBy(mi);
    if (with_zeta) {
      ASSERT_EQ(mi.friction_at_lost_peaks.size(), 1u);
      const FrictionAtLostPeak& p = mi.friction_at_lost_peaks[0];
      EXPECT_TRUE(p.stops_early);
      EXPECT_EQ(p.hits, 5u);
      EXPECT_NEAR(p.expected_stop_s, std::log(50.0) / (kZetaFrfB * Omega(kFB)), 1e-9);
      EXPECT_LT(p.stop_s, 0.7 * p.expected_stop_s);
      EXPECT_NE(shown.find("at 11 Hz, a clear peak no mode explains, they die in"),
                std::string::npos)
          << shown;
      // Friction that stops a ring-down: mode A keeps its values, not its intervals.
      EXPECT_FALSE(std::isfinite(mi.modes[0].zeta_ci95[0]));
      EXPECT_FALSE(std::isfinite(mi.modes[0].omega_ci95_rad_s[0]));
      EXPECT_NE(mi.modes[0].caution.find("strong enough to hide the mode at 11 Hz"),
                std::string::npos)
          << mi.modes[0].caution;
    } else {
      EXPECT_TRUE(mi.friction_at_lost_peaks.empty());
      EXPECT_TRUE(shown.empty()) << shown;
      EXPECT_DOUBLE_EQ(mi.modes[0].zeta_ci95[0], 0.99 * kZetaA);
    }
  }
}

}  // namespace
}  // namespace vibid::ident

namespace vibid::ident {
namespace {

// The viscous part's known bias under noise (docs/identification.md, "Dry friction at every
// level"): one mode on one response, each hit's envelope exactly viscous + Coulomb (friction
// offset b/a 0.08, zeta 0.0192 at 4.44 Hz, as the 2-mass rig's mode 1 at 10 mN per mass), 30
// records of 5 hits at 500 Hz. Without noise the fit returns zeta within 0.01 %; with white noise
// of a tenth of the ring-down's start per sample (the study's records: 0.5 % of the channel's
// largest value) it reads zeta about 0.6 % high, as the 2-mass study's viscous part ran (+0.6 %
// at 10 mN): the noise blurs the deep tail, where Coulomb's linear decay shows, and the fit gives
// part of the friction to the viscous term. The bias is stated, not corrected: this test fails
// when it goes away (the docs then stale) or grows.
double MeanViscousBias(double noise_sd) {
  constexpr double kF = 4.44, kZeta = 0.0192, kOffset = 0.08, kRateHz = 500.0;
  const double sigma = kZeta * Omega(kF);
  const double wd = Omega(kF) * std::sqrt(1.0 - kZeta * kZeta);
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, 1.0);
  double sum = 0.0;
  int n = 0;
  for (int rec = 0; rec < 30; ++rec) {
    RingDowns rd;
    rd.fs_hz = kRateHz;
    rd.sensor = Quantity::kAcceleration;
    for (int h = 0; h < 5; ++h) {
      Eigen::MatrixXd hit(5700, 1);
      for (Eigen::Index k = 0; k < hit.rows(); ++k) {
        const double t = static_cast<double>(k) / kRateHz;
        const double env = std::max(0.0, (1.0 + kOffset) * std::exp(-sigma * t) - kOffset);
        hit(k, 0) = env * std::cos(wd * t) + noise_sd * noise(rng);
      }
      rd.hits.push_back(hit);
    }
    ModeIdentification mi;
    mi.modes.push_back(Mode(kF, 1.2 * kZeta, Eigen::VectorXd::Ones(1)));
    ApplyAmplitudeCheck(rd, mi);
    const AmplitudeDamping& a = mi.modes[0].amplitude;
    EXPECT_TRUE(a.amplitude_dependent) << a.note;
    if (!(a.zeta_viscous > 0.0)) continue;
    sum += a.zeta_viscous / kZeta - 1.0;
    ++n;
  }
  return n > 0 ? sum / n : std::numeric_limits<double>::quiet_NaN();
}

TEST(RingDownStop, TheViscousPartReadsHighUnderNoise) {
  EXPECT_LT(std::abs(MeanViscousBias(0.0)), 1e-4);
  const double noisy = MeanViscousBias(0.1);
  EXPECT_GT(noisy, 0.003);
  EXPECT_LT(noisy, 0.012);
}

}  // namespace
}  // namespace vibid::ident
