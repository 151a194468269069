// System clock bring-up: HSE crystal (VIBID_HSE_HZ, 8 MHz by default) -> PLL -> 168 MHz SYSCLK,
// exactly 48 MHz for USB. The PLL factors come from clock_plan.hpp at compile time.
#pragma once

#include <cstdint>

namespace vibid::fw::stm32 {

enum class ClockSource : std::uint8_t {
  kPllFromHse = 0,   ///< Normal: 168 MHz from the crystal; USB usable.
  kHsiFallback = 1,  ///< HSE or PLL did not start in time: 16 MHz HSI, USB not clocked.
};

struct ClockConfig {
  ClockSource source;
  std::uint32_t sysclk_hz;
  std::uint32_t apb1_timer_hz;  ///< TIM2..TIM5 kernel clock.
  std::uint32_t apb2_hz;
};

/// Switches to 168 MHz (AHB 168, APB1 42, APB2 84, PLL48CK 48 MHz) with 5 flash wait states.
/// Every wait on the hardware is bounded; a crystal or PLL that does not come up leaves the
/// chip on HSI and says so in the result, so get-info can report it.
ClockConfig ConfigureClocks();

/// The crystal frequency this image was built for.
std::uint32_t HseHz();

}  // namespace vibid::fw::stm32
