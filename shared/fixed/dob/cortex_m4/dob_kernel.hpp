// The DOB kernel's Cortex-M4 backend (ARMv7E-M, Thumb-2): Load compiles the description into a
// word stream that one assembly routine runs as threaded code. It computes the arithmetic
// dob_filter.hpp states, bit for bit with the portable backend.
//
// Program: one copy of the section code per (q, feedback) pair, 32 in all, so the shifts, masks
// and rounding constants are immediates and there is no loop counter and no branch but the frame
// loop's; per section the stream holds {b2, start (2 words), a2, code address} (loaded, with the
// jump, by the previous block's last LDM) and {b0, b1, a1} plus the feedback weight word (1 for
// q <= 30, -1 for q = 31); the state stream holds {x[n-1], x[n-2], ~y[n-1], ~y[n-2], r'[n-1],
// r'[n-2]} per section (~y and r' as in the portable backend: -a y = a ~y + a, r' = r + 2^(q-1)):
// one LDM, seven SMLAL (six when 2 r1' - r2' fits one int32, i.e. q <= 30, five without
// feedback), the rounding and saturation test on immediates, one IT block, one STM; after a
// path's sections, an output stage {gain, 2^(p-1), 0, p, code address, 2^(32 - p)} forms the
// term, adds it to the frame's sum and loads the next path's input; the last one saturates d_hat,
// stores it and starts the next frame. For the default design (2 inputs, 4 + 3 feedback sections)
// that is 184 instructions per sample.
//
// Scaling and overflow (beyond dob_filter.hpp's): the partial sums are the portable backend's
// (start + a ~y products), exact; the feedback is added as one int32 2 r1' - r2' when q <= 30
// (0 <= r' < 2^30, so the value lies in (-2^30, 2^31)) and as -r2' and 2 r1' (< 2^32, unsigned)
// when q = 31: the same exact sum. The output term takes lo >> p + hi * 2^(32 - p) for the low
// word (the two do not overlap, so the 32-bit sum is the OR) and hi >> p (arithmetic) for the high.
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
  // Largest program: every path with kMaxSections feedback sections (5 + 4 words each) and its
  // output stage (5 + 1 words).
  static constexpr std::size_t kProgramWords = kMaxInputs * (kMaxSections * 9 + 6);
  static constexpr std::size_t kStateWords = kMaxInputs * kMaxSections * 6;

  std::array<std::uint32_t, kProgramWords> program_{};
  std::array<std::int32_t, kStateWords> state_{};
  std::uintptr_t frame_start_ = 0;  ///< Code address of the frame loop for input_count inputs.
};

}  // namespace vibid::fixed
