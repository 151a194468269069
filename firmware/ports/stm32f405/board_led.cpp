#include "board_led.hpp"

#include "regs/core_m4.hpp"
#include "regs/peripherals.hpp"
#include "regs/rcc.hpp"

namespace vibid::fw::stm32 {

void LightLed(const LedPin& led) {
  // GPIOx sit 0x400 apart from GPIOA (RM0090 table 1); their clock enables are AHB1ENR bits
  // 0.. (§7.3.10).
  const Address port = gpio::kPortA + 0x400 * led.port_index;
  EnableClock(rcc::kAhb1enr, Bit(led.port_index));
  // BSRR: bits 15:0 set, bits 31:16 reset (RM0090 §8.4.7).
  Reg(port + gpio::kBsrr) = led.active_high ? Bit(led.pin) : Bit(led.pin + 16);
  gpio::SetMode(port, led.pin, gpio::Mode::kOutput);
}

void DarkenLed(const LedPin& led) {
  const Address port = gpio::kPortA + 0x400 * led.port_index;
  Reg(port + gpio::kBsrr) = led.active_high ? Bit(led.pin + 16) : Bit(led.pin);
}

}  // namespace vibid::fw::stm32
