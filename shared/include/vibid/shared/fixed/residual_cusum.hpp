// The observer's residual test, run on the board beside the disturbance observer: it says when the
// model the observer was given has gone stale (a mass added, a spring fatigued, a mount loosened).
// Integer-only; no heap, no exceptions.
//
// Why the residual's power: with the right model the observer's residual
//   r[n] = d_hat[n] - reference force[n]        (or d_hat alone where no external force acts)
// is zero-mean noise whose spread the calibration day measured; a changed mass, spring or damper
// adds a term proportional to the motion (dM x'' + dC x' + dK x, through the observer's Q), which
// raises r's power whatever its sign. So the test watches the mean of r^2 over windows of W
// samples (W long against r's correlation time, so window means are nearly independent and, by
// the central limit theorem, nearly Gaussian), standardizes each with the calibration day's mean
// and spread of that window mean, z = (e - mu0) / sigma0, and runs Page's one-sided CUSUM
//   g = max(0, g + z - k),   alarm when g > h                     (Page, Biometrika 41, 1954)
// The host picks k and h from the false-alarm rate it is asked for (the in-control average run
// length, Siegmund's approximation) and mu0, sigma0 from a calibration-day recording replayed
// through the same integer arithmetic (host/lib/dob: residual_design).
//
// Arithmetic per sample (all integers):
//   r    = (d_hat * residual_gain + reference * reference_gain + 2^31) >> 32   int64, then
//   r    = clamp(r, -2^23, 2^23 - 1)                              (SSAT #24 on the Cortex-M4)
//   S   += r * r                                                   int64 (SMLAL)
// and at the end of each window of window_samples samples (S restarts at 0):
//   e    = clamp(S >> sum_shift - center, +-(2^31 - 1))             int64
//   z    = clamp((e * z_gain + 2^(z_shift-1)) >> z_shift, int32)    Q16: z / 2^16 is the real z
//   g    = clamp(max(0, g + z - k), kMaxStatistic)                  Q16
//   the first window with g > h trips the flag (latched until Reset) and records its end sample.
// Hold-off: the first holdoff_windows windows after Reset complete (z is computed and shown) but
// neither add to g nor trip, and the clamps counted in them are dropped at their end.
// The observer starts from rest while a running rig's inputs do not, so its first windows carry a
// start transient, not a model change; the host sizes the hold-off from the observer's slowest
// pole (host/lib/dob: watch_design). 0: judge from the first window (records written before the
// hold-off existed carry 0 there).
// The shift by 32 is the high word of the 64-bit sum: two multiply-accumulates and a saturate per
// sample, no variable shift (benchmarks/residual/m4_instructions.py counts them).
//
// Scaling and overflow:
//   d_hat and the reference are Q31 fractions of their full scales. residual_gain (Q32, the
//   residual's scale) and reference_gain (Q32: minus the reference's full scale over d_hat's,
//   times residual_gain) are in [-(2^31 - 1), 2^31 - 1], so each product is at most 2^62 - 2^31 in
//   magnitude and their sum with the rounding term 2^31 at most 2^63 - 2^31: exact in int64.
//   The host picks residual_gain so the calibration day's RMS of r sits near 2^15 (a gain of at
//   most 1/2: where d_hat itself is smaller than 2^16 LSB, r is d_hat / 2 and keeps its own
//   resolution but one bit): the clamp at 2^23 leaves 48 dB of headroom for a residual that grows
//   (a clamped sample still counts as a large one, and is counted in clamp_count), and the
//   rounding of r (uniform within 1/2 LSB) moves a window's z by 2 sqrt(W/12) RMS / (RMS^2
//   sqrt(2W)) = 0.41 / RMS in units of z: 1.3e-5 at RMS 2^15, under one LSB of z's Q16 (the
//   double-reference test measures it).
//   r^2 <= 2^46, so the window sum of up to kMaxWindowSamples = 2^16 samples stays below 2^62 and
//   the uint64 accumulator never wraps. sum_shift (<= 62) and center are the host's: S >> sum_shift
//   of an in-control window lies near 2^24 and the difference is clamped to int32 range, so
//   e * z_gain (|z_gain| < 2^31) is below 2^62 and the rounding term (z_shift <= 62) keeps it below
//   2^63. z is clamped to int32 (|z| < 32768 in real units: far beyond any threshold). The
//   statistic g is at most kMaxStatistic = 2^30 and z - k at most 2^32, so g + z - k is exact in
//   int64 before its clamp; g stays finite during a long alarm (it saturates there, counted).
//   The hold-off counts completed windows in the uint32 windows() against a u8: no new overflow.
//   Rounding error: z carries at most 1/2 LSB (2^-17) of its own rounding plus the rounding of
//   the window sum's shift and of the host's center and gain (relative 2^-20 of an in-control z);
//   the CUSUM adds these window by window while g > 0, so after n windows above zero g is within
//   about n/2 LSB of the exact double computation (the test bounds it against a double reference).
#pragma once

#include <cstdint>

#include "vibid/shared/status.hpp"

