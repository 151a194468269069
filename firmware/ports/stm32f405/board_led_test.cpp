// The status LED on the fake register file: the pyboard v1.1's blue LED4 (PB4, lit high) and
// an LED lit low; the level is set before the pin becomes an output.
#include "board_led.hpp"
#include "port_test_fixture.hpp"
#include "regs/peripherals.hpp"
#include "regs/rcc.hpp"

namespace vibid::fw::stm32::test {
namespace {

using BoardLedTest = PortTest;

TEST_F(BoardLedTest, PyboardBlueLedOnPb4IsDrivenHigh) {
  LightLed(LedPin{1, 4, true});
  // GPIOB clock: AHB1ENR bit 1 (RM0090 §7.3.10), then a DSB.
  EXPECT_EQ(regs().Peek(rcc::kAhb1enr), Bit(1));
  // GPIOB at 0x40020400; BSRR (offset 0x18) BS4; MODER (offset 0x00) bits 9:8 = 01, output.
  const std::size_t level = regs().FindWrite(0x40020418, Bit(4));
  const std::size_t output = regs().FindWrite(0x40020400, 0x1U << 8);
  ASSERT_NE(level, kNone);
  ASSERT_NE(output, kNone);
  EXPECT_LT(level, output);
  EXPECT_LT(regs().FindCpu(fake::CpuOp::kDsb), level);
}

TEST_F(BoardLedTest, LedLitLowIsResetNotSet) {
  regs().Poke(0x40020800, 0xFFFFFFFF);  // GPIOC MODER: every pin analog, as after a reset
  LightLed(LedPin{2, 12, false});
  // BSRR BR12 is bit 28; MODER bits 25:24 become 01, the others kept.
  EXPECT_EQ(regs().WritesTo(0x40020818), std::vector<std::uint32_t>{Bit(28)});
  EXPECT_EQ(regs().Peek(0x40020800), 0xFDFFFFFFU);
}

}  // namespace
}  // namespace vibid::fw::stm32::test
