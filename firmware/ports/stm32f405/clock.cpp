#include "clock.hpp"

#include "regs/rcc.hpp"

namespace vibid::fw::stm32 {
namespace {

// HSE startup is specified at 2 ms typical; at 16 MHz HSI one poll is a few cycles, so 100 000
// polls allow well over 10 ms before giving up.
constexpr std::uint32_t kHseTimeoutPolls = 100000;
constexpr std::uint32_t kPllTimeoutPolls = 100000;
constexpr std::uint32_t kSwitchTimeoutPolls = 100000;

constexpr std::uint32_t kHseHz = 8000000;
// VCO in = HSE / M = 1 MHz (1..2 MHz allowed), VCO = 336 MHz (100..432), SYSCLK = VCO / P = 168,
// PLL48CK = VCO / Q = 48 MHz exactly, as the OTG_FS core needs.
constexpr std::uint32_t kPllM = 8;
constexpr std::uint32_t kPllN = 336;
constexpr std::uint32_t kPllP = 2;
constexpr std::uint32_t kPllQ = 7;
static_assert(kHseHz / kPllM * kPllN / kPllP == 168000000);
static_assert(kHseHz / kPllM * kPllN / kPllQ == 48000000);

ClockConfig HsiFallback() {
  Reg(rcc::kCr) |= rcc::kCrHsiOn;
  (void)WaitFor(rcc::kCr, rcc::kCrHsiRdy, rcc::kCrHsiRdy, kHseTimeoutPolls);
  Modify(rcc::kCfgr, rcc::kCfgrSwMask | rcc::kCfgrPrescalerMask, rcc::kCfgrSwHsi);
  Reg(rcc::kCr) &= ~(rcc::kCrPllOn | rcc::kCrHseOn);
  return ClockConfig{ClockSource::kHsiFallback, 16000000, 16000000, 16000000};
}

}  // namespace

ClockConfig ConfigureClocks() {
  Reg(rcc::kCr) |= rcc::kCrHseOn;
  if (!WaitFor(rcc::kCr, rcc::kCrHseRdy, rcc::kCrHseRdy, kHseTimeoutPolls)) return HsiFallback();

  // Regulator scale 1 for 168 MHz.
  Reg(rcc::kApb1enr) |= rcc::kApb1Pwr;
  Reg(pwr::kCr) |= pwr::kCrVos;

  Reg(rcc::kCr) &= ~rcc::kCrPllOn;
  Reg(rcc::kPllcfgr) = Field(kPllM, rcc::kPllcfgrPllmPos) | Field(kPllN, rcc::kPllcfgrPllnPos) |
                       Field(kPllP / 2 - 1, rcc::kPllcfgrPllpPos) | rcc::kPllcfgrSrcHse |
                       Field(kPllQ, rcc::kPllcfgrPllqPos);
  Reg(rcc::kCr) |= rcc::kCrPllOn;
  if (!WaitFor(rcc::kCr, rcc::kCrPllRdy, rcc::kCrPllRdy, kPllTimeoutPolls)) return HsiFallback();

  // 5 wait states at 168 MHz and 2.7-3.6 V (RM0090 table 10), with prefetch and caches, set
  // before the clock goes up.
  Reg(flash::kAcr) = 5 | flash::kAcrPrften | flash::kAcrIcen | flash::kAcrDcen;
  if ((Reg(flash::kAcr) & flash::kAcrLatencyMask) != 5) return HsiFallback();

  Modify(rcc::kCfgr, rcc::kCfgrPrescalerMask, rcc::kCfgrPpre1Div4 | rcc::kCfgrPpre2Div2);
  Modify(rcc::kCfgr, rcc::kCfgrSwMask, rcc::kCfgrSwPll);
  if (!WaitFor(rcc::kCfgr, rcc::kCfgrSwsMask, rcc::kCfgrSwsPll, kSwitchTimeoutPolls)) return HsiFallback();
  // APB1 prescaler 4 doubles the timer clock: 84 MHz.
  return ClockConfig{ClockSource::kPllFromHse, 168000000, 84000000, 84000000};
}

}  // namespace vibid::fw::stm32
