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
/// 31 744 HSI ticks: one tick is 32 ppm, far below the band the check decides on.
inline constexpr std::uint32_t kHseCaptures = 64;

/// The HSI's spread over the part's whole temperature range, in permille of 16 MHz: -8 % to
/// +4.5 % from -40 to 105 C (STM32F405 datasheet DS8626, HSI oscillator characteristics,
/// ACC_HSI; +-1 % holds only at 25 C, -4 % / +4 % from -10 to 85 C). The check measures the HSE
/// in HSI ticks, so a crystal at f reads f x 16 MHz / f_HSI: from f / 1.045 to f / 0.92.
inline constexpr std::uint32_t kHsiSlowestPermille = 920;
inline constexpr std::uint32_t kHsiFastestPermille = 1045;
/// The band a crystal is accepted in, in percent of the image's: 95..109 % holds every reading of
/// the right crystal at any temperature the part allows (95.7..108.7 %), so a good crystal on a
/// cold or warm board is never refused, and is still far from the next crystal an image is built
/// for (kSupportedCrystalsHz: the nearest pair, 12 and 16 MHz, is 33 % apart).
inline constexpr std::uint32_t kHseAcceptLowPercent = 95;
inline constexpr std::uint32_t kHseAcceptHighPercent = 109;
/// The crystals the board images are built and tested for (README, "First board").
inline constexpr std::uint32_t kSupportedCrystalsHz[] = {8000000, 12000000, 16000000, 25000000};

/// The HSE in Hz from `ticks` HSI cycles over `captures` captures of HSE_RTC / 8, rounded.
/// Scaling and overflow: captures x 8 x 31 x 16e6 <= 2^32 x 248 x 1.6e7 < 1.8e19 needs
/// captures <= 4.6e3 (u64); the start-up check takes 64.
constexpr std::uint32_t HseHzFromTicks(std::uint64_t ticks, std::uint32_t captures) {
  if (ticks == 0) return 0;
  const std::uint64_t cycles = std::uint64_t{captures} * kEdgesPerCapture * kHseRtcDivider;
  return static_cast<std::uint32_t>((cycles * kHsiHz + ticks / 2) / ticks);
}

/// Whether `measured_hz` (against the HSI) is within 95..109 % of `expected_hz`.
constexpr bool HseWithinTolerance(std::uint32_t measured_hz, std::uint32_t expected_hz) {
  const std::uint64_t m = std::uint64_t{measured_hz} * 100;
  return m >= std::uint64_t{expected_hz} * kHseAcceptLowPercent &&
         m <= std::uint64_t{expected_hz} * kHseAcceptHighPercent;
}

/// Whether a board with a `fitted_hz` crystal passes an image for `image_hz` anywhere in the
/// HSI's spread: its lowest and highest readings, from the fastest and the slowest HSI.
constexpr bool AcceptedAtSomeTemperature(std::uint32_t fitted_hz, std::uint32_t image_hz) {
  const auto lowest =
      static_cast<std::uint32_t>(std::uint64_t{fitted_hz} * 1000 / kHsiFastestPermille);
  const auto highest = static_cast<std::uint32_t>(
      (std::uint64_t{fitted_hz} * 1000 + kHsiSlowestPermille - 1) / kHsiSlowestPermille);
  // The band is an interval and so is the reading's range: they meet when either end of one
  // lies in the other.
  return HseWithinTolerance(lowest, image_hz) || HseWithinTolerance(highest, image_hz) ||
         (std::uint64_t{lowest} * 100 <= std::uint64_t{image_hz} * kHseAcceptLowPercent &&
          std::uint64_t{highest} * 100 >= std::uint64_t{image_hz} * kHseAcceptHighPercent);
}
/// Whether the right crystal passes at every temperature (both ends of its reading's range).
constexpr bool AcceptedAtEveryTemperature(std::uint32_t hz) {
  return HseWithinTolerance(
             static_cast<std::uint32_t>(std::uint64_t{hz} * 1000 / kHsiFastestPermille), hz) &&
         HseWithinTolerance(
             static_cast<std::uint32_t>((std::uint64_t{hz} * 1000 + kHsiSlowestPermille - 1) /
                                        kHsiSlowestPermille),
             hz);
}
constexpr bool BandSeparatesTheSupportedCrystals() {
  for (const std::uint32_t image : kSupportedCrystalsHz) {
    if (!AcceptedAtEveryTemperature(image)) return false;
    for (const std::uint32_t fitted : kSupportedCrystalsHz) {
      if (fitted != image && AcceptedAtSomeTemperature(fitted, image)) return false;
    }
  }
  return true;
}
static_assert(
    BandSeparatesTheSupportedCrystals(),
    "the crystal band must pass the right crystal at any HSI error and refuse the others");

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
