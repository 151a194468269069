#include "sampler.hpp"

#include "regs/core_m4.hpp"
#include "regs/peripherals.hpp"
#include "regs/rcc.hpp"
#include "system.hpp"

namespace vibid::fw::stm32 {

namespace {

// DMA target; in SRAM (the CCM is not reachable by DMA).
volatile std::uint16_t g_adc_dma_buffer[4] = {};

// A four-channel scan takes about 13 us; 20 us leaves the DMA and the interrupt room.
constexpr std::uint32_t kMinPeriodUs = 20;
constexpr unsigned kAnalogChannels = 4;

void ConfigureEncoder(Address timer) {
  Reg(timer + tim::kCr1) = 0;
  Reg(timer + tim::kSmcr) = tim::kSmcrEncoderMode3;
  Reg(timer + tim::kCcmr1) = tim::kCcmr1EncoderInputs;
  Reg(timer + tim::kCcer) = 0;  // Both inputs non-inverted.
  Reg(timer + tim::kArr) = 0xFFFF;
  Reg(timer + tim::kCnt) = 0;
  Reg(timer + tim::kCr1) = tim::kCr1Cen;
}

}  // namespace

void Sampler::Init(std::uint32_t timer_clock_hz) {
  timer_clock_hz_ = timer_clock_hz;
  Reg(rcc::kAhb1enr) |= rcc::kAhb1GpioA | rcc::kAhb1GpioB | rcc::kAhb1Dma2;
  Reg(rcc::kApb1enr) |= rcc::kApb1Tim2 | rcc::kApb1Tim3 | rcc::kApb1Tim4;
  Reg(rcc::kApb2enr) |= rcc::kApb2Adc1;

  for (unsigned pin = 0; pin < kAnalogChannels; ++pin) gpio::SetMode(gpio::kPortA, pin, gpio::Mode::kAnalog);
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

  // TIM2 (32 bit) update = sample clock, routed to TRGO; stopped until Start.
  Reg(tim::kTim2 + tim::kCr1) = 0;
  Reg(tim::kTim2 + tim::kPsc) = 0;
  Reg(tim::kTim2 + tim::kCr2) = tim::kCr2MmsUpdate;

  // ADC1: scan IN0..IN3, 56-cycle sampling (4 x (56 + 12) / 21 MHz = 13 us per frame), one scan
  // per rising TRGO, DMA requests kept on for circular transfers.
  Reg(adc::kCommonCcr) = adc::kCcrAdcpreDiv4;
  Reg(adc::kAdc1 + adc::kCr2) = 0;
  Reg(adc::kAdc1 + adc::kCr1) = adc::kCr1Scan;
  Reg(adc::kAdc1 + adc::kSmpr2) = adc::kSample56Cycles | (adc::kSample56Cycles << 3) |
                                  (adc::kSample56Cycles << 6) | (adc::kSample56Cycles << 9);
  Reg(adc::kAdc1 + adc::kSqr1) = Field(kAnalogChannels - 1, adc::kSqr1LPos);
  Reg(adc::kAdc1 + adc::kSqr3) = 0U | (1U << 5) | (2U << 10) | (3U << 15);

  // DMA2 stream 0 channel 0 = ADC1 (RM0090 table 43): 16-bit peripheral to memory, circular.
  const Address stream = dma::Stream(dma::kDma2, 0);
  Reg(stream + dma::kSxCr) = 0;
  (void)WaitFor(stream + dma::kSxCr, dma::kCrEn, 0, 10000);
  Reg(dma::kDma2 + dma::kLifcr) = dma::kStream0Flags;
  Reg(stream + dma::kSxPar) = static_cast<std::uint32_t>(adc::kAdc1 + adc::kDr);
  Reg(stream + dma::kSxM0ar) = static_cast<std::uint32_t>(reinterpret_cast<std::uintptr_t>(g_adc_dma_buffer));
  Reg(stream + dma::kSxNdtr) = kAnalogChannels;
  Reg(stream + dma::kSxFcr) = 0;  // Direct mode.
  Reg(stream + dma::kSxCr) = Field(0, dma::kCrChselPos) | dma::kCrPlHigh | dma::kCrMsize16 |
                             dma::kCrPsize16 | dma::kCrMinc | dma::kCrCirc | dma::kCrTcie |
                             dma::kCrTeie | dma::kCrEn;
  Reg(adc::kAdc1 + adc::kCr2) = adc::kCr2Adon | adc::kCr2Dma | adc::kCr2Dds |
                                adc::kCr2ExtselTim2Trgo | adc::kCr2ExtenRising;
  nvic::SetPriority(irq::kDma2Stream0, 2);
  nvic::Enable(irq::kDma2Stream0);
}

Status Sampler::Start(std::uint32_t sample_period_us, FrameSink& sink) {
  if (running_) return Status::kFailedPrecondition;
  const std::uint64_t ticks = std::uint64_t{timer_clock_hz_} * sample_period_us;
  if (sample_period_us < kMinPeriodUs || ticks % 1000000 != 0 || ticks / 1000000 > 0xFFFFFFFFULL) {
    return Status::kInvalidArgument;
  }
  sink_ = &sink;
  tick_ = 0;
  sink_cycles_ = 0;
  last_encoder_raw_ = {static_cast<std::uint16_t>(Reg(tim::kTim3 + tim::kCnt)),
                       static_cast<std::uint16_t>(Reg(tim::kTim4 + tim::kCnt))};
  encoder_ = {0, 0};
  running_ = true;
  Reg(tim::kTim2 + tim::kArr) = static_cast<std::uint32_t>(ticks / 1000000 - 1);
  Reg(tim::kTim2 + tim::kEgr) = tim::kEgrUg;
  Reg(tim::kTim2 + tim::kCnt) = 0;
  Reg(tim::kTim2 + tim::kCr1) = tim::kCr1Cen;
  return Status::kOk;
}

void Sampler::Stop() {
  Reg(tim::kTim2 + tim::kCr1) = 0;
  running_ = false;
}

void Sampler::HandleDmaInterrupt() {
  const std::uint32_t flags = Reg(dma::kDma2 + dma::kLisr);
  Reg(dma::kDma2 + dma::kLifcr) = flags & dma::kStream0Flags;
  if ((flags & dma::kStream0Teif) != 0) ++counters_.dma_errors;
  if ((Reg(adc::kAdc1 + adc::kSr) & adc::kSrOvr) != 0) {
    Reg(adc::kAdc1 + adc::kSr) = 0;
    ++counters_.adc_overruns;
  }
  if ((flags & dma::kStream0Tcif) == 0 || !running_) return;

  SampleFrame frame;
  frame.tick = tick_++;
  for (unsigned i = 0; i < kAnalogChannels; ++i) frame.raw[i] = g_adc_dma_buffer[i];
  const std::array<std::uint16_t, 2> raw = {static_cast<std::uint16_t>(Reg(tim::kTim3 + tim::kCnt)),
                                            static_cast<std::uint16_t>(Reg(tim::kTim4 + tim::kCnt))};
  for (unsigned i = 0; i < 2; ++i) {
    // The 16-bit counter moves by far less than 2^15 counts per sample, so the signed
    // difference is the true motion and the 32-bit sum never misses a wrap.
    encoder_[i] += static_cast<std::int16_t>(static_cast<std::uint16_t>(raw[i] - last_encoder_raw_[i]));
    last_encoder_raw_[i] = raw[i];
  }
  frame.raw[4] = encoder_[0];
  frame.raw[5] = encoder_[1];
  const std::uint32_t before = CycleCount();
  sink_->OnFrame(frame);
  sink_cycles_ += CycleCount() - before;
}

}  // namespace vibid::fw::stm32
