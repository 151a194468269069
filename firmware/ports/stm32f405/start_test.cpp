// Start-up guards: a start without reset (ROM bootloader "leave", AN3156) becomes a system
// reset, whichever leftover shows it; the watchdog timeout holds at the fastest LSI; a reset waits
// for the reply to go out.
#include "board_port.hpp"
#include "otg_fs_dcd.hpp"
#include "port_test_fixture.hpp"
#include "regs/core_m4.hpp"
#include "regs/otg_fs.hpp"
#include "regs/peripherals.hpp"
#include "regs/rcc.hpp"
#include "system.hpp"

namespace vibid::fw::stm32::test {
namespace {

using StartTest = PortTest;

constexpr std::uint32_t kTable = 0x08000000;  // The image's vector table (FLASH_HEAD).

/// The registers the evidence is read from, at their reset values: RM0090 RCC_CR 0x0000XX83
/// (§7.3.1), RCC_AHB1ENR 0x00100000 (CCMDATARAMEN, §7.3.10); every other one 0.
void PokeResetState(FakeRegisters& r) {
  r.Poke(rcc::kCr, 0x00000083);
  r.Poke(rcc::kAhb1enr, 0x00100000);
}

TEST_F(StartTest, ResetStateIsAStartFromReset) {
  PokeResetState(regs());
  EXPECT_FALSE(StartedWithoutReset());
  regs().Clear();
  PokeResetState(regs());
  EXPECT_FALSE(FakeRegisters::RunUntilHalt([] { TakeOverCore(kTable); }));
  EXPECT_EQ(regs().CountWrites(scb::kAircr), 0U);
  // Even from reset: masked first, SysTick stopped, VTOR on the image's table, then barriers.
  ASSERT_FALSE(regs().log().empty());
  EXPECT_EQ(regs().log().front().kind, Access::Kind::kCpu);
  EXPECT_EQ(regs().log().front().op, fake::CpuOp::kDisableIrq);
  EXPECT_EQ(regs().WritesTo(systick::kCtrl), std::vector<std::uint32_t>{0});
  EXPECT_EQ(regs().WritesTo(scb::kVtor), std::vector<std::uint32_t>{kTable});
  EXPECT_LT(regs().FindWrite(scb::kVtor, kTable), regs().FindCpu(fake::CpuOp::kIsb));
}

TEST_F(StartTest, EveryLeftoverForcesASystemReset) {
  struct Leftover {
    const char* what;
    Address reg;
    std::uint32_t bits;
  };
  // One non-reset value each, with its RM0090 / ARMv7-M ARM register and bit.
  for (const Leftover l : {
           Leftover{"SWS = PLL (RCC_CFGR 3:2)", rcc::kCfgr, rcc::kCfgrSwsPll},
           Leftover{"APB2 prescaler (RCC_CFGR PPRE2)", rcc::kCfgr, rcc::kCfgrPpre2Div2},
           Leftover{"PLLON (RCC_CR 24)", rcc::kCr, 0x83 | rcc::kCrPllOn},
           Leftover{"HSEON (RCC_CR 16)", rcc::kCr, 0x83 | rcc::kCrHseOn},
           Leftover{"PLLI2SON (RCC_CR 26)", rcc::kCr, 0x83 | rcc::kCrPlli2sOn},
           Leftover{"GPIOA clock (AHB1ENR 0)", rcc::kAhb1enr, 0x00100000 | rcc::kAhb1GpioA},
           Leftover{"OTG_FS clock (AHB2ENR 7)", rcc::kAhb2enr, rcc::kAhb2OtgFs},
           Leftover{"AHB3ENR FSMC (bit 0)", rcc::kAhb3enr, Bit(0)},
           Leftover{"PWR clock (APB1ENR 28)", rcc::kApb1enr, rcc::kApb1Pwr},
           Leftover{"SYSCFG clock (APB2ENR 14)", rcc::kApb2enr, rcc::kApb2Syscfg},
           Leftover{"SysTick ENABLE (SYST_CSR 0)", systick::kCtrl, systick::kCtrlEnable},
           Leftover{"SysTick TICKINT (SYST_CSR 1)", systick::kCtrl, systick::kCtrlTickInt},
           Leftover{"NVIC line 18, ADC (ISER0)", nvic::kIser, Bit(irq::kAdc)},
           Leftover{"NVIC line 67, OTG_FS (ISER2)", nvic::kIser + 8, Bit(irq::kOtgFs - 64)},
           Leftover{"VTOR at the ROM (0x1FFF0000)", scb::kVtor, 0x1FFF0000},
       }) {
    SCOPED_TRACE(l.what);
    regs().Clear();
    PokeResetState(regs());
    regs().Poke(l.reg, l.bits);
    EXPECT_TRUE(StartedWithoutReset());
    EXPECT_TRUE(FakeRegisters::RunUntilHalt([] { TakeOverCore(kTable); }));
    // AIRCR: VECTKEY 0x05FA in 31:16 with SYSRESETREQ (bit 2), ARMv7-M ARM B3.2.6.
    EXPECT_EQ(regs().WritesTo(scb::kAircr), std::vector<std::uint32_t>{0x05FA0004U});
    // The reset is requested with interrupts masked, SysTick stopped and VTOR ours.
    const std::size_t reset = regs().FindWrite(scb::kAircr, 0x05FA0004U);
    EXPECT_LT(regs().FindCpu(fake::CpuOp::kDisableIrq), reset);
    EXPECT_LT(regs().FindWrite(systick::kCtrl, 0), reset);
    EXPECT_LT(regs().FindWrite(scb::kVtor, kTable), reset);
  }
}

TEST_F(StartTest, TheBootloaderRequestNeedsTheSoftwareResetFlag) {
  constexpr Address kSyscfgMemrmp = 0x40013800;  // RM0090 §9.2.1
  // The request is made and the reset asked for (AIRCR SYSRESETREQ).
  EXPECT_TRUE(FakeRegisters::RunUntilHalt([] { RebootToBootloader(); }));
  // A reset other than the software one (the reset pin here: RCC_CSR PINRSTF, bit 26) finds the
  // word but does not honour it, and drops it.
  regs().Clear();
  regs().Poke(rcc::kCsr, Bit(26));
  EnterBootloaderIfRequested();
  EXPECT_EQ(regs().CountWrites(kSyscfgMemrmp), 0U);
  regs().Poke(rcc::kCsr, Bit(28));
  EnterBootloaderIfRequested();  // the dropped request stays dropped
  EXPECT_EQ(regs().CountWrites(kSyscfgMemrmp), 0U);
  // Asked again, with the software reset's flag (SFTRSTF, bit 28): system memory mapped at 0
  // (MEMRMP MEM_MODE = 01) and VTOR back to 0, as before the ROM's jump.
  EXPECT_TRUE(FakeRegisters::RunUntilHalt([] { RebootToBootloader(); }));
  regs().Clear();
  regs().Poke(rcc::kCsr, Bit(28) | Bit(26));
  EnterBootloaderIfRequested();
  EXPECT_EQ(regs().WritesTo(kSyscfgMemrmp), std::vector<std::uint32_t>{1});
  EXPECT_EQ(regs().WritesTo(scb::kVtor), std::vector<std::uint32_t>{0});
}

TEST_F(StartTest, DebugBuildsFreezeTheWatchdogWhileHalted) {
  regs().Poke(dbgmcu::kApb1Fz, Bit(11));  // WWDG already frozen: kept.
  FreezeWatchdogWhenHalted();
  // DBGMCU_APB1_FZ (0xE0042008) bit 12 DBG_IWDG_STOP, RM0090 §38.16.4.
  EXPECT_EQ(regs().WritesTo(0xE0042008), std::vector<std::uint32_t>{Bit(11) | Bit(12)});
}

TEST_F(StartTest, CycleWaitCountsDwtCycles) {
  std::uint32_t now = 0xFFF00000;  // Wraps during the wait.
  regs().OnRead(dwt::kCyccnt, [&now](std::uint32_t) { return now += 1000000; });
  EXPECT_TRUE(WaitCycles(4200000));
  // The counter was started: DEMCR TRCENA (bit 24), DWT_CTRL CYCCNTENA (bit 0).
  EXPECT_EQ(regs().Peek(scb::kDemcr) & Bit(24), Bit(24));
  EXPECT_EQ(regs().Peek(dwt::kCtrl) & Bit(0), Bit(0));
  // Start, then +1, +2, +3, +4, +5 M: five polls to pass 4.2 M cycles.
  EXPECT_EQ(now, 0xFFF00000U + 6U * 1000000U);
}

TEST_F(StartTest, CycleWaitRefusesAStoppedCounter) {
  // A DWT that does not count (QEMU models none): refused, not an endless loop.
  EXPECT_FALSE(WaitCycles(100));
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
