// The fixed-point disturbance-observer kernel: the filter the board steps once per sample and the
// host replays bit for bit. Integer-only; no heap, no exceptions.
//
// Structure (per path i < input_count, per section k < section_count, Direct Form I):
//
//   acc = b0 x[n] + b1 x[n-1] + b2 x[n-2] - a1 y[n-1] - a2 y[n-2]          (int64, exact)
//   acc += 2 r[n-1] - r[n-2]                  only with ErrorFeedback::kSecondOrder
//   y[n] = sat32((acc + 2^(q-1)) >> q),   q = 31 - shift                     (round half up)
//   r[n] = acc - (y[n] << q)                  the rounding remainder, |r| <= 2^(q-1)
//   x of section k+1 = y of section k;  x of section 0 = input i
//   term_i = (y_last * output_gain + 2^(p-1)) >> p,   p = 31 - output_shift   (int64)
//   d_hat = sat32(sum_i term_i)
//
// Kernel layout (what Init derives from the description; the arithmetic above, rearranged so the
// per-section work is one run of multiply-accumulates with no branch and one rounding/saturation):
//   - the state holds ~y = -y - 1 instead of y: -a y = a ~y + a, so the description's a1, a2 are
//     used as they are (negating them could overflow int32 for a1 = -2^31) and the constant
//     a1 + a2 joins the accumulator's start value;
//   - the state holds r' = r + 2^(q-1), the low q bits of the accumulator (rounding constant
//     included): 2 r1 - r2 = 2 r1' - r2' - 2^(q-1), the constant again joining the start value;
//   - so acc' = start + b0 x + b1 x1 + b2 x2 + a1 ~y1 + a2 ~y2 + f1 r1' + f2 r2' = acc + 2^(q-1)
//     with (f1, f2) = (2, -1) under error feedback and (0, 0) without (the host runs the same
//     seven products for every section), start = 2^(q-1) + a1 + a2 - (feedback ? 2^(q-1) : 0);
//   - y = acc' >> q, read from the two 32-bit halves (lo >> q | hi << (32 - q), q in [16, 31]); it
//     fits an int32 exactly when hi lies in [-2^(q-1), 2^(q-1)), which is the saturation test;
//     r' = lo & (2^q - 1), the low q bits (exact: 0 <= r' < 2^q).
//   On the host, per path and section one record holds the state {x[n-1], x[n-2], ~y[n-1],
//   ~y[n-2], r'[n-1], r'[n-2]} and the run-time coefficients, walked by a plain loop.
//   At rest x = y = r = 0, i.e. ~y = -1 and r' = 2^(q-1); a saturated section stores the
//   railed y and r = 0 (r' = 2^(q-1)), so the feedback does not push a railed section further.
//
// Cortex-M4 program (dob_filter.cpp): Init compiles the description into a word stream that one
// assembly routine runs as threaded code, so the shifts, masks and rounding constants are
// immediates and there is no loop counter and no branch but the frame loop's:
//   - one copy of the section code per (q, feedback) pair, 32 in all; per section the stream holds
//     {b2, start (2 words), a2, code address} (loaded, with the jump, by the previous block's last
//     LDM) and {b0, b1, a1} plus the feedback weight word (1 for q <= 30, -1 for q = 31);
//   - the state stream holds {x[n-1], x[n-2], ~y[n-1], ~y[n-2], r'[n-1], r'[n-2]} per section:
//     one LDM, seven SMLAL (six when 2 r1' - r2' fits one int32, i.e. q <= 30, five without
//     feedback), the rounding and saturation test on immediates, one IT block, one STM;
//   - after a path's sections, an output stage {gain, 2^(p-1), 0, p, code address, 2^(32 - p)}
//     forms the term, adds it to the frame's sum and loads the next path's input; the last one
//     saturates d_hat, stores it and starts the next frame.
//   For the default design (2 inputs, 4 + 3 feedback sections) that is 184 instructions per sample.
//
// Scaling and overflow:
//   Inputs are Q31 fractions of each input's full scale; d_hat is a Q31 fraction of the output full
//   scale. Coefficients are Q(31 - shift). Every product is of two int32 values (|p| <= 2^62) and
//   ValidateDescription requires sum(|b0|,|b1|,|b2|,|a1|,|a2|) <= 2^32 - 4 on the raw integers, so
//   the products of the coefficients with x and ~y (and with them the constant a1 + a2, which
//   a ~y + a = -a y absorbs) stay below 2^31 (2^32 - 4) = 2^63 - 2^33 in magnitude at every partial
//   sum; the feedback products add less than 2^32 (2 r1' < 2^32, -r2' > -2^31) and the start value
//   at most 2^30 more, so every partial sum of the 64-bit accumulator is exact and never wraps.
//   The Cortex-M4 program adds the feedback as one int32 2 r1' - r2' when q <= 30 (0 <= r' < 2^30,
//   so the value lies in (-2^30, 2^31)) and as -r2' and 2 r1' (< 2^32, unsigned) when q = 31: the
//   same exact sum. Its output term takes lo >> p + hi * 2^(32 - p) for the low word (the two do
//   not overlap, so the 32-bit sum is the OR the host forms) and hi >> p (arithmetic) for the high.
//   Section outputs and d_hat are saturated to int32 (each saturation is counted), never wrapped.
//   Output terms are at most 2^61 each (output_shift <= 30), so the sum of three cannot overflow
//   before the final saturation; the paths are summed before saturating because the sensor and
//   force paths cancel to a small d_hat by design.
//   The host's design scales each section's numerator from the l1 norm of the impulse response from
//   the path input to that section's output, so no section saturates for any input within full
//   scale; a saturation therefore means the input left the designed range.
//   Rounding error: each section adds at most 1/2 LSB at its output, shaped by its own poles (or,
//   with error feedback, by (1 - z^-1)^2 over its poles) and by the following sections; the host
//   reports the predicted noise floor and enables the feedback where it lowers it.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "vibid/shared/fixed/filter_description.hpp"
#include "vibid/shared/status.hpp"

