// Impact records: hits of a sampled half-sine force on a digital resonator (its FRF in closed
// form), double hits, clipping, the exponential window's damping correction, and the LADISK
// hammer record (data/ladisk_impact_hammer/).
#include "vibid/ident/impact.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdint>
#include <numbers>
#include <string>

#include <gtest/gtest.h>

#include "vibid/common/csv.hpp"
#include "vibid/common/testing/real_data.hpp"
#include "vibid/common/error.hpp"
#include "vibid/ident/peaks.hpp"

namespace vibid::ident {
namespace {

using cd = std::complex<double>;

struct Resonator {
  double radius, angle;
  Eigen::VectorXd Filter(const Eigen::VectorXd& x) const {
    const double a1 = -2 * radius * std::cos(angle), a2 = radius * radius;
    Eigen::VectorXd y(x.size());
    for (Eigen::Index n = 0; n < x.size(); ++n) {
      y[n] = x[n] - (n >= 1 ? a1 * y[n - 1] : 0.0) - (n >= 2 ? a2 * y[n - 2] : 0.0);
    }
    return y;
  }
  cd Response(double omega) const {
    const cd z1 = std::exp(cd(0.0, -omega));
    return 1.0 / (1.0 - 2 * radius * std::cos(angle) * z1 + radius * radius * z1 * z1);
  }
  // Continuous-time equivalent of the pole r e^{j theta} at fs = 1: s = ln r + j theta.
  double Zeta() const { return -std::log(radius) / std::hypot(std::log(radius), angle); }
};

void AddHit(Eigen::VectorXd& f, Eigen::Index at, double amp, int width) {
  for (int i = 0; i < width; ++i) f[at + i] += amp * std::sin(std::numbers::pi * (i + 0.5) / width);
}

TEST(Impact, HitsAverageToTheAnalyticFrf) {
  const Resonator sys{0.98, 0.3};
  Eigen::VectorXd f = Eigen::VectorXd::Zero(7000);
  AddHit(f, 500, 100, 5);
  AddHit(f, 2700, 80, 5);
  AddHit(f, 4800, 120, 5);
  const Eigen::MatrixXd y = sys.Filter(f);
  const ImpactResult r = EstimateImpactFrf(f, y, 1.0, {}, Estimator::kH1, Quantity::kDisplacement);
  ASSERT_EQ(r.hits.size(), 3u);
  for (const Hit& h : r.hits) EXPECT_TRUE(h.used) << h.note;
  EXPECT_EQ(r.hits[1].trigger_index, 2700u);
  EXPECT_EQ(r.frf.averages, 3u);
  // Shortest spacing 2100 samples, rounded down to a 2-3-5 length: 2048 (2^11) < 2025? no: 2100.
  EXPECT_EQ(r.record_samples, FastFftLength(2100));
  const Eigen::VectorXd fmag = r.frf.h.col(0).cwiseAbs();
  double worst = 0.0;
  for (Eigen::Index i = 1; i < r.frf.freq_hz.size(); ++i) {
    if (r.frf.freq_hz[i] > 0.25) break;  // well below the half-sine's first spectral zero
    const cd ref = sys.Response(2 * std::numbers::pi * r.frf.freq_hz[i]);
    worst = std::max(worst, std::abs(r.frf.h(i, 0) - ref) / std::abs(ref));
  }
  EXPECT_LT(worst, 1e-9);
  (void)fmag;
}

TEST(Impact, DoubleHitIsRejectedAndClippingFlagged) {
  const Resonator sys{0.98, 0.3};
  Eigen::VectorXd f = Eigen::VectorXd::Zero(7000);
  AddHit(f, 500, 100, 5);
  AddHit(f, 2700, 80, 5);
  AddHit(f, 2720, 40, 5);  // rebound 20 samples later
  AddHit(f, 4800, 300, 5);
  Eigen::MatrixXd y = sys.Filter(f);
  // The third hit overloads the response channel: clip at the level the first two never reach.
  const double rail = 1.2 * y.col(0).head(4700).cwiseAbs().maxCoeff();
  y = y.cwiseMin(rail).cwiseMax(-rail);
  // fs = 1 Hz here: rebounds within 50 samples belong to their hit. The response's converter
  // ends at +-rail (the force's rails unknown: not checked).
  const ImpactOptions opt{.double_hit_window_s = 50, .converter_limits = {{}, {-rail, rail}}};
  const ImpactResult r = EstimateImpactFrf(f, y, 1.0, opt, Estimator::kH1, Quantity::kDisplacement);
  ASSERT_EQ(r.hits.size(), 3u);
  EXPECT_TRUE(r.hits[0].used);
  EXPECT_TRUE(r.hits[1].double_hit);
  EXPECT_FALSE(r.hits[1].used);
  EXPECT_TRUE(r.hits[2].clipped);
  EXPECT_FALSE(r.hits[2].used);
  EXPECT_NE(r.hits[2].note.find("response 1 clipped"), std::string::npos);
  EXPECT_EQ(r.frf.averages, 1u);
  // Flag only: every hit is used.
  const ImpactResult flagged = EstimateImpactFrf(f, y, 1.0,
                                                 {.double_hit_window_s = 50,
                                                  .converter_limits = {{}, {-rail, rail}},
                                                  .reject_bad_hits = false},
                                                 Estimator::kH1, Quantity::kDisplacement);
  EXPECT_EQ(flagged.frf.averages, 3u);
  // The only hit is clipped: an input error listing why and naming the override.
  Eigen::VectorXd g = Eigen::VectorXd::Zero(3000);
  AddHit(g, 500, 100, 5);
  Eigen::MatrixXd yg = sys.Filter(g);
  const double rail_g = 0.5 * yg.cwiseAbs().maxCoeff();
  yg = yg.cwiseMin(rail_g).cwiseMax(-rail_g);
  try {
    const ImpactOptions opt_g{.double_hit_window_s = 50,
                              .converter_limits = {{}, {-rail_g, rail_g}}};
    const ImpactResult bad =
        EstimateImpactFrf(g, yg, 1.0, opt_g, Estimator::kH1, Quantity::kDisplacement);
    FAIL() << bad.hits.size() << " " << bad.hits[0].note << " used " << bad.hits[0].used;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("clipped"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("--keep-bad-hits"), std::string::npos) << e.what();
  }
}

// Every hit of the record is a double hit (a rebound 20 samples after each pulse, 40 % of its
// height): the hits are used, each force window spanning both pulses, and the FRF equals the
// resonator's (closed form) wherever the force spectrum is within the dynamic range.
TEST(Impact, AllDoubleHitsAreUsedWithTheWholeGroupInTheForceWindow) {
  const Resonator sys{0.98, 0.3};
  Eigen::VectorXd f = Eigen::VectorXd::Zero(7000);
  for (Eigen::Index at : {500, 2700, 4800}) {
    AddHit(f, at, 100, 5);
    AddHit(f, at + 20, 40, 5);
  }
  const Eigen::MatrixXd y = sys.Filter(f);
  // Converters far beyond the signals: the clip check is made (and finds nothing).
  const ImpactResult r = EstimateImpactFrf(
      f, y, 1.0, {.double_hit_window_s = 50, .converter_limits = {{-1e9, 1e9}, {-1e9, 1e9}}},
      Estimator::kH1, Quantity::kDisplacement);
  ASSERT_EQ(r.hits.size(), 3u);
  for (const Hit& h : r.hits) {
    EXPECT_TRUE(h.used);
    EXPECT_TRUE(h.double_hit);
    EXPECT_EQ(h.pulses, 2u);
  }
  ASSERT_EQ(r.warnings.size(), 2u);
  EXPECT_NE(r.warnings[0].find("every hit is a double hit"), std::string::npos) << r.warnings[0];
  EXPECT_NE(r.warnings[1].find("Hz"), std::string::npos) << r.warnings[1];
  // |1 + 0.4 exp(-j 20 w)| >= 0.6 (-4.4 dB): no notch is deeper than the range; the half-sine of
  // 5 samples has its first zero at 0.3 cycles/sample, so the usable band ends below it.
  EXPECT_GT(r.usable_max_hz, 0.15);
  EXPECT_LT(r.usable_max_hz, 0.3);
  double worst = 0.0;
  int checked = 0;
  for (Eigen::Index i = 1; i < r.frf.freq_hz.size(); ++i) {
    if (r.frf.freq_hz[i] > r.usable_max_hz) {
      EXPECT_EQ(r.frf.coherence(i, 0), 0.0);
      continue;
    }
    const cd ref = sys.Response(2 * std::numbers::pi * r.frf.freq_hz[i]);
    worst = std::max(worst, std::abs(r.frf.h(i, 0) - ref) / std::abs(ref));
    ++checked;
  }
  EXPECT_GT(checked, 100);
  EXPECT_LT(worst, 1e-9);
  // The old force window (only the first pulse) is what made double hits unusable: force window
  // forced to 10 samples after the trigger cuts the rebound and the FRF is far off.
  const ImpactResult cut =
      EstimateImpactFrf(f, y, 1.0, {.force_window_s = 10, .double_hit_window_s = 50},
                        Estimator::kH1, Quantity::kDisplacement);
  const Eigen::Index probe = 100;
  const cd ref = sys.Response(2 * std::numbers::pi * cut.frf.freq_hz[probe]);
  EXPECT_GT(std::abs(cut.frf.h(probe, 0) - ref) / std::abs(ref), 0.1);
}

TEST(Impact, ClassifiesHammerRandomAndPeriodicForces) {
  const double fs = 1000.0;
  Eigen::VectorXd hammer = Eigen::VectorXd::Zero(20000);
  for (Eigen::Index at : {1000, 6000, 12000}) AddHit(hammer, at, 100, 3);
  std::uint64_t x = 12345;
  Eigen::VectorXd noise(20000), sine(20000);
  for (Eigen::Index i = 0; i < noise.size(); ++i) {
    // Sum of 12 uniforms: near-Gaussian (LCG as in scripts/golden/ident_welch.py).
    double s = 0.0;
    for (int k = 0; k < 12; ++k) {
      x = (1664525u * x + 1013904223u) % 4294967296u;
      s += static_cast<double>(x) / 4294967296.0 - 0.5;
    }
    noise[i] = s + 0.001 * hammer[i];
    sine[i] = std::sin(2 * std::numbers::pi * 13.0 * static_cast<double>(i) / fs);
    hammer[i] += 0.002 * (static_cast<double>(x % 1000) / 1000.0 - 0.5);
  }
  const ExcitationCheck h = ClassifyExcitation(hammer, fs);
  EXPECT_TRUE(h.impact) << h.description;
  EXPECT_EQ(h.pulses, 3u);
  EXPECT_GT(h.crest_factor, 30.0);
  const ExcitationCheck n = ClassifyExcitation(noise, fs);
  EXPECT_FALSE(n.impact) << n.description;
  EXPECT_LT(n.crest_factor, kImpactCrestFactor);
  const ExcitationCheck p = ClassifyExcitation(sine, fs);
  EXPECT_FALSE(p.impact) << p.description;
  EXPECT_NEAR(p.crest_factor, std::sqrt(2.0), 0.01);  // closed form for a sine over whole periods
}

TEST(Impact, ExponentialWindowDampingIsCorrected) {
  // Lightly damped: the response has not died out by the end of each hit record, so the
  // exponential window is needed; the corrected half-power damping must match the pole's.
  const Resonator sys{0.9985, 0.2};
  Eigen::VectorXd f = Eigen::VectorXd::Zero(26000);
  AddHit(f, 100, 100, 4);
  AddHit(f, 8300, 100, 4);
  AddHit(f, 16700, 100, 4);
  const Eigen::MatrixXd y = sys.Filter(f);
  const ImpactResult r = EstimateImpactFrf(f, y, 1.0, {.exp_window_end = 0.02}, Estimator::kH1,
                                           Quantity::kDisplacement);
  EXPECT_GT(r.frf.exp_window_tau_s, 0.0);
  const PeakResult p =
      PickPeaks(r.frf.freq_hz, r.frf.h.col(0).cwiseAbs(), {}, r.frf.exp_window_tau_s);
  ASSERT_EQ(p.peaks.size(), 1u);
  EXPECT_NEAR(p.peaks[0].zeta, sys.Zeta(), 0.05 * sys.Zeta());
  EXPECT_GT(p.peaks[0].zeta_measured, 1.25 * sys.Zeta());
  EXPECT_NEAR(p.peaks[0].omega_rad_s, 0.2, 0.002);
}

// A hit of 20 % of the others' peak is too weak (below 0.3 of their median, 100): flagged with
// the median it fell short of and left out; the FRF is the other hits' (analytic resonator).
TEST(Impact, WeakHitIsRejectedAgainstTheMedianPeak) {
  const Resonator sys{0.98, 0.3};
  Eigen::VectorXd f = Eigen::VectorXd::Zero(9000);
  AddHit(f, 500, 100, 5);
  AddHit(f, 2700, 20, 5);
  AddHit(f, 4800, 90, 5);
  AddHit(f, 6900, 110, 5);
  const Eigen::MatrixXd y = sys.Filter(f);
  const ImpactOptions opt{.record_s = 2000};
  const ImpactResult r = EstimateImpactFrf(f, y, 1.0, opt, Estimator::kH1, Quantity::kDisplacement);
  ASSERT_EQ(r.hits.size(), 4u);
  EXPECT_TRUE(r.hits[1].weak);
  EXPECT_FALSE(r.hits[1].used);
  // The half-sine's peak sample: 20 sin(pi 2.5 / 5) = 20 (closed form); median of 100, 90, 110.
  EXPECT_NE(r.hits[1].note.find("too weak: peak 20 below 0.3 of the median peak 100"),
            std::string::npos)
      << r.hits[1].note;
  for (std::size_t k : {0u, 2u, 3u}) EXPECT_TRUE(r.hits[k].used && !r.hits[k].weak);
  EXPECT_EQ(r.frf.averages, 3u);
  // Without the check the weak hit is used (H1 weights it by its force energy: 4 % of a hit).
  ImpactOptions lax = opt;
  lax.weak_hit_fraction = 0.0;
  EXPECT_EQ(EstimateImpactFrf(f, y, 1.0, lax, Estimator::kH1, Quantity::kDisplacement).frf.averages,
            4u);
}

// The noise floor: a hit of 10 N on a force with 1 N of noise (sd) is below 10 sd; the ones of
// 100 N are not. The noise is a fixed -1, 0, 1 cycle: its median absolute deviation is 1.
TEST(Impact, WeakHitBelowTheNoiseFloor) {
  const Resonator sys{0.98, 0.3};
  Eigen::VectorXd f(7000);
  for (Eigen::Index i = 0; i < f.size(); ++i) f[i] = static_cast<double>(i % 3) - 1.0;
  AddHit(f, 500, 100, 5);
  AddHit(f, 2700, 100, 5);
  AddHit(f, 4800, 12, 5);
  const Eigen::MatrixXd y = sys.Filter(f);
  ImpactOptions opt{.trigger_fraction = 0.05, .record_s = 2000};
  opt.weak_hit_fraction = 0.0;
  const ImpactDetection d = DetectImpactHits(f, y, 1.0, opt);
  ASSERT_EQ(d.hits.size(), 3u);
  EXPECT_NEAR(std::sqrt(d.force_noise_var), 1.4826, 1e-12);  // 1.4826 x MAD (MAD = 1)
  EXPECT_TRUE(d.hits[2].weak) << d.hits[2].note;
  EXPECT_NE(d.hits[2].note.find("force noise standard deviations"), std::string::npos);
  EXPECT_FALSE(d.hits[0].weak);
}

// The hit choice: the listed hits are used whatever their verdicts; the FRF equals the one the
// verdicts give when they list the same hits, bit for bit; a truncated hit or one past the end
// is refused.
TEST(Impact, UseHitsOverridesTheVerdicts) {
  const Resonator sys{0.98, 0.3};
  Eigen::VectorXd f = Eigen::VectorXd::Zero(7000);
  AddHit(f, 500, 100, 5);
  AddHit(f, 2700, 80, 5);
  AddHit(f, 2720, 40, 5);  // rebound: hit 2 is a double hit
  AddHit(f, 4800, 120, 5);
  AddHit(f, 6500, 100, 5);  // its record runs past the end: truncated
  const Eigen::MatrixXd y = sys.Filter(f);
  const ImpactOptions opt{.record_s = 1500, .double_hit_window_s = 50};
  const ImpactResult auto_r =
      EstimateImpactFrf(f, y, 1.0, opt, Estimator::kH1, Quantity::kDisplacement);
  ASSERT_EQ(auto_r.hits.size(), 4u);
  EXPECT_FALSE(auto_r.hits[1].used);
  EXPECT_TRUE(auto_r.hits[3].truncated);
  ImpactOptions same = opt;
  same.use_hits = {1, 3};
  const ImpactResult listed =
      EstimateImpactFrf(f, y, 1.0, same, Estimator::kH1, Quantity::kDisplacement);
  EXPECT_TRUE(listed.frf.h.cwiseEqual(auto_r.frf.h).all());
  EXPECT_TRUE(listed.frf.coherence.cwiseEqual(auto_r.frf.coherence).all());
  ImpactOptions with_double = opt;
  with_double.use_hits = {1, 2, 3};
  const ImpactResult d =
      EstimateImpactFrf(f, y, 1.0, with_double, Estimator::kH1, Quantity::kDisplacement);
  EXPECT_TRUE(d.hits[1].used);
  EXPECT_EQ(d.frf.averages, 3u);
  ImpactOptions truncated = opt;
  truncated.use_hits = {4};
  EXPECT_THROW(EstimateImpactFrf(f, y, 1.0, truncated, Estimator::kH1, Quantity::kDisplacement),
               InputError);
  ImpactOptions past = opt;
  past.use_hits = {5};
  EXPECT_THROW(EstimateImpactFrf(f, y, 1.0, past, Estimator::kH1, Quantity::kDisplacement),
               InputError);
  ImpactOptions unordered = opt;
  unordered.use_hits = {3, 1};
  EXPECT_THROW(unordered.Validate(), InputError);
}

// Per-hit spectra kept and averaged later give EstimateImpactFrf's bits, whichever way the
// channels are held (here a wider buffer, as a growing recording is).
TEST(Impact, KeptHitSpectraAverageToTheSameBits) {
  const Resonator sys{0.98, 0.3};
  Eigen::VectorXd f = Eigen::VectorXd::Zero(7001);
  AddHit(f, 501, 100, 5);
  AddHit(f, 2700, 80, 5);
  AddHit(f, 4803, 120, 5);
  for (Eigen::Index i = 0; i < f.size(); ++i)
    f[i] += 1e-3 * std::sin(0.37 * static_cast<double>(i));
  Eigen::MatrixXd y(f.size(), 2);
  y.col(0) = sys.Filter(f);
  y.col(1) = Resonator{0.97, 0.5}.Filter(f);
  const ImpactOptions opt{.exp_window_end = 0.05};
  const ImpactResult r = EstimateImpactFrf(f, y, 1.0, opt, Estimator::kH1, Quantity::kDisplacement);
  Eigen::MatrixXd wide = Eigen::MatrixXd::Zero(f.size() + 3, 3);
  wide.block(0, 1, f.size(), 2) = y;
  Eigen::VectorXd fw = Eigen::VectorXd::Zero(f.size() + 5);
  fw.head(f.size()) = f;
  const auto fh = fw.head(f.size());
  const auto yh = wide.block(0, 1, f.size(), 2);
  const ImpactDetection d = DetectImpactHits(fh, yh, 1.0, opt);
  RealFft fft(d.record_samples);
  std::vector<HitSpectra> kept;
  for (std::size_t g = 0; g < d.hits.size(); ++g)
    kept.push_back(ImpactHitSpectra(fh, yh, d, g, fft));
  std::vector<const HitSpectra*> used;
  for (const HitSpectra& s : kept) used.push_back(&s);
  const ImpactResult later =
      AverageHitSpectra(d, used, 1.0, opt, Estimator::kH1, Quantity::kDisplacement);
  EXPECT_TRUE(later.frf.h.cwiseEqual(r.frf.h).all());
  EXPECT_TRUE(later.frf.coherence.cwiseEqual(r.frf.coherence).all());
  EXPECT_TRUE(later.frf.level_rel_var.cwiseEqual(r.frf.level_rel_var).all());
}

TEST(Impact, BadOptionsAndSignals) {
  const Eigen::VectorXd f = Eigen::VectorXd::Zero(100);
  const Eigen::MatrixXd y = Eigen::MatrixXd::Zero(100, 1);
  EXPECT_THROW(EstimateImpactFrf(f, y, 1.0, {}, Estimator::kH1, Quantity::kDisplacement),
               InputError);
  EXPECT_THROW(EstimateImpactFrf(f, y, 1.0, {.trigger_fraction = 2}, Estimator::kH1,
                                 Quantity::kDisplacement),
               InputError);
  EXPECT_THROW(EstimateImpactFrf(f, Eigen::MatrixXd::Zero(99, 1), 1.0, {}, Estimator::kH1,
                                 Quantity::kDisplacement),
               InputError);
}

// The LADISK beam record: one hit near 0.7 ms, 50 kHz, accelerometer in g. Default options only.
// Expected peaks: the four most prominent maxima of |X / F| (the whole record's DFTs, no window)
// by scipy.signal.find_peaks, scripts/golden/ladisk_peaks.py (35.978, 695.583, 1897.861,
// 3671.797 Hz on lines 0.9994 Hz apart); vibid's impact FRF and cubic peak refinement must land
// within two lines of them.
TEST(ImpactLadisk, DefaultsFindTheBeamResonances) {
  const Recording rec =
      LoadRecording(vibid::testing::TestData("ladisk_impact_hammer/impact_acceleration_force.csv"));
  const Eigen::VectorXd force = rec.Signal(ParseColumnSpec("force_N"));
  EXPECT_TRUE(ClassifyExcitation(force, rec.fs_hz).impact)
      << ClassifyExcitation(force, rec.fs_hz).description;
  const Eigen::MatrixXd acc = rec.Signal(ParseColumnSpec("acceleration_g:g"));
  const ImpactResult r =
      EstimateImpactFrf(force, acc, rec.fs_hz, {}, Estimator::kH1, Quantity::kAcceleration);
  ASSERT_EQ(r.hits.size(), 1u);
  EXPECT_TRUE(r.hits[0].used) << r.hits[0].note;
  EXPECT_NEAR(r.hits[0].t_s, 0.0006, 0.0002);
  EXPECT_NEAR(r.hits[0].peak_n, 195.6 - 0.25, 1.0);  // peak 195.606 N above a ~0.25 N baseline
  const PeakResult p = PickPeaks(r.frf.freq_hz, r.frf.h.col(0).cwiseAbs(), {.freq_max_hz = 5000});
  std::vector<double> found;
  for (const Peak& pk : p.peaks) found.push_back(pk.freq_hz);
  // scripts/golden/ladisk_peaks.py
  for (double expected : {35.978, 695.583, 1897.861, 3671.797}) {
    const auto near = std::find_if(found.begin(), found.end(),
                                   [&](double fh) { return std::abs(fh - expected) < 2.0; });
    EXPECT_NE(near, found.end()) << "no peak near " << expected << " Hz";
  }
  // The same with an exponential window: the peaks stay, the damping is corrected back.
  const ImpactResult rw = EstimateImpactFrf(force, acc, rec.fs_hz, {.exp_window_end = 0.05},
                                            Estimator::kH1, Quantity::kAcceleration);
  const PeakResult pw = PickPeaks(rw.frf.freq_hz, rw.frf.h.col(0).cwiseAbs(), {.freq_max_hz = 5000},
                                  rw.frf.exp_window_tau_s);
  for (double expected : {695.583, 1897.861, 3671.797}) {  // scripts/golden/ladisk_peaks.py
    const auto near = std::find_if(pw.peaks.begin(), pw.peaks.end(), [&](const Peak& pk) {
      return std::abs(pk.freq_hz - expected) < 0.03 * expected;
    });
    ASSERT_NE(near, pw.peaks.end()) << "exp window: no peak near " << expected << " Hz";
    const auto plain = std::find_if(p.peaks.begin(), p.peaks.end(), [&](const Peak& pk) {
      return std::abs(pk.freq_hz - expected) < 0.03 * expected;
    });
    EXPECT_GT(near->zeta_measured, plain->zeta_measured);
    EXPECT_NEAR(near->zeta, plain->zeta, 0.5 * plain->zeta) << expected;
  }
  for (const Peak& pk : p.peaks) {
    std::printf("LADISK peak %.1f Hz zeta %.4f lines %.1f\n", pk.freq_hz, pk.zeta,
                pk.lines_in_band);
  }
}

}  // namespace
}  // namespace vibid::ident

