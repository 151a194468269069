#include "clock.hpp"

#include "clock_plan.hpp"
#include "crystal_check.hpp"
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

// On the HSI fallback the PLL runs from the 16 MHz HSI for the OTG core's 48 MHz only (the core
// stays on the HSI): the plan of a 16 MHz crystal, M 8, N 168, P 2, Q 7 (clock_plan.hpp).
constexpr PllPlan kHsiPlan = PlanPll(kHsiHz);
static_assert(kHsiPlan.ok && kHsiPlan.m == 8 && kHsiPlan.n == 168 && kHsiPlan.q == 7);

ClockConfig HsiFallback(HsiReason reason, std::uint32_t measured_hz) {
  Reg(rcc::kCr) |= rcc::kCrHsiOn;
  (void)WaitFor(rcc::kCr, rcc::kCrHsiRdy, rcc::kCrHsiRdy, kHseTimeoutPolls);
  Modify(rcc::kCfgr, rcc::kCfgrSwMask | rcc::kCfgrPrescalerMask, rcc::kCfgrSwHsi);
  (void)WaitFor(rcc::kCfgr, rcc::kCfgrSwsMask, rcc::kCfgrSwsHsi, kSwitchTimeoutPolls);
  Reg(rcc::kCr) &= ~(rcc::kCrPllOn | rcc::kCrHseOn);
  (void)WaitFor(rcc::kCr, rcc::kCrPllRdy, 0, kPllTimeoutPolls);
  // PLLCFGR is written only with the PLL off (RM0090 §7.3.2).
  Reg(rcc::kPllcfgr) = Field(kHsiPlan.m, rcc::kPllcfgrPllmPos) |
                       Field(kHsiPlan.n, rcc::kPllcfgrPllnPos) |
                       Field(kHsiPlan.p / 2 - 1, rcc::kPllcfgrPllpPos) | rcc::kPllcfgrSrcHsi |
                       Field(kHsiPlan.q, rcc::kPllcfgrPllqPos);
  Reg(rcc::kCr) |= rcc::kCrPllOn;
  const bool usb = WaitFor(rcc::kCr, rcc::kCrPllRdy, rcc::kCrPllRdy, kPllTimeoutPolls);
  return ClockConfig{ClockSource::kHsiFallback, kHsiHz, kHsiHz, kHsiHz, reason, measured_hz, usb};
}

}  // namespace

std::uint32_t HseHz() { return kHseHz; }

ClockConfig ConfigureClocks() {
  Reg(rcc::kCr) |= rcc::kCrHseOn;
  if (!WaitFor(rcc::kCr, rcc::kCrHseRdy, rcc::kCrHseRdy, kHseTimeoutPolls))
    return HsiFallback(HsiReason::kHseDidNotStart, 0);
  // Still on the HSI: the crystal is measured before the PLL multiplies it. An image for 8 MHz
  // on a 12 MHz board would otherwise run a 504 MHz VCO and a 252 MHz core.
  std::uint32_t measured_hz = 0;
  if (!MeasureHseAgainstHsi(measured_hz)) return HsiFallback(HsiReason::kHseDidNotStart, 0);
  if (!HseWithinTolerance(measured_hz, kHseHz))
    return HsiFallback(HsiReason::kHseWrongFrequency, measured_hz);

  // Regulator scale 1 for 168 MHz.
  EnableClock(rcc::kApb1enr, rcc::kApb1Pwr);
  Reg(pwr::kCr) |= pwr::kCrVos;

  Reg(rcc::kCr) &= ~rcc::kCrPllOn;
  Reg(rcc::kPllcfgr) = Field(kPlan.m, rcc::kPllcfgrPllmPos) | Field(kPlan.n, rcc::kPllcfgrPllnPos) |
                       Field(kPlan.p / 2 - 1, rcc::kPllcfgrPllpPos) | rcc::kPllcfgrSrcHse |
                       Field(kPlan.q, rcc::kPllcfgrPllqPos);
  Reg(rcc::kCr) |= rcc::kCrPllOn;
  if (!WaitFor(rcc::kCr, rcc::kCrPllRdy, rcc::kCrPllRdy, kPllTimeoutPolls))
    return HsiFallback(HsiReason::kPllDidNotLock, measured_hz);

  // 5 wait states at 168 MHz and 2.7-3.6 V (RM0090 table 10), caches on and prefetch off (the
  // ADC noise erratum, ES0182), set before the clock goes up.
  if (!ConfigureFlashAccess(5)) return HsiFallback(HsiReason::kPllDidNotLock, measured_hz);

  Modify(rcc::kCfgr, rcc::kCfgrPrescalerMask, rcc::kCfgrPpre1Div4 | rcc::kCfgrPpre2Div2);
  Modify(rcc::kCfgr, rcc::kCfgrSwMask, rcc::kCfgrSwPll);
  if (!WaitFor(rcc::kCfgr, rcc::kCfgrSwsMask, rcc::kCfgrSwsPll, kSwitchTimeoutPolls))
    return HsiFallback(HsiReason::kPllDidNotLock, measured_hz);
  // APB1 prescaler 4 doubles the timer clock: 84 MHz.
  return ClockConfig{ClockSource::kPllFromHse, 168000000,   84000000, 84000000,
                     HsiReason::kNone,         measured_hz, true};
}

}  // namespace vibid::fw::stm32
