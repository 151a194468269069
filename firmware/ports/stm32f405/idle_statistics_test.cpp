// The noise and offset checks' integer statistics against a double reference: the closed forms
// of constant, ramp and two-level data, the widest spread the bounds allow, and pseudo-random
// codes against a two-pass double mean and rms rounded as the emulator rounds (llround).
#include "idle_statistics.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

namespace vibid::fw::stm32 {
namespace {

constexpr std::uint32_t kMid = 2048;

CodeSums SumsOf(const std::vector<std::uint32_t>& codes) {
  CodeSums s;
  for (const std::uint32_t c : codes) s.Add(c);
  return s;
}

std::int64_t Rms(const std::vector<std::uint32_t>& codes) {
  std::int64_t v = -1;
  EXPECT_TRUE(RmsMilliLsb(SumsOf(codes), v));
  return v;
}

std::int64_t Offset(const std::vector<std::uint32_t>& codes) {
  std::int64_t v = -1;
  EXPECT_TRUE(OffsetMilliLsb(SumsOf(codes), kMid, v));
  return v;
}

// The reference: two passes in double, rounded as the emulator's llround(value x 1000).
struct Reference {
  std::int64_t rms_milli;
  std::int64_t offset_milli;
};
Reference DoubleReference(const std::vector<std::uint32_t>& codes) {
  double mean = 0.0;
  for (const std::uint32_t c : codes) mean += c;
  mean /= static_cast<double>(codes.size());
  double squares = 0.0;
  for (const std::uint32_t c : codes) squares += (c - mean) * (c - mean);
  const double rms = std::sqrt(squares / static_cast<double>(codes.size()));
  return {std::llround(rms * 1000.0), std::llround((mean - kMid) * 1000.0)};
}

TEST(IdleStatisticsTest, FloorSqrtOfSquaresAndTheirNeighbours) {
  for (const std::uint64_t k :
       {0ull, 1ull, 2ull, 3ull, 1000ull, 65535ull, 4'094'967'295ull, 4'294'967'295ull}) {
    EXPECT_EQ(FloorSqrt(k * k), k);
    if (k > 0) {
      EXPECT_EQ(FloorSqrt(k * k - 1), k - 1);
    }
  }
  EXPECT_EQ(FloorSqrt(~std::uint64_t{0}), 4'294'967'295ull);  // 2^64 - 1: floor is 2^32 - 1
}

TEST(IdleStatisticsTest, ConstantCodesHaveNoNoiseAndTheirOffset) {
  // Closed form: rms 0, offset = code - 2048.
  EXPECT_EQ(Rms(std::vector<std::uint32_t>(1000, 2048)), 0);
  EXPECT_EQ(Offset(std::vector<std::uint32_t>(1000, 2048)), 0);
  EXPECT_EQ(Offset(std::vector<std::uint32_t>(1000, 2100)), 52'000);
  EXPECT_EQ(Offset(std::vector<std::uint32_t>(1000, 0)), -2'048'000);
  EXPECT_EQ(Offset(std::vector<std::uint32_t>(1000, 4095)), 2'047'000);
}

TEST(IdleStatisticsTest, RampOfAThousandCodes) {
  // Closed form for codes b, b + 1, ..., b + n - 1: mean b + (n - 1) / 2, population variance
  // (n^2 - 1) / 12 = 83 333.25 for n = 1000, rms 288.674 990 LSB -> 288 675 milli-LSB.
  std::vector<std::uint32_t> ramp;
  for (std::uint32_t k = 0; k < 1000; ++k) ramp.push_back(1548 + k);
  EXPECT_EQ(Rms(ramp), std::llround(1000.0 * std::sqrt((1000.0 * 1000.0 - 1.0) / 12.0)));
  EXPECT_EQ(Rms(ramp), 288'675);
  EXPECT_EQ(Offset(ramp), -500);  // mean 2047.5
}

TEST(IdleStatisticsTest, TwoLevelCodesOfKnownVariance) {
  // 2048 +- a alternating: mean 2048, rms exactly a.
  std::vector<std::uint32_t> alternating;
  for (int k = 0; k < 500; ++k) alternating.insert(alternating.end(), {2051u, 2045u});
  EXPECT_EQ(Rms(alternating), 3'000);
  EXPECT_EQ(Offset(alternating), 0);
  // 2048, 2049, 2050, 2049 repeated: mean 2049, variance (1 + 0 + 1 + 0) / 4 = 1/2, rms
  // sqrt(1/2) = 0.707 107 LSB.
  std::vector<std::uint32_t> steps;
  for (int k = 0; k < 250; ++k) steps.insert(steps.end(), {2048u, 2049u, 2050u, 2049u});
  EXPECT_EQ(Rms(steps), 707);
  EXPECT_EQ(Offset(steps), 1'000);
}

TEST(IdleStatisticsTest, TheWidestSpreadStaysWithinTheBounds) {
  // The largest variance numerator: half the codes 0, half 4095, at the largest count. Closed
  // form: rms 4095 / 2 = 2047.5 LSB, mean 2047.5.
  std::vector<std::uint32_t> extremes;
  for (std::uint32_t k = 0; k < CodeSums::kMaxCodes / 2; ++k)
    extremes.insert(extremes.end(), {0u, 4095u});
  EXPECT_EQ(Rms(extremes), 2'047'500);
  EXPECT_EQ(Offset(extremes), -500);
}

TEST(IdleStatisticsTest, HalfMilliLsbOffsetsRoundAwayFromZeroAsTheEmulator) {
  // 2000 codes whose sum is one code off the mid: 1000 / 2000 = 0.5 milli-LSB, llround -> +-1.
  std::vector<std::uint32_t> up(2000, 2048);
  up[0] = 2049;
  EXPECT_EQ(Offset(up), std::llround(0.5));
  std::vector<std::uint32_t> down(2000, 2048);
  down[0] = 2047;
  EXPECT_EQ(Offset(down), std::llround(-0.5));
}

TEST(IdleStatisticsTest, PseudoRandomCodesMatchTheDoubleReference) {
  // Codes around a few offsets and spreads from a 32-bit LCG (Numerical Recipes' constants).
  std::uint32_t state = 12345;
  const auto next = [&state] {
    state = state * 1664525u + 1013904223u;
    return state >> 8;
  };
  for (const std::uint32_t centre : {2048u, 2000u, 2130u, 100u, 4000u}) {
    for (const std::uint32_t spread : {1u, 2u, 7u, 40u, 95u}) {
      std::vector<std::uint32_t> codes;
      for (std::uint32_t k = 0; k < 1000; ++k)
        codes.push_back(centre - spread + next() % (2 * spread + 1));
      const Reference ref = DoubleReference(codes);
      EXPECT_EQ(Rms(codes), ref.rms_milli) << centre << " +- " << spread;
      EXPECT_EQ(Offset(codes), ref.offset_milli) << centre << " +- " << spread;
    }
  }
}

TEST(IdleStatisticsTest, CountsTheArithmeticCannotRoundExactlyAreRefused) {
  std::int64_t v = 0;
  EXPECT_FALSE(RmsMilliLsb(SumsOf({2048, 2049, 2050}), v));  // odd
  EXPECT_FALSE(RmsMilliLsb(SumsOf({}), v));
  EXPECT_FALSE(OffsetMilliLsb(SumsOf({}), kMid, v));
  // Codes past the limit are not added; bits above 12 are not a code's.
  CodeSums s;
  for (std::uint32_t k = 0; k < CodeSums::kMaxCodes + 5; ++k) s.Add(0x1000 | 7);
  EXPECT_EQ(s.count(), CodeSums::kMaxCodes);
  EXPECT_EQ(s.sum(), 7u * CodeSums::kMaxCodes);
}

}  // namespace
}  // namespace vibid::fw::stm32
