// System clock bring-up: HSE crystal (VIBID_HSE_HZ, 8 MHz by default), checked against the HSI,
// -> PLL -> 168 MHz SYSCLK, exactly 48 MHz for USB. The PLL factors come from clock_plan.hpp at
// compile time.
#pragma once

#include <cstdint>

namespace vibid::fw::stm32 {

enum class ClockSource : std::uint8_t {
  kPllFromHse = 0,   ///< Normal: 168 MHz from the crystal; USB usable.
  kHsiFallback = 1,  ///< The crystal was refused or the PLL did not start: 16 MHz HSI.
};

/// Why a board is on the HSI (wire::ClockState's port side).
enum class HsiReason : std::uint8_t {
  kNone = 0,
  kHseDidNotStart = 1,     ///< HSERDY not set in time, or no edge of it reached TIM11.
  kHseWrongFrequency = 2,  ///< Measured outside 95..109 % of the crystal the image was built for.
  kPllDidNotLock = 3,      ///< PLLRDY, the flash wait states or the switch did not come.
};

struct ClockConfig {
  ClockSource source;
  std::uint32_t sysclk_hz;
  std::uint32_t apb1_timer_hz;  ///< TIM2..TIM5 kernel clock.
  std::uint32_t apb2_hz;
  HsiReason hsi_reason = HsiReason::kNone;
  std::uint32_t hse_measured_hz = 0;  ///< The crystal against the HSI at start; 0: not measured.
  /// PLL48CK runs (from the crystal, or on the HSI fallback from the HSI): the OTG core can
  /// enumerate, so the host can read why the board is on the HSI.
  bool usb_clocked = false;
};

/// Starts the HSE and measures it against the HSI (crystal_check.hpp) before the PLL may use
/// it; then 168 MHz (AHB 168, APB1 42, APB2 84, PLL48CK 48 MHz) with 5 flash wait states. Every
/// wait on the hardware is bounded. A crystal that does not start or reads outside 95..109 %
/// of VIBID_HSE_HZ (the HSI's spread, crystal_check.hpp) (an image for 8 MHz on a 12 MHz board
/// would run the core at 252 MHz), or a PLL that does not lock, leaves the core on the 16 MHz HSI,
/// the PLL on the HSI for USB's 48 MHz only, and the reason in the result, so get-info can report
/// it.
ClockConfig ConfigureClocks();

/// The crystal frequency this image was built for.
std::uint32_t HseHz();

}  // namespace vibid::fw::stm32
