// The main PLL settings for a given HSE crystal, computed at compile time: 168 MHz SYSCLK and
// exactly 48 MHz on PLL48CK, which the OTG_FS core needs (USB full speed tolerates +-0.25 %,
// and only an exact division gets there from a crystal).
//
// Limits (RM0090 rev 19 §7.3.2 RCC_PLLCFGR; HSE range from the STM32F405 datasheet, HSE
// oscillator characteristics):
//   HSE crystal        4..26 MHz
//   PLLM               2..63, VCO input = HSE / PLLM in 1..2 MHz (2 MHz recommended: less jitter)
//   PLLN               50..432, VCO output = VCO input * PLLN in 100..432 MHz
//   PLLP               2, 4, 6 or 8;  SYSCLK = VCO / PLLP
//   PLLQ               2..15;         PLL48CK = VCO / PLLQ
#pragma once

#include <cstdint>

namespace vibid::fw::stm32 {

inline constexpr std::uint32_t kHseMinHz = 4000000;
inline constexpr std::uint32_t kHseMaxHz = 26000000;
inline constexpr std::uint32_t kVcoInMinHz = 1000000;
inline constexpr std::uint32_t kVcoInMaxHz = 2000000;
inline constexpr std::uint32_t kVcoOutMinHz = 100000000;
inline constexpr std::uint32_t kVcoOutMaxHz = 432000000;
inline constexpr std::uint32_t kPllMMin = 2;
inline constexpr std::uint32_t kPllMMax = 63;
inline constexpr std::uint32_t kPllNMin = 50;
inline constexpr std::uint32_t kPllNMax = 432;
inline constexpr std::uint32_t kPllQMin = 2;
inline constexpr std::uint32_t kPllQMax = 15;
inline constexpr std::uint32_t kSysclkTargetHz = 168000000;
inline constexpr std::uint32_t kUsbTargetHz = 48000000;

struct PllPlan {
  bool ok = false;  ///< False: no setting meets every limit with both outputs exact.
  std::uint32_t m = 0;
  std::uint32_t n = 0;
  std::uint32_t p = 0;  ///< Division factor 2/4/6/8 (the register holds p / 2 - 1).
  std::uint32_t q = 0;
};

/// The plan for `hse_hz`: among exact solutions, the highest VCO input frequency (the
/// smallest PLLM, as RM0090 recommends for jitter), then the smallest PLLP.
constexpr PllPlan PlanPll(std::uint32_t hse_hz) {
  if (hse_hz < kHseMinHz || hse_hz > kHseMaxHz) return {};
  for (std::uint32_t m = kPllMMin; m <= kPllMMax; ++m) {
    // VCO input must be within 1..2 MHz: check on whole hertz without rounding.
    if (hse_hz > std::uint64_t{kVcoInMaxHz} * m) continue;
    if (hse_hz < std::uint64_t{kVcoInMinHz} * m) break;
    for (std::uint32_t p = 2; p <= 8; p += 2) {
      const std::uint64_t vco_hz = std::uint64_t{kSysclkTargetHz} * p;
      if (vco_hz < kVcoOutMinHz || vco_hz > kVcoOutMaxHz) continue;
      // PLLN = VCO * M / HSE must be a whole number, or SYSCLK is not exactly 168 MHz.
      if ((vco_hz * m) % hse_hz != 0) continue;
      const std::uint64_t n = vco_hz * m / hse_hz;
      if (n < kPllNMin || n > kPllNMax) continue;
      if (vco_hz % kUsbTargetHz != 0) continue;
      const std::uint64_t q = vco_hz / kUsbTargetHz;
      if (q < kPllQMin || q > kPllQMax) continue;
      return PllPlan{true, m, static_cast<std::uint32_t>(n), p, static_cast<std::uint32_t>(q)};
    }
  }
  return {};
}

}  // namespace vibid::fw::stm32
