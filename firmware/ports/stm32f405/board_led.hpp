// The board's status LED: lit once the image runs, so a board that shows nothing on USB still
// tells whether its image started (board definitions: cmake/boards.cmake).
#pragma once

#include <cstdint>

namespace vibid::fw::stm32 {

struct LedPin {
  unsigned port_index;  ///< 0 = GPIOA, 1 = GPIOB, 2 = GPIOC.
  unsigned pin;         ///< 0..15.
  bool active_high;     ///< Lit when the pin drives high (LED to ground) or low (LED to supply).
};

/// Drives `led` to its lit level, then makes the pin an output: the level is set before the
/// output driver turns on, so the pin never drives the other level.
void LightLed(const LedPin& led);

/// Drives `led` to its dark level (the pin stays an output).
void DarkenLed(const LedPin& led);

/// Whether the status LED is lit at `us` after boot: steadily on the crystal; on the HSI
/// fallback (crystal refused or not started) it blinks, 250 ms on and 250 ms off, so a board
/// that cannot be asked still shows that it runs but is not timing from its crystal.
constexpr bool StatusLedLit(bool on_crystal, std::uint64_t us) {
  return on_crystal || (us / 250000) % 2 == 0;
}

/// This image's board LED, lit; nothing on a board without one (board_definition.cpp).
void LightBoardLed();
/// This image's board LED lit or dark; nothing on a board without one.
void SetBoardLed(bool lit);

/// The board definition's facts the image needs (cmake/boards.cmake).
bool BoardHasLse();      ///< A 32.768 kHz crystal on PC14/PC15.
bool BoardSensesVbus();  ///< USB VBUS wired to PA9.

}  // namespace vibid::fw::stm32
