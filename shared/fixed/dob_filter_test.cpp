// The fixed-point observer kernel against a double-precision reference of the same integer
// coefficients (rounding and saturation are the only differences), and bit for bit against the
// host build's output (testdata/dob_kernel_vectors.inc, scripts/golden/dob_kernel_vectors.sh).
// Runs on the host and, in the firmware preset, on the Cortex-M4 under QEMU.
#include "vibid/shared/fixed/dob_filter.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>

namespace vibid::fixed {
namespace {

#include "testdata/dob_kernel_vectors.inc"

constexpr std::size_t kInputs = 2;
constexpr std::size_t kSplit = 1234;  // first block length (two-block runs)
constexpr std::size_t kLinearSamples = 3 * kVectorSamples / 4;  // before the full-scale part

FilterDescription VectorDescription() {
  FilterDescription d{};
  static_cast<void>(
      DecodeDescription(std::span<const std::uint8_t, kDescriptionBytes>(kVectorDescription), d));
  return d;
}

// The kernel's arithmetic without rounding or saturation, in units of the output LSB.
class DoubleReference {
 public:
  explicit DoubleReference(const FilterDescription& d) : d_(d) {}

  double Step(const std::int32_t* frame) {
    double sum = 0.0;
    for (std::size_t i = 0; i < d_.input_count; ++i) {
      const Path& p = d_.paths[i];
      double x = frame[i];
      for (std::size_t k = 0; k < p.section_count; ++k) {
        const Section& s = p.sections[k];
        const double one = std::ldexp(1.0, 31 - s.shift);
        auto& st = state_[i][k];
        const double y =
            (s.b0 * x + s.b1 * st[0] + s.b2 * st[1] - s.a1 * st[2] - s.a2 * st[3]) / one;
        st[1] = st[0];
        st[0] = x;
        st[3] = st[2];
        st[2] = y;
        x = y;
      }
      sum += x * p.output_gain / std::ldexp(1.0, 31 - p.output_shift);
    }
    return sum;
  }

