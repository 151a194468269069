// Chip-level services for the board image: reset cause, reset, watchdog, the ROM DFU bootloader,
// the board id, and the millisecond/cycle clocks.
#pragma once

#include <array>
#include <cstdint>

namespace vibid::fw::stm32 {

/// Why the chip last reset (RCC_CSR flags, RM0090 §7.3.21). When several flags are set the most
/// specific wins: watchdogs and software resets over pin, pin over brown-out, over power-on.
enum class ResetCause : std::uint8_t {
  kUnknown = 0,
  kPowerOn = 1,
  kPin = 2,
  kBrownOut = 3,
  kSoftware = 4,
  kIndependentWatchdog = 5,
  kWindowWatchdog = 6,
  kLowPower = 7,
};

/// Reads and clears the reset flags. Call once, early at boot; later calls return kUnknown.
ResetCause ReadAndClearResetCause();
/// Requests a system reset (AIRCR.SYSRESETREQ); does not return.
[[noreturn]] void SystemReset();
/// Arranges for the next boot to jump to the ROM bootloader (USB DFU on PA11/PA12) and resets:
/// the ROM then starts from a clean chip state, not from ours.
[[noreturn]] void RebootToBootloader();
/// Called first thing from the reset handler: jumps to the ROM when RebootToBootloader asked.
void EnterBootloaderIfRequested();

/// Starts the independent watchdog (LSI ~32 kHz) with a timeout of about `timeout_ms`
/// (1..4000); once started it cannot be stopped.
void StartWatchdog(std::uint32_t timeout_ms);
void KickWatchdog();

/// The 96-bit unique device id as 24 uppercase hex digits plus a terminating zero.
std::array<char, 25> BoardIdHex();

/// SysTick at 1 kHz from the core clock; MillisecondsSinceBoot counts its interrupts.
void StartMillisecondTick(std::uint32_t sysclk_hz);
std::uint32_t MillisecondsSinceBoot();
void OnSysTick();
/// DWT cycle counter (enabled by StartMillisecondTick).
std::uint32_t CycleCount();

}  // namespace vibid::fw::stm32
