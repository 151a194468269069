// The DOB kernel's Cortex-M4 backend (ARMv7E-M, Thumb-2): Load compiles the description into a
// word stream that one assembly routine runs as threaded code. It computes the arithmetic
// dob_filter.hpp states, bit for bit with the portable backend.
//
// Layout (what Load derives from the description):
//   - the state holds y, and the a coefficients are negated once by Load: -a y = (-a) y, one SMLAL
//     each. -a fits an int32 except for a1 = -2^31, which ValidateDescription's stability bound
//     (|a1| < 2^q + a2, |a2| < 2^q) allows only at q = 31: there the word's bits, -2^31, stand
//     for +2^31, and that section's code adds the difference, y1 2^32, to the high word;
//   - the state holds r' = r + 2^(q-1), the low q bits of the accumulator (rounding constant
//     included): 2 r1 - r2 = 2 r1' - r2' - 2^(q-1), so the start value is 2^(q-1) without error
//     feedback and 0 with it, and the feedback is UMLAL 2 r1' (unsigned: r1' < 2^31) and SMLAL
//     -r2';
//   - y = acc' >> q from the two 32-bit halves (lo >> q | hi << (32 - q)); it fits an int32 exactly
//     when hi equals y >> (32 - q) (arithmetic: the sign extension of hi's low q bits), one CMP;
//     r' = lo's low q bits (UBFX); a saturated section stores the railed y and r' = 2^(q-1).
// Program: one copy of the section code per (position parity, q, feedback), 64, and four for the
// q = 31 sections with a1 = -2^31, so the shifts and the mask are immediates. A section at an even
// position takes x in r0 and keeps {x1, x2, y1, y2, r1', r2'}, one at an odd position takes x in
// r7 and keeps {y1, y2, x1, x2, r1', r2'}: each leaves y where the next one takes x and stores its
// state with one STM, so nothing is moved between registers. Per section the stream holds
// {b2, start (2 words), a stage's slot, -a2, code address}, loaded with the jump by the previous
// block's last LDM, then {b0, b1, -a1} and, with feedback, the weights {2, -1}. Per section: one
// LDM of the state, two of the stream (the second is the next block's jump), five SMLAL, with
// feedback one UMLAL and one SMLAL more, LSL and ORR for y, UBFX for r', one STM, CMP and a branch
// not taken: 16 instructions with feedback, 14 without (one more for a1 = -2^31). A saturation
// branches to the section's own stub, which rails y, rewrites the stored y1 and r1', counts it and
// loads the next block. After a path's sections an output stage {gain, 2^(p-1), 0, 2^(32 - p), p,
// code address} forms the term, adds it to the frame's sum and loads the next path's input; the
// last one saturates d_hat, stores it and starts the next frame. For the default design (2 inputs,
// 4 + 3 feedback sections) that is 135 instructions per sample (184 with the previous program, one
// copy per (q, feedback) that kept ~y and saturated in an IT block: 22 per section).
//
// Scaling and overflow (beyond dob_filter.hpp's): the products are the contract's with the signs
// moved into the coefficients (|-a| = |a|), so the partial sums keep its bound; for a1 = -2^31 the
// SMLAL adds -2^31 y1 and the correction 2^32 y1, the feedback adds 2 r1' (< 2^32, as an unsigned
// product) and -r2': every step is a 64-bit addition, exact modulo 2^64, and the final accumulator
// is the contract's, within int64, so the result is exact whatever an intermediate sum. The output
// term's low word is lo >> p + hi 2^(32 - p) (the two do not overlap, so the sum is the OR) and
// its high word hi >> p (arithmetic).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "vibid/shared/fixed/filter_description.hpp"

namespace vibid::fixed {

class DobKernel {
 public:
  /// Compiles a description that passed ValidateDescription into the program; state at rest.
  void Load(const FilterDescription& description);
  /// State at rest for the loaded description (none for input_count 0).
  void Reset(const FilterDescription& description);
  /// Runs `frames` (>= 1) frames of input_count interleaved inputs; returns the saturations.
  std::uint32_t Run(const std::int32_t* inputs, std::int32_t* output, std::size_t frames);

 private:
  // Largest program: every path with kMaxSections feedback sections (6 + 5 words each) and its
  // output stage (6 words).
  static constexpr std::size_t kProgramWords = kMaxInputs * (kMaxSections * 11 + 6);
  static constexpr std::size_t kStateWords = kMaxInputs * kMaxSections * 6;

  std::array<std::uint32_t, kProgramWords> program_{};
  std::array<std::int32_t, kStateWords> state_{};
  std::uintptr_t frame_start_ = 0;  ///< Code address of the frame loop for input_count inputs.
};

}  // namespace vibid::fixed
