// The anti-aliasing decimator: the board's channels and d_hat, sampled at up to 10 kHz, reduced to
// a lower, independent log rate without aliasing. Integer-only, no heap, no exceptions; the
// board runs it in the sampling interrupt and the host replays it bit for bit.
//
// Structure: for a factor D = 2^a 5^b the signal passes a cascade of decimate-by-2 and
// decimate-by-5 stages, each a linear-phase FIR of odd length L with Q30 taps h (designed, verified
// and quantized by scripts/golden/decimator_design.py into
// shared/fixed/decimator_coefficients.inc). Stage s keeps every r_s-th output of its convolution
// (compute-on-output: the other phases only store the input), for input index n = j r_s:
//
//   acc  = 2^29 + h[c] x[n-c] + sum_i h[c-d_i] (x[n-c+d_i] + x[n-c-d_i])   int64, exact; c =
//   (L-1)/2 y[j] = sat32(acc >> 30)                                                  round half up
//
// d_i = 1 + i * stride (stride 2 for the half-band /2 designs, whose even distances are exactly
// zero; 1 otherwise). The symmetric pair is applied as two multiply-accumulates with one stored
// tap rather than one multiply of a pre-added pair: x + x' overflows int32 for full-range Q31
// input, and a 64 x 32-bit product costs more on the Cortex-M4 than the second SMLAL; the symmetry
// still halves the coefficient loads and the table.
//
// The stages of each factor come from a table the design script writes: coarse stages first (each
// the shortest design valid for the decimation still to come after it), the sharp one last at the
// lowest rate, in the order with the fewest multiplies per input sample.
//
// State layout: per channel ch, kDecimatorStateWordsPerChannel int32 words; stage s owns 2 L_s of
// them from offset o_s (stages in plan order, packed). Each input is written twice, at w and w + L,
// so the last L inputs are always contiguous at [w + 1, w + L] (no modulo in the inner loop).
//
// Scaling and overflow:
//   Every stage keeps its input's scale (the integer taps sum to exactly 2^30): ADC channels
//   in 12.4 (0..65520), encoder counts, d_hat in Q31 come out in the same units. Products are of
//   two int32 values (|p| <= 2^61 since |h| < 2^30) and the script asserts sum|h| <= 2^32 - 1 for
//   every design, so |acc| <= (2^32 - 1) 2^31 + 2^29 < 2^63: the 64-bit accumulator holds the exact
//   sum and never wraps. Each stage output is rounded once (half up) and saturated to int32; every
//   clipped stage output is counted. The worst-case gain from the input to any stage output (the l1
//   norm of the cascade's impulse response up to that stage) is at most 1.82 (the script computes
//   and asserts it), so only Q31 input beyond 55 % of full scale can clip, and a full-scale step
//   does, briefly (step-response overshoot up to 8.7 %); 12.4 ADC values and encoder counts below
//   2^30 never do. DC: a constant input passes every stage exactly (sum h = 2^30, no rounding
//   error), so after the delay the output equals the input; likewise a ramp comes out as the ramp
//   delayed by DecimatorDelayTicks, exactly. Rounding error: at most 1/2 LSB per stage output
//   (uniform, 0.29 LSB rms), filtered by the following stages (gain <= 1 + ripple in their
//   passband).
//
// Cost (benchmarks/decimator/m4_instructions.py: 7 channels, Cortex-M4 under QEMU, cycles estimated
// from the TRM timings): on average 375 (D = 625) .. 960 (D = 5) cycles per input frame, 2.2 ..
// 5.7 % of a 168 MHz core at 10 kHz; the output tick, where every stage computes, up to 1.6k
// (D = 2), 4.1k (D = 5, 50), 5.4k (D = 1000) and 6.7k (D = 625) cycles; the other ticks about
// 120 instructions (storing the frame). Spreading the last stage's sum over its r arrivals was
// measured (D = 5: output tick 4.1k -> 1.4k cycles, but 30 % more on average from the per-arrival
// set-up; hardly any gain for the /2 final stages) and left out for plain compute-on-output.
// sizeof(Decimator) is about 7.8 KB: give it static storage.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "vibid/shared/status.hpp"

