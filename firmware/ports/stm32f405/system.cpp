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

// The fault handler's record: survives the system reset it makes (.noinit, neither copied nor
// zeroed by the startup code). A magic word and a check word over the rest tell it from the
// RAM's power-on contents and from a record the reset interrupted half-written.
struct KeptFault {
  std::uint32_t magic;
  std::uint32_t exception, cfsr, hfsr, mmfar, bfar, pc, lr;
  std::uint32_t check;
};
constexpr std::uint32_t kFaultMagic = 0xFA417EC0;
[[gnu::section(".noinit")]] volatile KeptFault g_fault;

std::uint32_t FaultCheck(std::uint32_t exception, std::uint32_t cfsr, std::uint32_t hfsr,
                         std::uint32_t mmfar, std::uint32_t bfar, std::uint32_t pc,
                         std::uint32_t lr) {
  // Rotations keep two swapped fields from checking alike.
  std::uint32_t c = 0x5EED0000;
  for (const std::uint32_t w : {exception, cfsr, hfsr, mmfar, bfar, pc, lr})
    c = ((c << 5) | (c >> 27)) ^ w;
  return ~c;
}

/// Takes the kept record, if intact, and invalidates it.
bool TakeFault(wire::FaultInfoResponse& out) {
  const bool intact =
      g_fault.magic == kFaultMagic && g_fault.exception <= 0xFF &&
      g_fault.check == FaultCheck(g_fault.exception, g_fault.cfsr, g_fault.hfsr, g_fault.mmfar,
                                  g_fault.bfar, g_fault.pc, g_fault.lr);
  if (intact) {
    out = wire::FaultInfoResponse{.recorded = 1,
                                  .exception = static_cast<std::uint8_t>(g_fault.exception),
                                  .cfsr = g_fault.cfsr,
                                  .hfsr = g_fault.hfsr,
                                  .mmfar = g_fault.mmfar,
                                  .bfar = g_fault.bfar,
                                  .pc = g_fault.pc,
                                  .lr = g_fault.lr};
  }
  g_fault.magic = 0;
  return intact;
}

}  // namespace

void RecordFaultAndReset(const std::uint32_t* stacked_frame, std::uint32_t exception) {
  // The exception entry pushed r0, r1, r2, r3, r12, lr, pc, xPSR (ARMv7-M ARM B1.5.6).
  const std::uint32_t pc = stacked_frame != nullptr ? stacked_frame[6] : wire::kFaultNoStackedValue;
  const std::uint32_t lr = stacked_frame != nullptr ? stacked_frame[5] : wire::kFaultNoStackedValue;
  const std::uint32_t cfsr = Reg(scb::kCfsr);
  const std::uint32_t hfsr = Reg(scb::kHfsr);
  const std::uint32_t mmfar = Reg(scb::kMmfar);
  const std::uint32_t bfar = Reg(scb::kBfar);
  exception &= 0xFF;
  g_fault.exception = exception;
  g_fault.cfsr = cfsr;
  g_fault.hfsr = hfsr;
  g_fault.mmfar = mmfar;
  g_fault.bfar = bfar;
  g_fault.pc = pc;
  g_fault.lr = lr;
  g_fault.check = FaultCheck(exception, cfsr, hfsr, mmfar, bfar, pc, lr);
  g_fault.magic = kFaultMagic;
  SystemReset();
}

wire::ResetCause ReadAndClearResetCause(wire::FaultInfoResponse* fault) {
  using wire::ResetCause;
  const std::uint32_t csr = Reg(rcc::kCsr);
  Reg(rcc::kCsr) |= rcc::kCsrRmvf;
  wire::FaultInfoResponse kept;
  // Consumed whatever the cause: a record a power cycle or the watchdog overtook is stale.
  const bool faulted = TakeFault(kept);
  if ((csr & (rcc::kCsrIwdgRstf | rcc::kCsrWwdgRstf)) != 0) return ResetCause::kWatchdog;
  if ((csr & rcc::kCsrLpwrRstf) != 0) return ResetCause::kLowPower;
  if ((csr & rcc::kCsrSftRstf) != 0) {
    if (!faulted) return ResetCause::kSoftware;
    if (fault != nullptr) *fault = kept;
    return ResetCause::kFault;
  }
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
  // Only the software reset RebootToBootloader asked for honours the word (RCC_CSR SFTRSTF, as
  // MicroPython pairs its bootloader request with it): .noinit RAM that happens to hold it after
  // a pin or watchdog reset, or a request whose reset never came, does not send the board to
  // the ROM.
  if ((Reg(rcc::kCsr) & rcc::kCsrSftRstf) == 0) return;
  // Map system memory at 0 as a boot from BOOT0 = 1 would, then start the ROM with its own
  // stack pointer and reset vector.
  EnableClock(rcc::kApb2enr, rcc::kApb2Syscfg);
  Reg(kSyscfgMemrmp) = kMemrmpSystemFlash;
  const std::uint32_t stack = Reg(kSystemMemory);
  const std::uint32_t entry = Reg(kSystemMemory + 4);
  // The ROM expects the core as a reset leaves it: VTOR 0 (now the ROM's own table) and
  // interrupts unmasked; TakeOverCore changed both, and nothing can interrupt yet.
  Reg(scb::kVtor) = 0;
  DataSyncBarrier();
  EnableInterrupts();
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
  // RCC_CR resets to 0x0000XX83: HSI on, everything else off (RM0090 §7.3.1); RCC_CFGR to 0,
  // HSI as system clock and no prescaler (§7.3.3).
  constexpr std::uint32_t kOscillators =
      rcc::kCrHseOn | rcc::kCrCssOn | rcc::kCrPllOn | rcc::kCrPlli2sOn;
  const bool clock_tree = (Reg(rcc::kCr) & kOscillators) != 0 || Reg(rcc::kCfgr) != 0;
  // Peripheral clocks off at reset: all but CCM data RAM (§7.3.10 to §7.3.14).
  const bool peripheral_clock = (Reg(rcc::kAhb1enr) & ~rcc::kAhb1CcmDataRam) != 0 ||
                                Reg(rcc::kAhb2enr) != 0 || Reg(rcc::kAhb3enr) != 0 ||
                                Reg(rcc::kApb1enr) != 0 || Reg(rcc::kApb2enr) != 0;
  // SYST_CSR resets with ENABLE and TICKINT clear, NVIC_ISERn and VTOR to 0 (ARMv7-M ARM
  // B3.3.3, B3.4.4, B3.2.5).
  const bool systick = (Reg(systick::kCtrl) & (systick::kCtrlEnable | systick::kCtrlTickInt)) != 0;
  bool nvic_line = false;
  for (unsigned w = 0; w < nvic::kIserWords; ++w) nvic_line |= Reg(nvic::kIser + 4 * w) != 0;
  const bool vtor_moved = Reg(scb::kVtor) != 0;
  return clock_tree || peripheral_clock || systick || nvic_line || vtor_moved;
}

