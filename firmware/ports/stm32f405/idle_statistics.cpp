#include "idle_statistics.hpp"

namespace vibid::fw::stm32 {

std::uint64_t FloorSqrt(std::uint64_t x) {
  // Digit-by-digit in base 4 (Hacker's Delight 11-1): one result bit per step, no overflow.
  std::uint64_t root = 0;
  std::uint64_t bit = std::uint64_t{1} << 62;
  while (bit > x) bit >>= 2;
  while (bit != 0) {
    if (x >= root + bit) {
      x -= root + bit;
      root = (root >> 1) + bit;
    } else {
      root >>= 1;
    }
    bit >>= 2;
  }
  return root;
}

bool RmsMilliLsb(const CodeSums& sums, std::int64_t& milli_lsb) {
  const std::uint64_t n = sums.count();
  if (n < 2 || n % 2 != 0) return false;
  // rms = sqrt(D) / n with D = n sum_sq - sum^2 (bounds: idle_statistics.hpp); in milli-LSB
  // sqrt(D x 10^6) / n. With s = floor(sqrt(D x 10^6)) the nearest integer is
  // floor((2 s + n) / (2 n)): the exact floor((2 sqrt + n) / (2 n)) could only be larger if an
  // even multiple of n equalled 2 s + n + 1, which is odd for even n.
  const std::uint64_t d = n * sums.sum_squares() - sums.sum() * sums.sum();
  const std::uint64_t s = FloorSqrt(d * 1'000'000);
  milli_lsb = static_cast<std::int64_t>((2 * s + n) / (2 * n));
  return true;
}

bool OffsetMilliLsb(const CodeSums& sums, std::uint32_t mid_code, std::int64_t& milli_lsb) {
  const std::int64_t n = sums.count();
  if (n == 0) return false;
  const std::int64_t numerator =
      1000 * (static_cast<std::int64_t>(sums.sum()) - n * static_cast<std::int64_t>(mid_code));
  const std::int64_t magnitude = numerator < 0 ? -numerator : numerator;
  const std::int64_t rounded = (2 * magnitude + n) / (2 * n);
  milli_lsb = numerator < 0 ? -rounded : rounded;
  return true;
}

}  // namespace vibid::fw::stm32
