// Friction found on one mode bounds the others, and names a lost peak: ring-downs built in closed
// form (displacements), two modes on two responses. Mode 1's envelope falls as dA/dt = -sigma A
// - r (viscous + Coulomb, r = 2 F_q / (pi omega) for a modal friction force F_q: Den Hartog's
// equivalent viscous damping zeta_eq = 2 F_q / (pi omega^2 A) of Coulomb friction), mode 2's as
// a viscous mode's, too fast for the same friction to show in it.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
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
constexpr double kF1 = 4.4, kZeta1 = 0.02;    // mode 1, undamped frequency and viscous damping
constexpr double kF2 = 11.0, kZeta2 = 0.044;  // mode 2
constexpr double kA1 = 1e-3;                  // mode 1's start (m, modal)
constexpr double kFrictionOffset = 0.03;      // b / A0 of mode 1: b = r / sigma

const Eigen::Vector2d kPhi1(0.5, 0.7);
const Eigen::Vector2d kPhi2(0.7, -0.5);

// Mode 1's friction: r = sigma b, the modal force F_q = r pi omega / 2, per mass F_q / sum |phi|.
double FrictionPerMass() {
  const double r = kZeta1 * Omega(kF1) * kFrictionOffset * kA1;
  return r * std::numbers::pi * Omega(kF1) / 2.0 / kPhi1.cwiseAbs().sum();
}

// Mode 2's start: alone, the friction above would put the term tau = 2 r2 / (sigma2 A2) = 2
// zeta_eq(A2) / zeta2 into its ring-downs (r2 = 2 F sum |phi2| / (pi omega2)); A2 is chosen for
// 2 %.
double ModeTwoStart() {
  const double r2 =
      2.0 * FrictionPerMass() * kPhi2.cwiseAbs().sum() / (std::numbers::pi * Omega(kF2));
  return 2.0 * r2 / (kZeta2 * Omega(kF2) * 0.02);
}

// The reference term: mass j's friction acts on mode 2 as the relay's equivalent damping
// phi_j2^2 4 F / (pi V_j), V_j the larger of mode 2's and mode 1's velocity amplitude there (mode
// 1's envelope (A1 + b) e^(-sigma1 t) - b), averaged over mode 2's decay to 2 % with the weight
// A2(t)^2, over zeta2; by the trapezoidal rule on 20 000 steps, from the rig's own values.
double ReferenceTerm() {
  const double s1 = kZeta1 * Omega(kF1), s2 = kZeta2 * Omega(kF2);
  const double b = kFrictionOffset * kA1;
  const double end_s = std::log(50.0) / s2;
  const int steps = 20000;
  double num = 0.0, den = 0.0;
  for (int i = 0; i <= steps; ++i) {
    const double t = end_s * i / steps;
    const double w = std::exp(-2.0 * s2 * t) * (i == 0 || i == steps ? 0.5 : 1.0);
    const double a1 = std::max(0.0, (kA1 + b) * std::exp(-s1 * t) - b);
    const double a2 = ModeTwoStart() * std::exp(-s2 * t);
    double c = 0.0;
    for (int j = 0; j < 2; ++j) {
      const double v =
          std::max(std::abs(kPhi2[j]) * Omega(kF2) * a2, std::abs(kPhi1[j]) * Omega(kF1) * a1);
      c += kPhi2[j] * kPhi2[j] * 4.0 * FrictionPerMass() / (std::numbers::pi * v);
    }
    num += w * c / (2.0 * Omega(kF2));
    den += w;
  }
  return num / den / kZeta2;
}

// Five hits of 12 s; mode 1 with friction (offset b) or without (b = 0), mode 2 viscous.
RingDowns MakeRingDowns(double offset) {
  RingDowns rd;
  rd.fs_hz = kFs;
  rd.sensor = Quantity::kDisplacement;
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 2e-7);
  const double s1 = kZeta1 * Omega(kF1), s2 = kZeta2 * Omega(kF2);
  const double wd1 = Omega(kF1) * std::sqrt(1.0 - kZeta1 * kZeta1);
  const double wd2 = Omega(kF2) * std::sqrt(1.0 - kZeta2 * kZeta2);
  const double a2 = ModeTwoStart();
  for (int h = 0; h < 5; ++h) {
    const double scale = 1.0 + 0.1 * (h - 2);  // hits of different strength
    Eigen::MatrixXd hit(2400, 2);
    for (Eigen::Index k = 0; k < hit.rows(); ++k) {
      const double t = static_cast<double>(k) / kFs;
      const double b = offset * kA1;
      const double env1 = std::max(0.0, (scale * kA1 + b) * std::exp(-s1 * t) - b);
      const double q1 = env1 * std::cos(wd1 * t);
      const double q2 = scale * a2 * std::exp(-s2 * t) * std::cos(wd2 * t);
      hit.row(k) = (kPhi1 * q1 + kPhi2 * q2).transpose();
      hit(k, 0) += noise(rng);
      hit(k, 1) += noise(rng);
    }
    rd.hits.push_back(hit);
  }
  return rd;
}