namespace vibid::ident {
namespace {

// Ringing of 20 % at the end of 3 s records: the window that takes it to 5 % ends at 0.25 and
// adds ln(4) / 3 = 0.462 1/s (closed forms). Against a mode that decays at 1 1/s it is advised;
// against one at 0.1 1/s it would add 4.6 times that mode's own decay, and the record that lets
// that mode decay from 20 % to 5 % is advised instead: 3 + ln(4) / 0.1 = 16.86 s.
TEST(RingingAdvice, AWindowOnlyWhereItAddsNoMoreThanTheModesOwnDecay) {
  const RingingAdvice fast = AdviseOnRinging(0.2, 1.0, 3.0, 0.0, 0.1);
  EXPECT_DOUBLE_EQ(fast.exp_window_end, 0.25);
  EXPECT_DOUBLE_EQ(fast.record_s, 0.0);
  EXPECT_NEAR(fast.added_over_own, std::log(4.0) / 3.0, 1e-12);
  EXPECT_NE(fast.text.find("--exp-window 0.25"), std::string::npos) << fast.text;

  const RingingAdvice slow = AdviseOnRinging(0.2, 0.1, 3.0, 0.0, 0.1);
  EXPECT_DOUBLE_EQ(slow.exp_window_end, 0.0);
  EXPECT_NEAR(slow.record_s, 3.0 + std::log(4.0) / 0.1, 1e-9);
  EXPECT_NEAR(slow.added_over_own, std::log(4.0) / 3.0 / 0.1, 1e-9);
  EXPECT_NE(slow.text.find("not advised"), std::string::npos) << slow.text;

  // A window already at 0.5 that leaves 20 %: the ringing without it is 40 %, the end value
  // that takes it to 5 % is 0.125.
  const RingingAdvice more = AdviseOnRinging(0.2, 1.0, 3.0, 0.5, 0.1);
  EXPECT_DOUBLE_EQ(more.exp_window_end, 0.12);  // rounded down to two digits
}

}  // namespace
}  // namespace vibid::ident
