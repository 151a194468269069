// Welch spectra and FRF estimators against scipy.signal (golden vectors from
// scripts/golden/ident_welch.py) and against the closed-form FRF of a digital filter.
#include "vibid/ident/spectral.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdint>
#include <cstring>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "vibid/common/csv.hpp"
#include "vibid/common/error.hpp"

namespace vibid::ident {
namespace {

using cd = std::complex<double>;

// The same generator as scripts/golden/ident_welch.py: 32-bit LCG, u in [-0.5, 0.5).
Eigen::VectorXd LcgNoise(Eigen::Index n, std::uint64_t seed) {
  Eigen::VectorXd out(n);
  std::uint64_t x = seed;
  for (Eigen::Index k = 0; k < n; ++k) {
    x = (1664525u * x + 1013904223u) % (std::uint64_t{1} << 32);
    out[k] = static_cast<double>(x) / 4294967296.0 - 0.5;
  }
  return out;
}

struct Biquad {
  double b0, b1, b2, a1, a2;
  Eigen::VectorXd Filter(const Eigen::VectorXd& x) const {
    Eigen::VectorXd y(x.size());
    for (Eigen::Index n = 0; n < x.size(); ++n) {
      const double x1 = n >= 1 ? x[n - 1] : 0.0, x2 = n >= 2 ? x[n - 2] : 0.0;
      const double y1 = n >= 1 ? y[n - 1] : 0.0, y2 = n >= 2 ? y[n - 2] : 0.0;
      y[n] = b0 * x[n] + b1 * x1 + b2 * x2 - a1 * y1 - a2 * y2;
    }
    return y;
  }
  // H(e^{j omega}) at normalised frequency omega (rad/sample): the analytic reference.
  cd Response(double omega) const {
    const cd z1 = std::exp(cd(0.0, -omega));
    return (b0 + b1 * z1 + b2 * z1 * z1) / (1.0 + a1 * z1 + a2 * z1 * z1);
  }
};

Biquad Resonator(double radius, double angle, double b0, double b1, double b2) {
  return {b0, b1, b2, -2.0 * radius * std::cos(angle), radius * radius};
}

void CheckAgainstScipy(const std::string& name, const WelchOptions& options) {
  const Eigen::Index n = 4096;
  const double fs = 1000.0;
  Eigen::VectorXd force = LcgNoise(n, 12345);
  for (Eigen::Index k = 0; k < n; ++k) force[k] += 0.5 * std::sin(0.37 * static_cast<double>(k));
  Eigen::MatrixXd resp(n, 2);
  resp.col(0) = Resonator(0.98, 0.3, 0.2, 0.1, 0.0).Filter(force) + 0.05 * LcgNoise(n, 777);
  resp.col(1) = Resonator(0.95, 0.9, 0.0, 0.5, -0.25).Filter(force) + 0.05 * LcgNoise(n, 999);
  const CrossSpectra s = WelchSpectra(force, resp, fs, options);
  const Frf frf = FrfFromSpectra(s, Estimator::kH1, Quantity::kDisplacement);
  // Reference: scipy.signal.welch/csd/coherence, testdata/welch_<name>.csv.
  const CsvTable ref =
      ReadCsv(std::string(VIBID_SOURCE_DIR) + "/host/lib/ident/testdata/welch_" + name + ".csv");
  ASSERT_EQ(static_cast<Eigen::Index>(ref.rows()), s.freq_hz.size());
  const auto rel = [](double a, double b) {
    return std::abs(a - b) / std::max(std::abs(b), 1e-300);
  };
  double worst = 0.0;
  for (Eigen::Index i = 0; i < s.freq_hz.size(); ++i) {
    EXPECT_NEAR(s.freq_hz[i], ref.Column("freq_hz")[i], 1e-12);
    worst = std::max(worst, rel(s.gff[i], ref.Column("gff")[i]));
    for (int j = 0; j < 2; ++j) {
      const std::string c = std::to_string(j + 1);
      worst = std::max(worst, rel(s.gxx(i, j), ref.Column("gxx" + c)[i]));
      const cd g(ref.Column("gfx" + c + "_re")[i], ref.Column("gfx" + c + "_im")[i]);
      worst = std::max(worst, std::abs(s.gfx(i, j) - g) / std::abs(g));
      EXPECT_NEAR(frf.coherence(i, j), ref.Column("coh" + c)[i], 1e-9) << name << " line " << i;
    }
  }
  EXPECT_LT(worst, 1e-9) << name;
}

TEST(Welch, MatchesScipyHannEvenSegments) {
  CheckAgainstScipy("hann256",
                    {.segment_samples = 256, .overlap_samples = 128, .window = Window::kHann});
}

TEST(Welch, MatchesScipyHammingDetrendedSegments) {
  CheckAgainstScipy("hamming200", {.segment_samples = 200,
                                   .overlap_samples = 50,
                                   .window = Window::kHamming,
                                   .detrend = Detrend::kConstant});
}

// Periodic excitation (a multisine with every line present, period = segment) through a digital
// resonator in steady state: with a rectangular window each segment's DFT ratio is exactly the
// filter's H(e^{j omega}), so every estimator must reproduce the closed form.
TEST(FrfEstimators, NoiseFreePeriodicInputGivesTheAnalyticFrf) {
  const Eigen::Index period = 256;
  const Eigen::Index periods = 40;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> phase(0.0, 2.0 * std::numbers::pi);
  Eigen::VectorXd one(period);
  one.setZero();
  for (Eigen::Index k = 1; k < period / 2; ++k) {
    const double ph = phase(rng);
    for (Eigen::Index i = 0; i < period; ++i) {
      one[i] += std::cos(
          2.0 * std::numbers::pi * static_cast<double>(k * i) / static_cast<double>(period) + ph);
    }
  }
  Eigen::VectorXd force(period * periods);
  for (Eigen::Index p = 0; p < periods; ++p) force.segment(p * period, period) = one;
  const Biquad sys = Resonator(0.97, 0.5, 0.3, -0.1, 0.05);
  const Eigen::VectorXd y = sys.Filter(force);
  // Drop 20 periods of transient (0.97^5120 is far below double precision).
  const Eigen::Index skip = 20 * period;
  const Eigen::VectorXd f = force.tail(force.size() - skip);
  const Eigen::MatrixXd x = y.tail(y.size() - skip);
  const WelchOptions opt{.segment_samples = static_cast<std::size_t>(period),
                         .overlap_samples = 0,
                         .window = Window::kRectangular};
  const double fs = 100.0;
  const CrossSpectra s = WelchSpectra(f, x, fs, opt);
  for (Estimator e : {Estimator::kH1, Estimator::kH2, Estimator::kHv}) {
    const Frf frf = FrfFromSpectra(s, e, Quantity::kDisplacement);
    double worst = 0.0;
    for (Eigen::Index i = 1; i < period / 2; ++i) {
      const cd ref = sys.Response(2.0 * std::numbers::pi * frf.freq_hz[i] / fs);
      worst = std::max(worst, std::abs(frf.h(i, 0) - ref) / std::abs(ref));
      EXPECT_NEAR(frf.coherence(i, 0), 1.0, 1e-9);
    }
    EXPECT_LT(worst, 1e-6) << EstimatorName(e);
  }
}

struct NoiseCase {
  double ratio_h1 = 0.0;  // median |H_est| / |H| over the lines
  double ratio_h2 = 0.0;
  double ratio_hv = 0.0;
};

// White input through a well-damped resonator; noise of variance `output_var` on the response or
// `input_var` on the measured force. Theory: with output noise H1 is unbiased and H2 biased up by
// 1 + Gnn/Gxx; with input noise H2 is unbiased and H1 biased down by Gff/(Gff + Gmm).
NoiseCase RunNoise(double input_var, double output_var) {
  const Eigen::Index n = 1 << 18;
  std::mt19937_64 rng(2024);
  std::normal_distribution<double> g(0.0, 1.0);
  Eigen::VectorXd f(n);
  for (auto& v : f) v = g(rng);
  const Biquad sys = Resonator(0.8, 0.6, 1.0, 0.0, 0.0);
  Eigen::VectorXd y = sys.Filter(f);
  Eigen::VectorXd fm = f;
  for (Eigen::Index i = 0; i < n; ++i) {
    fm[i] += std::sqrt(input_var) * g(rng);
    y[i] += std::sqrt(output_var) * g(rng);
  }
  const CrossSpectra s = WelchSpectra(fm, y, 1.0, {.segment_samples = 512, .overlap_samples = 256});
  NoiseCase out;
  double* slots[] = {&out.ratio_h1, &out.ratio_h2, &out.ratio_hv};
  const Estimator est[] = {Estimator::kH1, Estimator::kH2, Estimator::kHv};
  for (int e = 0; e < 3; ++e) {
    const Frf frf = FrfFromSpectra(s, est[e], Quantity::kDisplacement);
    std::vector<double> r;
    for (Eigen::Index i = 5; i < frf.freq_hz.size() - 5; ++i) {
      r.push_back(std::abs(frf.h(i, 0)) /
                  std::abs(sys.Response(2.0 * std::numbers::pi * frf.freq_hz[i])));
    }
    std::nth_element(r.begin(), r.begin() + static_cast<std::ptrdiff_t>(r.size() / 2), r.end());
    *slots[e] = r[r.size() / 2];
  }
  return out;
}

TEST(FrfEstimators, H1IsUnbiasedUnderOutputNoise) {
  // |H| of the resonator spans about 0.3..2.8, so output noise of variance 1 is comparable to the
  // response away from resonance: H2 must be biased high there, H1 not.
  const NoiseCase c = RunNoise(0.0, 1.0);
  EXPECT_NEAR(c.ratio_h1, 1.0, 0.01);
  EXPECT_GT(c.ratio_h2, 1.2);
}

TEST(FrfEstimators, H2IsUnbiasedUnderInputNoise) {
  const NoiseCase c = RunNoise(0.25, 0.0);
  EXPECT_NEAR(c.ratio_h2, 1.0, 0.01);
  // Gff / (Gff + Gmm) = 1 / 1.25 for white signals.
  EXPECT_NEAR(c.ratio_h1, 0.8, 0.01);
  // Hv lies between the two.
  EXPECT_GT(c.ratio_hv, c.ratio_h1);
  EXPECT_LT(c.ratio_hv, c.ratio_h2 + 0.01);
}

TEST(FrfConversion, AccelerationToReceptanceDividesByMinusOmegaSquared) {
  Frf acc;
  acc.quantity = Quantity::kAcceleration;
  acc.freq_hz = Eigen::VectorXd::LinSpaced(5, 0.0, 4.0);
  acc.h = Eigen::MatrixXcd::Constant(5, 1, cd(2.0, 1.0));
  acc.coherence = Eigen::MatrixXd::Ones(5, 1);
  const Frf rec = ConvertFrf(acc, Quantity::kDisplacement);
  ASSERT_EQ(rec.freq_hz.size(), 4);  // DC dropped
  for (Eigen::Index i = 0; i < 4; ++i) {
    const double w = 2.0 * std::numbers::pi * rec.freq_hz[i];
    EXPECT_LT(std::abs(rec.h(i, 0) - cd(2.0, 1.0) / (-w * w)), 1e-15);
  }
  const Frf mob = ConvertFrf(rec, Quantity::kVelocity);
  const double w = 2.0 * std::numbers::pi * mob.freq_hz[1];
  EXPECT_LT(std::abs(mob.h(1, 0) - cd(0.0, w) * rec.h(1, 0)), 1e-15);
}

TEST(Windows, PeriodicClosedForms) {
  const Eigen::VectorXd h = MakeWindow(Window::kHann, 8);
  EXPECT_DOUBLE_EQ(h[0], 0.0);
  EXPECT_NEAR(h[2], 0.5, 1e-15);
  EXPECT_NEAR(h[4], 1.0, 1e-15);
  EXPECT_NEAR(MakeWindow(Window::kHamming, 8)[4], 1.0, 1e-15);
  // Flat-top peak is 1 within its coefficients' rounding (scipy's definition).
  EXPECT_NEAR(MakeWindow(Window::kFlatTop, 8)[4], 1.0, 1e-8);
  EXPECT_THROW(ParseWindow("kaiser"), InputError);
}

// The spectra must not depend on the thread count by a single bit: segments are summed in fixed
// runs whatever the threads. 61 segments (not a multiple of the runs) of 3 responses, Hann,
// detrended.
TEST(Welch, ThreadCountDoesNotChangeABit) {
  const Eigen::Index n = 64 * 62;
  const Eigen::VectorXd force = LcgNoise(n, 4242);
  Eigen::MatrixXd resp(n, 3);
  resp.col(0) = Resonator(0.98, 0.3, 0.2, 0.1, 0.0).Filter(force);
  resp.col(1) = Resonator(0.95, 0.9, 0.0, 0.5, -0.25).Filter(force) + 0.05 * LcgNoise(n, 31);
  resp.col(2) = LcgNoise(n, 99);
  WelchOptions o{.segment_samples = 128,
                 .overlap_samples = 64,
                 .window = Window::kHann,
                 .detrend = Detrend::kConstant};
  o.threads = 1;
  const CrossSpectra one = WelchSpectra(force, resp, 500.0, o);
  ASSERT_EQ(one.averages, 61u);
  const auto same = [](const auto& a, const auto& b) {
    return a.size() == b.size() &&
           std::memcmp(a.data(), b.data(),
                       static_cast<std::size_t>(a.size()) * sizeof(*a.data())) == 0;
  };
  for (const std::size_t threads : {2u, 3u, 8u, 64u}) {
    o.threads = threads;
    const CrossSpectra many = WelchSpectra(force, resp, 500.0, o);
    EXPECT_TRUE(same(one.gff, many.gff)) << threads;
    EXPECT_TRUE(same(one.gxx, many.gxx)) << threads;
    EXPECT_TRUE(same(one.gfx, many.gfx)) << threads;
  }
  // Separate response channels (a recording's own columns) give the same bits as the matrix.
  const std::vector<Eigen::VectorXd> columns = {resp.col(0), resp.col(1), resp.col(2)};
  const std::vector<const Eigen::VectorXd*> pointers = {&columns[0], &columns[1], &columns[2]};
  o.threads = 2;
  const CrossSpectra separate = WelchSpectra(force, pointers, 500.0, o);
  EXPECT_TRUE(same(one.gff, separate.gff));
  EXPECT_TRUE(same(one.gxx, separate.gxx));
  EXPECT_TRUE(same(one.gfx, separate.gfx));
  // And the runs add up to the plain one-pass average (closed form of Welch, summed directly here).
  const Eigen::VectorXd w = MakeWindow(Window::kHann, 128);
  RealFft fft(128);
  Eigen::VectorXd gff = Eigen::VectorXd::Zero(65);
  Eigen::VectorXcd spec;
  for (Eigen::Index s = 0; s < 61; ++s) {
    const Eigen::VectorXd seg = force.segment(s * 64, 128);
    const Eigen::VectorXd x = (seg.array() - seg.mean()) * w.array();
    fft.Transform(x.data(), spec);
    gff += spec.cwiseAbs2();
  }
  gff *= 2.0 / (500.0 * w.squaredNorm() * 61.0);
  gff[0] /= 2.0;
  gff[64] /= 2.0;
  EXPECT_LT((gff - one.gff).cwiseAbs().maxCoeff(), 1e-12 * gff.maxCoeff());
}

TEST(Welch, BadOptionsAreInputErrors) {
  const Eigen::VectorXd f = Eigen::VectorXd::Ones(100);
  const Eigen::MatrixXd x = Eigen::MatrixXd::Ones(100, 1);
  EXPECT_THROW(WelchSpectra(f, x, 10.0, {.segment_samples = 64, .overlap_samples = 64}),
               InputError);
  EXPECT_THROW(WelchSpectra(f, x, 10.0, {.segment_samples = 128, .overlap_samples = 0}),
               InputError);
  EXPECT_THROW(WelchSpectra(f, x, 0.0, {.segment_samples = 64, .overlap_samples = 0}), InputError);
}

TEST(DampingCorrection, RemovesTheExponentialWindowDecay) {
  // A mode with zeta 0.01 at 100 rad/s seen through exp(-t/0.5): sigma 1 + 2 = 3.
  const double wd = 100.0 * std::sqrt(1 - 1e-4);
  const double wm = std::hypot(wd, 3.0);
  EXPECT_NEAR(CorrectExponentialWindowDamping(3.0 / wm, wm, 0.5), 0.01, 1e-12);
  EXPECT_EQ(CorrectExponentialWindowDamping(0.02, 50.0, 0.0), 0.02);
}

}  // namespace
}  // namespace vibid::ident
