// What one board definition (cmake/boards.cmake) puts into an image besides its crystal
// (clock.cpp): the status LED, from VIBID_LED_PORT_INDEX, VIBID_LED_PIN, VIBID_LED_ACTIVE_HIGH,
// whether it has an LSE crystal (VIBID_BOARD_LSE) and VBUS on PA9 (VIBID_BOARD_VBUS_PA9).
#include "board_led.hpp"

namespace vibid::fw::stm32 {

#if defined(VIBID_LED_PIN)
static_assert(VIBID_LED_PORT_INDEX <= 2 && VIBID_LED_PIN <= 15, "LED on GPIOA..C, pin 0..15");
namespace {
constexpr LedPin kBoardLed{VIBID_LED_PORT_INDEX, VIBID_LED_PIN, VIBID_LED_ACTIVE_HIGH != 0};
}  // namespace
void LightBoardLed() { LightLed(kBoardLed); }
void SetBoardLed(bool lit) {
  if (lit) {
    LightLed(kBoardLed);
  } else {
    DarkenLed(kBoardLed);
  }
}
#else
void LightBoardLed() {}
void SetBoardLed(bool) {}
#endif

#if !defined(VIBID_BOARD_LSE) || !defined(VIBID_BOARD_VBUS_PA9)
#error \
    "VIBID_BOARD_LSE and VIBID_BOARD_VBUS_PA9 are set by the board definition (cmake/boards.cmake)"
#endif
bool BoardHasLse() { return VIBID_BOARD_LSE != 0; }
bool BoardSensesVbus() { return VIBID_BOARD_VBUS_PA9 != 0; }

}  // namespace vibid::fw::stm32
