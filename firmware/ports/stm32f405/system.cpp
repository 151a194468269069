#include "system.hpp"

#include "regs/core_m4.hpp"
#include "regs/peripherals.hpp"
#include "regs/rcc.hpp"

namespace vibid::fw::stm32 {
namespace {

constexpr std::uint32_t kBootloaderMagic = 0xB007DF00;
// Survives a system reset: placed in a section the startup code neither copies nor zeroes.
[[gnu::section(".noinit")]] volatile std::uint32_t g_bootloader_request;
std::uint64_t g_milliseconds = 0;  // Written by SysTick only; read with SysTick masked.
std::uint32_t g_ticks_per_us = 16;

constexpr Address kSyscfgMemrmp = 0x40013800;
constexpr std::uint32_t kMemrmpSystemFlash = 0x1;

}  // namespace

wire::ResetCause ReadAndClearResetCause() {
  using wire::ResetCause;
  const std::uint32_t csr = Reg(rcc::kCsr);
  Reg(rcc::kCsr) |= rcc::kCsrRmvf;
  if ((csr & (rcc::kCsrIwdgRstf | rcc::kCsrWwdgRstf)) != 0) return ResetCause::kWatchdog;
  if ((csr & rcc::kCsrLpwrRstf) != 0) return ResetCause::kLowPower;
  if ((csr & rcc::kCsrSftRstf) != 0) return ResetCause::kSoftware;
  // A power-on also sets PINRSTF and BORRSTF, so POR is checked before them.
  if ((csr & rcc::kCsrPorRstf) != 0) return ResetCause::kPowerOn;
  if ((csr & rcc::kCsrBorRstf) != 0) return ResetCause::kBrownOut;
  if ((csr & rcc::kCsrPinRstf) != 0) return ResetCause::kPin;
  return ResetCause::kUnknown;
}

void SystemReset() {
  DataSyncBarrier();
  Reg(scb::kAircr) = scb::kAircrVectKey | scb::kAircrSysResetReq;
  DataSyncBarrier();
#if defined(VIBID_STM32_FAKE_REGISTERS)
  fake::Halt();
#endif
  for (;;) {
  }
}

void RebootToBootloader() {
  g_bootloader_request = kBootloaderMagic;
  SystemReset();
}

void EnterBootloaderIfRequested() {
  if (g_bootloader_request != kBootloaderMagic) return;
  g_bootloader_request = 0;
  // Map system memory at 0 as a boot from BOOT0 = 1 would, then start the ROM with its own
  // stack pointer and reset vector.
  EnableClock(rcc::kApb2enr, rcc::kApb2Syscfg);
  Reg(kSyscfgMemrmp) = kMemrmpSystemFlash;
  const std::uint32_t stack = Reg(kSystemMemory);
  const std::uint32_t entry = Reg(kSystemMemory + 4);
#if defined(__arm__)
  asm volatile(
      "msr msp, %0\n"
      "bx %1\n" ::"r"(stack),
      "r"(entry));
#else
  (void)stack;
  (void)entry;
#endif
}

bool StartedWithoutReset() {
  // After any reset the chip runs from HSI with HSE, PLL and the OTG clock off (RM0090 §7.3.1,
  // §7.3.3 and §7.3.11 reset values). The ROM bootloader's DFU "leave" jumps here with its own
  // USB clocking still up (AN3156), and a debugger "go" without reset does the same.
  const bool pll_system_clock = (Reg(rcc::kCfgr) & rcc::kCfgrSwsMask) != rcc::kCfgrSwsHsi;
  const bool oscillators_on = (Reg(rcc::kCr) & (rcc::kCrPllOn | rcc::kCrHseOn)) != 0;
  const bool otg_clock_on = (Reg(rcc::kAhb2enr) & rcc::kAhb2OtgFs) != 0;
  return pll_system_clock || oscillators_on || otg_clock_on;
}

void ResetIfStartedWithoutReset() {
  if (StartedWithoutReset()) SystemReset();
}

std::uint32_t WatchdogReload(std::uint32_t timeout_ms) {
  if (timeout_ms < 1) timeout_ms = 1;
  if (timeout_ms > kWatchdogMaxTimeoutMs) timeout_ms = kWatchdogMaxTimeoutMs;
  // Counts at the fastest LSI, rounded up: the timeout is never shorter than asked.
  const std::uint64_t counts =
      (std::uint64_t{timeout_ms} * kLsiMaxHz + std::uint64_t{kWatchdogPrescaler} * 1000 - 1) /
      (std::uint64_t{kWatchdogPrescaler} * 1000);
  return static_cast<std::uint32_t>(counts);
}

void StartWatchdog(std::uint32_t timeout_ms) {
  Reg(iwdg::kKr) = iwdg::kKeyStart;
  Reg(iwdg::kKr) = iwdg::kKeyUnlock;
  Reg(iwdg::kPr) = iwdg::kPrDiv32;
  Reg(iwdg::kRlr) = WatchdogReload(timeout_ms) - 1;
  (void)WaitFor(iwdg::kSr, iwdg::kSrBusy, 0, 1000000);
  Reg(iwdg::kKr) = iwdg::kKeyReload;
}

void KickWatchdog() { Reg(iwdg::kKr) = iwdg::kKeyReload; }

std::array<char, 25> BoardIdHex() {
  static constexpr char kHex[] = "0123456789ABCDEF";
  std::array<char, 25> out{};
  for (unsigned word = 0; word < 3; ++word) {
    const std::uint32_t v = Reg(uid::kBase + 4 * word);
    for (unsigned nibble = 0; nibble < 8; ++nibble) {
      out[8 * word + nibble] = kHex[(v >> (28 - 4 * nibble)) & 0xF];
    }
  }
  out[24] = '\0';
  return out;
}

void StartMillisecondTick(std::uint32_t sysclk_hz) {
  g_ticks_per_us = sysclk_hz / 1000000;
  Reg(scb::kDemcr) |= scb::kDemcrTrcena;
  Reg(dwt::kCyccnt) = 0;
  Reg(dwt::kCtrl) |= dwt::kCtrlCyccntEna;
  Reg(systick::kLoad) = sysclk_hz / 1000 - 1;
  Reg(systick::kVal) = 0;
  Reg(systick::kCtrl) = systick::kCtrlEnable | systick::kCtrlTickInt | systick::kCtrlClkSourceCpu;
}

std::uint64_t MicrosecondsSinceBoot() {
  CriticalSection lock;
  std::uint64_t ms = g_milliseconds;
  const std::uint32_t load = Reg(systick::kLoad);
  std::uint32_t val = Reg(systick::kVal);
  // A wrap since the interrupt was masked is pending but not yet counted: count it, and re-read
  // the counter so it belongs to the new millisecond.
  if ((Reg(scb::kIcsr) & scb::kIcsrPendstset) != 0) {
    ++ms;
    val = Reg(systick::kVal);
  }
  return ms * 1000 + (load - val) / g_ticks_per_us;
}

void OnSysTick() { ++g_milliseconds; }
std::uint32_t CycleCount() { return Reg(dwt::kCyccnt); }

}  // namespace vibid::fw::stm32
