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
//     with (f1, f2) = (2, -1) under error feedback and (0, 0) without (every section runs the same
//     seven products), start = 2^(q-1) + a1 + a2 - (feedback ? 2^(q-1) : 0);
//   - y = acc' >> q, read from the two 32-bit halves (lo >> q | hi << (32 - q), q in [16, 31]); it
//     fits an int32 exactly when hi lies in [-2^(q-1), 2^(q-1)), which is the saturation test;
//     r' = lo & (2^q - 1), the low q bits (exact: 0 <= r' < 2^q).
//   Per path and section one record holds the state {x[n-1], x[n-2], ~y[n-1], ~y[n-2], r'[n-1],
//   r'[n-2]} and then {b0, start, b1, b2, a1, a2, f1, f2, q, 32 - q, 2^q - 1, 2^(q-1)}, in the
//   order the kernel reads them (on the Cortex-M4: four LDM, seven SMLAL, one STM per section).
//   At rest x = y = r = 0, i.e. ~y = -1 and r' = 2^(q-1); a saturated section stores the
//   railed y and r = 0 (r' = 2^(q-1)), so the feedback does not push a railed section further.
//
// Scaling and overflow:
//   Inputs are Q31 fractions of each input's full scale; d_hat is a Q31 fraction of the output full
//   scale. Coefficients are Q(31 - shift). Every product is of two int32 values (|p| <= 2^62) and
//   ValidateDescription requires sum(|b0|,|b1|,|b2|,|a1|,|a2|) <= 2^32 - 4 on the raw integers, so
//   the products of the coefficients with x and ~y (and with them the constant a1 + a2, which
//   a ~y + a = -a y absorbs) stay below 2^31 (2^32 - 4) = 2^63 - 2^33 in magnitude at every partial
//   sum; the feedback products add less than 2^32 (2 r1' < 2^32, -r2' > -2^31) and the start value
//   at most 2^30 more, so every partial sum of the 64-bit accumulator is exact and never wraps.
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
  // One section's state and run-time coefficients (derived from the description by Init, see
  // "Kernel layout" above), in the order the kernel reads them: 19 words, loaded by four LDM and
  // stored back by one STM on the Cortex-M4.
  struct SectionRecord {
    std::int32_t x1, x2, ny1, ny2, r1, r2;  ///< x[n-1], x[n-2], ~y[n-1], ~y[n-2], r'[n-1], r'[n-2].
    std::int32_t b0;
    std::uint32_t start_lo;  ///< Accumulator start value, low and high words.
    std::int32_t start_hi;
    std::int32_t b1, b2, a1, a2;
    std::int32_t f1, f2;     ///< Error-feedback weights: (2, -1) with feedback, (0, 0) without.
    std::int32_t q;          ///< 31 - shift: the right shift from the accumulator to y, 16..31.
    std::int32_t left;       ///< 32 - q.
    std::uint32_t mask;      ///< 2^q - 1: r' is the accumulator's low q bits.
    std::int32_t half;       ///< 2^(q-1): r' at rest and after a saturation.
  };
  struct KernelPath {
    std::int32_t sections;   ///< Section count.
    std::uint32_t count;     ///< (sections - 1) << 16: StepPath's loop count.
    std::int32_t gain;       ///< output_gain.
    std::int32_t p;          ///< 31 - output_shift, 1..31.
    std::int32_t left;       ///< 32 - p.
    std::int64_t half;       ///< 2^(p-1).
  };

  /// Runs the sections rec[0 .. (count >> 16)] on x; count's low half must be 0. Returns y in the
  /// low word and, in the high word, count with the saturations added to its low half.
  static std::uint64_t StepPath(std::int32_t x, SectionRecord* rec, std::uint32_t count);
  /// Step on `inputs[0 .. input_count)`; shared by Step and StepBlock (inlined into both).
  std::int32_t StepFrame(const std::int32_t* inputs);

  FilterDescription description_{.input_count = 0};
  std::array<KernelPath, kMaxInputs> paths_{};
  std::array<std::array<SectionRecord, kMaxSections>, kMaxInputs> records_{};
  std::uint32_t saturation_count_ = 0;
};

}  // namespace vibid::fixed