 private:
  FilterDescription d_;
  std::array<std::array<std::array<double, 4>, kMaxSections>, kMaxInputs> state_{};
};

std::span<const std::int32_t> Frames(std::size_t first, std::size_t count) {
  return std::span<const std::int32_t>(kVectorInput + first * kInputs, count * kInputs);
}

// Host <-> Cortex-M4 acceptance: identical integers from the same inputs, run in two blocks.
TEST(DobFilter, BitExactWithTheHostBuild) {
  const FilterDescription d = VectorDescription();
  ASSERT_EQ(ValidateDescription(d), Status::kOk);
  DobFilter filter;
  ASSERT_EQ(filter.Init(d), Status::kOk);
  static std::int32_t out[kVectorSamples];
  ASSERT_EQ(filter.StepBlock(Frames(0, kSplit), std::span<std::int32_t>(out, kSplit)), Status::kOk);
  ASSERT_EQ(filter.StepBlock(Frames(kSplit, kVectorSamples - kSplit),
                             std::span<std::int32_t>(out + kSplit, kVectorSamples - kSplit)),
            Status::kOk);
  std::size_t mismatches = 0;
  std::size_t first_mismatch = kVectorSamples;
  for (std::size_t n = 0; n < kVectorSamples; ++n) {
    if (out[n] != kVectorOutput[n]) {
      ++mismatches;
      if (first_mismatch == kVectorSamples) first_mismatch = n;
    }
  }
  EXPECT_EQ(mismatches, 0u);
  EXPECT_EQ(first_mismatch, kVectorSamples);
  EXPECT_EQ(filter.saturation_count(), kVectorSaturations);
}

// CMSIS-DSP style accuracy check over the linear part of the vector: SNR of the fixed output
// against the double reference and the largest error in output LSBs, filter run in two blocks.
TEST(DobFilter, MatchesTheDoubleReference) {
  const FilterDescription d = VectorDescription();
  DobFilter filter;
  ASSERT_EQ(filter.Init(d), Status::kOk);
  DoubleReference ref(d);
  static std::int32_t out[kLinearSamples];
  ASSERT_EQ(filter.StepBlock(Frames(0, kSplit), std::span<std::int32_t>(out, kSplit)), Status::kOk);
  ASSERT_EQ(filter.StepBlock(Frames(kSplit, kLinearSamples - kSplit),
                             std::span<std::int32_t>(out + kSplit, kLinearSamples - kSplit)),
            Status::kOk);
  double signal = 0.0;
  double noise = 0.0;
  double max_err = 0.0;
  for (std::size_t n = 0; n < kLinearSamples; ++n) {
    const double r = ref.Step(kVectorInput + n * kInputs);
    const double e = out[n] - r;
    signal += r * r;
    noise += e * e;
    max_err = std::fmax(max_err, std::fabs(e));
  }
  const double snr_db = 10.0 * std::log10(signal / noise);
  // Measured: 114.7 dB and 678 LSB (1 LSB of d_hat = 200 N / 2^31 = 9.3e-8 N). The error is the
  // sensor path's section rounding times its output gain (about 420, from the l1 scaling); the
  // host predicts 229 LSB rms for this design.
  EXPECT_GE(snr_db, 110.0);
  EXPECT_LE(max_err, 1000.0);
  EXPECT_EQ(filter.saturation_count(), 0u);
}

// Full-scale square waves: where the exact result leaves the int32 range the output sits on the
// matching rail; it never wraps to the opposite sign.
TEST(DobFilter, FullScaleInputSaturatesCleanly) {
  const FilterDescription d = VectorDescription();
  DobFilter filter;
  ASSERT_EQ(filter.Init(d), Status::kOk);
  DoubleReference ref(d);
  std::size_t railed = 0;
  for (std::size_t n = 0; n < kVectorSamples; ++n) {
    InputFrame frame{kVectorInput[2 * n], kVectorInput[2 * n + 1], 0};
    const std::int32_t y = filter.Step(frame);
    const double r = ref.Step(kVectorInput + 2 * n);
    if (r >= 2147483648.0) {
      EXPECT_EQ(y, std::numeric_limits<std::int32_t>::max());
      ++railed;
    } else if (r < -2147483648.0) {
      EXPECT_EQ(y, std::numeric_limits<std::int32_t>::min());
      ++railed;
    } else if (std::fabs(r) > 1073741824.0) {
      EXPECT_TRUE((y > 0) == (r > 0));
    }
  }
  EXPECT_GT(railed, 500u);
  EXPECT_EQ(filter.saturation_count(), railed);
}

// A section whose gain exceeds one saturates at its own output (counted), never wraps.
TEST(DobFilter, SectionOutputSaturatesAtTheRails) {
  FilterDescription d{};
  d.input_count = 1;
  d.sample_rate_hz = 1000;
  d.input_kind[0] = InputKind::kForce;
  d.input_full_scale_bits[0] = FullScaleBits(1.0f);
  d.output_full_scale_bits = FullScaleBits(1.0f);
  d.paths[0].section_count = 1;
  d.paths[0].output_gain = std::numeric_limits<std::int32_t>::max();  // ~1.0 with shift 0
  d.paths[0].sections[0] =
      Section{.b0 = 3 << 28, .b1 = 0, .b2 = 0, .a1 = 0, .a2 = 0, .shift = 2};  // 1.5
  Seal(d);
  DobFilter filter;
  ASSERT_EQ(filter.Init(d), Status::kOk);
  EXPECT_EQ(filter.Step({1 << 29, 0, 0}),
            3 << 28);  // 0.25 in, 0.375 out (gain 1 - 2^-31 rounds away)
  EXPECT_EQ(filter.Step({std::numeric_limits<std::int32_t>::max(), 0, 0}),
            std::numeric_limits<std::int32_t>::max() - 1);
  EXPECT_EQ(filter.Step({std::numeric_limits<std::int32_t>::min(), 0, 0}),
            std::numeric_limits<std::int32_t>::min() + 1);
  EXPECT_EQ(filter.saturation_count(), 2u);
}

// The documented arithmetic (header), one int64 expression per step, for the test below.
class IntegerReference {
 public:
  explicit IntegerReference(const FilterDescription& d) : d_(d) {}

