// ConfigureClocks on the fake register file: the PLL register takes the planned factors for
// the build's crystal (8 MHz in this test build), the flash wait states go up before the switch,
// and a PWR clock enable is followed by a DSB (ES0182 §2.1.13); the flash accelerator runs with
// caches and without prefetch; the option bytes' brown-out level reads back.
#include "board_port.hpp"
#include "clock.hpp"
#include "port_test_fixture.hpp"
#include "regs/rcc.hpp"
#include "system.hpp"

namespace vibid::fw::stm32::test {
namespace {

class ClockTest : public PortTest {
 protected:
  void ModelRcc(bool hse_starts) {
    regs().OnWrite(rcc::kCr, [hse_starts](std::uint32_t, std::uint32_t w) {
      if (hse_starts && (w & rcc::kCrHseOn) != 0) w |= rcc::kCrHseRdy;
      if ((w & rcc::kCrPllOn) != 0) w |= rcc::kCrPllRdy;
      if ((w & rcc::kCrHsiOn) != 0) w |= rcc::kCrHsiRdy;
      return w;
    });
    // SWS follows SW.
    regs().OnWrite(rcc::kCfgr, [](std::uint32_t, std::uint32_t w) {
      return (w & ~rcc::kCfgrSwsMask) | ((w & rcc::kCfgrSwMask) << 2);
    });
  }
};

TEST_F(ClockTest, ProgramsThePlannedPllFor8MHz) {
  ModelRcc(true);
  const ClockConfig c = ConfigureClocks();
  EXPECT_EQ(c.source, ClockSource::kPllFromHse);
  EXPECT_EQ(c.sysclk_hz, 168000000U);
  EXPECT_EQ(HseHz(), 8000000U);
  // PLLM 4 (bits 5:0), PLLN 168 (14:6), PLLP /2 = 00 (17:16), PLLSRC HSE (22), PLLQ 7 (27:24):
  // 4 | 168 << 6 | 1 << 22 | 7 << 24, by hand from RM0090 §7.3.2.
  EXPECT_EQ(regs().Peek(rcc::kPllcfgr), 0x07402A04U);
  const std::size_t latency = regs().FindWriteWithBits(flash::kAcr, 5);
  const std::size_t to_pll = regs().FindWriteWithBits(rcc::kCfgr, rcc::kCfgrSwPll);
  ASSERT_NE(latency, kNone);
  ASSERT_NE(to_pll, kNone);
  EXPECT_LT(latency, to_pll);
  const std::size_t pwr_clock = regs().FindWriteWithBits(rcc::kApb1enr, rcc::kApb1Pwr);
  const std::size_t dsb = regs().FindCpu(fake::CpuOp::kDsb, pwr_clock);
  const std::size_t vos = regs().FindWriteWithBits(pwr::kCr, pwr::kCrVos);
  ASSERT_NE(pwr_clock, kNone);
  ASSERT_NE(dsb, kNone);
  EXPECT_LT(dsb, vos);
}

TEST_F(ClockTest, FlashRunsWithCachesAndWithoutPrefetch) {
  ModelRcc(true);
  ASSERT_EQ(ConfigureClocks().source, ClockSource::kPllFromHse);
  // FLASH_ACR (RM0090 §3.9.1): LATENCY 2:0, PRFTEN 8, ICEN 9, DCEN 10, ICRST 11, DCRST 12. Caches
  // reset while off, then on; prefetch never on (ES0182 ADC noise workaround).
  EXPECT_EQ(regs().WritesTo(flash::kAcr), (std::vector<std::uint32_t>{0x1805, 0x0005, 0x0605}));
  EXPECT_EQ(regs().FindWriteWithBits(flash::kAcr, Bit(8)), kNone);
}

TEST_F(ClockTest, BrownOutLevelIsTheOptionBytesField) {
  // FLASH_OPTCR resets to 0x0FFFAAED (RM0090 §3.9.10): BOR_LEV (3:2) = 11, brown-out reset off.
  regs().Poke(flash::kOptcr, 0x0FFFAAED);
  EXPECT_EQ(BrownOutLevel(), BrownOut::kOff);
  regs().Poke(flash::kOptcr, 0x0FFFAAE1);  // BOR_LEV 00: level 3
  EXPECT_EQ(BrownOutLevel(), BrownOut::kLevel3);
  regs().Poke(flash::kOptcr, 0x0FFFAAE5);  // 01: level 2
  EXPECT_EQ(BrownOutLevel(), BrownOut::kLevel2);
  regs().Poke(flash::kOptcr, 0x0FFFAAE9);  // 10: level 1
  EXPECT_EQ(BrownOutLevel(), BrownOut::kLevel1);
  // The core's view through the port (what a self-test or get-info would report).
  const BoardSystemControl system;
  EXPECT_EQ(system.BrownOutLevel(), wire::BrownOut::kLevel1);
  regs().Poke(flash::kOptcr, 0x0FFFAAE1);
  EXPECT_EQ(system.BrownOutLevel(), wire::BrownOut::kLevel3);
  regs().Poke(flash::kOptcr, 0x0FFFAAED);
  EXPECT_EQ(system.BrownOutLevel(), wire::BrownOut::kOff);
}

TEST_F(ClockTest, FallsBackToHsiWhenTheCrystalDoesNotStart) {
  ModelRcc(false);
  const ClockConfig c = ConfigureClocks();
  EXPECT_EQ(c.source, ClockSource::kHsiFallback);
  EXPECT_EQ(c.sysclk_hz, 16000000U);
  EXPECT_EQ(regs().Peek(rcc::kCfgr) & rcc::kCfgrSwMask, rcc::kCfgrSwHsi);
  EXPECT_EQ(regs().FindWriteWithBits(rcc::kCr, rcc::kCrPllOn), kNone);
}

}  // namespace
}  // namespace vibid::fw::stm32::test
