// The anti-aliasing decimator against an exact integer model of the kernel and a double-precision
// reference of the same quantized taps (both from scripts/golden/decimator_design.py, in
// testdata/decimator_vectors.inc), and against its specification measured on its own fixed-point
// output (alias rejection, passband flatness, exact DC, delay). Runs on the host and, in the
// firmware preset, on the Cortex-M4 under QEMU: the same expected integers must come out of both.
#include "vibid/shared/fixed/decimator.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <numbers>
#include <span>

namespace vibid::fixed {
namespace {

#include "testdata/decimator_vectors.inc"

constexpr std::int32_t kMax = std::numeric_limits<std::int32_t>::max();
constexpr std::int32_t kMin = std::numeric_limits<std::int32_t>::min();
constexpr std::size_t kVectorChannels = 4;

static_assert(IsSupportedDecimation(1) && IsSupportedDecimation(2) && IsSupportedDecimation(5) &&
              IsSupportedDecimation(640) && IsSupportedDecimation(1000));
static_assert(!IsSupportedDecimation(0) && !IsSupportedDecimation(3) &&
              !IsSupportedDecimation(1024) && !IsSupportedDecimation(2048) &&
              !IsSupportedDecimation(30 * 7));

// ---- the golden input, mirrored from test_input() in scripts/golden/decimator_design.py:
// integer "magic circle" oscillators (k = 2 sin(pi f) in Q30, f = 0.0011 and 0.17 of fs_in) and
// xorshift32 noise; integer arithmetic only, so the script and both targets agree exactly.
class Oscillator {
 public:
  explicit Oscillator(std::int64_t k_q30) : k_(k_q30) {}
  std::int64_t Step() {
    c_ -= (k_ * s_) >> 30;
    s_ += (k_ * c_) >> 30;
    return c_;
  }

 private:
  std::int64_t k_;
  std::int64_t c_ = std::int64_t{1} << 30;
  std::int64_t s_ = 0;
};

class GoldenInput {
 public:
  // Frame n (called for n = 0, 1, 2, ... in order): ADC 12.4, encoder counts, Q31, square.
  void Next(std::int32_t* frame) {
    const std::int64_t a = lo_.Step();
    const std::int64_t b = hi_.Step();
    rng_ ^= rng_ << 13;
    rng_ ^= rng_ >> 17;
    rng_ ^= rng_ << 5;
    const std::int64_t r = rng_;
    std::int64_t code = 2048 + ((a * 1500) >> 30) + ((b * 300) >> 30) + (r >> 24) - 128;
    code = code < 0 ? 0 : (code > 4095 ? 4095 : code);
    frame[0] = static_cast<std::int32_t>(code * 16);
    frame[1] = static_cast<std::int32_t>(((a * (std::int64_t{1} << 23)) >> 30) +
                                         ((b * (std::int64_t{1} << 16)) >> 30) +
                                         ((r >> 12) & 0xFFF) - 2048);
    // 0.63 and 0.2 of full scale (the fast oscillator peaks at 1.16) plus +-1/8 of noise: peaks at
    // 98 % of full scale, within int32 (the script asserts it never needs the clamp it mirrors).
    frame[2] = static_cast<std::int32_t>(((a * 1352914698) >> 30) + ((b * 429496729) >> 30) +
                                         ((r & 0x1FFFFFFF) - (std::int64_t{1} << 28)));
    frame[3] = (n_ / 700) % 2 == 0 ? kMax : kMin;
    ++n_;
  }

