// Reset and fault handling for the mps2-an386 test images: vector table, .data/.bss set-up, FPU
// enable, static constructors, then the tests; the exit status goes back to the host over
// semihosting.
#include <cstdint>

#include "runner.hpp"
#include "semihosting.hpp"

extern "C" {
// Linker-script symbols (mps2_an386.ld).
extern std::uint32_t __data_load__;
extern std::uint32_t __data_start__;
extern std::uint32_t __data_end__;
extern std::uint32_t __bss_start__;
extern std::uint32_t __bss_end__;
extern std::uint32_t __stack_top__;
using InitFunction = void (*)();
extern InitFunction __init_array_start[];
extern InitFunction __init_array_end[];

void Reset_Handler();
void Fault_Handler();
}

namespace {

// Coprocessor Access Control Register (ARMv7-M ARM, B3.2.20): CP10/CP11 full access enables the
// FPU.
volatile std::uint32_t& Cpacr() { return *reinterpret_cast<volatile std::uint32_t*>(0xE000ED88u); }

}  // namespace

extern "C" void Reset_Handler() {
  Cpacr() = Cpacr() | (0xFu << 20);
  asm volatile("dsb\n\tisb" ::: "memory");
  const std::uint32_t* src = &__data_load__;
  for (std::uint32_t* dst = &__data_start__; dst < &__data_end__;) *dst++ = *src++;
  for (std::uint32_t* dst = &__bss_start__; dst < &__bss_end__;) *dst++ = 0;
  for (InitFunction* f = __init_array_start; f < __init_array_end; ++f) (*f)();
  vibid::testing::SemihostExit(vibid::testing::RunAllTests());
}

extern "C" void Fault_Handler() {
  vibid::testing::SemihostWrite("fault: the test image took an exception\n");
  vibid::testing::SemihostExit(3);
}

// Cortex-M vector table: initial stack pointer, then the handlers (ARMv7-M ARM, B1.5.3). Faults and
// unexpected interrupts end the run with a message instead of hanging until the ctest timeout.
using Vector = void (*)();
__attribute__((section(".vectors"), used)) const Vector kVectorTable[16] = {
    reinterpret_cast<Vector>(&__stack_top__),
    Reset_Handler,
    Fault_Handler,  // NMI
    Fault_Handler,  // HardFault
    Fault_Handler,  // MemManage
    Fault_Handler,  // BusFault
    Fault_Handler,  // UsageFault
    nullptr,
    nullptr,
    nullptr,
    nullptr,
    Fault_Handler,  // SVCall
    Fault_Handler,  // DebugMonitor
    nullptr,
    Fault_Handler,  // PendSV
    Fault_Handler,  // SysTick
};