namespace vibid::fixed {

inline constexpr std::uint32_t kMaxWindowSamples = 1u << 16;
inline constexpr std::uint8_t kMaxSumShift = 62;
inline constexpr std::uint8_t kMaxZShift = 62;
inline constexpr std::int32_t kMaxScaledResidual = (std::int32_t{1} << 23) - 1;
inline constexpr std::int32_t kMinScaledResidual = -(std::int32_t{1} << 23);
inline constexpr std::int32_t kMaxStatistic = std::int32_t{1} << 30;
/// Fraction bits of z, k, h and g.
inline constexpr int kStatisticFractionBits = 16;

/// The test's parameters as the host designs them (they travel in the calibration record).
struct ResidualCusumParams {
  std::uint32_t window_samples = 0;  ///< W: samples per window, 1..kMaxWindowSamples.
  std::int32_t residual_gain = 0;    ///< Q32 gain of d_hat into r, nonzero.
  std::int32_t reference_gain = 0;   ///< Q32 gain of the reference into r; 0 when r = d_hat.
  std::uint8_t sum_shift = 0;        ///< 0..kMaxSumShift.
  std::uint8_t z_shift = 0;          ///< 0..kMaxZShift.
  std::int32_t center = 0;           ///< round(W mu0 / 2^sum_shift), in units of S >> sum_shift.
  std::int32_t z_gain = 0;           ///< > 0: 2^(z_shift + 16 + sum_shift) / (W sigma0), rounded.
  std::int32_t k = 0;                ///< CUSUM reference value, Q16, >= 0.
  std::int32_t h = 0;                ///< CUSUM threshold, Q16, > 0 and < kMaxStatistic.
  /// Windows after Reset that are computed but not judged (the observer's start transient);
  /// 0: none. Any value is valid.
  std::uint8_t holdoff_windows = 0;
};

/// @returns kOk if the kernel may run them; kInvalidArgument for a window of 0 or above
///          kMaxWindowSamples, a residual_gain of 0 or either gain at -2^31, a shift beyond its
///          maximum, a z_gain <= 0, k < 0, or h outside (0, kMaxStatistic).
Status ValidateResidualCusum(const ResidualCusumParams& params);

class ResidualCusum {
 public:
  /// An uninitialised test does nothing (Step returns false, never trips).
  ResidualCusum() = default;

  /// Validates and copies the parameters, then Reset. On failure the test is left uninitialised.
  Status Init(const ResidualCusumParams& params);

  /// Starts from rest: empty window, g = 0, the flag cleared, the sample index at 0, the hold-off
  /// rearmed.
  void Reset();

  /// One sample: d_hat (Q31 of the observer's output full scale) and the reference force (Q31 of
  /// its channel's full scale; ignored when reference_gain is 0).
  /// @returns true when this sample completed a window (the statistic was updated).
  bool Step(std::int32_t d_hat, std::int32_t reference) {
    if (left_ == 0) return false;  // uninitialised
    const std::int64_t acc = std::int64_t{d_hat} * residual_gain_ +
                             std::int64_t{reference} * reference_gain_ + (std::int64_t{1} << 31);
    const auto r = static_cast<std::int32_t>(acc >> 32);
    const std::int32_t c = r < kMinScaledResidual
                               ? kMinScaledResidual
                               : (r > kMaxScaledResidual ? kMaxScaledResidual : r);
    if (c != r) ++clamp_count_;
    sum_ += std::int64_t{c} * c;
    if (--left_ != 0) return false;
    EndWindow();
    return true;
  }

  bool initialised() const { return params_.window_samples != 0; }
  const ResidualCusumParams& params() const { return params_; }
  /// g, Q16 (g / 2^16 in units of the window mean's spread).
  std::int32_t statistic() const { return g_; }
  /// z of the last completed window, Q16.
  std::int32_t last_z() const { return z_; }
  /// Latched at the first window whose g exceeded h.
  bool tripped() const { return tripped_; }
  /// Samples since Reset at the end of the window that tripped (0 while not tripped).
  std::uint32_t trip_sample() const { return trip_sample_; }
  /// g at that window, Q16.
  std::int32_t trip_statistic() const { return trip_statistic_; }
  std::uint32_t windows() const { return windows_; }
  /// True while the windows completed since Reset are within the hold-off (g stays 0).
  bool holding_off() const { return windows_ < params_.holdoff_windows; }
  std::uint32_t samples() const {
    return initialised() ? windows_ * params_.window_samples + (params_.window_samples - left_) : 0;
  }
  /// Residual samples clamped at kMaxScaledResidual, window excesses clamped to int32 and
  /// statistics clamped at kMaxStatistic: 0 while the residual stays within 48 dB of the design.
  /// Counted from the end of the hold-off (a start transient's clamps are dropped).
  std::uint32_t clamp_count() const { return clamp_count_; }

 private:
  void EndWindow();

  // The per-sample state first, together (the gains and the sum load as pairs).
  std::int32_t residual_gain_ = 0;
  std::int32_t reference_gain_ = 0;
  std::int64_t sum_ = 0;
  std::uint32_t left_ = 0;  // samples left in the window; 0 only when uninitialised
  std::uint32_t clamp_count_ = 0;
  ResidualCusumParams params_{};
  std::uint32_t windows_ = 0;
  std::int32_t g_ = 0;
  std::int32_t z_ = 0;
  bool tripped_ = false;
  std::uint32_t trip_sample_ = 0;
  std::int32_t trip_statistic_ = 0;
};

}  // namespace vibid::fixed