 private:
  Oscillator lo_{7421156};
  Oscillator hi_{1093158116};
  std::uint32_t rng_ = 0x2545F491u;
  std::size_t n_ = 0;
};

constexpr std::size_t kMaxVectorFrames = 79900;  // the D = 200 vector
std::int32_t g_input[kMaxVectorFrames * kVectorChannels];
std::int32_t g_output[400 * kVectorChannels];

void MakeInput(std::size_t frames) {
  GoldenInput gen;
  for (std::size_t n = 0; n < frames; ++n) gen.Next(g_input + n * kVectorChannels);
}

// Runs a vector's input in two blocks (the first not a whole number of output periods, so the
// second starts mid-phase) and returns the number of output frames.
std::size_t RunInTwoBlocks(const DecimatorVector& v, Decimator& dec) {
  const std::size_t split = v.frames / 3 + 1;
  std::size_t first = 0;
  std::size_t second = 0;
  EXPECT_EQ(dec.PushBlock(std::span<const std::int32_t>(g_input, split * kVectorChannels),
                          std::span<std::int32_t>(g_output, 400 * kVectorChannels), first),
            Status::kOk);
  EXPECT_EQ(dec.PushBlock(std::span<const std::int32_t>(g_input + split * kVectorChannels,
                                                        (v.frames - split) * kVectorChannels),
                          std::span<std::int32_t>(g_output + first * kVectorChannels,
                                                  (400 - first) * kVectorChannels),
                          second),
            Status::kOk);
  return first + second;
}

TEST(Decimator, GoldenInputMatchesTheScript) {
  // test_input(3) in scripts/golden/decimator_design.py.
  constexpr std::int32_t kFirst[3][kVectorChannels] = {{63120, 8452683, 1533159133, kMax},
                                                       {56752, 8386238, 1263412928, kMax},
                                                       {51328, 8321127, 721587587, kMax}};
  GoldenInput gen;
  for (const auto& expected : kFirst) {
    std::int32_t f[kVectorChannels];
    gen.Next(f);
    for (std::size_t ch = 0; ch < kVectorChannels; ++ch) EXPECT_EQ(f[ch], expected[ch]);
  }
}

// Host <-> Cortex-M4 acceptance: identical integers to the script's exact integer model of the
// kernel (ADC-like, encoder-like, Q31 and a full-scale square wave that saturates), two blocks.
TEST(Decimator, BitExactWithTheIntegerModel) {
  for (const DecimatorVector& v : kVectors) {
    MakeInput(v.frames);
    Decimator dec;
    ASSERT_EQ(dec.Init(v.factor, kVectorChannels), Status::kOk);
    const std::size_t outputs = RunInTwoBlocks(v, dec);
    ASSERT_EQ(outputs, v.outputs);
    std::size_t mismatches = 0;
    std::size_t first_mismatch = outputs * kVectorChannels;
    for (std::size_t i = 0; i < outputs * kVectorChannels; ++i) {
      if (g_output[i] != v.expected[i]) {
        ++mismatches;
        if (first_mismatch == outputs * kVectorChannels) first_mismatch = i;
      }
    }
    EXPECT_EQ(mismatches, 0u) << "D = " << v.factor;
    EXPECT_EQ(first_mismatch, outputs * kVectorChannels) << "D = " << v.factor;
    // The square wave clips (the model counts the same clips); the other channels never do.
    EXPECT_EQ(dec.saturation_count(), v.saturations) << "D = " << v.factor;
    EXPECT_GT(dec.saturation_count(), 0u);
  }
}

// All seven channels (the worst-case state) are independent: the vector's four channels and three
// copies run side by side give the same integers in every copy.
TEST(Decimator, SevenChannelsAreIndependent) {
  const DecimatorVector& v = kVectors[2];  // D = 10: two stages
  ASSERT_EQ(v.factor, 10u);
  MakeInput(v.frames);
  Decimator dec;
  ASSERT_EQ(dec.Init(v.factor, kDecimatorMaxChannels), Status::kOk);
  std::size_t m = 0;
  std::size_t mismatches = 0;
  for (std::size_t n = 0; n < v.frames; ++n) {
    const std::int32_t* f = g_input + n * kVectorChannels;
    // Reversed copies in 4..6, so a channel mix-up cannot hide behind equal neighbours.
    const std::int32_t in[kDecimatorMaxChannels] = {f[0], f[1], f[2], f[3], f[2], f[1], f[0]};
    std::int32_t out[kDecimatorMaxChannels];
    if (!dec.Push(in, out)) continue;
    const std::int32_t* e = v.expected + m * kVectorChannels;
    const std::int32_t want[kDecimatorMaxChannels] = {e[0], e[1], e[2], e[3], e[2], e[1], e[0]};
    for (std::size_t ch = 0; ch < kDecimatorMaxChannels; ++ch) mismatches += out[ch] != want[ch];
    ++m;
  }
  EXPECT_EQ(m, v.outputs);
  EXPECT_EQ(mismatches, 0u);
  EXPECT_EQ(dec.saturation_count(), v.saturations);  // only the square wave (channel 3) clips
}

// CMSIS-DSP style accuracy: SNR of the fixed output against the double reference
// (scipy.signal.upfirdn, same quantized taps, no rounding) and the largest error in output LSBs,
// per channel kind, run in two blocks.
TEST(Decimator, MatchesTheDoubleReference) {
  // Measured (scripts/golden/decimator_design.py prints the same): SNR ADC 100.2..102.1 dB,
  // encoder 144.1..146.4 dB, Q31 (peaks at 98 % of full scale) 187.0..190.4 dB; max error
  // 0.50 LSB with one stage (D = 2, 5), 0.92 LSB with two (D = 10), 1.16 LSB with five (D = 200).
  // The bound per stage is 1/2 LSB at its output, passed on with a gain of about one by the later
  // stages. The SNR is that of the signal (not full scale) against the rounding: 12.4 ADC input
  // carries 4 bits below one code.
  constexpr std::array<double, 3> kMinSnrDb = {98.0, 142.0, 185.0};
  for (const DecimatorVector& v : kVectors) {
    MakeInput(v.frames);
    Decimator dec;
    ASSERT_EQ(dec.Init(v.factor, kVectorChannels), Status::kOk);
    ASSERT_EQ(RunInTwoBlocks(v, dec), v.outputs);
    std::size_t stages = 0;
    for (std::uint32_t d = v.factor; d > 1; d /= (d % 5 == 0 ? 5u : 2u)) ++stages;
    const double max_lsb = 0.5 * static_cast<double>(stages) + 0.05;
    for (std::size_t ch = 0; ch < 3; ++ch) {
      double signal = 0.0;
      double noise = 0.0;
      double max_err = 0.0;
      for (std::size_t m = 0; m < v.outputs; ++m) {
        const double r = v.reference[m * 3 + ch];
        const double e = g_output[m * kVectorChannels + ch] - r;
        signal += r * r;
        noise += e * e;
        max_err = std::fmax(max_err, std::fabs(e));
      }
      const double snr_db = 10.0 * std::log10(signal / noise);
      EXPECT_GE(snr_db, kMinSnrDb[ch]) << "D = " << v.factor << " channel " << ch;
      EXPECT_LE(max_err, max_lsb) << "D = " << v.factor << " channel " << ch;
    }
  }
}

// ---- the specification, measured on the fixed-point output with a DFT.

constexpr std::size_t kBins = 100;  // output frames per DFT; tones sit exactly on its bins

// sin(2 pi i / (kBins D)) * 2^30 for one period; a tone of `cycles` cycles per kBins output frames
// reads entry (cycles * n) mod (kBins D) at input n, so it is exactly periodic (no leakage).
std::int32_t g_sine[kBins * 1000];

void FillSine(std::uint32_t factor) {
  const std::size_t period = kBins * factor;
  for (std::size_t i = 0; i < period; ++i) {
    const double phase =
        2.0 * std::numbers::pi * static_cast<double>(i) / static_cast<double>(period);
    g_sine[i] = static_cast<std::int32_t>(std::lround(std::sin(phase) * 1073741824.0));
  }
}

// Output amplitude at output bin `bin` (cycles per kBins outputs) for a 2^30 input tone of
// `cycles` cycles per kBins * D inputs, relative to the input amplitude, in dB. The transient
// (2 * delay inputs, the chain's impulse response) is skipped, so the DFT sees the steady state.
double ToneGainDb(std::uint32_t factor, std::size_t cycles, std::size_t bin) {
  Decimator dec;
  EXPECT_EQ(dec.Init(factor, 1), Status::kOk);
  const std::size_t period = kBins * factor;
  const std::size_t skip = 2 * DecimatorDelayTicks(factor) / factor + 1;
  double re = 0.0;
  double im = 0.0;
  std::size_t m = 0;
  for (std::size_t n = 0; m < skip + kBins; ++n) {
    const std::int32_t x = g_sine[(cycles * n) % period];
    std::int32_t y = 0;
    if (!dec.Push(&x, &y)) continue;
    if (m >= skip) {
      const double phase =
          2.0 * std::numbers::pi * static_cast<double>((bin * (m - skip)) % kBins) / kBins;
      re += y * std::cos(phase);
      im -= y * std::sin(phase);
    }
    ++m;
  }
  EXPECT_EQ(dec.saturation_count(), 0u);
  const double amplitude = 2.0 * std::sqrt(re * re + im * im) / kBins;
  return 20.0 * std::log10(amplitude / 1073741824.0 + 1e-30);
}

double EdgeGainDb(std::uint32_t factor) {
  for (const FactorFacts& f : kFactorFacts) {
    if (f.factor == factor) return f.edge_db;
  }
  return 1e9;
}

// Tones that fold to 0.39 fs_out: every j fs_out +- 0.39 fs_out up to fs_in / 2 (all of them for
// small D; for large D the ones next to each stage's own folding frequencies and the extremes).
// Each must come out >= 80 dB below the same tone in the passband (measured at 0.39 fs_out).
TEST(Decimator, RejectsEveryToneThatFoldsIntoThePassband) {
  struct Case {
    std::uint32_t factor;
    std::array<std::uint32_t, 12> j;  // 0 = end; empty = all
  };
  const Case cases[] = {
      {2, {}},
      {5, {}},
      {10, {}},
      {25, {}},
      {50, {}},
      {200, {1, 2, 3, 4, 8, 16, 39, 40, 41, 80, 99, 100}},
      {625, {1, 2, 5, 25, 124, 125, 126, 250, 312, 0}},
      {512, {1, 2, 3, 4, 8, 16, 64, 128, 255, 256, 0}},  // half-band stages only
      {1000, {1, 2, 4, 8, 40, 199, 200, 201, 400, 500, 0}},
  };
  constexpr std::size_t kAliasBin = 39;
  for (const Case& c : cases) {
    FillSine(c.factor);
    const double pass_db = ToneGainDb(c.factor, kAliasBin, kAliasBin);
    EXPECT_LE(std::fabs(pass_db), 0.1) << "D = " << c.factor;
    double worst_db = -1e9;
    const auto check = [&](std::uint32_t j) {
      for (const int sign : {-1, 1}) {
        const long cycles =
            static_cast<long>(j) * static_cast<long>(kBins) + sign * static_cast<long>(kAliasBin);
        if (cycles <= 0 || static_cast<std::size_t>(cycles) > kBins * c.factor / 2) continue;
        const double db =
            ToneGainDb(c.factor, static_cast<std::size_t>(cycles), kAliasBin) - pass_db;
        EXPECT_LE(db, -80.0) << "D = " << c.factor << ", tone at " << j << " fs_out "
                             << (sign < 0 ? "-" : "+") << " 0.39 fs_out";
        worst_db = std::fmax(worst_db, db);
      }
    };
    if (c.j[0] == 0) {
      for (std::uint32_t j = 1; j <= c.factor / 2; ++j) check(j);
    } else {
      for (const std::uint32_t j : c.j) {
        if (j != 0) check(j);
      }
    }
    EXPECT_LE(worst_db, -80.0) << "D = " << c.factor;
    EXPECT_GT(worst_db, -200.0) << "D = " << c.factor;  // the measurement did run
  }
}

// The passband edge (0.4 fs_out) within 0.1 dB, and within 0.005 dB of what the script predicts
// from the quantized taps; a low tone (0.1 fs_out) within 0.1 dB.
TEST(Decimator, PassbandIsFlatToItsEdge) {
  for (const std::uint32_t factor : {2u, 5u, 10u, 25u, 50u, 200u, 512u, 625u, 1000u}) {
    FillSine(factor);
    const double edge_db = ToneGainDb(factor, 40, 40);
    EXPECT_LE(std::fabs(edge_db), 0.1) << "D = " << factor;
    EXPECT_NEAR(edge_db, EdgeGainDb(factor), 0.005) << "D = " << factor;
    EXPECT_LE(std::fabs(ToneGainDb(factor, 10, 10)), 0.1) << "D = " << factor;
  }
}

// ---- exactness: DC and ramps, every supported factor.

// A constant comes out exactly (the taps sum to 2^30) once the chain's impulse response has
// passed; a ramp comes out as the same ramp DecimatorDelayTicks later, exactly (a symmetric FIR
// with unit DC gain maps n to n - (L-1)/2). Neither saturates anything.
TEST(Decimator, DcAndRampsAreExactAfterTheDelay) {
  std::size_t factors = 0;
  for (const FactorFacts& f : kFactorFacts) {
    ++factors;
    ASSERT_EQ(DecimatorDelayTicks(f.factor), f.delay) << "D = " << f.factor;
    Decimator dec;
    ASSERT_EQ(dec.Init(f.factor, 5), Status::kOk);
    const std::size_t settled =
        2 * std::size_t{f.delay} / f.factor + 1;  // first m with m D >= 2 delay
    std::size_t m = 0;
    std::size_t wrong = 0;
    for (std::int64_t n = 0; m < settled + 8; ++n) {
      const std::int32_t in[5] = {65520, -12345678, 1234567890,
                                  static_cast<std::int32_t>(97 * n - 5000000),
                                  static_cast<std::int32_t>(1900000000 - 40000 * n)};
      std::int32_t out[5];
      if (!dec.Push(in, out)) continue;
      if (m >= settled) {
        const std::int64_t t =
            static_cast<std::int64_t>(m) * f.factor - f.delay;  // the input index it reproduces
        wrong += out[0] != 65520;
        wrong += out[1] != -12345678;
        wrong += out[2] != 1234567890;
        wrong += out[3] != 97 * t - 5000000;
        wrong += out[4] != 1900000000 - 40000 * t;
      }
      ++m;
    }
    EXPECT_EQ(wrong, 0u) << "D = " << f.factor;
    EXPECT_EQ(dec.saturation_count(), 0u) << "D = " << f.factor;
  }
  EXPECT_EQ(factors, 29u);  // every 2^a 5^b <= 1000
  EXPECT_EQ(DecimatorDelayTicks(1), 0u);
  EXPECT_EQ(DecimatorDelayTicks(3), 0u);
}

// Full-scale constants: the step response overshoots the int32 range in the first stage(s), the
// clips are counted, the output never wraps to the other sign, and after the delay it is exactly
// the rail value again.
TEST(Decimator, FullScaleStepSaturatesCleanly) {
  for (const std::uint32_t factor : {2u, 5u, 10u, 200u, 512u, 625u}) {
    Decimator dec;
    ASSERT_EQ(dec.Init(factor, 2), Status::kOk);
    const std::size_t settled = 2 * std::size_t{DecimatorDelayTicks(factor)} / factor + 1;
    const std::int32_t in[2] = {kMax, kMin};
    std::size_t m = 0;
    std::size_t wrapped = 0;
    std::size_t wrong = 0;
    while (m < settled + 4) {
      std::int32_t out[2];
      if (!dec.Push(in, out)) continue;
      // Early outputs are small and may be slightly negative (leading negative taps); a wrap
      // would be near the opposite rail.
      wrapped += out[0] < -(1 << 29);
      wrapped += out[1] > (1 << 29);
      if (m >= settled) {
        wrong += out[0] != kMax;
        wrong += out[1] != kMin;
      }
      ++m;
    }
    EXPECT_EQ(wrapped, 0u) << "D = " << factor;
    EXPECT_EQ(wrong, 0u) << "D = " << factor;
    EXPECT_GT(dec.saturation_count(), 0u) << "D = " << factor;
  }
}

// ---- phases, copies, refusals.

TEST(Decimator, OutputsOnEveryFactorthInputFromTheFirst) {
  Decimator dec;
  ASSERT_EQ(dec.Init(10, 7), Status::kOk);
  EXPECT_EQ(dec.factor(), 10u);
  EXPECT_EQ(dec.channel_count(), 7u);
  std::int32_t in[7] = {1, 2, 3, 4, 5, 6, 7};
  std::int32_t out[7] = {};
  std::size_t outputs = 0;
  for (std::size_t n = 0; n < 95; ++n) {
    const bool emitted = dec.Push(in, out);
    EXPECT_EQ(emitted, n % 10 == 0) << "n = " << n;
    outputs += emitted;
  }
  EXPECT_EQ(outputs, 10u);
  // 95 inputs in: the next output is input 100, five frames away.
  EXPECT_EQ(dec.OutputFrames(5), 0u);
  EXPECT_EQ(dec.OutputFrames(6), 1u);
  EXPECT_EQ(dec.OutputFrames(16), 2u);
  ASSERT_EQ(dec.Init(10, 7), Status::kOk);
  EXPECT_EQ(dec.OutputFrames(0), 0u);
  EXPECT_EQ(dec.OutputFrames(1), 1u);
  EXPECT_EQ(dec.OutputFrames(10), 1u);
  EXPECT_EQ(dec.OutputFrames(11), 2u);
  // Reset: phase 0 again, state cleared (the same output as the very first Push).
  ASSERT_EQ(dec.Init(2, 1), Status::kOk);
  const std::int32_t x = 1 << 24;
  std::int32_t first = 0;
  ASSERT_TRUE(dec.Push(&x, &first));
  EXPECT_FALSE(dec.Push(&x, out));
  dec.Reset();
  std::int32_t again = 0;
  ASSERT_TRUE(dec.Push(&x, &again));
  EXPECT_EQ(first, again);
}

TEST(Decimator, FactorOneIsAPlainCopy) {
  Decimator dec;
  ASSERT_EQ(dec.Init(1, 7), Status::kOk);
  EXPECT_EQ(DecimatorDelayTicks(1), 0u);
  for (std::int32_t n = 0; n < 5; ++n) {
    const std::int32_t in[7] = {kMax, kMin, n, -n, 65520, 0, 12345};
    std::int32_t out[7] = {};
    ASSERT_TRUE(dec.Push(in, out));
    for (std::size_t ch = 0; ch < 7; ++ch) EXPECT_EQ(out[ch], in[ch]);
  }
  EXPECT_EQ(dec.saturation_count(), 0u);
}

TEST(Decimator, RefusesUnsupportedFactorsAndChannelCounts) {
  Decimator dec;
  EXPECT_FALSE(dec.initialised());
  const std::int32_t in[8] = {};
  std::int32_t out[8] = {};
  EXPECT_FALSE(dec.Push(in, out));  // uninitialised: takes nothing
  for (const std::uint32_t factor : {3u, 0u, 2048u, 1024u, 7u, 30u * 7u}) {
    EXPECT_EQ(dec.Init(factor, 1), Status::kInvalidArgument) << factor;
    EXPECT_FALSE(dec.initialised());
    EXPECT_FALSE(dec.Push(in, out));
  }
  EXPECT_EQ(dec.Init(10, 0), Status::kInvalidArgument);
  EXPECT_EQ(dec.Init(10, 8), Status::kInvalidArgument);
  EXPECT_FALSE(dec.initialised());
  EXPECT_EQ(dec.Init(1000, 7), Status::kOk);
  EXPECT_EQ(dec.Init(625, 7), Status::kOk);
  EXPECT_EQ(dec.Init(512, 7), Status::kOk);
  EXPECT_TRUE(dec.initialised());
  // A block of partial frames or with too little room for the outputs is refused whole.
  std::size_t frames = 99;
  EXPECT_EQ(
      dec.PushBlock(std::span<const std::int32_t>(in, 6), std::span<std::int32_t>(out, 8), frames),
      Status::kInvalidArgument);
  EXPECT_EQ(frames, 0u);
  ASSERT_EQ(dec.Init(2, 2), Status::kOk);
  EXPECT_EQ(
      dec.PushBlock(std::span<const std::int32_t>(in, 8), std::span<std::int32_t>(out, 2), frames),
      Status::kInvalidArgument);  // 4 frames can give 2 outputs: needs 4 words
  EXPECT_EQ(
      dec.PushBlock(std::span<const std::int32_t>(in, 8), std::span<std::int32_t>(out, 4), frames),
      Status::kOk);
  EXPECT_EQ(frames, 2u);
}

}  // namespace
}  // namespace vibid::fixed
