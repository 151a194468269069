// Start-up guards: a start without reset (ROM bootloader "leave", AN3156) becomes a system
// reset; the watchdog timeout holds at the fastest LSI; a reset waits for the reply to go out.
#include "board_port.hpp"
#include "otg_fs_dcd.hpp"
#include "port_test_fixture.hpp"
#include "regs/otg_fs.hpp"
#include "regs/peripherals.hpp"
#include "regs/rcc.hpp"
#include "system.hpp"

namespace vibid::fw::stm32::test {
namespace {

using StartTest = PortTest;

TEST_F(StartTest, ResetStateIsAStartFromReset) {
  // RM0090 reset values: CR = HSION | HSIRDY (0x83 with trim), CFGR = 0, AHB2ENR = 0.
  regs().Poke(rcc::kCr, 0x00000083);
  EXPECT_FALSE(StartedWithoutReset());
  EXPECT_FALSE(FakeRegisters::RunUntilHalt([] { ResetIfStartedWithoutReset(); }));
  EXPECT_EQ(regs().CountWrites(scb::kAircr), 0U);
}

TEST_F(StartTest, BootloaderLeftoversForceASystemReset) {
  struct Leftover {
    Address reg;
    std::uint32_t bits;
  };
  for (const Leftover l :
       {Leftover{rcc::kCfgr, rcc::kCfgrSwsPll}, Leftover{rcc::kCr, rcc::kCrPllOn},
        Leftover{rcc::kCr, rcc::kCrHseOn}, Leftover{rcc::kAhb2enr, rcc::kAhb2OtgFs}}) {
    regs().Clear();
    regs().Poke(l.reg, l.bits);
    EXPECT_TRUE(StartedWithoutReset());
    EXPECT_TRUE(FakeRegisters::RunUntilHalt([&] { ResetIfStartedWithoutReset(); }));
    // AIRCR: VECTKEY 0x05FA in 31:16 with SYSRESETREQ (bit 2), ARMv7-M ARM B3.2.6.
    EXPECT_EQ(regs().WritesTo(scb::kAircr), std::vector<std::uint32_t>{0x05FA0004U});
  }
}

TEST_F(StartTest, WatchdogTimeoutHoldsAtTheFastestLsi) {
  // ceil(1000 ms * 47 kHz / 32) = ceil(1468.75) = 1469 counts: 1.0002 s at 47 kHz, 1.47 s at
  // 32 kHz, 2.77 s at 17 kHz (datasheet LSI range 17..47 kHz).
  EXPECT_EQ(WatchdogReload(1000), 1469U);
  EXPECT_GE(1469.0 * 32 / 47000, 1.0);
  // 12-bit reload: the longest guaranteed timeout is 4095 * 32 / 47 kHz = 2788 ms.
  EXPECT_EQ(kWatchdogMaxTimeoutMs, 2788U);
  EXPECT_EQ(WatchdogReload(60000), 4095U);
  EXPECT_EQ(WatchdogReload(0), 2U);  // 1 ms: ceil(1.47)
  StartWatchdog(1000);
  const std::vector<std::uint32_t> keys = regs().WritesTo(iwdg::kKr);
  EXPECT_EQ(keys, (std::vector<std::uint32_t>{0xCCCC, 0x5555, 0xAAAA}));
  EXPECT_EQ(regs().WritesTo(iwdg::kPr), std::vector<std::uint32_t>{3});
  EXPECT_EQ(regs().WritesTo(iwdg::kRlr), std::vector<std::uint32_t>{1468});
}

class ResetDrainTest : public PortTest {
 protected:
  void SetUp() override {
    PortTest::SetUp();
    // Each SysTick read is one millisecond later.
    regs().OnRead(systick::kVal, [](std::uint32_t held) {
      OnSysTick();
      return held;
    });
    system_.AttachUsb(dcd_);
  }
  OtgFsDcd dcd_;
  BoardSystemControl system_;
};

TEST_F(ResetDrainTest, ResetWaitsUntilTheHostTookTheReply) {
  int reads = 0;
  regs().OnRead(otg::Diepctl(1),
                [&reads](std::uint32_t) { return ++reads <= 5 ? otg::kEpctlEpena : 0U; });
  EXPECT_TRUE(FakeRegisters::RunUntilHalt([&] { system_.Reset(); }));
  EXPECT_EQ(reads, 6);  // Polled until EPENA cleared, then reset.
  EXPECT_EQ(regs().WritesTo(scb::kAircr), std::vector<std::uint32_t>{0x05FA0004U});
  EXPECT_GE(regs().CountWrites(iwdg::kKr), 5U);  // Fed while waiting.
}

TEST_F(ResetDrainTest, ResetGivesUpOnAHostThatNeverReads) {
  regs().Poke(otg::Diepctl(1), otg::kEpctlEpena);
  EXPECT_TRUE(FakeRegisters::RunUntilHalt([&] { system_.EnterDfu(); }));
  EXPECT_EQ(regs().WritesTo(scb::kAircr), std::vector<std::uint32_t>{0x05FA0004U});
  // About 100 one-millisecond SysTick reads, not an endless loop.
  std::size_t waited = 0;
  for (const Access& a : regs().log())
    waited += (a.kind == Access::Kind::kRead && a.address == systick::kVal);
  EXPECT_GE(waited, 100U);
  EXPECT_LE(waited, 210U);
}

}  // namespace
}  // namespace vibid::fw::stm32::test
