// The converter noise and offset checks' arithmetic: the mean and the rms about it of one
// channel's idle codes, in milli-LSB, exact in integers (no floating point, no heap).
#pragma once

#include <cstdint>

namespace vibid::fw::stm32 {

/// Running sums of one channel's 12-bit codes.
///
/// Scaling and overflow: a code is at most 4095 (the value is masked to 12 bits) and at most
/// kMaxCodes are added, so sum <= 2000 x 4095 = 8.2e6 and sum_squares <= 2000 x 4095^2 = 3.4e10
/// (u64). The variance numerator D = n x sum_squares - sum^2 = sum over pairs of (x_i - x_j)^2
/// lies in [0, n^2 x 4095^2 / 4] <= 1.68e13, and D x 10^6 <= 1.68e19 < 2^64 = 1.84e19 (u64), the
/// largest intermediate of RmsMilliLsb. The offset's numerator 1000 x (sum - n x mid) is within
/// +-2000 x 1000 x 4096 = 8.2e9 (i64).
class CodeSums {
 public:
  static constexpr std::uint32_t kMaxCodes = 2000;
  static constexpr std::uint32_t kCodeMask = 0xFFF;

  /// Adds one code; codes past kMaxCodes are not added (count() stays at kMaxCodes).
  void Add(std::uint32_t code) {
    if (count_ >= kMaxCodes) return;
    code &= kCodeMask;
    sum_ += code;
    sum_squares_ += std::uint64_t{code} * code;
    ++count_;
  }
  std::uint32_t count() const { return count_; }
  std::uint64_t sum() const { return sum_; }
  std::uint64_t sum_squares() const { return sum_squares_; }

 private:
  std::uint32_t count_ = 0;
  std::uint64_t sum_ = 0;
  std::uint64_t sum_squares_ = 0;
};

/// floor(sqrt(x)) for any 64-bit x, bit by bit (32 steps).
std::uint64_t FloorSqrt(std::uint64_t x);

/// The rms about the mean (population: sqrt(sum (x - mean)^2 / n)) in milli-LSB, rounded to the
/// nearest (halves up): the emulator's value, llround(1000 x sqrt(sum_sq / n - mean^2)).
/// @returns false for an odd count or fewer than 2 codes (the rounding below is exact for even
///          counts only; the self-test takes wire::kSelfTestSamples = 1000).
bool RmsMilliLsb(const CodeSums& sums, std::int64_t& milli_lsb);

/// The mean minus `mid_code` in milli-LSB, rounded to the nearest (halves away from zero, as
/// llround): the emulator's value. @returns false for no codes.
bool OffsetMilliLsb(const CodeSums& sums, std::uint32_t mid_code, std::int64_t& milli_lsb);

}  // namespace vibid::fw::stm32