#if defined(__ARM_ARCH_7EM__) && defined(__thumb2__)
#define VIBID_DOB_THREADED_KERNEL 1
#else
#define VIBID_DOB_THREADED_KERNEL 0
#endif

namespace vibid::fixed {

/// One frame of kernel inputs (Q31), indexed like the description's inputs; entries at index
/// >= input_count are ignored.
using InputFrame = std::array<std::int32_t, kMaxInputs>;

class DobFilter {
 public:
  /// An uninitialised filter outputs 0 (no paths).
  DobFilter() = default;

  /// Validates the description (ValidateDescription), copies it and clears the state.
  /// @returns the validation status; on failure the filter is left uninitialised (outputs 0).
  Status Init(const FilterDescription& description);

  /// Clears every delay element and the saturation counter; coefficients stay.
  void Reset();

  /// Advances one sample and returns d_hat (Q31).
  std::int32_t Step(const InputFrame& inputs);

  /// Runs a block. `interleaved` holds frames of input_count samples (u0, u1, .., u0, u1, ..);
  /// output[n] receives d_hat of frame n. State carries over between calls.
  /// @returns kOk; kInvalidArgument if interleaved.size() != output.size() * input_count
  ///          (nothing is processed) or the filter is uninitialised.
  Status StepBlock(std::span<const std::int32_t> interleaved, std::span<std::int32_t> output);

  /// Number of saturations (section outputs and d_hat) since Init/Reset; 0 in a correct design.
  std::uint32_t saturation_count() const { return saturation_count_; }

  bool initialised() const { return description_.input_count != 0; }
  const FilterDescription& description() const { return description_; }

 private:
#if VIBID_DOB_THREADED_KERNEL
  // The Cortex-M4 kernel (see "Cortex-M4 program" above). Largest program: every path with
  // kMaxSections feedback sections (5 + 4 words each) and its output stage (5 + 1 words).
  static constexpr std::size_t kProgramWords = kMaxInputs * (kMaxSections * 9 + 6);
  static constexpr std::size_t kStateWords = kMaxInputs * kMaxSections * 6;
  /// Runs the program over `frames` frames of `inputs` into `output`; returns the saturations.
  std::uint32_t Run(const std::int32_t* inputs, std::int32_t* output, std::size_t frames);

  std::array<std::uint32_t, kProgramWords> program_{};
  std::array<std::int32_t, kStateWords> state_{};
  std::uintptr_t frame_start_ = 0;  ///< Code address of the frame loop for input_count inputs.
#else
  // One section's state and run-time coefficients (derived from the description by Init, see
  // "Kernel layout" above).
  struct SectionRecord {
    std::int32_t x1, x2, ny1, ny2, r1, r2;  ///< x[n-1], x[n-2], ~y[n-1], ~y[n-2], r'[n-1], r'[n-2].
    std::int32_t b0;
    std::uint32_t start_lo;  ///< Accumulator start value, low and high words.
    std::int32_t start_hi;
    std::int32_t b1, b2, a1, a2;
    std::int32_t f1, f2;  ///< Error-feedback weights: (2, -1) with feedback, (0, 0) without.
    std::int32_t q;       ///< 31 - shift: the right shift from the accumulator to y, 16..31.
    std::int32_t left;    ///< 32 - q.
    std::uint32_t mask;   ///< 2^q - 1: r' is the accumulator's low q bits.
    std::int32_t half;    ///< 2^(q-1): r' at rest and after a saturation.
  };
  struct KernelPath {
    std::int32_t sections;  ///< Section count.
    std::uint32_t count;    ///< (sections - 1) << 16: StepPath's loop count.
    std::int32_t gain;      ///< output_gain.
    std::int32_t p;         ///< 31 - output_shift, 1..31.
    std::int32_t left;      ///< 32 - p.
    std::int64_t half;      ///< 2^(p-1).
  };

  /// Runs the sections rec[0 .. (count >> 16)] on x; count's low half must be 0. Returns y in the
  /// low word and, in the high word, count with the saturations added to its low half.
  static std::uint64_t StepPath(std::int32_t x, SectionRecord* rec, std::uint32_t count);
  /// Step on `inputs[0 .. input_count)`; shared by Step and StepBlock (inlined into both).
  std::int32_t StepFrame(const std::int32_t* inputs);

  std::array<KernelPath, kMaxInputs> paths_{};
  std::array<std::array<SectionRecord, kMaxSections>, kMaxInputs> records_{};
#endif

  FilterDescription description_{.input_count = 0};
  std::uint32_t saturation_count_ = 0;
};

}  // namespace vibid::fixed
