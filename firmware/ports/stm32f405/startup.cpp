// Reset handler and vector table for the STM32F405 (RM0090 table 61). Shared by the board image
// and the QEMU netduinoplus2 image: the same chip, the same memory map.
//
// Handlers are weak aliases of DefaultHandler; an image defines the ones it uses
// (extern "C" void TIM2_IRQHandler() { ... }).
#include <array>
#include <cstdint>

#include "regs/core_m4.hpp"
#include "system.hpp"

extern "C" {
// Linker script symbols.
extern std::uint32_t _estack;
extern std::uint32_t _sidata, _sdata, _edata, _sbss, _ebss, _sccm_bss, _eccm_bss;
extern void (*__init_array_start[])();
extern void (*__init_array_end[])();

// The application's main(), reached through its symbol: ISO C++ does not let a program call
// main by name.
int ApplicationMain() __asm__("main");
[[noreturn]] void ResetHandler();
[[noreturn]] void ResetHandlerBody();

[[noreturn]] void FaultCapture(const std::uint32_t* stack, std::uint32_t ipsr);

// Every fault (HardFault, MemManage, BusFault, UsageFault) and every exception or interrupt
// without a handler. It may come before main has started the watchdog (a static constructor, the
// memory set-up), where waiting for the watchdog would hang for good, so it resets at once, after
// keeping a record the next boot reports (reset cause "fault", get-info's fault page). Naked: the
// frame the exception entry stacked is found from EXC_RETURN bit 2 (0: MSP, 1: PSP; ARMv7-M ARM
// B1.5.8), and MSP moves to the top of the stack before any C++ runs, so a fault from a stack
// overflow does not fault again on the way to its record.
[[gnu::naked]] void DefaultHandler() {
  asm volatile(
      "tst lr, #4\n"
      "ite eq\n"
      "mrseq r0, msp\n"
      "mrsne r0, psp\n"
      "mrs r1, ipsr\n"
      "ldr r2, =_estack\n"
      "msr msp, r2\n"
      "b FaultCapture\n");
}

void FaultCapture(const std::uint32_t* stack, std::uint32_t ipsr) {
  // The eight stacked words are read only where RAM is: SRAM 0x20000000-0x2001FFFF or CCM
  // 0x10000000-0x1000FFFF (RM0090 §2.3); a stack pointer elsewhere (an overflow below CCM) gives
  // no PC or LR rather than a second fault.
  const auto sp = static_cast<std::uint32_t>(reinterpret_cast<std::uintptr_t>(stack));
  constexpr std::uint32_t kFrameBytes = 32;
  const bool in_sram = sp >= 0x20000000u && sp <= 0x20020000u - kFrameBytes;
  const bool in_ccm = sp >= 0x10000000u && sp <= 0x10010000u - kFrameBytes;
  const bool readable = (sp & 3u) == 0 && (in_sram || in_ccm);
  vibid::fw::stm32::RecordFaultAndReset(readable ? stack : nullptr, ipsr & 0x1FFu);
}

#define VIBID_WEAK_HANDLER(name) void name() noexcept __attribute__((weak, alias("DefaultHandler")))
VIBID_WEAK_HANDLER(NMI_Handler);
VIBID_WEAK_HANDLER(HardFault_Handler);
VIBID_WEAK_HANDLER(MemManage_Handler);
VIBID_WEAK_HANDLER(BusFault_Handler);
VIBID_WEAK_HANDLER(UsageFault_Handler);
VIBID_WEAK_HANDLER(SVC_Handler);
VIBID_WEAK_HANDLER(DebugMon_Handler);
VIBID_WEAK_HANDLER(PendSV_Handler);
VIBID_WEAK_HANDLER(SysTick_Handler);
VIBID_WEAK_HANDLER(ADC_IRQHandler);
VIBID_WEAK_HANDLER(TIM2_IRQHandler);
VIBID_WEAK_HANDLER(USART1_IRQHandler);
VIBID_WEAK_HANDLER(DMA2_Stream0_IRQHandler);
VIBID_WEAK_HANDLER(OTG_FS_IRQHandler);
#undef VIBID_WEAK_HANDLER
}

