// The port's self-test measurements on the fake register file: the crystal error from DWT
// cycles over start-of-frame flags of a modelled host, its timeout without one, the encoder
// timers' state, and the converter noise and offsets through the sampler's own interrupt path.
#include <cmath>
#include <vector>

#include "board_port.hpp"
#include "crystal_check.hpp"
#include "port_test_fixture.hpp"
#include "regs/core_m4.hpp"
#include "regs/otg_fs.hpp"
#include "regs/peripherals.hpp"
#include "regs/rcc.hpp"
#include "sampler.hpp"
#include "self_test.hpp"
#include "system.hpp"

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
  EXPECT_EQ(m.reference, wire::SelfTestReference::kUsbFrames);
}

TEST_F(SelfTestPortTest, OnTheHsiFallbackTheCrystalChecksAreUnavailable) {
  regs().LogReads(false);
  ModelFrames(168'008.4, 97);  // a host is there, but the core is not on the crystal
  BoardSystemControl system;
  system.AttachClock(ClockConfig{ClockSource::kHsiFallback, 16000000, 16000000, 16000000,
                                 HsiReason::kHseWrongFrequency, 12000000, true},
                     true);
  regs().Poke(rcc::kBdcr, rcc::kBdcrLseRdy);
  EXPECT_FALSE(system.MeasureSelfTest(wire::SelfTestCheck::kHsePpm, 200).available);
  EXPECT_FALSE(system.MeasureSelfTest(wire::SelfTestCheck::kHsePpmLse, 200).available);
  // get-info's health page: why, and the crystal as measured.
  EXPECT_EQ(system.ClockHealth().state, wire::ClockState::kCrystalWrongFrequency);
  EXPECT_EQ(system.ClockHealth().hse_measured_hz, 12000000u);
}

// TIM5 counting 84 MHz from the HSE, its channel 4 capturing every 8th LSE edge: the k-th capture
// at k x 8 / 32768 s x 84 MHz x (1 + e) for an HSE fast by e.
class LseCheckTest : public PortTest {
 protected:
  void ModelLse(double hse_error, bool lse_ready = true) {
    regs().Poke(rcc::kBdcr, lse_ready ? rcc::kBdcrLseRdy : 0);
    regs().OnRead(tim::kTim5 + tim::kSr, [](std::uint32_t held) { return held | tim::kSrCc4if; });
    regs().OnRead(tim::kTim5 + tim::kCcr4, [this, hse_error](std::uint32_t) {
      const double ticks = static_cast<double>(capture_++) * 8.0 / 32768.0 * 84e6 * (1 + hse_error);
      return static_cast<std::uint32_t>(std::llround(ticks) & 0xFFFFFFFF);
    });
  }
  std::uint64_t capture_ = 1000;  // the counter runs from anywhere
};

TEST_F(LseCheckTest, TheCrystalAgainstTheLse) {
  // Closed form: over 4096 captures (32 768 LSE cycles, 1 s) the 84 MHz timer counts 84 000 000
  // x (1 + e): +37 ppm reads +37.000 ppm, the rounding of each capture cancelling.
  EXPECT_EQ(LseErrorMilliPpm(84'003'108, 4096, 84'000'000), 37'000);
  EXPECT_EQ(LseErrorMilliPpm(83'991'600, 4096, 84'000'000), -100'000);
  regs().LogReads(false);
  ModelLse(37e-6);
  // The sampler's frame counter set-up, to be put back.
  regs().Poke(tim::kTim5 + tim::kSmcr, 0x7);
  regs().Poke(tim::kTim5 + tim::kArr, 0xFFFFFFFF);
  regs().Poke(tim::kTim5 + tim::kCnt, 1234);
  BoardSystemControl system;
  system.AttachClock(ClockConfig{ClockSource::kPllFromHse, 168000000, 84000000, 84000000}, true);
  const auto m = system.MeasureSelfTest(wire::SelfTestCheck::kHsePpmLse, 200);
  ASSERT_TRUE(m.available);
  EXPECT_EQ(m.exp10, -3);
  EXPECT_NEAR(static_cast<double>(m.mantissa), 37'000.0, 20.0);
  EXPECT_EQ(m.reference, wire::SelfTestReference::kLse);
  // TIM5_OR TI4_RMP = 10 (LSE, 0x80), CCMR2 CC4S = 01 and IC4PSC = 11 (0xD00), CC4E (bit 12),
  // counting the internal clock (SMCR 0) while it measured; then the frame counter's set-up again.
  EXPECT_NE(regs().FindWrite(tim::kTim5 + tim::kOr, 0x80), kNone);
  EXPECT_NE(regs().FindWrite(tim::kTim5 + tim::kCcmr2, 0xD00), kNone);
  EXPECT_NE(regs().FindWrite(tim::kTim5 + tim::kCcer, Bit(12)), kNone);
  EXPECT_NE(regs().FindWrite(tim::kTim5 + tim::kSmcr, 0), kNone);
  EXPECT_EQ(regs().Peek(tim::kTim5 + tim::kSmcr), 0x7U);
  EXPECT_EQ(regs().Peek(tim::kTim5 + tim::kOr), 0U);
  EXPECT_EQ(regs().Peek(tim::kTim5 + tim::kCnt), 1234U);
  EXPECT_GE(regs().CountWrites(iwdg::kKr), 60u);  // fed through the second
}

TEST_F(LseCheckTest, NoLseOrNotReadyIsUnavailable) {
  ModelLse(0.0, /*lse_ready=*/false);
  BoardSystemControl system;
  system.AttachClock(ClockConfig{ClockSource::kPllFromHse, 168000000, 84000000, 84000000}, true);
  EXPECT_FALSE(system.MeasureSelfTest(wire::SelfTestCheck::kHsePpmLse, 200).available);
  regs().Poke(rcc::kBdcr, rcc::kBdcrLseRdy);
  system.AttachClock(ClockConfig{ClockSource::kPllFromHse, 168000000, 84000000, 84000000}, false);
  EXPECT_FALSE(system.MeasureSelfTest(wire::SelfTestCheck::kHsePpmLse, 200).available);
}

TEST_F(LseCheckTest, StartLseOpensTheBackupDomainOnlyForLseOn) {
  // PWR_CR DBP reads back set only after a few reads (the write reaching the backup domain).
  int dbp_reads = 0;
  regs().OnRead(pwr::kCr, [&dbp_reads](std::uint32_t held) {
    return (held & Bit(8)) != 0 && ++dbp_reads < 3 ? held & ~Bit(8) : held;
  });
  StartLse();
  // PWR clock (APB1ENR bit 28), PWR_CR DBP (bit 8) set and read back set, RCC_BDCR LSEON
  // (bit 0), DBP cleared (RM0090 §5.1.2, §7.3.20).
  const std::size_t dbp = regs().FindWriteWithBits(pwr::kCr, Bit(8));
  const std::size_t lse = regs().FindWriteWithBits(rcc::kBdcr, Bit(0));
  ASSERT_NE(dbp, kNone);
  ASSERT_NE(lse, kNone);
  EXPECT_LT(regs().FindWriteWithBits(rcc::kApb1enr, Bit(28)), dbp);
  EXPECT_LT(dbp, lse);
  std::size_t set_read = kNone;
  for (std::size_t i = dbp + 1; i < lse; ++i) {
    const Access& a = regs().log()[i];
    if (a.kind == Access::Kind::kRead && a.address == pwr::kCr && (a.value & Bit(8)) != 0)
      set_read = i;
  }
  EXPECT_NE(set_read, kNone);  // LSEON only after DBP read back set
  EXPECT_GE(dbp_reads, 3);
  EXPECT_EQ(regs().Peek(pwr::kCr) & Bit(8), 0U);
  // A DBP that never reads back set: LSEON is not written (the self-test's LSE check then finds
  // no LSE ready and answers unavailable), DBP is cleared.
  regs().Clear();
  regs().OnRead(pwr::kCr, [](std::uint32_t held) { return held & ~Bit(8); });
  StartLse();
  EXPECT_EQ(regs().CountWrites(rcc::kBdcr), 0U);
}

TEST_F(SelfTestPortTest, NoFramesIsUnavailableNotAPass) {
  regs().LogReads(false);
  ModelFrames(1e18, 1000);  // no host: one frame, then none
  std::uint32_t cycles = 0;
  EXPECT_FALSE(CountCyclesOverFrames(1000, 168'000'000, cycles));
  BoardSystemControl system;
  EXPECT_FALSE(system.MeasureSelfTest(wire::SelfTestCheck::kHsePpm, 200).available);
  // Without the sampler and the image attached (main attaches both) there is nothing to measure.
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
  const std::uint32_t cr2 =
      adc::kCr2Adon | adc::kCr2Eocs | adc::kCr2ExtselTim2Trgo | adc::kCr2ExtenRising;
  regs().Poke(adc::kCommonCcr, ccr);
  regs().Poke(adc::kAdc1 + adc::kCr1, cr1);
  regs().Poke(adc::kAdc1 + adc::kCr2, cr2);
  const std::uint32_t slave_cr2 = adc::kCr2Adon | adc::kCr2Eocs;
  regs().Poke(adc::kAdc2 + adc::kCr2, slave_cr2);
  regs().Poke(adc::kAdc3 + adc::kCr2, slave_cr2);
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
  // RM0090 §13.13.17 (MULTI: "disable the multi ADC mode before any change of configuration"):
  // ADC1, ADC2 and ADC3 all off (CR2 = 0) before MULTI goes to 00000 with the DMA bits and DDS
  // (ADCPRE /4 and TSVREFE only: 0x810000), and all off again before it goes back to triple.
  const std::size_t vref = regs().FindWrite(adc::kCommonCcr, 0x810000U);
  ASSERT_NE(vref, kNone);
  for (const Address converter : {adc::kAdc1, adc::kAdc2, adc::kAdc3})
    EXPECT_LT(regs().FindWrite(converter + adc::kCr2, 0), vref) << std::hex << converter;
  const std::size_t back = regs().FindWrite(adc::kCommonCcr, ccr, vref);
  ASSERT_NE(back, kNone);
  const std::size_t adc1_off = regs().FindWrite(adc::kAdc1 + adc::kCr2, 0, vref);
  EXPECT_LT(adc1_off, back);
  // The slaves come back on before the master, after the mode.
  const std::size_t adc3_on = regs().FindWrite(adc::kAdc3 + adc::kCr2, slave_cr2, back);
  const std::size_t adc1_on = regs().FindWrite(adc::kAdc1 + adc::kCr2, cr2, back);
  ASSERT_NE(adc3_on, kNone);
  EXPECT_LT(adc3_on, adc1_on);
  EXPECT_EQ(regs().Peek(adc::kAdc2 + adc::kCr2), slave_cr2);
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

// The sampler as the board runs it, its interrupt modelled at each watchdog kick of the
// self-test's wait: a frame with the next codes of each channel's sequence while `deliver` is
// set, otherwise a millisecond passes (SysTick).
class IdleSamplingTest : public PortTest {
 protected:
  void SetUp() override {
    PortTest::SetUp();
    regs().LogReads(false);
    sampler_.Init({ClockSource::kPllFromHse, 168000000, 84000000, 84000000});
    system_.AttachSampler(sampler_);
    regs().OnWrite(iwdg::kKr, [this](std::uint32_t, std::uint32_t written) {
      Tick();
      return written;
    });
  }
  void Tick() {
    if (!deliver_ || (regs().Peek(tim::kTim2 + tim::kCr1) & tim::kCr1Cen) == 0) {
      OnSysTick();
      return;
    }
    // DMA buffer items: force1 0, acc1 1, acc2 2, force2 3 (sampler.cpp kBufferIndex).
    constexpr unsigned kItem[4] = {0, 3, 1, 2};
    for (unsigned ch = 0; ch < 4; ++ch)
      sampler_dma::adc[kItem[ch]] = static_cast<std::uint16_t>(codes_[ch][k_ % codes_[ch].size()]);
    ++k_;
    regs().Poke(tim::kTim5 + tim::kCnt, regs().Peek(tim::kTim5 + tim::kCnt) + 1);
    regs().Poke(dma::Stream(dma::kDma2, 0) + dma::kSxNdtr, 6);
    regs().Poke(tim::kTim2 + tim::kCnt, 2000);
    regs().Poke(dma::kDma2 + dma::kLisr, dma::kStream0Tcif);
    sampler_.HandleDmaInterrupt();
  }
  SystemControl::SelfTestMeasurement Measure(wire::SelfTestCheck check, std::uint32_t period_us) {
    k_ = 0;
    return system_.MeasureSelfTest(check, period_us);
  }

  Sampler sampler_;
  BoardSystemControl system_;
  bool deliver_ = true;
  std::size_t k_ = 0;
  // force1: 2048 +- 3 alternating (rms 3, offset 0); force2: 2048, 2049, 2050, 2049 (rms
  // sqrt(1/2) = 0.707, offset +1); acc1: constant 2100 (rms 0, offset +52); acc2: the ramp
  // 1548 .. 2547 (rms sqrt((1000^2 - 1) / 12) = 288.675, offset -0.5).
  std::vector<std::uint32_t> codes_[4] = {{2051, 2045}, {2048, 2049, 2050, 2049}, {2100}, {}};
};

TEST_F(IdleSamplingTest, NoiseAndOffsetOfEachChannelFromAThousandFrames) {
  for (std::uint32_t k = 0; k < 1000; ++k) codes_[3].push_back(1548 + k);
  using C = wire::SelfTestCheck;
  const struct {
    C check;
    std::int64_t milli_lsb;
  } expected[] = {{C::kNoiseForce1, 3'000},   {C::kNoiseForce2, 707},  {C::kNoiseAccel1, 0},
                  {C::kNoiseAccel2, 288'675}, {C::kOffsetForce1, 0},   {C::kOffsetForce2, 1'000},
                  {C::kOffsetAccel1, 52'000}, {C::kOffsetAccel2, -500}};
  for (const auto& e : expected) {
    const auto m = Measure(e.check, 200);
    ASSERT_TRUE(m.available) << wire::SelfTestCheckName(static_cast<std::uint8_t>(e.check));
    EXPECT_EQ(m.exp10, -3);
    EXPECT_EQ(m.mantissa, e.milli_lsb)
        << wire::SelfTestCheckName(static_cast<std::uint8_t>(e.check));
    EXPECT_EQ(sampler_.frames(), wire::kSelfTestSamples);
  }
  // At the configured period: 84 MHz x 200 us = 16 800 timer clocks; stopped afterwards.
  EXPECT_EQ(regs().Peek(tim::kTim2 + tim::kArr), 16'799u);
  EXPECT_EQ(regs().Peek(tim::kTim2 + tim::kCr1) & tim::kCr1Cen, 0u);
}

TEST_F(IdleSamplingTest, NoFramesTooLongOrABusySamplerIsUnavailable) {
  codes_[3] = {2048};
  // No frame comes: given up after the frames' time plus the slack, the sampler stopped.
  deliver_ = false;
  EXPECT_FALSE(Measure(wire::SelfTestCheck::kNoiseForce1, 200).available);
  EXPECT_EQ(regs().Peek(tim::kTim2 + tim::kCr1) & tim::kCr1Cen, 0u);
  deliver_ = true;
  // 1000 frames at 1001 us exceed the second the main loop may wait: not started at all.
  const std::size_t starts = regs().WritesTo(tim::kTim2 + tim::kCr1).size();
  EXPECT_FALSE(Measure(wire::SelfTestCheck::kNoiseForce1, 1001).available);
  EXPECT_EQ(regs().WritesTo(tim::kTim2 + tim::kCr1).size(), starts);
  EXPECT_TRUE(Measure(wire::SelfTestCheck::kNoiseForce1, 1000).available);
  // A period the sampler refuses: 5 us is below its minimum (one scan and the interrupt).
  EXPECT_FALSE(Measure(wire::SelfTestCheck::kOffsetForce1, 5).available);
  // Running already (an acquisition): refused by the sampler, left running.
  class Idle final : public FrameSink {
    void OnFrame(const SampleFrame&) override {}
  } idle;
  ASSERT_EQ(sampler_.Start(200, idle), Status::kOk);
  EXPECT_FALSE(Measure(wire::SelfTestCheck::kOffsetForce1, 200).available);
  EXPECT_NE(regs().Peek(tim::kTim2 + tim::kCr1) & tim::kCr1Cen, 0u);
  sampler_.Stop();
}

TEST_F(IdleSamplingTest, TheImageCrcIsTheTrailersCheck) {
  // The trailer check itself: image_crc_test.cpp; here only that the port answers with it.
  EXPECT_FALSE(system_.MeasureSelfTest(wire::SelfTestCheck::kImageCrc, 200).available);
  std::vector<std::uint8_t> bytes(24, 0);
  system_.AttachImage({.bytes = bytes.data(), .address = 0x08000000, .size = bytes.size()});
  const auto m = system_.MeasureSelfTest(wire::SelfTestCheck::kImageCrc, 200);
  EXPECT_TRUE(m.available);  // a trailer without its magic: a failure, not "unavailable"
  EXPECT_FALSE(m.ok);
}

}  // namespace
}  // namespace vibid::fw::stm32::test
