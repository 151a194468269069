// The residual CUSUM kernel against a double-precision evaluation of the test it implements
// (r = d_hat - reference gain * reference, the mean of (r / 2^s)^2 over each window, z = (e - mu0)
// / sigma0, g = max(0, g + z - k)), with the real parameters the integer ones were rounded from.
// The input is integer noise whose power steps up part way (a model gone stale), fed in two
// blocks split inside a window so the partial window carries over. Runs on the host and, in the
// firmware preset, on the Cortex-M4 under QEMU.
#include "vibid/shared/fixed/residual_cusum.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <vector>

namespace vibid::fixed {
namespace {

constexpr double kQ16 = 65536.0;

// Near-Gaussian integer noise: the sum of four xorshift32 uniforms (variance 4/12 of the range^2),
// scaled to the given RMS; integer-only so every target sees the same samples.
class Noise {
 public:
  explicit Noise(std::uint32_t seed) : state_(seed) {}
  std::int32_t Next(double rms) {
    double u = 0.0;
    for (int i = 0; i < 4; ++i) u += static_cast<double>(Draw()) / 4294967296.0 - 0.5;
    return static_cast<std::int32_t>(std::lround(u * rms * std::sqrt(3.0)));
  }

 private:
  std::uint32_t Draw() {
    state_ ^= state_ << 13;
    state_ ^= state_ >> 17;
    state_ ^= state_ << 5;
    return state_;
  }
  std::uint32_t state_;
};

// The test's real parameters: what the host measures and chooses.
struct RealParams {
  std::uint32_t window = 256;
  double reference_gain = 0.0;         // reference full scale / d_hat full scale
  double residual_scale = 1.0 / 16.0;  // r = residual_scale (d_hat - reference_gain reference)
  double mu0 = 0.0;                    // in-control mean of r^2
  double sigma0 = 0.0;                 // in-control spread of its window mean
  double k = 0.5;
  double h = 10.0;  // an in-control run length far beyond these tests' 200 windows
};

// Rounds the real parameters to the kernel's (the same rules the host's design follows, written
// out here independently): S >> sum_shift near 2^24, z_gain in [2^30, 2^31).
ResidualCusumParams Quantize(const RealParams& real) {
  ResidualCusumParams p;
  p.window_samples = real.window;
  p.residual_gain = static_cast<std::int32_t>(std::lround(std::ldexp(real.residual_scale, 32)));
  p.reference_gain = static_cast<std::int32_t>(
      std::lround(-std::ldexp(real.reference_gain * real.residual_scale, 32)));
  const double w_mu0 = real.window * real.mu0;
  p.sum_shift = static_cast<std::uint8_t>(std::max(0, static_cast<int>(std::log2(w_mu0)) - 24));
  p.center = static_cast<std::int32_t>(std::lround(w_mu0 / std::ldexp(1.0, p.sum_shift)));
  const double gain_unit = std::ldexp(1.0, 16 + p.sum_shift) / (real.window * real.sigma0);
  int z_shift = 0;
  while (gain_unit * std::ldexp(1.0, z_shift + 1) < 2147483647.0) ++z_shift;
  p.z_shift = static_cast<std::uint8_t>(z_shift);
  p.z_gain = static_cast<std::int32_t>(std::lround(gain_unit * std::ldexp(1.0, z_shift)));
  p.k = static_cast<std::int32_t>(std::lround(real.k * kQ16));
  p.h = static_cast<std::int32_t>(std::lround(real.h * kQ16));
  return p;
}

struct Window {
  double z = 0.0;
  double g = 0.0;
};

// The double reference, run over the whole input at once.
std::vector<Window> Reference(const RealParams& real, const std::vector<std::int32_t>& d_hat,
                              const std::vector<std::int32_t>& reference) {
  std::vector<Window> out;
  double sum = 0.0;
  double g = 0.0;
  for (std::size_t n = 0; n < d_hat.size(); ++n) {
    const double r = (d_hat[n] - real.reference_gain * reference[n]) * real.residual_scale;
    sum += r * r;
    if ((n + 1) % real.window == 0) {
      const double e = sum / real.window;
      const double z = (e - real.mu0) / real.sigma0;
      g = std::max(0.0, g + z - real.k);
      out.push_back({z, g});
      sum = 0.0;
    }
  }
  return out;
}

struct Input {
  std::vector<std::int32_t> d_hat;
  std::vector<std::int32_t> reference;
};

// In-control residual of RMS rms_scaled / residual_scale for `calm` windows, then `ratio` times the
// power; with a reference, d_hat = gain * reference + residual.
Input MakeInput(const RealParams& real, double rms_scaled, int calm, int stale, double ratio) {
  Input in;
  Noise residual(0x2545F491u);
  Noise force(0x9E3779B9u);
  const double rms = rms_scaled / real.residual_scale;
  const std::size_t total = static_cast<std::size_t>(calm + stale) * real.window;
  for (std::size_t n = 0; n < total; ++n) {
    const bool after = n >= static_cast<std::size_t>(calm) * real.window;
    const std::int32_t ref = real.reference_gain != 0.0 ? force.Next(1.0e8) : 0;
    const double r = residual.Next(after ? rms * std::sqrt(ratio) : rms);
    in.reference.push_back(ref);
    in.d_hat.push_back(static_cast<std::int32_t>(std::lround(real.reference_gain * ref + r)));
  }
  return in;
}

struct Comparison {
  double snr_db = 0.0;
  double max_g_lsb = 0.0;
  double max_z_lsb = 0.0;
  std::size_t trip_window = 0;  // 1-based; 0: never
};

// Runs the kernel over `in` in two blocks (the split inside a window) and compares each window's
// z and g with the double reference.
Comparison Compare(const RealParams& real, const Input& in, ResidualCusum& kernel) {
  const std::vector<Window> ref = Reference(real, in.d_hat, in.reference);
  const std::size_t split = real.window * (ref.size() / 2) + real.window / 3;
  Comparison c;
  double signal = 0.0;
  double noise = 0.0;
  std::size_t w = 0;
  for (std::size_t n = 0; n < in.d_hat.size(); ++n) {
    if (n == split) {
      EXPECT_EQ(kernel.samples(), split);  // the first block ends mid-window ...
      EXPECT_EQ(kernel.windows(), split / real.window);
    }
    if (!kernel.Step(in.d_hat[n], in.reference[n])) continue;
    const double g = kernel.statistic() / kQ16;
    c.max_g_lsb = std::max(c.max_g_lsb, std::fabs(g - ref[w].g) * kQ16);
    c.max_z_lsb = std::max(c.max_z_lsb, std::fabs(kernel.last_z() / kQ16 - ref[w].z) * kQ16);
    signal += ref[w].g * ref[w].g;
    noise += (g - ref[w].g) * (g - ref[w].g);
    ++w;
    if (c.trip_window == 0 && ref[w - 1].g > real.h) c.trip_window = w;
  }
  EXPECT_EQ(w, ref.size());  // ... and the second carries it over
  c.snr_db = 10.0 * std::log10(signal / std::max(noise, 1e-300));
  // Integers only: the Cortex-M4 runner's printf has no floating point.
  std::printf("%u windows: g SNR %ld dB, max g error %ld/100 LSB, max z error %ld/100 LSB (Q16)\n",
              static_cast<unsigned>(w), std::lround(c.snr_db), std::lround(100 * c.max_g_lsb),
              std::lround(100 * c.max_z_lsb));
  return c;
}

RealParams StaleRig(double reference_gain) {
  RealParams real;
  real.reference_gain = reference_gain;
  // The in-control statistics of the generated residual (RMS 2^15 after the scale): the mean of
  // r^2 and, for white near-Gaussian r, the spread sqrt(2 / W) mu0 of its window mean.
  real.mu0 = std::ldexp(1.0, 30);
  real.sigma0 = real.mu0 * std::sqrt(2.0 / real.window);
  return real;
}

TEST(ResidualCusum, MatchesTheDoubleReferenceWithoutAReference) {
  const RealParams real = StaleRig(0.0);
  // 60 windows in control, then the residual's power 1.3 times higher (a 30 % rise, about 3.4
  // spreads of the window mean at W = 256): the statistic climbs and trips.
  const Input in = MakeInput(real, std::ldexp(1.0, 15), 60, 60, 1.3);
  ResidualCusum kernel;
  ASSERT_EQ(kernel.Init(Quantize(real)), Status::kOk);
  const Comparison c = Compare(real, in, kernel);
  // Bounds from the kernel's error analysis (residual_cusum.hpp): z within a few LSB of Q16, g
  // accumulating those while above zero.
  EXPECT_LE(c.max_z_lsb, 4.0);
  EXPECT_LE(c.max_g_lsb, 20.0);
  EXPECT_GE(c.snr_db, 90.0);
  ASSERT_GT(c.trip_window, 60u);  // the reference trips after the step, ...
  EXPECT_TRUE(kernel.tripped());  // ... and the kernel in the same window
  EXPECT_EQ(kernel.trip_sample(), c.trip_window * real.window);
  EXPECT_GT(kernel.trip_statistic(), Quantize(real).h);
  EXPECT_EQ(kernel.clamp_count(), 0u);
}

TEST(ResidualCusum, MatchesTheDoubleReferenceWithAReferenceForce) {
  const RealParams real = StaleRig(0.75);
  const Input in = MakeInput(real, std::ldexp(1.0, 15), 60, 60, 1.3);
  ResidualCusum kernel;
  ASSERT_EQ(kernel.Init(Quantize(real)), Status::kOk);
  const Comparison c = Compare(real, in, kernel);
  EXPECT_LE(c.max_z_lsb, 4.0);
  EXPECT_LE(c.max_g_lsb, 20.0);
  EXPECT_GE(c.snr_db, 90.0);
  ASSERT_GT(c.trip_window, 60u);
  EXPECT_EQ(kernel.trip_sample(), c.trip_window * real.window);
}

TEST(ResidualCusum, StaysQuietInControl) {
  const RealParams real = StaleRig(0.0);
  const Input in = MakeInput(real, std::ldexp(1.0, 15), 200, 0, 1.0);
  ResidualCusum kernel;
  ASSERT_EQ(kernel.Init(Quantize(real)), Status::kOk);
  const Comparison c = Compare(real, in, kernel);
  EXPECT_EQ(c.trip_window, 0u);
  EXPECT_FALSE(kernel.tripped());
  EXPECT_EQ(kernel.trip_sample(), 0u);
  EXPECT_LE(c.max_g_lsb, 20.0);
}

TEST(ResidualCusum, ClampsAHugeResidualAndCountsIt) {
  RealParams real = StaleRig(0.0);
  ResidualCusum kernel;
  ASSERT_EQ(kernel.Init(Quantize(real)), Status::kOk);
  // Full-scale d_hat at a scale of 1/16 is 2^27 >> 2^23: every sample clamps, the window's z is
  // huge and the statistic trips at the first window, bounded, never wrapped.
  for (std::uint32_t n = 0; n < 3 * real.window; ++n) {
    (void)kernel.Step(n % 2 == 0 ? 2147483647 : -2147483647 - 1, 0);
  }
  // Every sample, and the excess of each of the three windows.
  EXPECT_EQ(kernel.clamp_count(), 3 * real.window + 3);
  EXPECT_TRUE(kernel.tripped());
  EXPECT_EQ(kernel.trip_sample(), real.window);
  EXPECT_GT(kernel.statistic(), 0);
  EXPECT_LE(kernel.statistic(), kMaxStatistic);
  kernel.Reset();
  EXPECT_FALSE(kernel.tripped());
  EXPECT_EQ(kernel.statistic(), 0);
  EXPECT_EQ(kernel.clamp_count(), 0u);
}

// A start transient: the first windows' residual decays from a large value (the observer starting
// from rest beside a running rig) over in-control noise. Without a hold-off the first window trips;
// with a hold-off past the transient, the judged windows are in control and nothing trips.
Input StartTransient(const RealParams& real, int windows) {
  Input in = MakeInput(real, std::ldexp(1.0, 15), windows, 0, 1.0);
  // Amplitude 2^22 (scaled; 2^14 times the noise's power) halving every 64 samples: after 3
  // windows of 256 it is 2^22 / 2^12 = 2^10, 2^-10 of the noise's power.
  for (std::size_t n = 0; n < in.d_hat.size(); ++n) {
    const double t =
        std::ldexp(1.0, 22) / real.residual_scale * std::exp2(-static_cast<double>(n) / 64.0);
    in.d_hat[n] = static_cast<std::int32_t>(std::lround(in.d_hat[n] + t));
  }
  return in;
}

TEST(ResidualCusum, HoldOffKeepsAStartTransientFromTripping) {
  const RealParams real = StaleRig(0.0);
  const Input in = StartTransient(real, 100);
  ResidualCusumParams p = Quantize(real);
  ResidualCusum without;
  ASSERT_EQ(without.Init(p), Status::kOk);
  p.holdoff_windows = 3;
  ResidualCusum with;
  ASSERT_EQ(with.Init(p), Status::kOk);
  std::uint32_t completed = 0;
  for (std::size_t n = 0; n < in.d_hat.size(); ++n) {
    (void)without.Step(in.d_hat[n], 0);
    if (!with.Step(in.d_hat[n], 0)) continue;
    ++completed;
    // Within the hold-off the window is computed (its z is huge in the first) but not judged.
    if (completed <= 3) {
      EXPECT_EQ(with.statistic(), 0) << completed;
      EXPECT_TRUE(completed == 3 ? !with.holding_off() : with.holding_off());
    }
    if (completed == 1) {
      EXPECT_GT(with.last_z(), 100 * 65536);
    }
  }
  EXPECT_TRUE(without.tripped());
  EXPECT_EQ(without.trip_sample(), real.window);  // the first window
  // The first window's excess (2^14 times the in-control power) is clamped to int32 and counted.
  EXPECT_GT(without.clamp_count(), 0u);
  EXPECT_FALSE(with.tripped());
  EXPECT_EQ(with.windows(), 100u);
  EXPECT_EQ(with.clamp_count(), 0u);  // the transient's clamps are dropped with the hold-off
  // Reset rearms the hold-off: the same start is again held off.
  with.Reset();
  EXPECT_TRUE(with.holding_off());
  for (std::size_t n = 0; n < 4 * real.window; ++n) (void)with.Step(in.d_hat[n], 0);
  EXPECT_FALSE(with.tripped());
}

TEST(ResidualCusum, RefusesParametersOutOfRange) {
  const ResidualCusumParams good = Quantize(StaleRig(0.0));
  EXPECT_EQ(ValidateResidualCusum(good), Status::kOk);
  auto refused = [&](auto change) {
    ResidualCusumParams p = good;
    change(p);
    ResidualCusum kernel;
    const Status s = kernel.Init(p);
    EXPECT_FALSE(kernel.initialised());
    EXPECT_FALSE(kernel.Step(1 << 30, 0));
    return s;
  };
  EXPECT_EQ(refused([](auto& p) { p.window_samples = 0; }), Status::kInvalidArgument);
  EXPECT_EQ(refused([](auto& p) { p.window_samples = kMaxWindowSamples + 1; }),
            Status::kInvalidArgument);
  EXPECT_EQ(refused([](auto& p) { p.residual_gain = 0; }), Status::kInvalidArgument);
  EXPECT_EQ(refused([](auto& p) { p.residual_gain = -2147483647 - 1; }), Status::kInvalidArgument);
  EXPECT_EQ(refused([](auto& p) { p.reference_gain = -2147483647 - 1; }), Status::kInvalidArgument);
  EXPECT_EQ(refused([](auto& p) { p.sum_shift = kMaxSumShift + 1; }), Status::kInvalidArgument);
  EXPECT_EQ(refused([](auto& p) { p.z_shift = kMaxZShift + 1; }), Status::kInvalidArgument);
  EXPECT_EQ(refused([](auto& p) { p.z_gain = 0; }), Status::kInvalidArgument);
  EXPECT_EQ(refused([](auto& p) { p.k = -1; }), Status::kInvalidArgument);
  EXPECT_EQ(refused([](auto& p) { p.h = 0; }), Status::kInvalidArgument);
  EXPECT_EQ(refused([](auto& p) { p.h = kMaxStatistic; }), Status::kInvalidArgument);
}

}  // namespace
}  // namespace vibid::fixed
