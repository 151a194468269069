#include "clock.hpp"

#include "clock_plan.hpp"
#include "regs/core_m4.hpp"
#include "regs/rcc.hpp"
#include "system.hpp"

namespace vibid::fw::stm32 {
namespace {

// HSE startup is specified at 2 ms typical; at 16 MHz HSI one poll is a few cycles, so 100 000
// polls allow well over 10 ms before giving up.
constexpr std::uint32_t kHseTimeoutPolls = 100000;
constexpr std::uint32_t kPllTimeoutPolls = 100000;
constexpr std::uint32_t kSwitchTimeoutPolls = 100000;

// The crystal is a build option (-DVIBID_HSE_HZ=..., see README "First board").
#ifndef VIBID_HSE_HZ
#error "VIBID_HSE_HZ (the HSE crystal frequency in Hz) is set by the build"
#endif
constexpr std::uint32_t kHseHz = VIBID_HSE_HZ;
static_assert(kHseHz >= kHseMinHz && kHseHz <= kHseMaxHz,
              "VIBID_HSE_HZ: the HSE crystal must be within 4..26 MHz (STM32F405 datasheet)");
constexpr PllPlan kPlan = PlanPll(kHseHz);
static_assert(kPlan.ok,
              "VIBID_HSE_HZ: no PLL setting gives 168 MHz SYSCLK and exactly 48 MHz USB within "
              "VCO input 1..2 MHz (PLLM 2..63), VCO output 100..432 MHz (PLLN 50..432), "
              "PLLP 2/4/6/8, PLLQ 2..15 (RM0090 7.3.2)");
// Both outputs exact, checked in whole hertz: HSE * N = target * M * divider.
static_assert(std::uint64_t{kHseHz} * kPlan.n ==
              std::uint64_t{kSysclkTargetHz} * kPlan.m * kPlan.p);
static_assert(std::uint64_t{kHseHz} * kPlan.n == std::uint64_t{kUsbTargetHz} * kPlan.m * kPlan.q);

ClockConfig HsiFallback() {
  Reg(rcc::kCr) |= rcc::kCrHsiOn;
  (void)WaitFor(rcc::kCr, rcc::kCrHsiRdy, rcc::kCrHsiRdy, kHseTimeoutPolls);
  Modify(rcc::kCfgr, rcc::kCfgrSwMask | rcc::kCfgrPrescalerMask, rcc::kCfgrSwHsi);
  Reg(rcc::kCr) &= ~(rcc::kCrPllOn | rcc::kCrHseOn);
  return ClockConfig{ClockSource::kHsiFallback, 16000000, 16000000, 16000000};
}

}  // namespace

std::uint32_t HseHz() { return kHseHz; }

ClockConfig ConfigureClocks() {
  Reg(rcc::kCr) |= rcc::kCrHseOn;
  if (!WaitFor(rcc::kCr, rcc::kCrHseRdy, rcc::kCrHseRdy, kHseTimeoutPolls)) return HsiFallback();

  // Regulator scale 1 for 168 MHz.
  EnableClock(rcc::kApb1enr, rcc::kApb1Pwr);
  Reg(pwr::kCr) |= pwr::kCrVos;

  Reg(rcc::kCr) &= ~rcc::kCrPllOn;
  Reg(rcc::kPllcfgr) = Field(kPlan.m, rcc::kPllcfgrPllmPos) | Field(kPlan.n, rcc::kPllcfgrPllnPos) |
                       Field(kPlan.p / 2 - 1, rcc::kPllcfgrPllpPos) | rcc::kPllcfgrSrcHse |
                       Field(kPlan.q, rcc::kPllcfgrPllqPos);
  Reg(rcc::kCr) |= rcc::kCrPllOn;
  if (!WaitFor(rcc::kCr, rcc::kCrPllRdy, rcc::kCrPllRdy, kPllTimeoutPolls)) return HsiFallback();

  // 5 wait states at 168 MHz and 2.7-3.6 V (RM0090 table 10), caches on and prefetch off (the
  // ADC noise erratum, ES0182), set before the clock goes up.
  if (!ConfigureFlashAccess(5)) return HsiFallback();

  Modify(rcc::kCfgr, rcc::kCfgrPrescalerMask, rcc::kCfgrPpre1Div4 | rcc::kCfgrPpre2Div2);
  Modify(rcc::kCfgr, rcc::kCfgrSwMask, rcc::kCfgrSwPll);
  if (!WaitFor(rcc::kCfgr, rcc::kCfgrSwsMask, rcc::kCfgrSwsPll, kSwitchTimeoutPolls))
    return HsiFallback();
  // APB1 prescaler 4 doubles the timer clock: 84 MHz.
  return ClockConfig{ClockSource::kPllFromHse, 168000000, 84000000, 84000000};
}

}  // namespace vibid::fw::stm32
