// Chip-level services for the board image: reset cause, reset, watchdog, the ROM DFU bootloader,
// the board id, and the millisecond/cycle clocks.
#pragma once

#include <array>
#include <cstdint>

#include "vibid/shared/wire/commands.hpp"
#include "vibid/shared/wire/device.hpp"

namespace vibid::fw::stm32 {

/// Reads and clears the reset flags (RCC_CSR, RM0090 §7.3.21). When several are set the most
/// specific wins: watchdogs, low-power and software resets first; then power-on (which also sets
/// the pin and brown-out flags); then brown-out; then the reset pin. A software reset that
/// RecordFaultAndReset made (its record in .noinit is intact) is kFault, and `fault` gets the
/// record; the record is consumed either way, so the next commanded reset is kSoftware again.
/// Call once, early at boot; a second call returns kUnknown.
wire::ResetCause ReadAndClearResetCause(wire::FaultInfoResponse* fault = nullptr);

/// The fault handler's body (startup.cpp's DefaultHandler, for every fault and every exception
/// without a handler): keeps CFSR, HFSR, MMFAR, BFAR, the exception number and the stacked PC and
/// LR of `stacked_frame` (r0, r1, r2, r3, r12, lr, pc, xPSR as the exception entry pushed them;
/// nullptr when the stack pointer was not in RAM, then both read kFaultNoStackedValue) in a
/// .noinit record, and resets the chip. It runs before the watchdog may have started, so it
/// resets at once rather than waiting for it.
[[noreturn]] void RecordFaultAndReset(const std::uint32_t* stacked_frame, std::uint32_t exception);
/// Requests a system reset (AIRCR.SYSRESETREQ); does not return.
[[noreturn]] void SystemReset();
/// Arranges for the next boot to jump to the ROM bootloader (USB DFU on PA11/PA12) and resets:
/// the ROM then starts from a clean chip state, not from ours.
[[noreturn]] void RebootToBootloader();
/// Called first thing from the reset handler: jumps to the ROM when RebootToBootloader asked and
/// the reset was a software reset (RCC_CSR SFTRSTF; the flags are cleared later, by main).
void EnterBootloaderIfRequested();

/// True when anything the image would find at its reset value is not (the reset values of
/// RM0090 §7.3 and of the ARMv7-M system registers): a system clock or oscillator left on (RCC_CR
/// HSEON, CSSON, PLLON, PLLI2SON; RCC_CFGR nonzero), a peripheral clock that is off at reset, the
/// SysTick counter or its interrupt enabled, an NVIC line enabled, or VTOR moved. The ROM
/// bootloader's DFU "leave" jumps here without a reset (AN2606, AN3156) and frees what it used
/// (AN2662), so no single one of these is relied on; a debugger's "go" without reset is caught
/// the same way.
bool StartedWithoutReset();
/// First thing in the reset handler, before memory is initialised: masks interrupts, reads the
/// evidence of StartedWithoutReset, stops SysTick, points VTOR at `vector_table`, and turns a
/// start without reset into a system reset so the image always starts from the reset state
/// (PLL off, OTG core idle, nothing pending). Interrupts stay masked; main enables them once
/// its handlers' drivers are set up.
void TakeOverCore(std::uint32_t vector_table);

/// Debug builds: the independent watchdog stops while a debugger halts the core
/// (DBGMCU_APB1_FZ DBG_IWDG_STOP), so a breakpoint does not reset the board.
void FreezeWatchdogWhenHalted();

/// The LSI clocking the independent watchdog is 17..47 kHz (STM32F405 datasheet, LSI
/// characteristics): the timeout is computed at 47 kHz, the shortest it can be, and is up to
/// 2.8 times longer on a slow LSI.
inline constexpr std::uint32_t kLsiMaxHz = 47000;
inline constexpr std::uint32_t kWatchdogPrescaler = 32;
/// 4095 counts (the 12-bit reload) at 47 kHz / 32.
inline constexpr std::uint32_t kWatchdogMaxTimeoutMs =
    4095ULL * kWatchdogPrescaler * 1000 / kLsiMaxHz;
/// The board image's watchdog: at least 1 s at the fastest LSI. The main loop kicks it at least
/// once per SysTick (1 ms); a calibration commit kicks it right before each sector erase, which
/// then has the whole period (the CPU stalls while the flash erases), and while programming.
inline constexpr std::uint32_t kWatchdogTimeoutMs = 1000;
/// Reload count for a timeout of at least `timeout_ms` (clamped to 1..kWatchdogMaxTimeoutMs).
std::uint32_t WatchdogReload(std::uint32_t timeout_ms);
/// Starts the independent watchdog with a timeout of at least `timeout_ms` at any LSI frequency;
/// once started it cannot be stopped.
void StartWatchdog(std::uint32_t timeout_ms);
void KickWatchdog();

/// The brown-out reset threshold the option bytes set (FLASH_OPTCR BOR_LEV, RM0090 §3.9.10;
/// thresholds: STM32F405 datasheet, "reset and power control block characteristics").
enum class BrownOut : std::uint8_t {
  kLevel3 = 0,  ///< 2.75-2.88 V (DS8626): above the 2.7 V x32 flash programming needs (§3.6.2).
  kLevel2 = 1,  ///< About 2.4 V.
  kLevel1 = 2,  ///< About 2.1 V.
  kOff = 3,     ///< Only POR/PDR (about 1.8 V): the factory setting.
};
/// Reads the option bytes' brown-out level as the flash interface loaded it at reset.
BrownOut BrownOutLevel();

enum class BrownOutProgramming : std::uint8_t {
  kAlreadyLevel3,  ///< Nothing written.
  kProgrammed,     ///< The option bytes now hold level 3.
  kFailed,         ///< The flash stayed busy or the level did not read back: left as it was.
};
/// Brings the option bytes' brown-out reset to level 3 (2.75-2.88 V) once, at boot, before the
/// clock goes up: 168 MHz with 5 flash wait states holds only from 2.7 V (RM0090 table 10, 6-8
/// wait states below), and factory parts have the brown-out reset off. RM0090 §3.7.2
/// ("Programming user option bytes"): OPTKEY1, OPTKEY2 to FLASH_OPTKEYR, BSY clear, FLASH_OPTCR
/// with only BOR_LEV changed (read protection, write protection and the user bits written as
/// read), OPTSTRT, BSY clear, OPTLOCK. A board already at level 3 is not written (the option
/// bytes' sector has a limited number of erase cycles).
BrownOutProgramming EnsureBrownOutLevel3();

/// Flash access for `wait_states` (RM0090 table 10: 5 at 168 MHz and 2.7-3.6 V): instruction and
/// data caches reset, then on; prefetch off, because ES0182's ADC erratum ("internal noise
/// impacting the ADC accuracy") traces ADC noise to the prefetch's flash reads and gives this as
/// the workaround. @returns false when FLASH_ACR did not take the wait states.
[[nodiscard]] bool ConfigureFlashAccess(std::uint32_t wait_states);

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
/// Waits at least `cycles` core cycles by the DWT cycle counter, enabling it when it is off.
/// @returns false when the counter does not advance (no DWT, e.g. under QEMU), instead of
///          waiting for ever or for an unknown time.
[[nodiscard]] bool WaitCycles(std::uint32_t cycles);

}  // namespace vibid::fw::stm32