void TakeOverCore(std::uint32_t vector_table) {
  // Nothing a previous owner armed may run before the image has its own state: no interrupt,
  // no SysTick, and exceptions vectored to this image's table.
  DisableInterrupts();
  const bool without_reset = StartedWithoutReset();
  Reg(systick::kCtrl) = 0;
  Reg(scb::kVtor) = vector_table;
  DataSyncBarrier();
  InstructionSyncBarrier();
  if (without_reset) SystemReset();
}

void FreezeWatchdogWhenHalted() { Reg(dbgmcu::kApb1Fz) |= dbgmcu::kApb1FzIwdgStop; }

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

BrownOut BrownOutLevel() {
  return static_cast<BrownOut>((Reg(flash::kOptcr) & flash::kOptcrBorLevMask) >>
                               flash::kOptcrBorLevPos);
}

BrownOutProgramming EnsureBrownOutLevel3() {
  if (BrownOutLevel() == BrownOut::kLevel3) return BrownOutProgramming::kAlreadyLevel3;
  // The option bytes' erase and write take up to a sector erase's time (hundreds of ms at most):
  // the watchdog (1 s) is fed before and polled against a bound far above that at 16 MHz.
  constexpr std::uint32_t kBusyPolls = 4000000;
  KickWatchdog();
  if (!WaitFor(flash::kSr, flash::kSrBsy, 0, kBusyPolls)) return BrownOutProgramming::kFailed;
  Reg(flash::kOptkeyr) = flash::kOptKey1;
  Reg(flash::kOptkeyr) = flash::kOptKey2;
  // Only BOR_LEV changes (00: level 3); RDP (15:8) is written back as read, so read protection
  // never moves (0xCC would lock the chip for good).
  const std::uint32_t options =
      Reg(flash::kOptcr) & ~(flash::kOptcrBorLevMask | flash::kOptcrOptlock | flash::kOptcrOptstrt);
  Reg(flash::kOptcr) = options;
  Reg(flash::kOptcr) = options | flash::kOptcrOptstrt;
  const bool done = WaitFor(flash::kSr, flash::kSrBsy, 0, kBusyPolls);
  KickWatchdog();
  Reg(flash::kOptcr) |= flash::kOptcrOptlock;
  return done && BrownOutLevel() == BrownOut::kLevel3 ? BrownOutProgramming::kProgrammed
                                                      : BrownOutProgramming::kFailed;
}

bool ConfigureFlashAccess(std::uint32_t wait_states) {
  // The cache resets work only while the caches are off (RM0090 §3.5.2 / FLASH_ACR ICRST, DCRST);
  // the latency goes in first so it never lags the clock.
  Reg(flash::kAcr) = wait_states | flash::kAcrIcrst | flash::kAcrDcrst;
  Reg(flash::kAcr) = wait_states;
  Reg(flash::kAcr) = wait_states | flash::kAcrIcen | flash::kAcrDcen;
  return (Reg(flash::kAcr) & flash::kAcrLatencyMask) == wait_states;
}

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

bool WaitCycles(std::uint32_t cycles) {
  // TRCENA powers the DWT (ARMv7-M ARM C1.6.5), CYCCNTENA starts the counter (C1.8.7).
  if ((Reg(dwt::kCtrl) & dwt::kCtrlCyccntEna) == 0) {
    Reg(scb::kDemcr) |= scb::kDemcrTrcena;
    Reg(dwt::kCtrl) |= dwt::kCtrlCyccntEna;
  }
  // Unsigned differences survive the counter's wrap (25.6 s at 168 MHz).
  const std::uint32_t start = Reg(dwt::kCyccnt);
  constexpr std::uint32_t kStuckPolls = 1000;  // Each poll takes several cycles.
  std::uint32_t last = start;
  std::uint32_t unchanged = 0;
  for (;;) {
    const std::uint32_t now = Reg(dwt::kCyccnt);
    if (now - start >= cycles) return true;
    unchanged = now == last ? unchanged + 1 : 0;
    if (unchanged >= kStuckPolls) return false;
    last = now;
  }
}

}  // namespace vibid::fw::stm32
