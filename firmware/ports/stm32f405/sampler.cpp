#include "sampler.hpp"

#include "regs/core_m4.hpp"
#include "regs/peripherals.hpp"
#include "regs/rcc.hpp"
#include "system.hpp"
#include "vibid/shared/board_profile.hpp"

namespace vibid::fw::stm32 {

namespace sampler_dma {
volatile std::uint16_t adc[6] = {};
volatile std::uint16_t encoders[2] = {};
}  // namespace sampler_dma

namespace {

volatile std::uint16_t* const g_adc_dma_buffer = sampler_dma::adc;
volatile std::uint16_t* const g_encoder_latch = sampler_dma::encoders;
static_assert(sizeof(sampler_dma::adc) / sizeof(sampler_dma::adc[0]) == Sampler::kDmaItems);

// Where each analog channel's result lands in the DMA buffer (rank x 3 + converter): force1 is
// ADC1 rank 1, force2 ADC1 rank 2, acc1 ADC2 rank 1, acc2 ADC3 rank 1 (items 4 and 5 are ADC2's
// and ADC3's second conversions, not used).
constexpr unsigned kBufferIndex[Sampler::kAnalogChannels] = {0, 3, 1, 2};
// The board profile states the instants this sequence gives; they must agree.
static_assert(kBoardProfile.adc_sampling_cycles == Sampler::kSamplingCycles);
static_assert(kBoardProfile.conversion_slot[0] == kBufferIndex[0] / Sampler::kConverters);
static_assert(kBoardProfile.conversion_slot[1] == kBufferIndex[1] / Sampler::kConverters);
static_assert(kBoardProfile.conversion_slot[2] == kBufferIndex[2] / Sampler::kConverters);
static_assert(kBoardProfile.conversion_slot[3] == kBufferIndex[3] / Sampler::kConverters);
// The encoders are latched at the end of the first sampling phase (TIM2 channels 3 and 4).
static_assert(kBoardProfile.conversion_slot[4] == 0 && kBoardProfile.conversion_slot[5] == 0);
static_assert(kBoardProfile.adc_clock_hz * Sampler::kAdcPrescaler == 84000000);  // PCLK2

// ADC1 (in multi-ADC mode: the common data register) on DMA2 stream 0 channel 0 (RM0090
// table 43). The encoder latches on DMA1 (table 42): TIM2_CH3 on stream 1 channel 3 (shared
// with TIM2_UP, whose request stays off), TIM2_CH4 on stream 7 channel 3 (likewise). DMA1
// reaches TIM3/TIM4 on APB1 and SRAM; DMA2 would not reach APB1.
constexpr unsigned kAdcStream = 0;
constexpr unsigned kEncoder0Stream = 1;
constexpr std::uint32_t kEncoder0Channel = 3;
constexpr unsigned kEncoder1Stream = 7;
constexpr std::uint32_t kEncoder1Channel = 3;
constexpr std::uint32_t kStreamDisablePolls = 10000;
// Room after the scan for the DMA, the interrupt and the frame sink before the next edge.
constexpr std::uint32_t kPeriodMarginUs = 7;

std::uint32_t Addr32(const volatile void* p) {
  return static_cast<std::uint32_t>(reinterpret_cast<std::uintptr_t>(p));
}

void ConfigureEncoder(Address timer) {
  Reg(timer + tim::kCr1) = 0;
  Reg(timer + tim::kSmcr) = tim::kSmcrEncoderMode3;
  Reg(timer + tim::kCcmr1) = tim::kCcmr1EncoderInputs;
  Reg(timer + tim::kCcer) = 0;  // Both inputs non-inverted.
  Reg(timer + tim::kArr) = 0xFFFF;
  Reg(timer + tim::kCnt) = 0;
  Reg(timer + tim::kCr1) = tim::kCr1Cen;
}

/// Disables a stream and waits until the hardware has let go of it (EN reads 0), then clears its
/// flags: the order RM0090 §10.3.17 asks before a stream is reprogrammed.
void DisableStream(Address dma_base, unsigned stream) {
  const Address cr = dma::Stream(dma_base, stream) + dma::kSxCr;
  Reg(cr) &= ~dma::kCrEn;
  (void)WaitFor(cr, dma::kCrEn, 0, kStreamDisablePolls);
  Reg(dma_base + dma::FlagClear(stream)) = dma::kStream0Flags << dma::FlagShift(stream);
}

/// The converters' results to the frame buffer, circular, 16 bit, from ADC1's first one: in DMA
/// mode 1 each request reads one result from ADC_CDR's low half-word (RM0090 §13.9).
void ArmAdcStream() {
  const Address stream = dma::Stream(dma::kDma2, kAdcStream);
  DisableStream(dma::kDma2, kAdcStream);
  Reg(stream + dma::kSxPar) = static_cast<std::uint32_t>(adc::kCommonCdr);
  Reg(stream + dma::kSxM0ar) = Addr32(g_adc_dma_buffer);
  Reg(stream + dma::kSxNdtr) = Sampler::kDmaItems;
  Reg(stream + dma::kSxFcr) = 0;  // Direct mode.
  Reg(stream + dma::kSxCr) = Field(0, dma::kCrChselPos) | dma::kCrPlHigh | dma::kCrMsize16 |
                             dma::kCrPsize16 | dma::kCrMinc | dma::kCrCirc | dma::kCrTcie |
                             dma::kCrTeie | dma::kCrEn;
}

/// One encoder count register to one latch word at every request, circular, no increment.
void ArmEncoderStream(unsigned stream_number, std::uint32_t channel, Address counter,
                      const volatile std::uint16_t* latch) {
  const Address stream = dma::Stream(dma::kDma1, stream_number);
  DisableStream(dma::kDma1, stream_number);
  Reg(stream + dma::kSxPar) = static_cast<std::uint32_t>(counter);
  Reg(stream + dma::kSxM0ar) = Addr32(latch);
  Reg(stream + dma::kSxNdtr) = 1;
  Reg(stream + dma::kSxFcr) = 0;
  Reg(stream + dma::kSxCr) = Field(channel, dma::kCrChselPos) | dma::kCrPlHigh | dma::kCrMsize16 |
                             dma::kCrPsize16 | dma::kCrCirc | dma::kCrEn;
}

// In multi-ADC mode the DMA and DDS bits of ADC_CR2 are unused (ADC_CCR's DMA and DDS take
// their place) and only the master, ADC1, takes the external trigger; ADC2 and ADC3 start with
// it (RM0090 §13.9, §13.13.3). EOCS on all three: overrun detection is enabled only when DMA = 1
// or EOCS = 1 (§13.8.1), and with CR2's DMA bit unused only EOCS can make OVR come at all (ST's
// single-conversion default sets it too). Without it a lost item would never be flagged.
constexpr std::uint32_t kAdcCr2Master =
    adc::kCr2Adon | adc::kCr2Eocs | adc::kCr2ExtselTim2Trgo | adc::kCr2ExtenRising;
constexpr std::uint32_t kAdcCr2Slave = adc::kCr2Adon | adc::kCr2Eocs;
constexpr Address kConverter[Sampler::kConverters] = {adc::kAdc1, adc::kAdc2, adc::kAdc3};
// Each converter's two ranks: force1 (IN0) and force2 (IN1) on ADC1; acc1 (IN2) twice on ADC2,
// acc2 (IN3) twice on ADC3 (the sequences must be as long as each other, and no channel is
// converted by two converters at once).
constexpr std::uint32_t kChannel[Sampler::kConverters][Sampler::kRanks] = {{0, 1}, {2, 2}, {3, 3}};

void ConvertersOff() {
  for (Address a : kConverter) Reg(a + adc::kCr2) = 0;
}
/// OVR cleared, then the slaves on before the master, so no trigger finds a slave off.
void ConvertersOn() {
  for (Address a : kConverter) Reg(a + adc::kSr) = 0;
  Reg(adc::kAdc3 + adc::kCr2) = kAdcCr2Slave;
  Reg(adc::kAdc2 + adc::kCr2) = kAdcCr2Slave;
  Reg(adc::kAdc1 + adc::kCr2) = kAdcCr2Master;
}
/// The whole interleave from scratch, as RM0090 asks for a change of configuration in multi
/// mode (ADC_CCR MULTI, §13.13.17: "disable the multi ADC mode before any change of
/// configuration"): every converter off, MULTI independent and the common DMA requests off,
/// each converter's scan, sampling time and sequence written, the stream re-armed from the
/// buffer's start, OVR cleared, then triple regular simultaneous mode with DMA mode 1 and DDS,
/// and the slaves on before the master. Whatever a previous run or a self-test left (a rotated
/// buffer, independent mode, another sequence on ADC1) is gone; the next TRGO edge starts a
/// whole scan at ADC1's first rank.
void ArmConverters() {
  ConvertersOff();
  Reg(adc::kCommonCcr) = adc::kCcrAdcpreDiv4;  // MULTI 00000: independent, no DMA requests
  for (unsigned i = 0; i < Sampler::kConverters; ++i) {
    const Address a = kConverter[i];
    Reg(a + adc::kCr1) = adc::kCr1Scan | adc::kCr1Ovrie;
    Reg(a + adc::kSmpr2) = adc::kSample56Cycles | (adc::kSample56Cycles << 3) |
                           (adc::kSample56Cycles << 6) | (adc::kSample56Cycles << 9);
    Reg(a + adc::kSqr1) = Field(Sampler::kRanks - 1, adc::kSqr1LPos);
    Reg(a + adc::kSqr3) = adc::Sqr3(0, kChannel[i][0]) | adc::Sqr3(1, kChannel[i][1]);
  }
  ArmAdcStream();
  for (Address a : kConverter) Reg(a + adc::kSr) = 0;  // OVR cleared before the requests
  Reg(adc::kCommonCcr) = adc::kCcrAdcpreDiv4 | adc::kCcrDmaMode1 | adc::kCcrDds |
                         adc::kCcrMultiTripleRegularSimultaneous;
  ConvertersOn();
}

/// The 32-bit count `near` moved to the 16-bit counter value `raw`: the signed 16-bit difference
/// is the true motion while the counter moved less than 2^15 counts since `near` was taken.
std::uint32_t Extend(std::uint32_t near, std::uint16_t raw) {
  const auto step = static_cast<std::int16_t>(static_cast<std::uint16_t>(raw - near));
  return near + static_cast<std::uint32_t>(static_cast<std::int32_t>(step));
}

bool AnyOverrun() {
  for (Address a : kConverter) {
    if ((Reg(a + adc::kSr) & adc::kSrOvr) != 0) return true;
  }
  return false;
}

}  // namespace

void Sampler::Init(const ClockConfig& clocks) {
  timer_clock_hz_ = clocks.apb1_timer_hz;
  sysclk_hz_ = clocks.sysclk_hz;
  // The shortest time from the edge to the scan's last result: the conversions alone (the
  // trigger synchronisation only adds to it). 136 x 4 = 544 timer clocks at full speed.
  scan_timer_ticks_ = static_cast<std::uint32_t>(std::uint64_t{kScanAdcClocks} * kAdcPrescaler *
                                                 timer_clock_hz_ / clocks.apb2_hz);
  const std::uint64_t scan_ns =
      std::uint64_t{kScanAdcClocks} * kAdcPrescaler * 1000000000ULL / clocks.apb2_hz;
  min_period_us_ = static_cast<std::uint32_t>((scan_ns + 999) / 1000) + kPeriodMarginUs;

  EnableClock(rcc::kAhb1enr, rcc::kAhb1GpioA | rcc::kAhb1GpioB | rcc::kAhb1Dma1 | rcc::kAhb1Dma2);
  EnableClock(rcc::kApb1enr, rcc::kApb1Tim2 | rcc::kApb1Tim3 | rcc::kApb1Tim4 | rcc::kApb1Tim5);
  EnableClock(rcc::kApb2enr, rcc::kApb2Adc1 | rcc::kApb2Adc2 | rcc::kApb2Adc3);

  for (unsigned pin = 0; pin < kAnalogChannels; ++pin)
    gpio::SetMode(gpio::kPortA, pin, gpio::Mode::kAnalog);
  // Encoder inputs: TIM3 CH1/CH2 on PA6/PA7, TIM4 CH1/CH2 on PB6/PB7, alternate function 2,
  // pulled up for open-collector encoders.
  for (unsigned pin : {6U, 7U}) {
    gpio::SetAlternate(gpio::kPortA, pin, 2);
    gpio::SetPullUp(gpio::kPortA, pin);
    gpio::SetAlternate(gpio::kPortB, pin, 2);
    gpio::SetPullUp(gpio::kPortB, pin);
  }
  ConfigureEncoder(tim::kTim3);
  ConfigureEncoder(tim::kTim4);

  // TIM2 (32 bit) update = sample clock, routed to TRGO; stopped until Start. Its compare
  // channels 3 and 4 (frozen output compare, no pin) match when the converters end their first
  // sampling phase, 56 ADC clocks = 224 timer clocks after the edge, and their DMA requests
  // latch the two encoders then (RM0090 §18.3.8: a match sets CCxIF and, with CCxDE, requests
  // DMA): the encoders are sampled with force1, acc1 and acc2.
  latch_timer_ticks_ = static_cast<std::uint32_t>(std::uint64_t{kSamplingCycles} * kAdcPrescaler *
                                                  timer_clock_hz_ / clocks.apb2_hz);
  Reg(tim::kTim2 + tim::kCr1) = 0;
  Reg(tim::kTim2 + tim::kPsc) = 0;
  Reg(tim::kTim2 + tim::kCr2) = tim::kCr2MmsUpdate;
  Reg(tim::kTim2 + tim::kCcr3) = latch_timer_ticks_;
  Reg(tim::kTim2 + tim::kCcr4) = latch_timer_ticks_;
  Reg(tim::kTim2 + tim::kDier) = tim::kDierCc3de | tim::kDierCc4de;
  // TIM5 (32 bit) counts TIM2's TRGO edges: the frame counter.
  Reg(tim::kTim5 + tim::kCr1) = 0;
  Reg(tim::kTim5 + tim::kPsc) = 0;
  Reg(tim::kTim5 + tim::kArr) = 0xFFFFFFFF;
  Reg(tim::kTim5 + tim::kSmcr) = tim::kSmcrTsItr0 | tim::kSmcrExternalClock1;
  Reg(tim::kTim5 + tim::kDier) = 0;

  // ADC1, ADC2, ADC3 in triple regular simultaneous mode (RM0090 §13.9.2), DMA mode 1 with
  // requests kept on for circular transfers, ADCCLK = PCLK2 / 4 = 21 MHz. Each converter scans
  // two channels with 56-cycle sampling, one scan per rising TRGO (ADC1's trigger): rank 1 is
  // force1 (IN0), acc1 (IN2), acc2 (IN3), converted at one instant; rank 2 is force2 (IN1) on
  // ADC1 and a second conversion of IN2 and IN3 on ADC2 and ADC3. 2 x (56 + 12) / 21 MHz =
  // 6.5 us per frame. Overrun interrupts on all three. Start runs the same sequence again.
  ArmEncoderStream(kEncoder0Stream, kEncoder0Channel, tim::kTim3 + tim::kCnt, &g_encoder_latch[0]);
  ArmEncoderStream(kEncoder1Stream, kEncoder1Channel, tim::kTim4 + tim::kCnt, &g_encoder_latch[1]);
  ArmConverters();

  for (unsigned irq_number : {irq::kDma2Stream0, irq::kAdc}) {
    nvic::Disable(irq_number);
    nvic::ClearPending(irq_number);
    nvic::SetPriority(irq_number, 2);
    nvic::Enable(irq_number);
  }
}

Status Sampler::Start(std::uint32_t sample_period_us, FrameSink& sink) {
  if (running_) return Status::kFailedPrecondition;
  const std::uint64_t ticks = std::uint64_t{timer_clock_hz_} * sample_period_us;
  if (sample_period_us < min_period_us_ || ticks % 1000000 != 0 ||
      ticks / 1000000 > 0xFFFFFFFFULL) {
    return Status::kInvalidArgument;
  }
  sink_ = &sink;
  next_tick_ = 0;
  drop_next_frame_ = false;
  torn_in_a_row_ = 0;
  delivered_ = 0;
  sink_cycles_ = 0;
  // Every start re-establishes the interleave (a self-test's VREFINT conversion switches ADC1 to
  // independent mode and back; a previous run may have stopped with a rotated buffer), and the
  // converters get their t_STAB before the first edge.
  // The converters' and the stream's interrupts stay off meanwhile, so no recovery runs into
  // the middle of it, and whatever they raised before is dropped.
  nvic::Disable(irq::kDma2Stream0);
  nvic::Disable(irq::kAdc);
  ArmConverters();
  (void)WaitCycles(sysclk_hz_ / 1000000 * kStabilisationUs);
  for (unsigned irq_number : {irq::kDma2Stream0, irq::kAdc}) {
    nvic::ClearPending(irq_number);
    nvic::Enable(irq_number);
  }
  TrackEncoders();
  encoder_origin_ = {tracked_[0], tracked_[1]};
  Reg(tim::kTim5 + tim::kCnt) = 0;
  Reg(tim::kTim5 + tim::kCr1) = tim::kCr1Cen;
  running_ = true;
  Reg(tim::kTim2 + tim::kArr) = static_cast<std::uint32_t>(ticks / 1000000 - 1);
  // UG is the first edge: frame 0 (a scan, both latches, TIM5 = 1) at the start instant.
  Reg(tim::kTim2 + tim::kEgr) = tim::kEgrUg;
  Reg(tim::kTim2 + tim::kCnt) = 0;
  Reg(tim::kTim2 + tim::kCr1) = tim::kCr1Cen;
  return Status::kOk;
}

void Sampler::Stop() {
  Reg(tim::kTim2 + tim::kCr1) = 0;
  Reg(tim::kTim5 + tim::kCr1) = 0;
  running_ = false;
}

void Sampler::Recover() {
  ++counters_.recoveries;
  // RM0090 §13.8.1 gives the overrun recovery for one converter (re-initialise the DMA, clear
  // OVR, trigger again); in multi-ADC mode the DMA requests come from ADC_CCR, whose DMA bits
  // must be cleared and set again before new requests are taken (§13.9, "DMA requests in
  // multi ADC mode"). The converters go off first, so their sequencers restart at rank 1 and
  // the common data register's ADC1 -> ADC2 -> ADC3 order at ADC1; the stream restarts at the
  // buffer's first element; OVR is cleared before DMA mode 1 and DDS are back; the slaves come
  // on before the master. The next TRGO edge starts a whole scan on all three.
  ConvertersOff();
  Modify(adc::kCommonCcr, adc::kCcrDmaMask | adc::kCcrDds, 0);
  ArmAdcStream();
  for (Address a : kConverter) Reg(a + adc::kSr) = 0;
  Modify(adc::kCommonCcr, adc::kCcrDmaMask | adc::kCcrDds, adc::kCcrDmaMode1 | adc::kCcrDds);
  ConvertersOn();
  // t_STAB before the converters are trusted; an edge may still fall inside it (the wait runs
  // in the interrupt, the timer keeps going), so the first frame after this is dropped too.
  (void)WaitCycles(sysclk_hz_ / 1000000 * kStabilisationUs);
  drop_next_frame_ = true;
}

void Sampler::TrackEncoders() {
  tracked_[0] = Extend(tracked_[0], static_cast<std::uint16_t>(Reg(tim::kTim3 + tim::kCnt)));
  tracked_[1] = Extend(tracked_[1], static_cast<std::uint16_t>(Reg(tim::kTim4 + tim::kCnt)));
}

void Sampler::CheckEncoderStreams() {
  const std::uint32_t teif = dma::kStream0Teif;
  const auto failed = [&](unsigned stream) {
    return (Reg(dma::kDma1 + dma::FlagStatus(stream)) & (teif << dma::FlagShift(stream))) != 0;
  };
  if (failed(kEncoder0Stream)) {
    ++counters_.dma_errors;
    ArmEncoderStream(kEncoder0Stream, kEncoder0Channel, tim::kTim3 + tim::kCnt,
                     &g_encoder_latch[0]);
  }
  if (failed(kEncoder1Stream)) {
    ++counters_.dma_errors;
    ArmEncoderStream(kEncoder1Stream, kEncoder1Channel, tim::kTim4 + tim::kCnt,
                     &g_encoder_latch[1]);
  }
}

void Sampler::HandleAdcInterrupt() {
  if (!AnyOverrun()) return;
  ++counters_.adc_overruns;
  Recover();
}

void Sampler::HandleDmaInterrupt() {
  const std::uint32_t flags = Reg(dma::kDma2 + dma::kLisr) & dma::kStream0Flags;
  Reg(dma::kDma2 + dma::kLifcr) = flags;
  CheckEncoderStreams();
  // A transfer error disables the stream; an overrun stops the ADC's requests. Either way no
  // further scan would arrive, and the frames missed meanwhile show as a gap in the tick.
  const bool overrun = AnyOverrun();
  if ((flags & dma::kStream0Teif) != 0 || overrun) {
    if ((flags & dma::kStream0Teif) != 0) ++counters_.dma_errors;
    if (overrun) ++counters_.adc_overruns;
    Recover();
    return;
  }
  if ((flags & dma::kStream0Tcif) == 0 || !running_) return;

  // Edges so far (TIM5), the stream's position and timer clocks since the latest edge (TIM2).
  // The buffer holds that edge's whole scan once the conversions' time has passed and the
  // stream is back at its start. Otherwise this interrupt ran late, the newer scan is under way
  // and the buffer mixes two scans (and the latches belong to the newer edge): the frame is
  // dropped, the newer scan's own interrupt follows, and the gap counts an overrun.
  const std::uint32_t edges = Reg(tim::kTim5 + tim::kCnt);
  const std::uint32_t remaining = Reg(dma::Stream(dma::kDma2, kAdcStream) + dma::kSxNdtr);
  const std::uint32_t since_edge = Reg(tim::kTim2 + tim::kCnt);
  const bool whole_scan = since_edge >= scan_timer_ticks_ && remaining == kDmaItems;
  if (Reg(tim::kTim5 + tim::kCnt) != edges || !whole_scan || edges == 0) {
    ++counters_.torn_frames;
    // A late interrupt tears one frame and the next one is whole. Torn frames in a row mean the
    // stream and the scans no longer line up (an item lost without an overrun flag rotates the
    // buffer: every later transfer-complete comes mid-scan); only a re-arm brings them back.
    if (++torn_in_a_row_ >= kTornFramesBeforeRecovery) {
      torn_in_a_row_ = 0;
      ++counters_.torn_recoveries;
      Recover();
    }
    return;
  }
  torn_in_a_row_ = 0;
  const std::uint32_t tick = edges - 1;
  // Already delivered (an interrupt that was pending across a recovery).
  if (static_cast<std::int32_t>(tick - next_tick_) < 0) return;
  next_tick_ = tick + 1;
  if (drop_next_frame_) {
    // The first scan after a recovery may have begun while the converters settled: the tick
    // it leaves out is a gap the core counts as an overrun.
    drop_next_frame_ = false;
    ++counters_.dropped_after_recovery;
    return;
  }

  SampleFrame frame;
  frame.tick = tick;
  for (unsigned i = 0; i < kAnalogChannels; ++i) frame.raw[i] = g_adc_dma_buffer[kBufferIndex[i]];
  for (unsigned i = 0; i < 2; ++i) {
    // The latch (16 bits, at the edge) extended from the count the SysTick keeps (at most
    // 1 ms old, one aligned word): a wrap is never missed however long the sample period.
    const std::uint32_t position = Extend(tracked_[i], g_encoder_latch[i]);
    frame.raw[4 + i] = static_cast<std::int32_t>(position - encoder_origin_[i]);
  }
  ++delivered_;
  const std::uint32_t before = CycleCount();
  sink_->OnFrame(frame);
  sink_cycles_ += CycleCount() - before;
}

}  // namespace vibid::fw::stm32
