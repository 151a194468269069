// ConfigureClocks on the fake register file: the PLL register takes the planned factors for
// the build's crystal (8 MHz in this test build), the flash wait states go up before the switch,
// and a PWR clock enable is followed by a DSB (ES0182 §2.1.13); the flash accelerator runs with
// caches and without prefetch; the option bytes' brown-out level reads back.
#include <cmath>
#include <utility>

#include "board_port.hpp"
#include "clock.hpp"
#include "crystal_check.hpp"
#include "port_test_fixture.hpp"
#include "regs/peripherals.hpp"
#include "regs/rcc.hpp"
#include "system.hpp"

namespace vibid::fw::stm32::test {
namespace {

class ClockTest : public PortTest {
 protected:
  /// RCC_CR's ready flags follow their enables; SWS follows SW. `hse_hz` is the crystal on the
  /// board (0: none starts); TIM11 captures HSE_RTC = HSE / RTCPRE every 8 edges, counting the
  /// 16 MHz HSI, and `captures` says whether edges reach it at all.
  void ModelRcc(std::uint32_t hse_hz, bool captures = true, double hsi_hz = 16e6) {
    regs().OnWrite(rcc::kCr, [hse_hz](std::uint32_t, std::uint32_t w) {
      w &= ~(rcc::kCrHseRdy | rcc::kCrPllRdy | rcc::kCrHsiRdy);
      if (hse_hz != 0 && (w & rcc::kCrHseOn) != 0) w |= rcc::kCrHseRdy;
      if ((w & rcc::kCrPllOn) != 0) w |= rcc::kCrPllRdy;
      if ((w & rcc::kCrHsiOn) != 0) w |= rcc::kCrHsiRdy;
      return w;
    });
    regs().OnWrite(rcc::kCfgr, [](std::uint32_t, std::uint32_t w) {
      return (w & ~rcc::kCfgrSwsMask) | ((w & rcc::kCfgrSwMask) << 2);
    });
    regs().OnRead(tim::kTim11 + tim::kSr, [captures](std::uint32_t held) {
      return captures ? held | tim::kSrCc1if : held;
    });
    capture_ = 0;
    regs().OnRead(tim::kTim11 + tim::kCcr1, [this, hse_hz, hsi_hz](std::uint32_t) {
      // The k-th capture: k x 8 x RTCPRE HSE cycles in HSI ticks, on the 16-bit counter.
      const std::uint32_t rtcpre = (regs().Peek(rcc::kCfgr) >> 16) & 0x1F;
      const double ticks = static_cast<double>(capture_++) * 8.0 * rtcpre * hsi_hz / hse_hz;
      return static_cast<std::uint32_t>(std::llround(ticks)) & 0xFFFF;
    });
  }
  std::uint64_t capture_ = 0;
};

TEST_F(ClockTest, ProgramsThePlannedPllFor8MHz) {
  ModelRcc(8000000);
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
  ModelRcc(8000000);
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

TEST_F(ClockTest, BrownOutResetIsProgrammedToLevel3OnceWithReadProtectionUntouched) {
  // A factory part: FLASH_OPTCR 0x0FFFAAED (RM0090 §3.9.10): OPTLOCK set, BOR_LEV 11 (off), RDP
  // 0xAA (level 0), nWRP all 1. RM0090 §3.7.2: OPTKEYR (0x40023C08) <- 0x08192A3B then
  // 0x4C5D6E7F; FLASH_SR BSY (bit 16) clear; FLASH_OPTCR with BOR_LEV 00 and everything else as
  // read (0x0FFFAAE0: OPTLOCK clear); the same with OPTSTRT (bit 1, 0x0FFFAAE2); BSY clear
  // again; OPTLOCK set.
  regs().Poke(flash::kOptcr, 0x0FFFAAED);
  EXPECT_EQ(EnsureBrownOutLevel3(), BrownOutProgramming::kProgrammed);
  EXPECT_EQ(regs().WritesTo(0x40023C08), (std::vector<std::uint32_t>{0x08192A3B, 0x4C5D6E7F}));
  EXPECT_EQ(regs().WritesTo(0x40023C14),
            (std::vector<std::uint32_t>{0x0FFFAAE0, 0x0FFFAAE2, 0x0FFFAAE3}));
  const std::size_t key2 = regs().FindWrite(0x40023C08, 0x4C5D6E7F);
  const std::size_t start = regs().FindWrite(0x40023C14, 0x0FFFAAE2);
  std::size_t busy_before = kNone, busy_after = kNone;
  for (std::size_t i = 0; i < regs().log().size(); ++i) {
    const Access& a = regs().log()[i];
    if (a.kind != Access::Kind::kRead || a.address != 0x40023C0C) continue;
    if (i < key2 && busy_before == kNone) busy_before = i;
    if (i > start && busy_after == kNone) busy_after = i;
  }
  EXPECT_NE(busy_before, kNone);
  EXPECT_NE(busy_after, kNone);
  EXPECT_EQ(BrownOutLevel(), BrownOut::kLevel3);
  // At level 3 already: not a single write (the option bytes' sector wears with each one).
  regs().Clear();
  regs().Poke(flash::kOptcr, 0x0FFFAAE1);
  EXPECT_EQ(EnsureBrownOutLevel3(), BrownOutProgramming::kAlreadyLevel3);
  EXPECT_EQ(regs().CountWrites(0x40023C08), 0U);
  EXPECT_EQ(regs().CountWrites(0x40023C14), 0U);
  // Read protection level 1 (RDP 0x55) and a write-protected sector 2 (nWRP bit 18 clear) stay
  // exactly as they are; brown-out level 1 (10) goes to 00.
  regs().Clear();
  regs().Poke(flash::kOptcr, 0x0FFB55E9);
  EXPECT_EQ(EnsureBrownOutLevel3(), BrownOutProgramming::kProgrammed);
  for (const std::uint32_t v : regs().WritesTo(0x40023C14))
    EXPECT_EQ(v & 0x0FFFFF00U, 0x0FFB5500U) << std::hex << v;
  // A flash that stays busy: nothing is programmed, the option register stays locked.
  regs().Clear();
  regs().LogReads(false);
  regs().Poke(flash::kOptcr, 0x0FFFAAED);
  regs().Poke(flash::kSr, flash::kSrBsy);
  EXPECT_EQ(EnsureBrownOutLevel3(), BrownOutProgramming::kFailed);
  EXPECT_EQ(regs().CountWrites(0x40023C14), 0U);
}

TEST_F(ClockTest, FallsBackToHsiWhenTheCrystalDoesNotStart) {
  ModelRcc(0);
  const ClockConfig c = ConfigureClocks();
  EXPECT_EQ(c.source, ClockSource::kHsiFallback);
  EXPECT_EQ(c.hsi_reason, HsiReason::kHseDidNotStart);
  EXPECT_EQ(c.sysclk_hz, 16000000U);
  EXPECT_EQ(regs().Peek(rcc::kCfgr) & rcc::kCfgrSwMask, rcc::kCfgrSwHsi);
  // The PLL never runs from the HSE (PLLSRC, bit 22, never set).
  EXPECT_EQ(regs().FindWriteWithBits(rcc::kPllcfgr, rcc::kPllcfgrSrcHse), kNone);
}

TEST_F(ClockTest, MeasuresTheCrystalAgainstTheHsiBeforeThePllUsesIt) {
  ModelRcc(8000000);
  const ClockConfig c = ConfigureClocks();
  ASSERT_EQ(c.source, ClockSource::kPllFromHse);
  // 64 captures x 8 x 31 HSE cycles = 31 744 HSI ticks at 8 MHz: 8 000 000 Hz, exactly.
  EXPECT_EQ(c.hse_measured_hz, 8000000U);
  // RCC_CFGR RTCPRE (20:16) = 31, TIM11 (APB2ENR bit 18) with TIM11_OR TI1_RMP = 10 (HSE_RTC),
  // CCMR1 CC1S = 01 and IC1PSC = 11 (0xD), CC1E: all before RCC_PLLCFGR is written.
  const std::size_t rtcpre = regs().FindWriteWithBits(rcc::kCfgr, 31U << 16);
  const std::size_t remap = regs().FindWrite(tim::kTim11 + tim::kOr, 0x2);
  const std::size_t input = regs().FindWrite(tim::kTim11 + tim::kCcmr1, 0xD);
  const std::size_t pll = regs().FindWriteWithBits(rcc::kPllcfgr, rcc::kPllcfgrSrcHse);
  ASSERT_NE(rtcpre, kNone);
  ASSERT_NE(remap, kNone);
  ASSERT_NE(input, kNone);
  ASSERT_NE(pll, kNone);
  EXPECT_LT(rtcpre, pll);
  EXPECT_LT(remap, pll);
  EXPECT_NE(regs().FindWriteWithBits(rcc::kApb2enr, Bit(18)), kNone);
  // Put back: TIM11 off and unclocked, RTCPRE 0, no remap.
  EXPECT_EQ(regs().Peek(tim::kTim11 + tim::kCr1), 0U);
  EXPECT_EQ(regs().Peek(tim::kTim11 + tim::kOr), 0U);
  EXPECT_EQ(regs().Peek(rcc::kApb2enr) & Bit(18), 0U);
  EXPECT_EQ(regs().Peek(rcc::kCfgr) & (0x1FU << 16), 0U);
}

TEST_F(ClockTest, ACrystalOutsideTheHsiBandStaysOnTheHsi) {
  // An image for 8 MHz on a board with a 12 MHz crystal: the PLL would make 504 MHz VCO and a
  // 252 MHz core. It stays on the HSI, says why, and runs the PLL from the HSI for USB only.
  ModelRcc(12000000);
  const ClockConfig c = ConfigureClocks();
  EXPECT_EQ(c.source, ClockSource::kHsiFallback);
  EXPECT_EQ(c.hsi_reason, HsiReason::kHseWrongFrequency);
  EXPECT_NEAR(c.hse_measured_hz, 12000000.0, 12000000.0 * 1e-4);
  EXPECT_EQ(c.sysclk_hz, 16000000U);
  EXPECT_TRUE(c.usb_clocked);
  EXPECT_EQ(regs().FindWriteWithBits(rcc::kPllcfgr, rcc::kPllcfgrSrcHse), kNone);
  // HSI plan: PLLM 8, PLLN 168, PLLP /2, PLLSRC HSI (0), PLLQ 7: 8 | 168 << 6 | 7 << 24.
  EXPECT_EQ(regs().Peek(rcc::kPllcfgr), 0x07002A08U);
  EXPECT_EQ(regs().Peek(rcc::kCfgr) & rcc::kCfgrSwMask, rcc::kCfgrSwHsi);
  EXPECT_EQ(regs().Peek(rcc::kCr) & rcc::kCrHseOn, 0U);
  // Within 95..109 % is the board's crystal; beyond it is not (8 MHz image: 7.6..8.72 MHz).
  for (const auto& [hz, accepted] : {std::pair{7610000U, true}, std::pair{8710000U, true},
                                     std::pair{7590000U, false}, std::pair{8730000U, false}}) {
    regs().Clear();
    ModelRcc(hz);
    EXPECT_EQ(ConfigureClocks().source == ClockSource::kPllFromHse, accepted) << hz;
  }
}

TEST_F(ClockTest, TheRightCrystalPassesAtEitherEndOfTheHsisSpread) {
  // DS8626 HSI accuracy over -40..105 C: -8 % / +4.5 %. A good 8 MHz crystal on a cold board
  // whose HSI runs at 14.72 MHz reads 8 x 16 / 14.72 = 8.696 MHz (+8.7 %), on a hot one at
  // 16.72 MHz 7.656 MHz (-4.3 %): both run from the crystal; the old 2 % limit refused both.
  for (const double hsi_hz : {16e6 * 0.92, 16e6 * 1.045}) {
    regs().Clear();
    ModelRcc(8000000, true, hsi_hz);
    const ClockConfig c = ConfigureClocks();
    EXPECT_EQ(c.source, ClockSource::kPllFromHse) << hsi_hz;
    EXPECT_NEAR(c.hse_measured_hz, 8e6 * 16e6 / hsi_hz, 8e6 * 1e-4) << hsi_hz;
  }
  // A 12 MHz board under an 8 MHz image at either end still stays on the HSI (11.48 / 13.04).
  for (const double hsi_hz : {16e6 * 0.92, 16e6 * 1.045}) {
    regs().Clear();
    ModelRcc(12000000, true, hsi_hz);
    EXPECT_EQ(ConfigureClocks().hsi_reason, HsiReason::kHseWrongFrequency) << hsi_hz;
  }
}

TEST_F(ClockTest, AReadyCrystalWhoseEdgesNeverArriveCountsAsNotStarted) {
  ModelRcc(8000000, /*captures=*/false);
  const ClockConfig c = ConfigureClocks();
  EXPECT_EQ(c.source, ClockSource::kHsiFallback);
  EXPECT_EQ(c.hsi_reason, HsiReason::kHseDidNotStart);
  EXPECT_EQ(c.hse_measured_hz, 0U);
}

TEST(CrystalArithmetic, HseFromTicksAndTheHsiBand) {
  // 64 x 248 = 15 872 HSE cycles; at 12 MHz that is 1.3227 ms = 21 162.67 HSI ticks.
  EXPECT_EQ(HseHzFromTicks(31744, 64), 8000000U);
  EXPECT_EQ(HseHzFromTicks(21163, 64), 11999811U);  // 15872 x 16e6 / 21163, rounded
  EXPECT_EQ(HseHzFromTicks(0, 64), 0U);
  EXPECT_TRUE(HseWithinTolerance(8720000, 8000000));  // exactly 109 %
  EXPECT_FALSE(HseWithinTolerance(8720001, 8000000));
  EXPECT_TRUE(HseWithinTolerance(7600000, 8000000));  // exactly 95 %
  EXPECT_FALSE(HseWithinTolerance(7599999, 8000000));
  // The band against the HSI's full spread (DS8626: a crystal f reads f / 1.045 .. f / 0.92):
  // 16 MHz reads 15.311..17.391 MHz, outside 12 MHz's band (11.4..13.08) and 25 MHz's
  // (23.75..27.25); 12 MHz reads 11.483..13.044, outside 16 MHz's (15.2..17.44).
  EXPECT_TRUE(AcceptedAtEveryTemperature(8000000));
  EXPECT_TRUE(AcceptedAtEveryTemperature(25000000));
  EXPECT_FALSE(AcceptedAtSomeTemperature(16000000, 12000000));
  EXPECT_FALSE(AcceptedAtSomeTemperature(12000000, 16000000));
  EXPECT_FALSE(AcceptedAtSomeTemperature(25000000, 16000000));
  EXPECT_TRUE(AcceptedAtSomeTemperature(24000000, 25000000));  // not a crystal an image takes
  EXPECT_TRUE(BandSeparatesTheSupportedCrystals());
}

}  // namespace
}  // namespace vibid::fw::stm32::test
