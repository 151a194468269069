// The fault record: what the fault handler keeps across its reset (.noinit) and how the next boot
// reports it: reset cause "fault" with CFSR, HFSR, MMFAR, BFAR, the exception number and the
// stacked PC and LR; a commanded reset stays "software".
#include "board_port.hpp"
#include "port_test_fixture.hpp"
#include "regs/core_m4.hpp"
#include "regs/rcc.hpp"
#include "system.hpp"

namespace vibid::fw::stm32::test {
namespace {

using FaultRecordTest = PortTest;

// RCC_CSR after a system reset request: SFTRSTF (bit 28) and PINRSTF (bit 26), as the internal
// reset pulses NRST (RM0090 §7.1.2, §7.3.21).
constexpr std::uint32_t kCsrAfterSoftwareReset = Bit(28) | Bit(26);

/// A BusFault at 0x08012345 called from 0x08011111: r0, r1, r2, r3, r12, lr, pc, xPSR as the
/// exception entry stacks them (ARMv7-M ARM B1.5.6).
constexpr std::uint32_t kFrame[8] = {1, 2, 3, 4, 12, 0x08011111, 0x08012345, 0x01000000};

void FaultWith(const std::uint32_t* frame, std::uint32_t exception) {
  // CFSR 0x8200: BFARVALID (bit 15) and PRECISERR (bit 9); HFSR FORCED (bit 30); BFAR the bad
  // address (ARMv7-M ARM B3.2.15-B3.2.18).
  FakeRegisters& r = FakeRegisters::Get();
  r.Poke(0xE000ED28, 0x00008200);
  r.Poke(0xE000ED2C, 0x40000000);
  r.Poke(0xE000ED34, 0);
  r.Poke(0xE000ED38, 0x40026400);
  const std::size_t before = r.log().size();
  EXPECT_TRUE(FakeRegisters::RunUntilHalt([&] { RecordFaultAndReset(frame, exception); }));
  // The record is kept before the reset is asked for (AIRCR SYSRESETREQ with its key): CFSR,
  // HFSR, MMFAR and BFAR are read, each once, before the AIRCR write.
  EXPECT_EQ(r.WritesTo(0xE000ED0C), std::vector<std::uint32_t>{0x05FA0004U});
  const std::size_t reset = r.FindWrite(0xE000ED0C, 0x05FA0004U, before);
  ASSERT_NE(reset, FakeRegisters::kNone);
  for (const Address fault_register : {0xE000ED28U, 0xE000ED2CU, 0xE000ED34U, 0xE000ED38U}) {
    std::size_t reads = 0;
    for (std::size_t i = before; i < reset; ++i) {
      const Access& a = r.log()[i];
      reads += a.kind == Access::Kind::kRead && a.address == fault_register;
    }
    EXPECT_EQ(reads, 1U) << std::hex << fault_register;
  }
}

TEST_F(FaultRecordTest, AFaultResetIsReportedWithItsRecord) {
  FaultWith(kFrame, 5);
  regs().Clear();  // the reset: registers at their reset values, .noinit kept
  regs().Poke(rcc::kCsr, kCsrAfterSoftwareReset);
  BoardSystemControl system;
  system.Init();
  EXPECT_EQ(system.LastResetCause(), wire::ResetCause::kFault);
  const wire::FaultInfoResponse f = system.LastFault();
  EXPECT_EQ(f.recorded, 1);
  EXPECT_EQ(f.exception, 5);  // BusFault
  EXPECT_EQ(f.cfsr, 0x00008200u);
  EXPECT_EQ(f.hfsr, 0x40000000u);
  EXPECT_EQ(f.mmfar, 0u);
  EXPECT_EQ(f.bfar, 0x40026400u);
  EXPECT_EQ(f.pc, 0x08012345u);
  EXPECT_EQ(f.lr, 0x08011111u);
  // The flags are cleared (RMVF, bit 24), and the record is consumed: the next software reset,
  // a commanded one, is "software" with no record.
  EXPECT_NE(regs().FindWriteWithBits(rcc::kCsr, Bit(24)), kNone);
  regs().Clear();
  regs().Poke(rcc::kCsr, kCsrAfterSoftwareReset);
  wire::FaultInfoResponse again{};
  EXPECT_EQ(ReadAndClearResetCause(&again), wire::ResetCause::kSoftware);
  EXPECT_EQ(again.recorded, 0);
}

TEST_F(FaultRecordTest, ACommandedResetIsSoftware) {
  EXPECT_TRUE(FakeRegisters::RunUntilHalt([] { SystemReset(); }));
  regs().Clear();
  regs().Poke(rcc::kCsr, kCsrAfterSoftwareReset);
  BoardSystemControl system;
  system.Init();
  EXPECT_EQ(system.LastResetCause(), wire::ResetCause::kSoftware);
  EXPECT_EQ(system.LastFault().recorded, 0);
}

TEST_F(FaultRecordTest, APowerCycleOrTheWatchdogOvertakesTheRecord) {
  // A record whose reset became a power-on (PORRSTF 27 with PINRSTF and BORRSTF) or a watchdog
  // reset (IWDGRSTF 29) is not that boot's cause, and is dropped.
  FaultWith(kFrame, 3);
  regs().Clear();
  regs().Poke(rcc::kCsr, Bit(27) | Bit(26) | Bit(25));
  EXPECT_EQ(ReadAndClearResetCause(), wire::ResetCause::kPowerOn);
  regs().Clear();
  regs().Poke(rcc::kCsr, kCsrAfterSoftwareReset);
  EXPECT_EQ(ReadAndClearResetCause(), wire::ResetCause::kSoftware);
  FaultWith(kFrame, 3);
  regs().Clear();
  regs().Poke(rcc::kCsr, Bit(29) | Bit(26));
  EXPECT_EQ(ReadAndClearResetCause(), wire::ResetCause::kWatchdog);
}

TEST_F(FaultRecordTest, AStackOutsideRamGivesNoPcOrLr) {
  // startup.cpp's FaultCapture passes no frame when the stack pointer was not in RAM (an
  // overflow below the CCM): the registers are still kept, PC and LR read 0xFFFFFFFF.
  FaultWith(nullptr, 3);
  regs().Clear();
  regs().Poke(rcc::kCsr, kCsrAfterSoftwareReset);
  wire::FaultInfoResponse f{};
  EXPECT_EQ(ReadAndClearResetCause(&f), wire::ResetCause::kFault);
  EXPECT_EQ(f.exception, 3);
  EXPECT_EQ(f.cfsr, 0x00008200u);
  EXPECT_EQ(f.pc, wire::kFaultNoStackedValue);
  EXPECT_EQ(f.lr, wire::kFaultNoStackedValue);
}

}  // namespace
}  // namespace vibid::fw::stm32::test
