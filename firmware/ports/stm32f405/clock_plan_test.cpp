// The compile-time PLL planner against an exhaustive search over every register value RM0090
// allows, and against ST's published settings.
#include <gtest/gtest.h>

#include <cstdint>
#include <optional>

#include "clock_plan.hpp"

namespace vibid::fw::stm32 {
namespace {

struct Solution {
  std::uint32_t m, n, p, q;
};

/// Every (PLLM, PLLN, PLLP, PLLQ) within the RM0090 §7.3.2 register ranges and clock limits
/// that gives exactly 168 MHz and 48 MHz; returns the one with the highest VCO input (smallest
/// M), then the smallest P. Written independently of PlanPll: loops over register values, not
/// over target frequencies.
std::optional<Solution> Exhaustive(std::uint32_t hse_hz) {
  if (hse_hz < 4000000 || hse_hz > 26000000) return std::nullopt;
  for (std::uint32_t m = 2; m <= 63; ++m) {
    const double vco_in = static_cast<double>(hse_hz) / m;
    if (vco_in < 1e6 || vco_in > 2e6) continue;
    for (std::uint32_t p : {2U, 4U, 6U, 8U}) {
      for (std::uint32_t n = 50; n <= 432; ++n) {
        const std::uint64_t vco_times_m = std::uint64_t{hse_hz} * n;  // VCO * M, in Hz
        if (vco_times_m < 100000000ULL * m || vco_times_m > 432000000ULL * m) continue;
        if (vco_times_m != 168000000ULL * m * p) continue;
        for (std::uint32_t q = 2; q <= 15; ++q) {
          if (vco_times_m == 48000000ULL * m * q) return Solution{m, n, p, q};
        }
      }
    }
  }
  return std::nullopt;
}

TEST(ClockPlan, AgreesWithExhaustiveSearchOverTheCrystalRange) {
  // Every 50 kHz from 3.5 to 27 MHz (outside the range must be refused too), plus the common
  // UART and odd crystals.
  std::vector<std::uint32_t> crystals = {11059200, 14745600, 18432000, 7372800, 8500000, 13000000};
  for (std::uint32_t hz = 3500000; hz <= 27000000; hz += 50000) crystals.push_back(hz);
  int usable = 0;
  for (std::uint32_t hz : crystals) {
    const PllPlan plan = PlanPll(hz);
    const std::optional<Solution> ref = Exhaustive(hz);
    ASSERT_EQ(plan.ok, ref.has_value()) << hz;
    if (!ref) continue;
    ++usable;
    EXPECT_EQ(plan.m, ref->m) << hz;
    EXPECT_EQ(plan.n, ref->n) << hz;
    EXPECT_EQ(plan.p, ref->p) << hz;
    EXPECT_EQ(plan.q, ref->q) << hz;
  }
  // The search is not vacuous.
  EXPECT_GT(usable, 50);
}

TEST(ClockPlan, EveryWholeMegahertzCrystalHasAPlan) {
  // HSE / M = 1 MHz with N = 336, P = 2, Q = 7 always works for a whole-MHz crystal up to
  // 63 MHz, so every one in 4..26 MHz must be accepted.
  for (std::uint32_t mhz = 4; mhz <= 26; ++mhz) EXPECT_TRUE(PlanPll(mhz * 1000000).ok) << mhz;
}

TEST(ClockPlan, PublishedAndClosedFormSettings) {
  // ST STM324xG-EVAL (25 MHz crystal), system_stm32f4xx.c / CubeF4 examples:
  // PLL_M 25, PLL_N 336, PLL_P 2, PLL_Q 7.
  const PllPlan eval = PlanPll(25000000);
  ASSERT_TRUE(eval.ok);
  EXPECT_EQ(eval.m, 25U);
  EXPECT_EQ(eval.n, 336U);
  EXPECT_EQ(eval.p, 2U);
  EXPECT_EQ(eval.q, 7U);
  // 8, 12 and 16 MHz: closed form with the 2 MHz VCO input RM0090 recommends:
  // M = HSE / 2 MHz, N = 336 MHz / 2 MHz = 168, P = 336 / 168 = 2, Q = 336 / 48 = 7.
  for (std::uint32_t mhz : {8U, 12U, 16U}) {
    const PllPlan plan = PlanPll(mhz * 1000000);
    ASSERT_TRUE(plan.ok) << mhz;
    EXPECT_EQ(plan.m, mhz / 2) << mhz;
    EXPECT_EQ(plan.n, 168U) << mhz;
    EXPECT_EQ(plan.p, 2U) << mhz;
    EXPECT_EQ(plan.q, 7U) << mhz;
  }
}

TEST(ClockPlan, RefusesCrystalsWithoutAnExactPlan) {
  EXPECT_FALSE(PlanPll(8500000).ok);   // 336 MHz * M / 8.5 MHz is never whole for M = 5..8
  EXPECT_FALSE(PlanPll(14745600).ok);  // UART crystal
  EXPECT_FALSE(PlanPll(3999999).ok);   // below the HSE oscillator range
  EXPECT_FALSE(PlanPll(26000001).ok);  // above it
  static_assert(PlanPll(12000000).ok && PlanPll(25000000).ok, "the preset's test crystals");
}

}  // namespace
}  // namespace vibid::fw::stm32
