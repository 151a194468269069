// The DOB kernel's portable backend: plain C++ for the host (the replay, the design's checks) and
// any target without a program of its own. It computes the arithmetic dob_filter.hpp states.
//
// Layout (what Load derives from the description; the arithmetic rearranged so the per-section
// work is one run of multiply-accumulates with no branch and one rounding/saturation):
//   - the state holds ~y = -y - 1 instead of y: -a y = a ~y + a, so the description's a1, a2 are
//     used as they are (negating them could overflow int32 for a1 = -2^31) and the constant
//     a1 + a2 joins the accumulator's start value;
//   - the state holds r' = r + 2^(q-1), the low q bits of the accumulator (rounding constant
//     included): 2 r1 - r2 = 2 r1' - r2' - 2^(q-1), the constant again joining the start value;
//   - so acc' = start + b0 x + b1 x1 + b2 x2 + a1 ~y1 + a2 ~y2 + f1 r1' + f2 r2' = acc + 2^(q-1)
//     with (f1, f2) = (2, -1) under error feedback and (0, 0) without (the same seven products for
//     every section), start = 2^(q-1) + a1 + a2 - (feedback ? 2^(q-1) : 0);
//   - y = acc' >> q, read from the two 32-bit halves (lo >> q | hi << (32 - q), q in [16, 31]); it
//     fits an int32 exactly when hi lies in [-2^(q-1), 2^(q-1)), which is the saturation test;
//     r' = lo & (2^q - 1), the low q bits (exact: 0 <= r' < 2^q).
//   Per path and section one record holds the state {x[n-1], x[n-2], ~y[n-1], ~y[n-2], r'[n-1],
//   r'[n-2]} and the run-time coefficients, walked by a plain loop. At rest x = y = r = 0, i.e.
//   ~y = -1 and r' = 2^(q-1); a saturated section stores the railed y and r = 0 (r' = 2^(q-1)),
//   so the feedback does not push a railed section further.
//
// Scaling and overflow (beyond dob_filter.hpp's): the products with ~y and the constant a1 + a2
// together equal -a1 y1 - a2 y2, and each partial sum of a ~y products and a's stays within the
// contract's 2^31 (2^32 - 4) bound; the feedback products add less than 2^32 (2 r1' < 2^32,
// -r2' > -2^31) and the start value at most 2^30 more, so every partial sum is exact. The output
// term's low word is lo >> p | hi << (32 - p) and its high word hi >> p (arithmetic).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "vibid/shared/fixed/filter_description.hpp"

namespace vibid::fixed {

class DobKernel {
 public:
  /// Derives the records from a description that passed ValidateDescription; state at rest.
  void Load(const FilterDescription& description);
  /// State at rest; the records' coefficients stay.
  void Reset(const FilterDescription& description);
  /// Runs `frames` (>= 1) frames of input_count interleaved inputs; returns the saturations.
  std::uint32_t Run(const std::int32_t* inputs, std::int32_t* output, std::size_t frames);

 private:
  // One section's state and run-time coefficients (see "Layout" above).
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
  /// One frame of `inputs[0 .. input_count)`: d_hat, the saturations added to `saturations`.
  std::int32_t StepFrame(const std::int32_t* inputs, std::uint32_t& saturations);

  std::size_t input_count_ = 0;
  std::array<KernelPath, kMaxInputs> paths_{};
  std::array<std::array<SectionRecord, kMaxSections>, kMaxInputs> records_{};
};

}  // namespace vibid::fixed
