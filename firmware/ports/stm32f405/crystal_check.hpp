// The crystals measured by input capture, with no host needed: the HSE against the internal
// HSI before the PLL is allowed to use it (RM0090 §7.2, "Internal/external clock measurement using
// TIM5/TIM11": TIM11 channel 1 captures HSE_RTC, the HSE divided by RTCPRE), and, for the
// self-test, the HSE against the board's 32.768 kHz LSE crystal (TIM5 channel 4 on the LSE).
#pragma once

#include <cstdint>

#include "regs/mmio.hpp"

namespace vibid::fw::stm32 {

/// The HSI's nominal frequency: factory-trimmed to +-1 % at 25 C (STM32F405 datasheet, HSI
/// oscillator characteristics), the reference of the start-up check.
inline constexpr std::uint32_t kHsiHz = 16000000;
/// HSE_RTC = HSE / 31 (RTCPRE's largest divider): 129..839 kHz for a 4..26 MHz crystal.
inline constexpr std::uint32_t kHseRtcDivider = 31;
/// The capture prescaler (ICxPSC = 11): one capture every 8 input edges.
inline constexpr std::uint32_t kEdgesPerCapture = 8;
/// Captures the start-up check counts over: 64 x 8 x 31 = 15 872 HSE cycles, 2 ms at 8 MHz,
/// 31 744 HSI ticks: one tick is 32 ppm, far below the 2 % the check decides on.
inline constexpr std::uint32_t kHseCaptures = 64;
/// A crystal more than 1/50 (2 %) from the image's is refused: the HSI's own +-1 % leaves room,
/// and the nearest crystals with a plan (24 / 25 / 26 MHz, 4 %) are still told apart.
inline constexpr std::uint32_t kHseToleranceDivisor = 50;

/// The HSE in Hz from `ticks` HSI cycles over `captures` captures of HSE_RTC / 8, rounded.
/// Scaling and overflow: captures x 8 x 31 x 16e6 <= 2^32 x 248 x 1.6e7 < 1.8e19 needs
/// captures <= 4.6e3 (u64); the start-up check takes 64.
constexpr std::uint32_t HseHzFromTicks(std::uint64_t ticks, std::uint32_t captures) {
  if (ticks == 0) return 0;
  const std::uint64_t cycles = std::uint64_t{captures} * kEdgesPerCapture * kHseRtcDivider;
  return static_cast<std::uint32_t>((cycles * kHsiHz + ticks / 2) / ticks);
}

/// Whether `measured_hz` is within 2 % of `expected_hz`.
constexpr bool HseWithinTolerance(std::uint32_t measured_hz, std::uint32_t expected_hz) {
  const std::uint64_t diff =
      measured_hz > expected_hz ? measured_hz - expected_hz : expected_hz - measured_hz;
  return diff * kHseToleranceDivisor <= expected_hz;
}

/// One input-capture channel of a timer, polled.
struct CaptureChannel {
  Address timer;
  Address ccr;                 ///< Its capture register (reading it clears the capture flag).
  std::uint32_t flag;          ///< CCxIF.
  std::uint32_t overflow;      ///< CCxOF: a capture came while the previous one was unread.
  std::uint32_t counter_mask;  ///< 0xFFFF for a 16-bit timer.
};

/// Timer ticks from the first capture to the one `captures` later, as the sum of the captures'
/// differences (each one shorter than the counter's wrap). Each capture is awaited at most
/// `polls_per_capture` reads of the status register; `feed` feeds the watchdog every 64.
/// @returns false when a capture does not come or one was lost (overcapture).
bool CountTicksOverCaptures(const CaptureChannel& channel, std::uint32_t captures,
                            std::uint32_t polls_per_capture, bool feed, std::uint64_t& ticks);

/// On the HSI, with the HSE ready and before the PLL is set: TIM11 captures HSE_RTC (RTCPRE 31,
/// TIM11_OR TI1_RMP = HSE_RTC, IC1 every 8 edges) over kHseCaptures captures, and everything it
/// set goes back to its reset value. @returns false when no capture comes in time.
bool MeasureHseAgainstHsi(std::uint32_t& hse_hz);

/// Starts the 32.768 kHz LSE oscillator (PWR_CR DBP, RCC_BDCR LSEON) without waiting for it: its
/// start-up takes up to 2 s (datasheet), long before a self-test asks.
void StartLse();
bool LseReady();

/// The LSE captured 4096 x 8 times (1 s) by TIM5 channel 4 (TIM5_OR TI4_RMP = LSE) counting
/// `timer_hz` from the HSE: the crystal's error in milli-ppm against the LSE. TIM5 (the sampler's
/// frame counter) is put back as it was. Only while idle. @returns false when a capture does
/// not come or one is lost.
bool MeasureHseAgainstLse(std::uint32_t timer_hz, std::int64_t& milli_ppm);

/// Captures MeasureHseAgainstLse counts over: 4096 x 8 = 32 768 LSE cycles, exactly 1 s.
inline constexpr std::uint32_t kLseCaptures = 4096;
inline constexpr std::uint32_t kLseHz = 32768;

/// The HSE's error in milli-ppm from `ticks` of a timer nominally at `timer_hz` over
/// `captures` x 8 LSE cycles. Scaling and overflow: the nominal count is timer_hz x cycles /
/// 32768 <= 2^32 here; (ticks - nominal) x 10^9 stays within int64 for |ticks - nominal| < 9e9.
constexpr std::int64_t LseErrorMilliPpm(std::uint64_t ticks, std::uint32_t captures,
                                        std::uint32_t timer_hz) {
  const std::uint64_t cycles = std::uint64_t{captures} * kEdgesPerCapture;
  const std::int64_t nominal = static_cast<std::int64_t>(cycles * timer_hz / kLseHz);
  if (nominal == 0) return 0;
  return (static_cast<std::int64_t>(ticks) - nominal) * 1'000'000'000 / nominal;
}

}  // namespace vibid::fw::stm32
