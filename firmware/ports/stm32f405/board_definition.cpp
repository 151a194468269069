// What one board definition (cmake/boards.cmake) puts into an image besides its crystal
// (clock.cpp): the status LED, from VIBID_LED_PORT_INDEX, VIBID_LED_PIN, VIBID_LED_ACTIVE_HIGH.
#include "board_led.hpp"

namespace vibid::fw::stm32 {

void LightBoardLed() {
#if defined(VIBID_LED_PIN)
  static_assert(VIBID_LED_PORT_INDEX <= 2 && VIBID_LED_PIN <= 15, "LED on GPIOA..C, pin 0..15");
  LightLed(LedPin{VIBID_LED_PORT_INDEX, VIBID_LED_PIN, VIBID_LED_ACTIVE_HIGH != 0});
#endif
}

}  // namespace vibid::fw::stm32