// Mode 1 as an FRF gives it: zeta 30 % high, at the ring-down's damped frequency (an undamped
// omega carrying the high zeta). Mode 2 as it is.
TEST(RingDownBound, FrictionFoundOnOneModeWidensTheOthersAndCorrectsOmega) {
  const double zeta_frf = 1.3 * kZeta1;
  const double wd1 = Omega(kF1) * std::sqrt(1.0 - kZeta1 * kZeta1);
  ModeIdentification mi;
  mi.modes.push_back(Mode(kF1, zeta_frf, kPhi1));
  mi.modes[0].omega_rad_s = wd1 / std::sqrt(1.0 - zeta_frf * zeta_frf);
  mi.modes[0].freq_hz = mi.modes[0].omega_rad_s / (2.0 * std::numbers::pi);
  mi.modes.push_back(Mode(kF2, kZeta2, kPhi2));
  ApplyAmplitudeCheck(MakeRingDowns(kFrictionOffset), mi);
  const ModeEstimate& m1 = mi.modes[0];
  const ModeEstimate& m2 = mi.modes[1];
  ASSERT_TRUE(m1.amplitude.amplitude_dependent) << m1.amplitude.note;
  ASSERT_FALSE(m2.amplitude.amplitude_dependent) << m2.amplitude.note;
  EXPECT_NEAR(m1.amplitude.friction_per_mass_n, FrictionPerMass(), 0.1 * FrictionPerMass());
  // omega = omega_d / sqrt(1 - zeta_v^2): the truth within 2e-5 (the FRF's omega is 1.4e-4 high).
  EXPECT_NEAR(m1.omega_rad_s / Omega(kF1), 1.0, 2e-5);
  EXPECT_GT(mi.modes[0].omega_rad_s, 0.0);
  // Mode 2: its term from mode 1's force (ReferenceTerm; numpy's trapz on the same integral:
  // 0.67 %, and 1.96 % with mode 1's velocity left out);
  // zeta's interval reaches kFrictionTerms = 5 terms below zeta (the force the upper end of
  // mode 1's interval, so a little more), and omega's down to omega sqrt((1 - zeta^2) / (1 -
  // zeta_lo^2)).
  const double tau = ReferenceTerm();
  EXPECT_NEAR(tau, 0.0067, 0.0002);
  ASSERT_NE(m2.caution.find("widened down"), std::string::npos) << m2.caution;
  const double drop = 1.0 - m2.zeta_ci95[0] / kZeta2;
  EXPECT_GT(drop, 5.0 * tau * 0.9) << m2.caution;
  EXPECT_LT(drop, 5.0 * tau * 1.3) << m2.caution;
  EXPECT_DOUBLE_EQ(m2.zeta_ci95[1], 1.01 * kZeta2);
  const double lo = m2.zeta_ci95[0];
  EXPECT_NEAR(m2.omega_ci95_rad_s[0],
              Omega(kF2) * std::sqrt((1.0 - kZeta2 * kZeta2) / (1.0 - lo * lo)), 1e-9);
  EXPECT_NE(m2.caution.find("dry friction found at 4.4"), std::string::npos) << m2.caution;
}

// Without friction nothing moves: mode 2's intervals stay the FRF's.
TEST(RingDownBound, NoFrictionNoBound) {
  ModeIdentification mi;
  mi.modes.push_back(Mode(kF1, kZeta1, kPhi1));
  mi.modes.push_back(Mode(kF2, kZeta2, kPhi2));
  ApplyAmplitudeCheck(MakeRingDowns(0.0), mi);
  EXPECT_FALSE(mi.modes[0].amplitude.amplitude_dependent) << mi.modes[0].amplitude.note;
  EXPECT_DOUBLE_EQ(mi.modes[1].zeta_ci95[0], 0.99 * kZeta2);
  EXPECT_TRUE(FrictionShownBy(mi).empty());
}

// Mode 1 lost (a clear peak with no mode): its ring-down read at the peak, in what mode 2's
// shape leaves of the responses, shows the friction, which is named as the likely cause; without
// friction the same peak is not.
TEST(RingDownBound, ALostPeakThatRingsWithFrictionNamesIt) {
  for (const double offset : {kFrictionOffset, 0.0}) {
    ModeIdentification mi;
    mi.modes.push_back(Mode(kF2, kZeta2, kPhi2));
    mi.peaks_without_mode_hz = {kF1};
    ApplyAmplitudeCheck(MakeRingDowns(offset), mi);
    const std::string shown = FrictionShownBy(mi);
    bool warned = false;
    for (const std::string& w : mi.warnings)
      warned = warned || w.find("dry friction, which hides modes") != std::string::npos;
    if (offset > 0.0) {
      EXPECT_NE(shown.find("at 4.4 Hz, a clear peak no mode explains"), std::string::npos) << shown;
      EXPECT_TRUE(warned);
      ASSERT_EQ(mi.friction_at_lost_peaks.size(), 1u);
      EXPECT_DOUBLE_EQ(mi.friction_at_lost_peaks[0].freq_hz, kF1);
      EXPECT_GT(mi.friction_at_lost_peaks[0].zeta_late, mi.friction_at_lost_peaks[0].zeta_early);
      // Friction that hides a mode: mode 2 keeps its values, not its intervals.
      EXPECT_FALSE(std::isfinite(mi.modes[0].zeta_ci95[0]));
      EXPECT_FALSE(std::isfinite(mi.modes[0].omega_ci95_rad_s[0]));
      EXPECT_DOUBLE_EQ(mi.modes[0].zeta, kZeta2);
      EXPECT_NE(mi.modes[0].caution.find("strong enough to hide the mode at 4.4 Hz"),
                std::string::npos)
          << mi.modes[0].caution;
    } else {
      EXPECT_TRUE(shown.empty()) << shown;
      EXPECT_FALSE(warned);
      EXPECT_TRUE(mi.friction_at_lost_peaks.empty());
      EXPECT_DOUBLE_EQ(mi.modes[0].zeta_ci95[0], 0.99 * kZeta2);
    }
  }
}

}  // namespace
}  // namespace vibid::ident
