// The port's self-test measurements on the fake register file: the crystal error from DWT
// cycles over start-of-frame flags of a modelled host, its timeout without one, and the encoder
// timers' state.
#include "board_port.hpp"
#include "port_test_fixture.hpp"
#include "regs/core_m4.hpp"
#include "regs/otg_fs.hpp"
#include "regs/peripherals.hpp"
#include "self_test.hpp"

namespace vibid::fw::stm32::test {
namespace {

class SelfTestPortTest : public PortTest {
 protected:
  // A core whose cycle counter moves `per_read` cycles at every read, and a host whose frames
  // last `cycles_per_frame` core cycles: SOF reads set once the counter passes the next frame,
  // and a write of 1 clears it.
  void ModelFrames(double cycles_per_frame, std::uint32_t per_read) {
    regs().OnRead(dwt::kCyccnt, [this, per_read](std::uint32_t) {
      now_ += per_read;
      return static_cast<std::uint32_t>(now_);
    });
    regs().OnRead(otg::kGintsts, [this, cycles_per_frame](std::uint32_t held) {
      while (static_cast<double>(now_) >= next_frame_) {
        next_frame_ += cycles_per_frame;
        sof_ = true;
      }
      return sof_ ? (held | otg::kIntSof) : held;
    });
    regs().OnWrite(otg::kGintsts, [this](std::uint32_t held, std::uint32_t written) {
      if ((written & otg::kIntSof) != 0) sof_ = false;
      return held;
    });
  }
  std::uint64_t now_ = 0;
  double next_frame_ = 1000.0;
  bool sof_ = false;
};

TEST_F(SelfTestPortTest, CrystalErrorIsTheCycleCountOverFrames) {
  // Closed form: 168 000 x (1 + e) cycles per frame for a crystal fast by e. Over 1000 frames of
  // 168 008.4 cycles (+50 ppm) the count is 168 008 400, +50.000 ppm; a read every 97 cycles
  // places each flag within 2 x 97 cycles (both polls), 1.2 ppm of the 1 s count at most.
  EXPECT_EQ(CrystalErrorMilliPpm(168'008'400, 1000, 168'000'000), 50'000);
  EXPECT_EQ(CrystalErrorMilliPpm(167'983'200, 1000, 168'000'000), -100'000);
  regs().LogReads(false);
  ModelFrames(168'008.4, 97);
  std::uint32_t cycles = 0;
  ASSERT_TRUE(CountCyclesOverFrames(1000, 168'000'000, cycles));
  const std::int64_t milli_ppm = CrystalErrorMilliPpm(cycles, 1000, 168'000'000);
  EXPECT_NEAR(static_cast<double>(milli_ppm), 50'000.0, 1'200.0);
  // DWT powered and counting (ARMv7-M ARM C1.6.5, C1.8.7); the watchdog fed during the second.
  EXPECT_NE(regs().Peek(scb::kDemcr) & scb::kDemcrTrcena, 0u);
  EXPECT_NE(regs().Peek(dwt::kCtrl) & dwt::kCtrlCyccntEna, 0u);
  EXPECT_GE(regs().CountWrites(iwdg::kKr), 10u);

  BoardSystemControl system;
  const auto m = system.MeasureSelfTest(wire::SelfTestCheck::kHsePpm, 200);
  ASSERT_TRUE(m.available);
  EXPECT_EQ(m.exp10, -3);
  EXPECT_NEAR(static_cast<double>(m.mantissa), 50'000.0, 1'200.0);
}

TEST_F(SelfTestPortTest, NoFramesIsUnavailableNotAPass) {
  regs().LogReads(false);
  ModelFrames(1e18, 1000);  // no host: one frame, then none
  std::uint32_t cycles = 0;
  EXPECT_FALSE(CountCyclesOverFrames(1000, 168'000'000, cycles));
  BoardSystemControl system;
  EXPECT_FALSE(system.MeasureSelfTest(wire::SelfTestCheck::kHsePpm, 200).available);
  // Not measured on this port: the converters and the image.
  EXPECT_FALSE(system.MeasureSelfTest(wire::SelfTestCheck::kNoiseForce1, 200).available);
  EXPECT_FALSE(system.MeasureSelfTest(wire::SelfTestCheck::kImageCrc, 200).available);
}

TEST_F(SelfTestPortTest, VddaFromVrefintAndItsFactoryCalibration) {
  // Closed form: VDDA = 3300 mV x VREFINT_CAL / VREFINT_DATA. A calibration of 1500 (1.209 V at
  // 3.3 V: 1500 / 4095 x 3.3 V) converted as 1650 means VDDA = 3000 mV; 1500 exactly 3.3 V.
  EXPECT_EQ(VddaMillivolts(1500, 1650), 3000u);
  EXPECT_EQ(VddaMillivolts(1500, 1500), 3300u);
  EXPECT_EQ(VddaMillivolts(1500, 0), 0u);

  // ADC1 as the sampler leaves it (scan, overrun interrupt, triple mode, trigger on TIM2).
  const std::uint32_t ccr = adc::kCcrAdcpreDiv4 | adc::kCcrDmaMode1 | adc::kCcrDds |
                            adc::kCcrMultiTripleRegularSimultaneous;
  const std::uint32_t cr1 = adc::kCr1Scan | adc::kCr1Ovrie;
  const std::uint32_t cr2 = adc::kCr2Adon | adc::kCr2ExtselTim2Trgo | adc::kCr2ExtenRising;
  regs().Poke(adc::kCommonCcr, ccr);
  regs().Poke(adc::kAdc1 + adc::kCr1, cr1);
  regs().Poke(adc::kAdc1 + adc::kCr2, cr2);
  regs().Poke(adc::kAdc1 + adc::kSqr1, 1u << adc::kSqr1LPos);
  regs().Poke(adc::kAdc1 + adc::kSqr3, adc::Sqr3(0, 0) | adc::Sqr3(1, 1));
  regs().Poke(kVrefintCalWord, 1500u << 16);  // 0x1FFF7A2A holds the upper half-word
  // Converter model: a software start ends the conversion (EOC), DR reads 1650 and clears EOC.
  regs().OnRead(dwt::kCyccnt, [](std::uint32_t held) {
    FakeRegisters::Get().Poke(dwt::kCyccnt, held + 100);
    return held;
  });
  regs().OnWrite(adc::kAdc1 + adc::kCr2, [](std::uint32_t, std::uint32_t w) {
    if ((w & adc::kCr2Swstart) != 0) FakeRegisters::Get().Poke(adc::kAdc1 + adc::kSr, adc::kSrEoc);
    return w & ~adc::kCr2Swstart;
  });
  regs().OnRead(adc::kAdc1 + adc::kDr, [](std::uint32_t) {
    FakeRegisters::Get().Poke(adc::kAdc1 + adc::kSr, 0);
    return 1650u;
  });

  BoardSystemControl system;
  const auto m = system.MeasureSelfTest(wire::SelfTestCheck::kVdda, 200);
  ASSERT_TRUE(m.available);
  EXPECT_EQ(m.mantissa, 3000);
  EXPECT_EQ(m.exp10, -3);
  // Converted with VREFINT connected, in independent mode, 480-cycle sampling of channel 17.
  const std::size_t vref = regs().FindWrite(adc::kCommonCcr, (ccr & ~0x1Fu) | adc::kCcrTsvrefe);
  ASSERT_NE(vref, kNone);
  EXPECT_NE(regs().FindWrite(adc::kAdc1 + adc::kSmpr1, 7u << 21), kNone);
  EXPECT_NE(regs().FindWrite(adc::kAdc1 + adc::kSqr3, 17u), kNone);
  EXPECT_EQ(regs().WritesTo(adc::kAdc1 + adc::kCr2).size(), 2u + 16u + 2u);
  // ... and everything put back as the sampler had it.
  EXPECT_EQ(regs().Peek(adc::kCommonCcr), ccr);
  EXPECT_EQ(regs().Peek(adc::kAdc1 + adc::kCr1), cr1);
  EXPECT_EQ(regs().Peek(adc::kAdc1 + adc::kCr2), cr2);
  EXPECT_EQ(regs().Peek(adc::kAdc1 + adc::kSqr1), 1u << adc::kSqr1LPos);
  EXPECT_EQ(regs().Peek(adc::kAdc1 + adc::kSqr3), adc::Sqr3(0, 0) | adc::Sqr3(1, 1));
  EXPECT_EQ(regs().Peek(adc::kAdc1 + adc::kSmpr1), 0u);

  // No factory calibration (erased system memory reads 0xFFFF): unavailable, not a guess.
  regs().Poke(kVrefintCalWord, 0xFFFFu << 16);
  EXPECT_FALSE(system.MeasureSelfTest(wire::SelfTestCheck::kVdda, 200).available);
}

TEST_F(SelfTestPortTest, EncoderRunsWhenEnabledInEncoderMode3) {
  BoardSystemControl system;
  // Reset state: CEN clear, SMS 000 (RM0090 §18.4.1, §18.4.3).
  auto m = system.MeasureSelfTest(wire::SelfTestCheck::kEncoder1, 200);
  ASSERT_TRUE(m.available);
  EXPECT_FALSE(m.ok);
  regs().Poke(tim::kTim3 + tim::kCr1, tim::kCr1Cen);
  regs().Poke(tim::kTim3 + tim::kSmcr, tim::kSmcrEncoderMode3);
  regs().Poke(tim::kTim3 + tim::kCnt, 1234);
  m = system.MeasureSelfTest(wire::SelfTestCheck::kEncoder1, 200);
  EXPECT_TRUE(m.ok);
  EXPECT_EQ(m.mantissa, 1234);
  // Enabled but in external clock mode 1 (SMS 111) is not counting the encoder.
  regs().Poke(tim::kTim4 + tim::kCr1, tim::kCr1Cen);
  regs().Poke(tim::kTim4 + tim::kSmcr, tim::kSmcrExternalClock1);
  EXPECT_FALSE(system.MeasureSelfTest(wire::SelfTestCheck::kEncoder2, 200).ok);
  regs().Poke(tim::kTim4 + tim::kSmcr, tim::kSmcrEncoderMode3);
  EXPECT_TRUE(system.MeasureSelfTest(wire::SelfTestCheck::kEncoder2, 200).ok);
}

}  // namespace
}  // namespace vibid::fw::stm32::test