namespace vibid::fixed {

inline constexpr std::size_t kDecimatorMaxChannels = 7;  // six channels + d_hat
inline constexpr std::uint32_t kDecimatorMaxFactor = 1000;
/// Stages of the longest cascade: 512 = 2^9 needs nine /2 stages.
inline constexpr std::size_t kDecimatorMaxStages = 9;
/// State words per channel for the worst factor (625: 11 + 11 + 21 + 95 taps, twice each);
/// decimator.cpp checks it against the generated tables.
inline constexpr std::size_t kDecimatorStateWordsPerChannel = 276;

/// True for factor = 2^a * 5^b with 1 <= factor <= kDecimatorMaxFactor.
constexpr bool IsSupportedDecimation(std::uint32_t factor) {
  if (factor == 0 || factor > kDecimatorMaxFactor) return false;
  while (factor % 2 == 0) factor /= 2;
  while (factor % 5 == 0) factor /= 5;
  return factor == 1;
}

/// Group delay of the whole chain for a supported factor, in input samples (an integer: every
/// stage is a linear-phase FIR of odd length). 0 for factor 1 and for unsupported factors.
std::uint32_t DecimatorDelayTicks(std::uint32_t factor);

class Decimator {
 public:
  /// An uninitialised decimator takes no input: Push returns false and writes nothing.
  Decimator() = default;

  /// Selects the stage plan for `factor`, clears the state (phase 0).
  /// @returns kOk; kInvalidArgument for an unsupported factor or channel_count 0 or > max (the
  ///          decimator is then left uninitialised).
  Status Init(std::uint32_t factor, std::size_t channel_count);

  /// Zero state, phase 0 (the next Push is input index 0); clears the saturation counter.
  void Reset();

  /// One input frame (channel_count values). Returns true and writes channel_count outputs on
  /// input indices 0, D, 2D, ... (so the first call after Reset/Init outputs; factor 1 is a
  /// plain copy). Output m is the filtered signal at input index m*D (delayed by
  /// DecimatorDelayTicks).
  bool Push(const std::int32_t* in, std::int32_t* out);

  /// Runs `interleaved` (whole frames of channel_count values) through Push and appends the output
  /// frames to `out`; `out_frames` receives their number. State carries over between calls.
  /// @returns kOk; kInvalidArgument if uninitialised, if interleaved.size() is not a multiple of
  ///          channel_count, or if `out` cannot hold OutputFrames(frames) frames (nothing is
  ///          processed then).
  Status PushBlock(std::span<const std::int32_t> interleaved, std::span<std::int32_t> out,
                   std::size_t& out_frames);

  /// How many output frames the next `frames` input frames produce from the current phase (at
  /// most ceil(frames / D)); 0 when uninitialised.
  std::size_t OutputFrames(std::size_t frames) const;

  std::uint32_t factor() const { return factor_; }
  std::size_t channel_count() const { return channel_count_; }
  bool initialised() const { return channel_count_ != 0; }
  /// Stage outputs clipped to the int32 range since Init/Reset (all stages, all channels).
  std::uint32_t saturation_count() const { return saturation_count_; }

 private:
  struct Stage {
    std::uint8_t design = 0;   // index into the generated design table
    std::uint16_t offset = 0;  // first state word of this stage within a channel's block
    std::uint16_t write = 0;   // next write position w, 0 <= w < L
    std::uint16_t phase = 0;   // inputs since the last output, 0 <= phase < factor
  };

  std::uint32_t factor_ = 0;
  std::size_t channel_count_ = 0;
  std::size_t stage_count_ = 0;
  std::uint32_t tick_ = 0;  // input index modulo factor_ (0: the next Push outputs)
  std::uint32_t saturation_count_ = 0;
  std::array<Stage, kDecimatorMaxStages> stages_{};
  std::array<std::array<std::int32_t, kDecimatorStateWordsPerChannel>, kDecimatorMaxChannels>
      state_{};
};

}  // namespace vibid::fixed
