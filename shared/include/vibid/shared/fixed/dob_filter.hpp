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
// Backends: the arithmetic above is the contract; how it is run is the backend's. Each backend is
// one folder of shared/fixed/dob/ holding dob_kernel.hpp (the class DobKernel that DobFilter
// holds) and dob_kernel.cpp; the build picks one (CMake's VIBID_DOB_BACKEND: cortex_m4 when the
// target is a Cortex-M4, portable elsewhere), so no source carries both. A backend's DobKernel
// has
//   void Load(const FilterDescription& d);   // d passed ValidateDescription; state at rest
//   void Reset(const FilterDescription& d);  // the loaded d (or input_count 0): state at rest
//   std::uint32_t Run(const std::int32_t* inputs, std::int32_t* output, std::size_t frames);
//     // frames >= 1 frames of input_count interleaved inputs into output[0 .. frames), state
//     // carried over; returns the saturations counted in them
// and computes, bit for bit, what this comment states: same d_hat, same saturation count, from
// the same inputs, whatever the split into blocks. Every backend runs the same test suite
// (shared/fixed/dob_filter_test.cpp, against the golden vectors and an int64 evaluation of the
// arithmetic above): portable on the host and under QEMU, cortex_m4 under QEMU.
//   portable:  plain C++ (the host, the replay, any target without a program of its own).
//   cortex_m4: Load compiles the description into a word stream one assembly routine runs as
//              threaded code (per-section code copies with the shifts as immediates).
// Each backend's header describes how it rearranges the sums, with its own overflow notes.
//
// Scaling and overflow:
//   Inputs are Q31 fractions of each input's full scale; d_hat is a Q31 fraction of the output full
//   scale. Coefficients are Q(31 - shift). Every product is of two int32 values (|p| <= 2^62) and
//   ValidateDescription requires sum(|b0|,|b1|,|b2|,|a1|,|a2|) <= 2^32 - 4 on the raw integers, so
//   the five coefficient products with int32 x and y stay below 2^31 (2^32 - 4) = 2^63 - 2^33 in
//   magnitude at every partial sum; the feedback 2 r[n-1] - r[n-2] adds at most 3 2^(q-1) <= 3 2^30
//   and the rounding constant 2^(q-1) <= 2^30, so the 64-bit accumulator is exact and never wraps.
//   A backend that rearranges the sum (biased states, negated coefficients) shows in its own header
//   that its partial sums stay exact too, or that they agree modulo 2^64 with a final sum in range.
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

#include "dob_kernel.hpp"  // the build's backend (shared/fixed/dob/<backend>/, see above)
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
  DobKernel kernel_;
  FilterDescription description_{.input_count = 0};
  std::uint32_t saturation_count_ = 0;
};

}  // namespace vibid::fixed
