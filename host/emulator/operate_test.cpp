// The operate scenario: band-limited Gaussian force measured by load cell 1, against closed
// forms (a Butterworth's noise bandwidth and stop band) and the rig's modes, by a Welch PSD
// written here (radix-2 FFT, Hann window, half overlap).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <numbers>
#include <vector>

#include "rig.hpp"
#include "scenario.hpp"
#include "vibid/model/modal.hpp"

namespace vibid::emu {
namespace {

constexpr double kPi = std::numbers::pi;

Scenario Parse(std::array<float, 4> params, int dofs = 2, int hammer_mass = kUnmounted) {
  wire::ScenarioRequest r;
  std::snprintf(r.name.data(), r.name.size(), "operate");
  r.params = params;
  Scenario s;
  EXPECT_EQ(ParseScenario(r, dofs, s, nullptr, hammer_mass), Status::kOk);
  return s;
}

// In-place radix-2 FFT (size a power of two).
void Fft(std::vector<std::complex<double>>& a) {
  const std::size_t n = a.size();
  for (std::size_t i = 1, j = 0; i < n; ++i) {
    std::size_t bit = n >> 1;
    for (; (j & bit) != 0; bit >>= 1) j ^= bit;
    j ^= bit;
    if (i < j) std::swap(a[i], a[j]);
  }
  for (std::size_t len = 2; len <= n; len <<= 1) {
    const std::complex<double> w = std::polar(1.0, -2.0 * kPi / static_cast<double>(len));
    for (std::size_t i = 0; i < n; i += len) {
      std::complex<double> wk = 1.0;
      for (std::size_t k = 0; k < len / 2; ++k) {
        const std::complex<double> u = a[i + k], v = a[i + k + len / 2] * wk;
        a[i + k] = u + v;
        a[i + k + len / 2] = u - v;
        wk *= w;
      }
    }
  }
}

// One-sided PSD (unit²/Hz) by Welch's method: Hann segments of `n` samples, half overlapping,
// each with its mean removed; line i at i fs / n.
std::vector<double> WelchPsd(const std::vector<double>& x, std::size_t n, double fs_hz) {
  std::vector<double> window(n), psd(n / 2 + 1, 0.0);
  double power = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    window[i] = 0.5 - 0.5 * std::cos(2.0 * kPi * static_cast<double>(i) / static_cast<double>(n));
    power += window[i] * window[i];
  }
  int segments = 0;
  for (std::size_t start = 0; start + n <= x.size(); start += n / 2, ++segments) {
    double mean = 0.0;
    for (std::size_t i = 0; i < n; ++i) mean += x[start + i];
    mean /= static_cast<double>(n);
    std::vector<std::complex<double>> a(n);
    for (std::size_t i = 0; i < n; ++i) a[i] = (x[start + i] - mean) * window[i];
    Fft(a);
    for (std::size_t i = 0; i < psd.size(); ++i) {
      const double scale = (i == 0 || i == n / 2) ? 1.0 : 2.0;
      psd[i] += scale * std::norm(a[i]) / (fs_hz * power);
    }
  }
  for (double& p : psd) p /= segments;
  return psd;
}

double MeanOver(const std::vector<double>& psd, double lo_hz, double hi_hz, double df_hz) {
  double sum = 0.0;
  int lines = 0;
  for (std::size_t i = 0; i < psd.size(); ++i) {
    const double f = static_cast<double>(i) * df_hz;
    if (f >= lo_hz && f <= hi_hz) {
      sum += psd[i];
      ++lines;
    }
  }
  return sum / lines;
}

double Db(double ratio) { return 10.0 * std::log10(ratio); }

TEST(Operate, ParametersAndRefusals) {
  Scenario s = Parse({0, 0, 0, 0});
  EXPECT_EQ(s.kind, ScenarioKind::kOperate);
  EXPECT_DOUBLE_EQ(s.force_n, 2.0);
  EXPECT_DOUBLE_EQ(s.frequency_hz, 0.0);  // from the rig when selected
  EXPECT_EQ(s.mass, 1);                   // the last mass
  EXPECT_DOUBLE_EQ(s.push_n, 0.0);
  EXPECT_EQ(s.configuration, Configuration::kChain);
  EXPECT_EQ(Parse({0, 0, 0, 0}, 3, 1).mass, 1);  // the rig's hammer mass
  s = Parse({5, 80, 1, 4});
  EXPECT_DOUBLE_EQ(s.force_n, 5.0);
  EXPECT_DOUBLE_EQ(s.frequency_hz, 80.0);
  EXPECT_EQ(s.mass, 0);
  EXPECT_DOUBLE_EQ(s.push_n, 4.0);

  const auto refused = [](std::array<float, 4> p) {
    wire::ScenarioRequest r;
    std::snprintf(r.name.data(), r.name.size(), "operate");
    r.params = p;
    Scenario out;
    wire::Refusal why{};
    return ParseScenario(r, 2, out, &why) == Status::kInvalidArgument ? static_cast<int>(why.detail)
                                                                      : -1;
  };
  EXPECT_EQ(refused({0, 0.5f, 0, 0}), 1);  // a band below 1 Hz
  EXPECT_EQ(refused({0, 0, 3, 0}), 2);     // no mass 3
  EXPECT_EQ(refused({0, 0, 1.5f, 0}), 2);
  EXPECT_EQ(refused({-1, 0, 0, 0}), 0);
  EXPECT_EQ(refused({0, 0, 0, std::nanf("")}), 3);

  // The band edge left open: 50 Hz, or twice the highest mode (the built-in chain's: 10.6 Hz).
  RigSimulator rig(DefaultRig(), 1);
  rig.Select(Parse({0, 0, 0, 0}));
  EXPECT_DOUBLE_EQ(rig.scenario().frequency_hz, 50.0);
  RigSpec stiff = DefaultRig();
  stiff.springs_n_per_m = {352000.0, 276000.0};  // 10 times the frequencies: 106 Hz
  RigSimulator stiff_rig(stiff, 1);
  stiff_rig.Select(Parse({0, 0, 0, 0}));
  EXPECT_NEAR(stiff_rig.scenario().frequency_hz,
              2.0 * model::Modal(stiff.Truth()).freq_hz.maxCoeff(), 1e-9);
  EXPECT_GT(stiff_rig.scenario().frequency_hz, 200.0);
}

// The force drives the mass asked for and load cell 1 reads it: at the first sample the driven
// mass alone accelerates (F/m, less 2.667 us of the springs' reaction).
TEST(Operate, LoadCellOneMeasuresTheForceOnTheDrivenMass) {
  RigSpec quiet = DefaultRig();
  quiet.coulomb_n = {0.0, 0.0};
  for (auto& s : quiet.load_cells) s.noise_rms = 0.0;
  RigSimulator rig(quiet, 2);
  rig.Select(Parse({2, 0, 1, 0}));  // mass 1
  rig.Start(1e-3);
  std::array<std::int32_t, wire::kChannelCount> raw{};
  for (int k = 0; k < 200; ++k) {
    rig.Step(raw);
    EXPECT_EQ(raw[0], quiet.load_cells[0].Code(rig.last().force_n)) << k;
    EXPECT_EQ(rig.last().push_n, 0.0);
  }
  RigSimulator first(quiet, 2);
  first.Select(Parse({2, 0, 1, 0}));
  first.Start(1e-3);
  first.Step(raw);
  const auto& v = first.last();
  ASSERT_NE(v.force_n, 0.0);
  EXPECT_NEAR(v.a_m_s2[0], v.force_n / 1.82, 1e-4 * std::abs(v.force_n) / 1.82);
  // Mass 2 feels mass 1 through damper 2 only so far: c2 (F / m1) tau / m2 = 3.3e-6 F per kg.
  EXPECT_NEAR(v.a_m_s2[1], 0.0, 1e-5 * std::abs(v.force_n));
}

// Five minutes at 1 kHz on the built-in rig with its converter noise, 2 N RMS up to 50 Hz on the
// last mass. References: the force's RMS; a 4th-order Butterworth passes white noise of
// density S0 as sigma^2 = S0 fc (pi / 8) / sin(pi / 8), so its flat band sits at
// sigma^2 / (1.0262 fc) = 0.07796 N^2/Hz; at 3 fc it is down 10 log10(1 + 3^8) = 38.2 dB, at
// 0.5 fc 0.017 dB. Welch: 16 384-sample Hann segments (0.061 Hz lines), 35 of them.
TEST(Operate, BandLimitedForceAndResponsePeaksAtTheModes) {
  const double fs = 1000.0, rms = 2.0, edge = 50.0;
  RigSpec spec = DefaultRig();
  RigSimulator rig(spec, 7);
  rig.Select(Parse({static_cast<float>(rms), static_cast<float>(edge), 0, 0}));
  rig.Start(1.0 / fs);
  std::vector<double> force, force1, acc1;
  std::array<std::int32_t, wire::kChannelCount> raw{};
  for (int k = 0; k < static_cast<int>(300.0 * fs); ++k) {
    rig.Step(raw);
    force.push_back(rig.last().force_n);
    force1.push_back(spec.load_cells[0].Value(raw[0]));
    acc1.push_back(spec.accelerometers[0].Value(raw[2]));
  }
  double power = 0.0;
  for (double f : force) power += f * f;
  const double measured_rms = std::sqrt(power / static_cast<double>(force.size()));
  // The power of 300 s of a 50 Hz band scatters by 1 / sqrt(B T) = 0.8 % (0.4 % in RMS).
  EXPECT_NEAR(measured_rms, rms, 0.02 * rms);

  const std::size_t n = 16384;
  const double df = fs / static_cast<double>(n);
  const std::vector<double> psd = WelchPsd(force1, n, fs);
  const double flat = rms * rms / (edge * (kPi / 8.0) / std::sin(kPi / 8.0));
  const double low = MeanOver(psd, 1.0, 12.5, df), mid = MeanOver(psd, 12.5, 25.0, df);
  const double above = MeanOver(psd, 140.0, 160.0, df);
  const double truth_above = MeanOver(WelchPsd(force, n, fs), 140.0, 160.0, df);
  std::printf(
      "operate: force RMS %.4f N; force1 PSD 1-12.5 Hz %.5f, 12.5-25 Hz %.5f N^2/Hz (flat band "
      "%.5f); 140-160 Hz %.1f dB below the band (force itself %.1f dB, Butterworth 38.2 dB at "
      "150 Hz)\n",
      measured_rms, low, mid, flat, -Db(above / low), -Db(truth_above / low));
  // Flat below the edge: each half of the lower band within 0.5 dB of the closed form (about
  // 500 lines of 35 averages each: 0.8 % scatter; the load cell's noise adds 0.04 %).
  EXPECT_NEAR(Db(low / flat), 0.0, 0.5);
  EXPECT_NEAR(Db(mid / flat), 0.0, 0.5);
  // Well above it: down by 20 dB or more in what load cell 1 reads (its noise floor, 0.1 N and
  // the 0.24 N code, lies 34 dB below the band), by 35 dB in the force itself.
  EXPECT_LE(Db(above / low), -20.0);
  EXPECT_LE(Db(truth_above / low), -35.0);

  // The response: acc1's PSD (mass 1, driven through spring 2: no antiresonance, falling above
  // the last mode) peaks at the rig's two modes, within the mode's half-power half-width zeta f
  // (0.085 and 0.47 Hz: 1.4 and 7.7 lines). The lines of a 35-segment Welch estimate scatter by
  // 17 %, as much as a resonance falls a few lines from its top, so each line is averaged with
  // two on either side first (8 % scatter; a symmetric average leaves a peak where it is).
  const std::vector<double> raw_response = WelchPsd(acc1, n, fs);
  std::vector<double> response(raw_response.size(), 0.0);
  for (std::size_t i = 2; i + 2 < response.size(); ++i) {
    for (std::size_t j = i - 2; j <= i + 2; ++j) response[i] += raw_response[j] / 5.0;
  }
  const model::ModalResult modes = model::Modal(spec.Truth());
  for (int r = 0; r < modes.size(); ++r) {
    const double f_mode = modes.freq_hz(r);
    std::size_t best = 0;
    for (std::size_t i = 1; i + 1 < response.size(); ++i) {
      const double f = static_cast<double>(i) * df;
      if (std::abs(f - f_mode) < 0.2 * f_mode && (best == 0 || response[i] > response[best]))
        best = i;
    }
    const double peak_hz = static_cast<double>(best) * df;
    // A peak, not the edge of the search: higher than the PSD 20 % away on both sides.
    const double left = MeanOver(response, 0.75 * f_mode, 0.8 * f_mode, df);
    const double right = MeanOver(response, 1.2 * f_mode, 1.25 * f_mode, df);
    std::printf(
        "mode %d: %.4f Hz, acc1 PSD peak at %.4f Hz, %.1f and %.1f dB above 0.8 and 1.2 "
        "times it\n",
        r + 1, f_mode, peak_hz, Db(response[best] / left), Db(response[best] / right));
    EXPECT_NEAR(peak_hz, f_mode, std::max(1.5 * df, modes.zeta(r) * f_mode)) << "mode " << r + 1;
    EXPECT_GT(Db(response[best] / left), 10.0);
    EXPECT_GT(Db(response[best] / right), 10.0);
  }
}

}  // namespace
}  // namespace vibid::emu
