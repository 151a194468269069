// Sampler on the fake register file: encoders latched by DMA at the converters' instant, the frame
// tick taken from the TIM5 edge counter (so lost frames leave a gap the core counts as overruns),
// torn frames dropped, and ADC overrun / DMA error recovery from the first channel.
#include <algorithm>
#include <vector>

#include "port_test_fixture.hpp"
#include "regs/core_m4.hpp"
#include "regs/peripherals.hpp"
#include "regs/rcc.hpp"
#include "sampler.hpp"

namespace vibid::fw::stm32::test {
namespace {

constexpr ClockConfig kFullSpeed{ClockSource::kPllFromHse, 168000000, 84000000, 84000000};
const Address kAdcStream = dma::Stream(dma::kDma2, 0);
const Address kEnc0Stream = dma::Stream(dma::kDma1, 1);
const Address kEnc1Stream = dma::Stream(dma::kDma1, 7);

class CaptureSink final : public FrameSink {
 public:
  void OnFrame(const SampleFrame& frame) override { frames.push_back(frame); }
  std::vector<SampleFrame> frames;
};

class SamplerTest : public PortTest {
 protected:
  void SetUp() override {
    PortTest::SetUp();
    sampler_.Init(kFullSpeed);
    ASSERT_EQ(sampler_.Start(1000, sink_), Status::kOk);  // 1 kHz
  }
  /// One DMA transfer-complete interrupt with `edges` counted by TIM5 and the TIM2 counter at
  /// `since_edge` timer clocks after the latest edge.
  void Interrupt(std::uint32_t edges, std::uint32_t since_edge = 2000,
                 std::uint32_t lisr = dma::kStream0Tcif, std::uint32_t ndtr = 6) {
    regs().Poke(tim::kTim5 + tim::kCnt, edges);
    regs().Poke(kAdcStream + dma::kSxNdtr, ndtr);
    regs().Poke(tim::kTim2 + tim::kCnt, since_edge);
    regs().Poke(dma::kDma2 + dma::kLisr, lisr);
    sampler_.HandleDmaInterrupt();
  }
  std::vector<std::uint32_t> Ticks() const {
    std::vector<std::uint32_t> t;
    for (const SampleFrame& f : sink_.frames) t.push_back(f.tick);
    return t;
  }
  Sampler sampler_;
  CaptureSink sink_;
};

TEST_F(SamplerTest, InitRoutesTheEdgeToAdcEncodersAndFrameCounter) {
  // TIM5: external clock mode 1 (SMS 111) from ITR0 = TIM2 TRGO (TS 000), no DMA request.
  EXPECT_EQ(regs().Peek(tim::kTim5 + tim::kSmcr), 0x7U);
  EXPECT_EQ(regs().Peek(tim::kTim5 + tim::kDier), 0U);
  // TIM2 (RM0090 §18.4): DIER CC3DE (bit 11) and CC4DE (bit 12), no UDE (bit 8); CCR3 (0x3C)
  // and CCR4 (0x40) at 56 ADC clocks x 4 = 224 timer clocks, when the converters' first
  // sampling phase ends: the encoders are latched with force1, acc1 and acc2.
  EXPECT_EQ(regs().Peek(tim::kTim2 + tim::kDier), Bit(11) | Bit(12));
  EXPECT_EQ(regs().Peek(tim::kTim2 + 0x3C), 224U);
  EXPECT_EQ(regs().Peek(tim::kTim2 + 0x40), 224U);
  EXPECT_EQ(regs().Peek(tim::kTim2 + tim::kCr2), 0x2U << 4);  // MMS update -> TRGO
  // DMA1 stream 1 channel 3 (TIM2_UP/TIM2_CH3) <- TIM3_CNT, stream 7 channel 3 (TIM2_UP/
  // TIM2_CH4) <- TIM4_CNT: RM0090 table 42. 16 bit, circular, one item, no increment, enabled.
  const std::uint32_t common =
      dma::kCrPlHigh | dma::kCrMsize16 | dma::kCrPsize16 | dma::kCrCirc | dma::kCrEn;
  EXPECT_EQ(regs().Peek(kEnc0Stream + dma::kSxCr), common | (3U << 25));
  EXPECT_EQ(regs().Peek(kEnc1Stream + dma::kSxCr), common | (3U << 25));
  EXPECT_EQ(kEnc1Stream, 0x400260B8U);  // DMA1 0x40026000 + 0x10 + 0x18 x 7
  EXPECT_EQ(regs().Peek(kEnc0Stream + dma::kSxPar), 0x40000424U);  // TIM3 base + CNT 0x24
  EXPECT_EQ(regs().Peek(kEnc1Stream + dma::kSxPar), 0x40000824U);  // TIM4 base + CNT 0x24
  EXPECT_EQ(regs().Peek(kEnc0Stream + dma::kSxNdtr), 1U);
  // The converters: see ConvertersSampleTheHammerChannelsAtOneInstant.
  EXPECT_EQ(regs().Peek(adc::kAdc1 + adc::kCr1), Bit(8) | Bit(26));  // SCAN | OVRIE
  // ADC interrupt (IRQ 18) enabled in the NVIC after its pending bit was cleared.
  const std::size_t clear = regs().FindWrite(0xE000E280, Bit(18));
  const std::size_t enable = regs().FindWrite(0xE000E100, Bit(18), clear);
  EXPECT_NE(clear, kNone);
  EXPECT_NE(enable, kNone);
  // A DSB after the clock enables, before the first peripheral access (ES0182 §2.1.13).
  const std::size_t clocks = regs().FindWriteWithBits(rcc::kApb2enr, rcc::kApb2Adc1);
  const std::size_t dsb = regs().FindCpu(fake::CpuOp::kDsb, clocks);
  EXPECT_EQ(dsb, clocks + 1);  // right after the enable write
  // 2 x 68 ADC clocks at 21 MHz = 6.48 us, plus 7 us: 14 us (ceil).
  EXPECT_EQ(sampler_.min_period_us(), 14U);
}

TEST_F(SamplerTest, ConvertersSampleTheHammerChannelsAtOneInstant) {
  // ADC_CCR (RM0090 §13.13.17): MULTI 4:0 = 10110 (triple, regular simultaneous only), DDS bit 13,
  // DMA 15:14 = 01 (mode 1), ADCPRE 17:16 = 01 (PCLK2 / 4): 0x16 | 0x2000 | 0x4000 | 0x10000.
  EXPECT_EQ(regs().Peek(adc::kCommonCcr), 0x16016U);
  // The common data register ADC_CDR at 0x40012308 (common base 0x40012300 + 0x08, §13.13.18)
  // feeds DMA2 stream 0 (channel 0, ADC1: table 43), six half-words per frame, circular.
  EXPECT_EQ(regs().Peek(kAdcStream + dma::kSxPar), 0x40012308U);
  EXPECT_EQ(regs().Peek(kAdcStream + dma::kSxNdtr), 6U);
  EXPECT_EQ(regs().Peek(kAdcStream + dma::kSxCr),
            dma::kCrPlHigh | dma::kCrMsize16 | dma::kCrPsize16 | dma::kCrMinc | dma::kCrCirc |
                dma::kCrTcie | dma::kCrTeie | dma::kCrEn);
  // ADC1 at 0x40012000, ADC2 at 0x40012100, ADC3 at 0x40012200 (§13.13.19). Each: SCAN (CR1 bit
  // 8) and OVRIE (bit 26); SQR1 L 23:20 = 1 (two conversions); SMPR2 SMP0..SMP3 = 011
  // (56 cycles); SQR3 SQ1 4:0 and SQ2 9:5 (§13.13.11).
  struct Expected {
    Address base;
    std::uint32_t sq1, sq2, cr2;
  };
  // CR2 (§13.13.3): ADON bit 0 and EOCS bit 10 on all three (§13.8.1: overrun detection is on
  // only with DMA = 1 or EOCS = 1, and CR2's DMA bit is unused here); on ADC1 only EXTEN 29:28 =
  // 01 (rising) and EXTSEL 27:24 = 0110 (TIM2_TRGO); DMA (bit 8) and DDS (bit 9) stay 0 in
  // multi-ADC mode.
  const Expected expected[] = {{0x40012000, 0, 1, 0x16000401},   // force1 IN0, force2 IN1
                               {0x40012100, 2, 2, 0x00000401},   // acc1 IN2 twice
                               {0x40012200, 3, 3, 0x00000401}};  // acc2 IN3 twice
  for (const Expected& e : expected) {
    EXPECT_EQ(regs().Peek(e.base + 0x04), Bit(8) | Bit(26)) << std::hex << e.base;
    EXPECT_EQ(regs().Peek(e.base + 0x2C), 1U << 20) << std::hex << e.base;
    EXPECT_EQ(regs().Peek(e.base + 0x10), 0x3U | (0x3U << 3) | (0x3U << 6) | (0x3U << 9));
    EXPECT_EQ(regs().Peek(e.base + 0x34), e.sq1 | (e.sq2 << 5)) << std::hex << e.base;
    EXPECT_EQ(regs().Peek(e.base + 0x08), e.cr2) << std::hex << e.base;
  }
  // The slaves are on before the master can be triggered.
  const std::size_t master_on = regs().FindWrite(0x40012008, 0x16000401);
  ASSERT_NE(master_on, kNone);
  EXPECT_LT(regs().FindWrite(0x40012108, 0x401), master_on);
  EXPECT_LT(regs().FindWrite(0x40012208, 0x401), master_on);
  // All three clocked: RCC_APB2ENR ADC1EN 8, ADC2EN 9, ADC3EN 10 (RM0090 §7.3.14).
  EXPECT_NE(regs().FindWriteWithBits(rcc::kApb2enr, Bit(8) | Bit(9) | Bit(10)), kNone);
}

TEST_F(SamplerTest, FramesTakeEachChannelFromItsConverterAndRank) {
  // DMA mode 1 order: ADC1, ADC2, ADC3 of rank 1, then of rank 2 (RM0090 §13.9).
  const std::uint16_t buffer[6] = {101, 202, 303, 404, 505, 606};
  for (unsigned i = 0; i < 6; ++i) sampler_dma::adc[i] = buffer[i];
  Interrupt(1);
  ASSERT_EQ(sink_.frames.size(), 1U);
  EXPECT_EQ(sink_.frames[0].raw[0], 101);  // force1: ADC1 rank 1
  EXPECT_EQ(sink_.frames[0].raw[1], 404);  // force2: ADC1 rank 2
  EXPECT_EQ(sink_.frames[0].raw[2], 202);  // acc1: ADC2 rank 1
  EXPECT_EQ(sink_.frames[0].raw[3], 303);  // acc2: ADC3 rank 1
}

TEST_F(SamplerTest, StartArmsTheCounterBeforeTheFirstEdge) {
  const auto& log = regs().log();
  const std::size_t counter_on = regs().FindWrite(tim::kTim5 + tim::kCr1, tim::kCr1Cen);
  const std::size_t first_edge = regs().FindWrite(tim::kTim2 + tim::kEgr, tim::kEgrUg);
  const std::size_t timer_on = regs().FindWrite(tim::kTim2 + tim::kCr1, tim::kCr1Cen);
  ASSERT_NE(counter_on, kNone);
  EXPECT_LT(counter_on, first_edge);
  EXPECT_LT(first_edge, timer_on);
  EXPECT_EQ(timer_on + 1, log.size());
  // 1 ms at 84 MHz: ARR = 84000 - 1.
  EXPECT_EQ(regs().Peek(tim::kTim2 + tim::kArr), 83999U);
  sampler_.Stop();
  EXPECT_EQ(sampler_.Start(13, sink_), Status::kInvalidArgument);
  EXPECT_EQ(sampler_.Start(14, sink_), Status::kOk);
}

TEST_F(SamplerTest, FramesCarryTheTimerTickAndTheLatchedEncoders) {
  sampler_dma::adc[0] = 100;
  sampler_dma::adc[2] = 4000;
  sampler_dma::encoders[0] = 5;
  sampler_dma::encoders[1] = 0xFFFE;  // -2 from 0
  Interrupt(1);
  // The encoder counters moved on since the edge; the frame must not see that.
  regs().Poke(tim::kTim3 + tim::kCnt, 999);
  sampler_dma::encoders[0] = 8;
  sampler_dma::encoders[1] = 1;
  Interrupt(2);
  ASSERT_EQ(Ticks(), (std::vector<std::uint32_t>{0, 1}));
  EXPECT_EQ(sink_.frames[0].raw[0], 100);
  EXPECT_EQ(sink_.frames[0].raw[3], 4000);
  EXPECT_EQ(sink_.frames[0].raw[4], 5);
  EXPECT_EQ(sink_.frames[0].raw[5], -2);
  EXPECT_EQ(sink_.frames[1].raw[4], 8);
  EXPECT_EQ(sink_.frames[1].raw[5], 1);
  EXPECT_EQ(sampler_.frames(), 2U);
}

TEST_F(SamplerTest, MergedInterruptsLeaveAGapInTheTick) {
  Interrupt(1);
  Interrupt(4);  // Edges 2 and 3 came and went before this interrupt ran.
  Interrupt(5);
  // The core counts tick - expected as overruns (firmware/core/sampler.cpp): 2 here.
  EXPECT_EQ(Ticks(), (std::vector<std::uint32_t>{0, 3, 4}));
}

TEST_F(SamplerTest, AFrameWhoseNextScanHasBegunIsDropped) {
  Interrupt(1);
  // 2 x (56 + 12) ADC clocks x (84 MHz / 21 MHz) = 544 timer clocks per scan: at 543 the
  // newer scan is still converting.
  Interrupt(3, 543);
  // Past the conversion time but the last result not yet moved (NDTR 1 of 6).
  Interrupt(3, 600, dma::kStream0Tcif, 1);
  // An interrupt right after its own scan, as in normal running: delivered.
  Interrupt(3, 544);
  EXPECT_EQ(Ticks(), (std::vector<std::uint32_t>{0, 2}));
  EXPECT_EQ(sampler_.counters().torn_frames, 2U);
}

TEST_F(SamplerTest, AdcOverrunIsCountedAndRecoveredFromTheFirstChannel) {
  Interrupt(1);
  // The DWT cycle counter runs (10 cycles per read) so the stabilisation wait ends by its count.
  std::uint32_t cycles = 0;
  regs().OnRead(dwt::kCyccnt, [&cycles](std::uint32_t) { return cycles += 10; });
  const std::size_t before = regs().log().size();
  regs().Poke(adc::kAdc1 + adc::kSr, adc::kSrOvr);
  sampler_.HandleAdcInterrupt();
  EXPECT_EQ(sampler_.counters().adc_overruns, 1U);
  EXPECT_EQ(sampler_.counters().recoveries, 1U);
  // RM0090 §13.9 (multi-ADC DMA requests) and §13.8.1 (overrun): converters off (sequencers
  // back to rank 1, the ADC1 -> ADC2 -> ADC3 order from ADC1) -> ADC_CCR DMA bits 15:14 and DDS
  // (13) cleared, MULTI and ADCPRE kept (0x16 | 0x10000) -> stream disabled -> flags cleared ->
  // NDTR 6 and the buffer start -> stream on -> OVR cleared -> CCR DMA mode 1 and DDS again
  // (0x16016) -> slaves on -> ADC1 on with the trigger -> at least 3 us (504 cycles at 168 MHz).
  const std::size_t adc_off = regs().FindWrite(adc::kAdc3 + adc::kCr2, 0, before);
  EXPECT_LT(regs().FindWrite(adc::kAdc1 + adc::kCr2, 0, before), adc_off);
  const std::size_t dma_off = regs().FindWrite(adc::kCommonCcr, 0x10016U, adc_off);
  const std::size_t stream_off = regs().FindWrite(
      kAdcStream + dma::kSxCr, regs().Peek(kAdcStream + dma::kSxCr) & ~dma::kCrEn, dma_off);
  const std::size_t flags =
      regs().FindWrite(dma::kDma2 + dma::kLifcr, dma::kStream0Flags, stream_off);
  const std::size_t ndtr = regs().FindWrite(kAdcStream + dma::kSxNdtr, 6, flags);
  const std::size_t stream_on = regs().FindWriteWithBits(kAdcStream + dma::kSxCr, dma::kCrEn, ndtr);
  const std::size_t ovr = regs().FindWrite(adc::kAdc1 + adc::kSr, 0, stream_on);
  const std::size_t dma_on = regs().FindWrite(adc::kCommonCcr, 0x16016U, ovr);
  const std::size_t slave_on =
      regs().FindWrite(adc::kAdc3 + adc::kCr2, adc::kCr2Adon | adc::kCr2Eocs, dma_on);
  const std::size_t adc_on = regs().FindWriteWithBits(
      adc::kAdc1 + adc::kCr2, adc::kCr2Adon | adc::kCr2ExtenRising, slave_on);
  for (std::size_t step :
       {adc_off, dma_off, stream_off, flags, ndtr, stream_on, ovr, dma_on, slave_on, adc_on})
    EXPECT_NE(step, kNone);
  EXPECT_GE(cycles, 504U);
  EXPECT_EQ(regs().Peek(adc::kCommonCcr), 0x16016U);
  // An overrun on a slave converter is caught too.
  regs().Poke(adc::kAdc3 + adc::kSr, adc::kSrOvr);
  sampler_.HandleAdcInterrupt();
  EXPECT_EQ(sampler_.counters().adc_overruns, 2U);
  EXPECT_EQ(regs().Peek(adc::kAdc3 + adc::kSr), 0U);
  // The first scan after the recovery may have started before the converters settled: dropped,
  // a gap the core counts. Scans lost meanwhile show as the gap too: edges 2..4 never delivered.
  Interrupt(4);
  EXPECT_EQ(Ticks(), (std::vector<std::uint32_t>{0}));
  EXPECT_EQ(sampler_.counters().dropped_after_recovery, 1U);
  Interrupt(5);
  EXPECT_EQ(Ticks(), (std::vector<std::uint32_t>{0, 4}));
}

TEST_F(SamplerTest, DmaTransferErrorsAreCountedAndRecovered) {
  Interrupt(1, 2000, dma::kStream0Teif);
  EXPECT_EQ(sampler_.counters().dma_errors, 1U);
  EXPECT_EQ(sampler_.counters().recoveries, 1U);
  EXPECT_TRUE(sink_.frames.empty());
  Interrupt(2);  // the first frame after the recovery is dropped
  EXPECT_TRUE(sink_.frames.empty());
  // An encoder latch stream error (TEIF1 is LISR bit 9) is re-armed on the next frame.
  regs().Poke(dma::kDma1 + dma::kLisr, Bit(9));
  const std::size_t before = regs().log().size();
  Interrupt(3);
  EXPECT_EQ(sampler_.counters().dma_errors, 2U);
  EXPECT_NE(regs().FindWriteWithBits(kEnc0Stream + dma::kSxCr, dma::kCrEn | dma::kCrCirc, before),
            kNone);
  EXPECT_NE(regs().FindWrite(dma::kDma1 + dma::kLifcr, dma::kStream0Flags << 6, before), kNone);
  EXPECT_EQ(Ticks(), (std::vector<std::uint32_t>{2}));
  // Stream 7's transfer error (TEIF7) is HISR bit 22 + 3 = 25; its flags clear in HIFCR.
  regs().Poke(dma::kDma1 + dma::kLisr, 0);
  regs().Poke(dma::kDma1 + dma::kHisr, Bit(25));
  const std::size_t later = regs().log().size();
  Interrupt(4);
  EXPECT_EQ(sampler_.counters().dma_errors, 3U);
  EXPECT_NE(regs().FindWriteWithBits(kEnc1Stream + dma::kSxCr, dma::kCrEn | dma::kCrCirc, later),
            kNone);
  EXPECT_NE(regs().FindWrite(dma::kDma1 + dma::kHifcr, dma::kStream0Flags << 22, later), kNone);
}

TEST_F(SamplerTest, OverrunDetectionIsOnForEveryConverter) {
  // RM0090 §13.8.1: "Overrun detection is enabled only when DMA = 1 or EOCS = 1". CR2's DMA bit
  // (8) is unused in multi-ADC mode and stays 0, so EOCS (bit 10) must be set on ADC1, ADC2 and
  // ADC3, and OVRIE (CR1 bit 26) with it, every time the converters are switched on: at Init, at
  // Start and in a recovery.
  for (const Address base : {0x40012000U, 0x40012100U, 0x40012200U}) {
    std::size_t on_writes = 0;
    for (const std::uint32_t v : regs().WritesTo(base + 0x08)) {
      if ((v & Bit(0)) == 0) continue;  // an off write
      ++on_writes;
      EXPECT_EQ(v & (Bit(10) | Bit(8)), Bit(10)) << std::hex << base << " " << v;
    }
    EXPECT_EQ(on_writes, 2U) << std::hex << base;  // Init and Start
    EXPECT_EQ(regs().Peek(base + 0x04) & Bit(26), Bit(26));
  }
}

TEST_F(SamplerTest, StartReArmsTheInterleaveWhateverTheLastUseLeft) {
  sampler_.Stop();
  // What a self-test's VREFINT conversion or an unrecovered run may leave: ADC1 independent on
  // channel 17 alone, the common DMA requests off, the stream three items into a frame.
  regs().Poke(adc::kCommonCcr, 0x00810000U);  // TSVREFE, ADCPRE /4, MULTI 0
  regs().Poke(adc::kAdc1 + adc::kSqr3, 17);
  regs().Poke(adc::kAdc1 + adc::kSqr1, 0);
  regs().Poke(adc::kAdc1 + adc::kCr1, 0);
  regs().Poke(kAdcStream + dma::kSxNdtr, 3);
  std::uint32_t cycles = 0;
  regs().OnRead(dwt::kCyccnt, [&cycles](std::uint32_t) { return cycles += 10; });
  regs().OnRead(dwt::kCtrl, [](std::uint32_t) { return dwt::kCtrlCyccntEna; });
  const std::size_t before = regs().log().size();
  ASSERT_EQ(sampler_.Start(1000, sink_), Status::kOk);
  // RM0090 §13.13.17 (ADC_CCR, MULTI): "disable the multi ADC mode before any change of
  // configuration". In order: all three converters off (CR2 = 0) -> CCR MULTI 0 and DMA 00
  // (ADCPRE /4 only, 0x10000) -> ADC1's SQR3 back to IN0, IN1 (0x20) -> stream disabled -> its
  // flags cleared -> NDTR 6 from the buffer's start -> stream on -> OVR cleared -> CCR triple
  // regular simultaneous, DMA mode 1, DDS (0x16016) -> ADC3, ADC2 on -> ADC1 on with the
  // trigger -> t_STAB (3 us = 504 cycles at 168 MHz) -> the first edge (TIM2 UG).
  const std::size_t off1 = regs().FindWrite(0x40012008, 0, before);
  const std::size_t off2 = regs().FindWrite(0x40012108, 0, before);
  const std::size_t off3 = regs().FindWrite(0x40012208, 0, before);
  const std::size_t independent = regs().FindWrite(0x40012304, 0x10000U, before);
  const std::size_t sequence = regs().FindWrite(0x40012034, 0x20U, independent);
  const std::size_t stream_off = regs().FindWrite(
      kAdcStream + dma::kSxCr, regs().Peek(kAdcStream + dma::kSxCr) & ~dma::kCrEn, sequence);
  const std::size_t flags =
      regs().FindWrite(dma::kDma2 + dma::kLifcr, dma::kStream0Flags, stream_off);
  const std::size_t ndtr = regs().FindWrite(kAdcStream + dma::kSxNdtr, 6, flags);
  const std::size_t stream_on = regs().FindWriteWithBits(kAdcStream + dma::kSxCr, dma::kCrEn, ndtr);
  const std::size_t ovr = regs().FindWrite(0x40012000, 0, stream_on);
  const std::size_t triple = regs().FindWrite(0x40012304, 0x16016U, ovr);
  const std::size_t slave3 = regs().FindWrite(0x40012208, 0x401, triple);
  const std::size_t slave2 = regs().FindWrite(0x40012108, 0x401, slave3);
  const std::size_t master = regs().FindWrite(0x40012008, 0x16000401, slave2);
  const std::size_t first_edge = regs().FindWrite(tim::kTim2 + tim::kEgr, tim::kEgrUg, master);
  for (std::size_t step : {off1, off2, off3, independent, sequence, stream_off, flags, ndtr,
                           stream_on, ovr, triple, slave3, slave2, master, first_edge})
    EXPECT_NE(step, kNone);
  EXPECT_LT(std::max({off1, off2, off3}), independent);
  // The ADC (IRQ 18) and DMA2 stream 0 (IRQ 56) interrupts are off through it (NVIC ICER0 bit
  // 18, ICER1 bit 24) and on again after, their pending bits cleared first (ICPR0, ICPR1).
  const std::size_t adc_irq_off = regs().FindWrite(0xE000E180, Bit(18), before);
  const std::size_t dma_irq_off = regs().FindWrite(0xE000E184, Bit(24), before);
  const std::size_t adc_irq_on = regs().FindWrite(0xE000E100, Bit(18), master);
  const std::size_t dma_irq_on = regs().FindWrite(0xE000E104, Bit(24), master);
  EXPECT_LT(std::max(adc_irq_off, dma_irq_off), off1);
  EXPECT_LT(regs().FindWrite(0xE000E280, Bit(18), master), adc_irq_on);
  EXPECT_LT(regs().FindWrite(0xE000E284, Bit(24), master), dma_irq_on);
  EXPECT_LT(std::max(adc_irq_on, dma_irq_on), first_edge);
  EXPECT_GE(cycles, 504U);
  EXPECT_EQ(regs().Peek(adc::kCommonCcr), 0x16016U);
  EXPECT_EQ(regs().Peek(adc::kAdc1 + adc::kSqr1), 1U << 20);
  EXPECT_EQ(regs().Peek(adc::kAdc1 + adc::kCr1), Bit(8) | Bit(26));
}

TEST_F(SamplerTest, TornFramesInARowReArmTheConverters) {
  Interrupt(1);
  // A rotated buffer: every transfer-complete comes with NDTR short of 6 (mid-scan). Two torn
  // frames are a late interrupt's; the third in a row runs the recovery.
  const std::size_t before = regs().log().size();
  Interrupt(2, 2000, dma::kStream0Tcif, 5);
  Interrupt(3, 2000, dma::kStream0Tcif, 5);
  EXPECT_EQ(sampler_.counters().recoveries, 0U);
  EXPECT_EQ(regs().FindWrite(adc::kAdc1 + adc::kCr2, 0, before), kNone);
  Interrupt(4, 2000, dma::kStream0Tcif, 5);
  EXPECT_EQ(sampler_.counters().torn_frames, 3U);
  EXPECT_EQ(sampler_.counters().torn_recoveries, 1U);
  EXPECT_EQ(sampler_.counters().recoveries, 1U);
  // The recovery's steps (see AdcOverrunIsCountedAndRecoveredFromTheFirstChannel): converters
  // off, the stream back to 6 items, the converters on again.
  const std::size_t off = regs().FindWrite(adc::kAdc1 + adc::kCr2, 0, before);
  const std::size_t ndtr = regs().FindWrite(kAdcStream + dma::kSxNdtr, 6, off);
  const std::size_t on = regs().FindWrite(adc::kAdc1 + adc::kCr2, 0x16000401, ndtr);
  EXPECT_NE(off, kNone);
  EXPECT_NE(ndtr, kNone);
  EXPECT_NE(on, kNone);
  // A whole frame in between resets the run: two torn, one whole, two torn: no recovery.
  Interrupt(5);  // dropped after the recovery
  Interrupt(6);
  Interrupt(7, 2000, dma::kStream0Tcif, 5);
  Interrupt(8, 2000, dma::kStream0Tcif, 5);
  Interrupt(9);
  Interrupt(10, 2000, dma::kStream0Tcif, 5);
  Interrupt(11, 2000, dma::kStream0Tcif, 5);
  EXPECT_EQ(sampler_.counters().torn_recoveries, 1U);
  EXPECT_EQ(Ticks(), (std::vector<std::uint32_t>{0, 5, 8}));
}

TEST_F(SamplerTest, EncoderMotionAbove32768CountsPerSampleIsNotWrapped) {
  // 1 s per sample (the longest period a board takes) and an encoder moving 40 000 counts in it:
  // the latch-to-latch difference of a 16-bit counter would read 40 000 - 65 536 = -25 536.
  // The SysTick tracks the counter every millisecond (40 counts each), so the frame says 40 000.
  sampler_.Stop();
  ASSERT_EQ(sampler_.Start(1000000, sink_), Status::kOk);
  Interrupt(1, 84000000 - 1);
  std::uint32_t count = 0;
  for (int ms = 0; ms < 1000; ++ms) {
    count += 40;
    regs().Poke(tim::kTim3 + tim::kCnt, count & 0xFFFF);
    regs().Poke(tim::kTim4 + tim::kCnt, (0x10000 - count) & 0xFFFF);  // the other way
    sampler_.TrackEncoders();
  }
  sampler_dma::encoders[0] = static_cast<std::uint16_t>(count);
  sampler_dma::encoders[1] = static_cast<std::uint16_t>(0x10000 - count);
  Interrupt(2, 84000000 - 1);
  ASSERT_EQ(sink_.frames.size(), 2U);
  EXPECT_EQ(sink_.frames[1].raw[4], 40000);
  EXPECT_EQ(sink_.frames[1].raw[5], -40000);
  // The latch is taken at the edge, the track up to 1 ms before or after it: both ways agree.
  regs().Poke(tim::kTim3 + tim::kCnt, (count + 30) & 0xFFFF);
  sampler_.TrackEncoders();
  sampler_dma::encoders[0] = static_cast<std::uint16_t>(count + 10);
  Interrupt(3, 84000000 - 1);
  EXPECT_EQ(sink_.frames[2].raw[4], 40010);
}

}  // namespace
}  // namespace vibid::fw::stm32::test