  std::int32_t Step(const std::int32_t* frame) {
    std::int64_t sum = 0;
    for (std::size_t i = 0; i < d_.input_count; ++i) {
      const Path& p = d_.paths[i];
      std::int64_t x = frame[i];
      for (std::size_t k = 0; k < p.section_count; ++k) {
        const Section& s = p.sections[k];
        auto& st = state_[i][k];  // x1 x2 y1 y2 r1 r2
        const int q = 31 - s.shift;
        std::int64_t acc = s.b0 * x + s.b1 * st[0] + s.b2 * st[1] - s.a1 * st[2] - s.a2 * st[3];
        if (s.feedback == ErrorFeedback::kSecondOrder) acc += 2 * st[4] - st[5];
        std::int64_t y = (acc + (std::int64_t{1} << (q - 1))) >> q;
        std::int64_t r = acc - (y << q);
        if (y > std::numeric_limits<std::int32_t>::max() ||
            y < std::numeric_limits<std::int32_t>::min()) {
          y = y > 0 ? std::numeric_limits<std::int32_t>::max()
                    : std::numeric_limits<std::int32_t>::min();
          r = 0;
          ++saturations_;
        }
        st = {x, st[0], y, st[2], r, st[4]};
        x = y;
      }
      const int shift = 31 - p.output_shift;
      sum += (x * p.output_gain + (std::int64_t{1} << (shift - 1))) >> shift;
    }
    if (sum > std::numeric_limits<std::int32_t>::max() ||
        sum < std::numeric_limits<std::int32_t>::min()) {
      ++saturations_;
      return sum > 0 ? std::numeric_limits<std::int32_t>::max()
                     : std::numeric_limits<std::int32_t>::min();
    }
    return static_cast<std::int32_t>(sum);
  }
  std::uint32_t saturations() const { return saturations_; }

