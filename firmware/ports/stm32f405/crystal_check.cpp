#include "crystal_check.hpp"

#include "regs/core_m4.hpp"
#include "regs/peripherals.hpp"
#include "regs/rcc.hpp"
#include "system.hpp"

namespace vibid::fw::stm32 {

bool CountTicksOverCaptures(const CaptureChannel& channel, std::uint32_t captures,
                            std::uint32_t polls_per_capture, bool feed, std::uint64_t& ticks) {
  const Address sr = channel.timer + tim::kSr;
  // A capture left from before the count is dropped: the first one read starts it.
  const std::uint32_t stale = Reg(channel.ccr);
  (void)stale;
  Reg(sr) = 0;
  std::uint32_t previous = 0;
  std::uint64_t sum = 0;
  for (std::uint32_t k = 0; k <= captures; ++k) {
    if (!WaitFor(sr, channel.flag, channel.flag, polls_per_capture)) return false;
    const std::uint32_t now = Reg(channel.ccr);           // reading CCRx clears CCxIF
    if ((Reg(sr) & channel.overflow) != 0) return false;  // one was lost: the sum is short
    if (k > 0) sum += (now - previous) & channel.counter_mask;
    previous = now;
    if (feed && k % 64 == 0) KickWatchdog();
  }
  ticks = sum;
  return true;
}

bool MeasureHseAgainstHsi(std::uint32_t& hse_hz) {
  // On the HSI with the reset prescalers, TIM11 (APB2) counts 16 MHz. HSE_RTC = HSE / 31 gives
  // a capture every 248 HSE cycles: 62 us at 4 MHz, 9.5 us (152 ticks) at 26 MHz, so polling
  // keeps up and the 16-bit counter never wraps between two captures.
  Modify(rcc::kCfgr, rcc::kCfgrRtcpreMask, Field(kHseRtcDivider, rcc::kCfgrRtcprePos));
  EnableClock(rcc::kApb2enr, rcc::kApb2Tim11);
  const Address t = tim::kTim11;
  Reg(t + tim::kCr1) = 0;
  Reg(t + tim::kPsc) = 0;
  Reg(t + tim::kArr) = 0xFFFF;
  Reg(t + tim::kOr) = tim::kTim11OrHseRtc;
  Reg(t + tim::kCcmr1) = tim::kCcmr1Ic1Every8;
  Reg(t + tim::kCcer) = tim::kCcerCc1e;
  Reg(t + tim::kCr1) = tim::kCr1Cen;
  std::uint64_t ticks = 0;
  // 20 000 polls per capture: a few ms at 16 MHz, far above the 62 us the slowest crystal takes.
  const bool ok = CountTicksOverCaptures(
      CaptureChannel{t, t + tim::kCcr1, tim::kSrCc1if, tim::kSrCc1of, 0xFFFF}, kHseCaptures, 20000,
      false, ticks);
  // Everything back to its reset value: the timer, its clock and RTCPRE.
  Reg(t + tim::kCr1) = 0;
  Reg(t + tim::kCcer) = 0;
  Reg(t + tim::kCcmr1) = 0;
  Reg(t + tim::kOr) = 0;
  Reg(rcc::kApb2enr) &= ~rcc::kApb2Tim11;
  Modify(rcc::kCfgr, rcc::kCfgrRtcpreMask, 0);
  if (!ok) return false;
  hse_hz = HseHzFromTicks(ticks, kHseCaptures);
  return true;
}

namespace {
// A few bus cycles in practice; 10 000 polls at 16 MHz are well over a millisecond.
constexpr std::uint32_t kDbpPolls = 10000;
}  // namespace

void StartLse() {
  // The backup domain is write-protected after reset: DBP opens it for LSEON (RM0090 §5.1.2,
  // §7.3.20), then it is closed again.
  EnableClock(rcc::kApb1enr, rcc::kApb1Pwr);
  Reg(pwr::kCr) |= pwr::kCrDbp;
  // The backup domain takes the write only once DBP reads back set (ST's HAL polls it, bounded,
  // before touching RCC_BDCR): LSEON written earlier would be ignored and the LSE never start.
  if (WaitFor(pwr::kCr, pwr::kCrDbp, pwr::kCrDbp, kDbpPolls)) Reg(rcc::kBdcr) |= rcc::kBdcrLseOn;
  Reg(pwr::kCr) &= ~pwr::kCrDbp;
}

bool LseReady() { return (Reg(rcc::kBdcr) & rcc::kBdcrLseRdy) != 0; }

bool MeasureHseAgainstLse(std::uint32_t timer_hz, std::int64_t& milli_ppm) {
  const Address t = tim::kTim5;
  // TIM5 is the sampler's frame counter (external clock from TIM2's TRGO): its set-up is kept
  // and restored, the count included.
  const std::uint32_t saved[] = {Reg(t + tim::kCr1),  Reg(t + tim::kSmcr), Reg(t + tim::kCcmr2),
                                 Reg(t + tim::kCcer), Reg(t + tim::kOr),   Reg(t + tim::kPsc),
                                 Reg(t + tim::kArr),  Reg(t + tim::kCnt)};
  Reg(t + tim::kCr1) = 0;
  Reg(t + tim::kSmcr) = 0;  // internal clock: the APB1 timer clock, from the HSE
  Reg(t + tim::kPsc) = 0;
  Reg(t + tim::kArr) = 0xFFFFFFFF;
  Reg(t + tim::kEgr) = tim::kEgrUg;  // the prescaler and ARR take effect
  Reg(t + tim::kOr) = tim::kTim5OrLse;
  Reg(t + tim::kCcmr2) = tim::kCcmr2Ic4Every8;
  Reg(t + tim::kCcer) = tim::kCcerCc4e;
  Reg(t + tim::kCr1) = tim::kCr1Cen;
  std::uint64_t ticks = 0;
  // One capture every 8 LSE cycles (244 us); 200 000 polls is well over that at 168 MHz.
  const bool ok = CountTicksOverCaptures(
      CaptureChannel{t, t + tim::kCcr4, tim::kSrCc4if, tim::kSrCc4of, 0xFFFFFFFF}, kLseCaptures,
      200000, true, ticks);
  Reg(t + tim::kCr1) = 0;
  Reg(t + tim::kCcer) = 0;
  Reg(t + tim::kCcmr2) = saved[2];
  Reg(t + tim::kCcer) = saved[3];
  Reg(t + tim::kOr) = saved[4];
  Reg(t + tim::kPsc) = saved[5];
  Reg(t + tim::kArr) = saved[6];
  Reg(t + tim::kSmcr) = saved[1];
  Reg(t + tim::kCnt) = saved[7];
  Reg(t + tim::kSr) = 0;
  Reg(t + tim::kCr1) = saved[0];
  if (!ok) return false;
  milli_ppm = LseErrorMilliPpm(ticks, kLseCaptures, timer_hz);
  return true;
}

}  // namespace vibid::fw::stm32
