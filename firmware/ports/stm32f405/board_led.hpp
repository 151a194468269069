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

/// This image's board LED, lit; nothing on a board without one (board_definition.cpp).
void LightBoardLed();

}  // namespace vibid::fw::stm32