 private:
  FilterDescription d_;
  std::array<std::array<std::array<std::int64_t, 6>, kMaxSections>, kMaxInputs> state_{};
  std::uint32_t saturations_ = 0;
};

// Every section shift with and without error feedback, three inputs (one a pure gain), output
// shifts from 0 to 30, inputs up to full scale so sections and d_hat saturate: the kernel (on the
// Cortex-M4, one program block per shift and feedback mode) against the int64 reference.
TEST(DobFilter, EveryShiftAndInputCountMatchesTheIntegerReference) {
  for (std::uint8_t inputs = 1; inputs <= kMaxInputs; ++inputs) {
    FilterDescription d{};
    d.input_count = inputs;
    d.sample_rate_hz = 1000;
    d.output_full_scale_bits = FullScaleBits(1.0f);
    int shift = inputs;  // each input count starts the shifts elsewhere
    for (std::size_t i = 0; i < inputs; ++i) {
      d.input_kind[i] = InputKind::kForce;
      d.input_full_scale_bits[i] = FullScaleBits(1.0f);
      Path& p = d.paths[i];
      p.output_shift = static_cast<std::uint8_t>(i == 0 ? 30 : 15 * i - 15);
      p.output_gain = i == 0 ? 3 : 1500000000 - static_cast<std::int32_t>(i) * 800000000;
      p.section_count = static_cast<std::uint8_t>(i == 1 ? 0 : kMaxSections);
      for (std::size_t k = 0; k < p.section_count; ++k) {
        const int s = shift++ % 16;
        const double one = std::ldexp(1.0, 31 - s);
        // Poles at radius rho, angle 0.3 rad; |a1| < 1 needs rho = 0.5 at shift 0.
        const double rho = s == 0 ? 0.5 : 0.95;
        const double gain = (k % 3 == 0) ? 1.6 : 0.4;  // some sections gain more than one: rails
        p.sections[k] = Section{
            .b0 = static_cast<std::int32_t>(0.3 * gain * one),
            .b1 = static_cast<std::int32_t>(0.2 * gain * one),
            .b2 = static_cast<std::int32_t>(-0.1 * gain * one),
            .a1 = static_cast<std::int32_t>(-2.0 * rho * std::cos(0.3) * one),
            .a2 = static_cast<std::int32_t>(rho * rho * one),
            .shift = static_cast<std::uint8_t>(s),
            .feedback = (k + i) % 2 == 0 ? ErrorFeedback::kSecondOrder : ErrorFeedback::kNone};
      }
    }
    Seal(d);
    DobFilter filter;
    ASSERT_EQ(filter.Init(d), Status::kOk) << int{inputs} << " inputs";
    IntegerReference ref(d);
    constexpr std::size_t kFrames = 600;
    static std::int32_t in[kFrames * kMaxInputs];
    static std::int32_t out[kFrames];
    std::uint32_t lcg = 12345u;
    for (std::size_t n = 0; n < kFrames * inputs; ++n) {
      lcg = lcg * 1664525u + 1013904223u;
      // Quiet first half, full scale second half.
      in[n] = static_cast<std::int32_t>(lcg) >> (n < kFrames * inputs / 2 ? 6 : 0);
    }
    ASSERT_EQ(filter.StepBlock(std::span<const std::int32_t>(in, 100 * inputs),
                               std::span<std::int32_t>(out, 100)),
              Status::kOk);
    for (std::size_t n = 100; n < kFrames; ++n) {
      InputFrame frame{};
      for (std::size_t i = 0; i < inputs; ++i) frame[i] = in[n * inputs + i];
      out[n] = filter.Step(frame);
    }
    std::size_t mismatches = 0;
    for (std::size_t n = 0; n < kFrames; ++n) mismatches += out[n] != ref.Step(in + n * inputs);
    EXPECT_EQ(mismatches, 0u) << int{inputs} << " inputs";
    EXPECT_EQ(filter.saturation_count(), ref.saturations()) << int{inputs} << " inputs";
    EXPECT_GT(ref.saturations(), 0u);
  }
}

// One path of eight sections whose shifts start at every value in turn, all with and all without
// error feedback: every shift and feedback mode at an even and at an odd position in the path
// (a backend may compile sections by position), the path ending on either. The last runs put
// a1 = -2^31 (a1 = -1.0, the only shift where |a1| < 1 + a2 allows it) in every section of shift
// 0, at both positions. Quiet, then full-scale inputs, against the int64 reference.
TEST(DobFilter, EverySectionKindAtEveryPositionMatchesTheIntegerReference) {
  for (int run = 0; run < 36; ++run) {
    const int first_shift = run % 16;
    const bool feedback = (run / 16) % 2 == 1;
    const bool a1_min = run >= 32;
    FilterDescription d{};
    d.input_count = 1;
    d.sample_rate_hz = 1000;
    d.output_full_scale_bits = FullScaleBits(1.0f);
    d.input_kind[0] = InputKind::kForce;
    d.input_full_scale_bits[0] = FullScaleBits(1.0f);
    Path& p = d.paths[0];
    p.output_shift = 2;
    p.output_gain = 1234567891;
    p.section_count = static_cast<std::uint8_t>(run % 2 == 0 ? kMaxSections : kMaxSections - 1);
    for (std::size_t k = 0; k < p.section_count; ++k) {
      // a1 = -2^31 runs: shift 0 at positions 0 and 1 (first_shift 0 and 15), both feedback modes.
      const int s = a1_min ? ((run % 2 == 0 ? 0 : 15) + static_cast<int>(k)) % 16
                           : (first_shift + static_cast<int>(k)) % 16;
      const bool fb = a1_min ? run % 4 >= 2 : feedback;
      const double one = std::ldexp(1.0, 31 - s);
      const double rho = s == 0 ? 0.5 : 0.9;
      const double gain = (k % 3 == 1 && s != 0) ? 1.5 : 0.5;  // shift 0: the coefficient bound
      Section sec{.b0 = static_cast<std::int32_t>(0.4 * gain * one),
                  .b1 = static_cast<std::int32_t>(0.3 * gain * one),
                  .b2 = static_cast<std::int32_t>(0.2 * gain * one),
                  .a1 = static_cast<std::int32_t>(-2.0 * rho * std::cos(0.5) * one),
                  .a2 = static_cast<std::int32_t>(rho * rho * one),
                  .shift = static_cast<std::uint8_t>(s),
                  .feedback = fb ? ErrorFeedback::kSecondOrder : ErrorFeedback::kNone};
      if (a1_min && s == 0) {
        // z^2 - z + 0.6: poles of radius 0.77; |b| sum kept within the coefficient bound.
        sec.a1 = std::numeric_limits<std::int32_t>::min();
        sec.a2 = static_cast<std::int32_t>(0.6 * one);
        sec.b0 = static_cast<std::int32_t>(0.15 * one);
        sec.b1 = static_cast<std::int32_t>(0.1 * one);
        sec.b2 = static_cast<std::int32_t>(-0.05 * one);
      }
      p.sections[k] = sec;
    }
    Seal(d);
    DobFilter filter;
    ASSERT_EQ(filter.Init(d), Status::kOk) << "run " << run;
    IntegerReference ref(d);
    constexpr std::size_t kFrames = 400;
    static std::int32_t in[kFrames];
    static std::int32_t out[kFrames];
    std::uint32_t lcg = 777u + static_cast<std::uint32_t>(run);
    for (std::size_t n = 0; n < kFrames; ++n) {
      lcg = lcg * 1664525u + 1013904223u;
      // Quiet noise, then a full-scale square wave (period 50) with noise: the sections' DC gains
      // of 1.2 to 5.9 rail them.
      const std::int32_t noise = static_cast<std::int32_t>(lcg) >> 8;
      in[n] = n < kFrames / 2 ? noise : ((n / 25) % 2 == 0 ? 2000000000 : -2000000000) + noise;
    }
    ASSERT_EQ(filter.StepBlock(std::span<const std::int32_t>(in, kFrames),
                               std::span<std::int32_t>(out, kFrames)),
              Status::kOk);
    std::size_t mismatches = 0;
    for (std::size_t n = 0; n < kFrames; ++n) mismatches += out[n] != ref.Step(in + n);
    EXPECT_EQ(mismatches, 0u) << "run " << run;
    EXPECT_EQ(filter.saturation_count(), ref.saturations()) << "run " << run;
    EXPECT_GT(ref.saturations(), 0u) << "run " << run;
  }
}

TEST(DobFilter, ResetRestartsFromRest) {
  DobFilter filter;
  ASSERT_EQ(filter.Init(VectorDescription()), Status::kOk);
  std::int32_t first[64];
  std::int32_t again[64];
  ASSERT_EQ(filter.StepBlock(Frames(100, 64), first), Status::kOk);
  filter.Reset();
  EXPECT_EQ(filter.saturation_count(), 0u);
  ASSERT_EQ(filter.StepBlock(Frames(100, 64), again), Status::kOk);
  for (int n = 0; n < 64; ++n) EXPECT_EQ(first[n], again[n]);
}

TEST(DobFilter, RefusesBadDescriptionsAndBlocks) {
  FilterDescription d = VectorDescription();
  d.paths[0].sections[1].a2 = 1 << 30;  // |a2| = 1 at shift 1: poles on the unit circle
  Seal(d);
  DobFilter filter;
  EXPECT_EQ(filter.Init(d), Status::kUnstable);
  EXPECT_FALSE(filter.initialised());
  EXPECT_EQ(filter.Step({1000, 1000, 0}), 0);
  std::int32_t out[4];
  EXPECT_EQ(filter.StepBlock(Frames(0, 4), out), Status::kInvalidArgument);
  ASSERT_EQ(filter.Init(VectorDescription()), Status::kOk);
  EXPECT_EQ(filter.StepBlock(Frames(0, 3), out), Status::kInvalidArgument);  // 3 frames, 4 outputs
  EXPECT_EQ(filter.StepBlock(Frames(0, 4), out), Status::kOk);
}

}  // namespace
}  // namespace vibid::fixed
