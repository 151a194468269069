// Free-decay analysis: synthetic damped sinusoids with a hold before the release (closed forms);
// the ECP cart records against the values the lab published are in decay_ecp_test.cpp.
#include "vibid/ident/decay.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "vibid/common/csv.hpp"
#include "vibid/common/error.hpp"

namespace vibid::ident {
namespace {

TEST(Decay, RecoversAnExactDampedSinusoid) {
  const double fs = 200.0;
  const double wn = 30.0;
  const double zeta = 0.02;
  const double wd = wn * std::sqrt(1 - zeta * zeta);
  Eigen::VectorXd x(1200);
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    const double t = (static_cast<double>(i) - 100.0) / fs;
    // Held at 0.02 for 100 samples, released at zero velocity: x = A e^{-s t}(cos + s/wd sin).
    x[i] = i <= 100 ? 0.02
                    : 0.001 + 0.019 * std::exp(-zeta * wn * t) *
                                  (std::cos(wd * t) + zeta * wn / wd * std::sin(wd * t));
  }
  const DecayResult r = AnalyzeDecay(x, fs, {});
  EXPECT_EQ(r.release_index, 100u);
  EXPECT_NEAR(r.omega_d_rad_s, wd, 1e-6 * wd);
  EXPECT_NEAR(r.zeta, zeta, 1e-6 * zeta);
  EXPECT_NEAR(r.omega_n_rad_s, wn, 1e-6 * wn);
  EXPECT_NEAR(r.offset, 0.001, 1e-9);
  EXPECT_TRUE(r.summary.Converged()) << r.summary.message;
}

// A pull-and-release record of a mass m_kg on the spring k_n_per_m at 200 Hz for 8 s: at rest,
// pulled to 2 cm over 0.5 s, held 1 s, released at t = 2 s into the closed form
// x = 0.02 exp(-zeta wn t) cos(wd t), with 1 um of noise on every sample (the hold included).
Eigen::VectorXd ReleaseRecord(double k_n_per_m, double m_kg, double zeta, unsigned seed) {
  const double fs = 200.0;
  const double wn = std::sqrt(k_n_per_m / m_kg);
  const double wd = wn * std::sqrt(1 - zeta * zeta);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 1e-6);
  Eigen::VectorXd x(1600);
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    const double t = static_cast<double>(i) / fs;
    const double tr = t - 2.0;
    x[i] = tr < 0.0 ? std::clamp((t - 0.5) / 0.5, 0.0, 1.0) * 0.02
                    : 0.02 * std::exp(-zeta * wn * tr) * std::cos(wd * tr);
    x[i] += noise(rng);
  }
  return x;
}

TEST(Decay, NoisyHoldGivesTheClosedFormBack) {
  // The hold is a noisy plateau: the fit starts where the motion leaves it (sample 400, t = 2 s),
  // not at its largest sample, and gives the closed form's parameters back (reference: the closed
  // form, wn = sqrt(800 / 2) = 20 rad/s, zeta 0.02).
  const double wn = 20.0, zeta = 0.02, wd = wn * std::sqrt(1 - zeta * zeta);
  for (const int cycles : {0, 3}) {
    for (unsigned seed = 0; seed < 4; ++seed) {
      const DecayResult r = AnalyzeDecay(ReleaseRecord(800.0, 2.0, zeta, seed), 200.0,
                                         {.end_fraction = 0.1, .cycles = cycles});
      SCOPED_TRACE("cycles " + std::to_string(cycles) + ", seed " + std::to_string(seed));
      EXPECT_GE(r.release_index, 400u);
      EXPECT_LE(r.release_index, 401u);
      EXPECT_NEAR(r.omega_n_rad_s, wn, 1e-4 * wn);
      EXPECT_NEAR(r.omega_d_rad_s, wd, 1e-4 * wd);
      EXPECT_NEAR(r.zeta, zeta, 1e-3 * zeta);
      EXPECT_LT(r.rms_residual, 2e-6);  // the noise, 1 um, not the hold
    }
  }
}

TEST(Decay, NoisyHoldPairGivesTheSpringAndMassBack) {
  // Same spring, 2 kg and 3 kg: wn^2 = k/m gives k 800 N/m and m 2 kg back (closed form).
  const DecayOptions o{.end_fraction = 0.1, .cycles = 3};
  const DecayResult u = AnalyzeDecay(ReleaseRecord(800.0, 2.0, 0.02, 1), 200.0, o);
  const DecayResult l = AnalyzeDecay(ReleaseRecord(800.0, 3.0, 0.02, 11), 200.0, o);
  EXPECT_NEAR(l.omega_n_rad_s, std::sqrt(800.0 / 3.0), 1e-4 * std::sqrt(800.0 / 3.0));
  const AddedMassSolution s = SolveAddedMass(u.omega_n_rad_s, l.omega_n_rad_s, 1.0);
  EXPECT_NEAR(s.k_n_per_m, 800.0, 1e-3 * 800.0);
  EXPECT_NEAR(s.base_mass_kg, 2.0, 1e-3 * 2.0);
}

TEST(Decay, GrowingOscillationIsRefusedWithTheReason) {
  // zeta <= 0 is no passive spring-mass: refused, naming the damping, never printed as a result.
  try {
    AnalyzeDecay(ReleaseRecord(800.0, 2.0, -0.01, 3), 200.0, {.end_fraction = 0.1, .cycles = 3});
    ADD_FAILURE() << "a growing oscillation was analysed";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("<= 0 (a growing oscillation)"), std::string::npos)
        << e.what();
  }
}

TEST(Decay, AddedMassPairClosedForm) {
  // k = 700, m = 0.6, added 0.986: omega^2 = k/m.
  const AddedMassSolution s =
      SolveAddedMass(std::sqrt(700.0 / 0.6), std::sqrt(700.0 / 1.586), 0.986);
  EXPECT_NEAR(s.k_n_per_m, 700.0, 1e-9);
  EXPECT_NEAR(s.base_mass_kg, 0.6, 1e-12);
  EXPECT_THROW(SolveAddedMass(10.0, 12.0, 1.0), InputError);
}

TEST(Decay, ConstantOrShortRecordIsAnInputError) {
  EXPECT_THROW(AnalyzeDecay(Eigen::VectorXd::Ones(100), 200.0, {}), InputError);
  EXPECT_THROW(AnalyzeDecay(Eigen::VectorXd::LinSpaced(10, 0, 1), 200.0, {}), InputError);
}

}  // namespace
}  // namespace vibid::ident