namespace {

using Handler = void (*)();
namespace irq = vibid::fw::stm32::irq;

constexpr std::size_t kSystemVectors = 15;  // After the initial stack pointer.
constexpr std::size_t kVectorCount = kSystemVectors + irq::kCount;

constexpr std::array<Handler, kVectorCount> MakeVectors() {
  std::array<Handler, kVectorCount> v{};
  for (auto& h : v) h = DefaultHandler;
  v[0] = ResetHandler;
  v[1] = NMI_Handler;
  v[2] = HardFault_Handler;
  v[3] = MemManage_Handler;
  v[4] = BusFault_Handler;
  v[5] = UsageFault_Handler;
  v[6] = v[7] = v[8] = v[9] = nullptr;  // Reserved.
  v[10] = SVC_Handler;
  v[11] = DebugMon_Handler;
  v[12] = nullptr;
  v[13] = PendSV_Handler;
  v[14] = SysTick_Handler;
  v[kSystemVectors + irq::kAdc] = ADC_IRQHandler;
  v[kSystemVectors + irq::kTim2] = TIM2_IRQHandler;
  v[kSystemVectors + irq::kUsart1] = USART1_IRQHandler;
  v[kSystemVectors + irq::kDma2Stream0] = DMA2_Stream0_IRQHandler;
  v[kSystemVectors + irq::kOtgFs] = OTG_FS_IRQHandler;
  return v;
}

struct VectorTable {
  const std::uint32_t* initial_stack;
  std::array<Handler, kVectorCount> handlers;
};

}  // namespace

extern const VectorTable g_vector_table;
[[gnu::section(".isr_vector"), gnu::used]] const VectorTable g_vector_table = {&_estack,
                                                                               MakeVectors()};

// The stack pointer is loaded first, from the linker's _estack, as MicroPython's and the CMSIS
// start-up files do: a reset loads MSP from the vector table, but a jump into the image (the
// ROM's DFU "leave", a debugger's "go") leaves whatever stack the previous owner had, and the
// thread mode on MSP (CONTROL 0), so nothing below runs on a foreign stack.
extern "C" [[gnu::naked, noreturn]] void ResetHandler() {
  asm volatile(
      "ldr r0, =_estack\n"
      "msr msp, r0\n"
      "movs r0, #0\n"
      "msr control, r0\n"
      "isb\n"
      "b ResetHandlerBody\n");
}

extern "C" [[noreturn]] void ResetHandlerBody() {
  // Before anything else: interrupts masked, SysTick stopped and VTOR on this image's table,
  // and a start without a reset (ROM bootloader "leave", a debugger's "go") turned into a real
  // one, so no state a previous owner left (the PLL, the OTG core, pending interrupts) is live.
  vibid::fw::stm32::TakeOverCore(
      static_cast<std::uint32_t>(reinterpret_cast<std::uintptr_t>(&g_vector_table)));
  vibid::fw::stm32::EnterBootloaderIfRequested();
  // The FPU must be on before any code that may use it (the compiler is free to).
  using vibid::fw::stm32::Reg;
  namespace scb = vibid::fw::stm32::scb;
  Reg(scb::kCpacr) |= scb::kCpacrFpuFull;
  vibid::fw::stm32::DataSyncBarrier();
  vibid::fw::stm32::InstructionSyncBarrier();

  const std::uint32_t* src = &_sidata;
  for (std::uint32_t* dst = &_sdata; dst < &_edata;) *dst++ = *src++;
  for (std::uint32_t* dst = &_sbss; dst < &_ebss;) *dst++ = 0;
  for (std::uint32_t* dst = &_sccm_bss; dst < &_eccm_bss;) *dst++ = 0;
  for (auto* f = __init_array_start; f < __init_array_end; ++f) (*f)();
  (void)ApplicationMain();
  for (;;) {
  }
}
