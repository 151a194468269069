// Chip-level services for the board image: reset cause, reset, watchdog, the ROM DFU bootloader,
// the board id, and the millisecond/cycle clocks.
#pragma once

#include <array>
#include <cstdint>

#include "vibid/shared/wire/device.hpp"

namespace vibid::fw::stm32 {

/// Reads and clears the reset flags (RCC_CSR, RM0090 §7.3.21). When several are set the most
/// specific wins: watchdogs, low-power and software resets first; then power-on (which also sets
/// the pin and brown-out flags); then brown-out; then the reset pin.
/// Call once, early at boot; a second call returns kUnknown.
wire::ResetCause ReadAndClearResetCause();
/// Requests a system reset (AIRCR.SYSRESETREQ); does not return.
[[noreturn]] void SystemReset();
/// Arranges for the next boot to jump to the ROM bootloader (USB DFU on PA11/PA12) and resets:
/// the ROM then starts from a clean chip state, not from ours.
[[noreturn]] void RebootToBootloader();
/// Called first thing from the reset handler: jumps to the ROM when RebootToBootloader asked.
void EnterBootloaderIfRequested();

/// True when the chip runs from anything but its reset clock state (HSI, PLL/HSE off, OTG clock
/// off): the ROM bootloader jumped here after a DFU "leave" without a reset (AN3156).
bool StartedWithoutReset();
/// Called first thing from the reset handler: a start without a reset becomes a system reset, so
/// the image always starts from the reset state (PLL off, OTG core idle, nothing pending).
void ResetIfStartedWithoutReset();

/// The LSI clocking the independent watchdog is 17..47 kHz (STM32F405 datasheet, LSI
/// characteristics): the timeout is computed at 47 kHz, the shortest it can be, and is up to
/// 2.8 times longer on a slow LSI.
inline constexpr std::uint32_t kLsiMaxHz = 47000;
inline constexpr std::uint32_t kWatchdogPrescaler = 32;
/// 4095 counts (the 12-bit reload) at 47 kHz / 32.
inline constexpr std::uint32_t kWatchdogMaxTimeoutMs =
    4095ULL * kWatchdogPrescaler * 1000 / kLsiMaxHz;
/// Reload count for a timeout of at least `timeout_ms` (clamped to 1..kWatchdogMaxTimeoutMs).
std::uint32_t WatchdogReload(std::uint32_t timeout_ms);
/// Starts the independent watchdog with a timeout of at least `timeout_ms` at any LSI frequency;
/// once started it cannot be stopped.
void StartWatchdog(std::uint32_t timeout_ms);
void KickWatchdog();

/// The 96-bit unique device id as 24 uppercase hex digits plus a terminating zero.
std::array<char, 25> BoardIdHex();

/// SysTick at 1 kHz from the core clock, plus the DWT cycle counter.
void StartMillisecondTick(std::uint32_t sysclk_hz);
/// Microseconds since StartMillisecondTick: the interrupt-counted milliseconds plus the SysTick
/// position within the current one. Callable from any context.
std::uint64_t MicrosecondsSinceBoot();
/// The SysTick interrupt handler body.
void OnSysTick();
/// DWT cycle counter (enabled by StartMillisecondTick).
std::uint32_t CycleCount();

}  // namespace vibid::fw::stm32
