// Cortex-M4 system registers (ARMv7-M architecture reference manual, Cortex-M4 generic user
// guide §4): SCB, NVIC, SysTick, DWT cycle counter, FPU access.
#pragma once

#include "mmio.hpp"

namespace vibid::fw::stm32 {

namespace scb {
inline constexpr Address kCpuid = 0xE000ED00;
inline constexpr Address kIcsr = 0xE000ED04;
inline constexpr Address kVtor = 0xE000ED08;
inline constexpr Address kAircr = 0xE000ED0C;
inline constexpr Address kCpacr = 0xE000ED88;
inline constexpr Address kDemcr = 0xE000EDFC;
/// Fault status and address registers (ARMv7-M ARM B3.2.15-B3.2.18; Cortex-M4 generic user guide
/// §4.3.10-4.3.13): CFSR (MemManage, BusFault, UsageFault status), HFSR, MMFAR, BFAR.
inline constexpr Address kCfsr = 0xE000ED28;
inline constexpr Address kHfsr = 0xE000ED2C;
inline constexpr Address kMmfar = 0xE000ED34;
inline constexpr Address kBfar = 0xE000ED38;
/// AIRCR writes need the key in bits 31:16; SYSRESETREQ (bit 2) requests a system reset.
inline constexpr std::uint32_t kAircrVectKey = 0x05FAU << 16;
inline constexpr std::uint32_t kAircrSysResetReq = Bit(2);
/// CPACR: full access to CP10 and CP11 (the FPU), bits 23:20.
inline constexpr std::uint32_t kCpacrFpuFull = 0xFU << 20;
inline constexpr std::uint32_t kDemcrTrcena = Bit(24);
/// ICSR PENDSTSET: a SysTick exception is pending.
inline constexpr std::uint32_t kIcsrPendstset = Bit(26);
}  // namespace scb

namespace nvic {
inline constexpr Address kIser = 0xE000E100;  ///< Set-enable, one bit per IRQ, 32 per word.
inline constexpr Address kIcer = 0xE000E180;  ///< Clear-enable.
inline constexpr Address kIcpr = 0xE000E280;  ///< Clear-pending.
inline constexpr Address kIpr = 0xE000E400;   ///< Priority, one byte per IRQ (top 4 bits used).
/// ISER words that hold the STM32F405's 82 interrupt lines (0..81).
inline constexpr unsigned kIserWords = 3;

inline void Enable(unsigned irq) { Reg(kIser + 4 * (irq / 32)) = Bit(irq % 32); }
inline void Disable(unsigned irq) { Reg(kIcer + 4 * (irq / 32)) = Bit(irq % 32); }
inline void ClearPending(unsigned irq) { Reg(kIcpr + 4 * (irq / 32)) = Bit(irq % 32); }
/// Priority 0 (highest) .. 15; the STM32F4 implements 4 priority bits.
inline void SetPriority(unsigned irq, unsigned priority) {
  Reg8(kIpr + irq) = static_cast<std::uint8_t>(priority << 4);
}
}  // namespace nvic

namespace systick {
inline constexpr Address kCtrl = 0xE000E010;
inline constexpr Address kLoad = 0xE000E014;
inline constexpr Address kVal = 0xE000E018;
inline constexpr std::uint32_t kCtrlEnable = Bit(0);
inline constexpr std::uint32_t kCtrlTickInt = Bit(1);
inline constexpr std::uint32_t kCtrlClkSourceCpu = Bit(2);
}  // namespace systick

/// STM32F4 debug support (RM0090 §38.16): DBGMCU_APB1_FZ freezes APB1 peripherals while the
/// core is halted by a debugger; DBG_IWDG_STOP (bit 12) stops the independent watchdog.
namespace dbgmcu {
inline constexpr Address kApb1Fz = 0xE0042008;
inline constexpr std::uint32_t kApb1FzIwdgStop = Bit(12);
}  // namespace dbgmcu

namespace dwt {
inline constexpr Address kCtrl = 0xE0001000;
inline constexpr Address kCyccnt = 0xE0001004;
inline constexpr std::uint32_t kCtrlCyccntEna = Bit(0);
}  // namespace dwt

/// STM32F405 interrupt numbers used by the ports (RM0090 table 61, vector table).
namespace irq {
inline constexpr unsigned kAdc = 18;
inline constexpr unsigned kTim2 = 28;
inline constexpr unsigned kUsart1 = 37;
inline constexpr unsigned kDma2Stream0 = 56;
inline constexpr unsigned kOtgFs = 67;
inline constexpr unsigned kCount = 82;  ///< Vector entries after the 16 system exceptions.
}  // namespace irq

#if defined(VIBID_STM32_FAKE_REGISTERS)

// Host build of the port's tests: barriers and interrupt masking are events the fake register
// file records, so a test can check that a barrier follows a clock enable.
namespace fake {
enum class CpuOp : std::uint8_t { kDisableIrq, kEnableIrq, kWfi, kDsb, kIsb };
void Cpu(CpuOp op);
/// Where the target would never return (after a reset request): the test's register file throws.
[[noreturn]] void Halt();
}  // namespace fake
inline void DisableInterrupts() { fake::Cpu(fake::CpuOp::kDisableIrq); }
inline void EnableInterrupts() { fake::Cpu(fake::CpuOp::kEnableIrq); }
inline void WaitForInterrupt() { fake::Cpu(fake::CpuOp::kWfi); }
inline void DataSyncBarrier() { fake::Cpu(fake::CpuOp::kDsb); }
inline void InstructionSyncBarrier() { fake::Cpu(fake::CpuOp::kIsb); }

/// Single-threaded tests: nothing to mask. User-provided members keep `CriticalSection lock;`
/// from warning as unused.
class CriticalSection {
 public:
  CriticalSection() {}   // NOLINT(modernize-use-equals-default)
  ~CriticalSection() {}  // NOLINT(modernize-use-equals-default)
  CriticalSection(const CriticalSection&) = delete;
  CriticalSection& operator=(const CriticalSection&) = delete;
};

#else

inline void DisableInterrupts() { asm volatile("cpsid i" ::: "memory"); }
inline void EnableInterrupts() { asm volatile("cpsie i" ::: "memory"); }
inline void WaitForInterrupt() { asm volatile("wfi"); }
inline void DataSyncBarrier() { asm volatile("dsb 0xF" ::: "memory"); }
inline void InstructionSyncBarrier() { asm volatile("isb 0xF" ::: "memory"); }

/// Saves PRIMASK and masks interrupts for the scope.
class CriticalSection {
 public:
  CriticalSection() {
    asm volatile("mrs %0, primask" : "=r"(primask_));
    DisableInterrupts();
  }
  ~CriticalSection() { asm volatile("msr primask, %0" ::"r"(primask_) : "memory"); }
  CriticalSection(const CriticalSection&) = delete;
  CriticalSection& operator=(const CriticalSection&) = delete;

 private:
  std::uint32_t primask_ = 0;
};

#endif

/// Enables a peripheral clock and waits for it to take effect: ES0182 §2.1.13 (a delay after an
/// RCC peripheral clock enable) asks for a DSB before the peripheral's registers are touched.
inline void EnableClock(Address rcc_enable_register, std::uint32_t bits) {
  Reg(rcc_enable_register) |= bits;
  DataSyncBarrier();
}

}  // namespace vibid::fw::stm32
