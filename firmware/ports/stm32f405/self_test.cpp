#include "self_test.hpp"

#include <atomic>

#include "regs/core_m4.hpp"
#include "regs/otg_fs.hpp"
#include "regs/peripherals.hpp"
#include "system.hpp"

namespace vibid::fw::stm32 {

EncoderState ReadEncoder(Address timer) {
  constexpr std::uint32_t kSmsMask = 0x7;  // SMCR SMS, bits 2:0
  const bool enabled = (Reg(timer + tim::kCr1) & tim::kCr1Cen) != 0;
  const bool encoder = (Reg(timer + tim::kSmcr) & kSmsMask) == tim::kSmcrEncoderMode3;
  return {.running = enabled && encoder, .count = Reg(timer + tim::kCnt)};
}

namespace {

// Waits for the next SOF flag and clears it; false after `timeout` cycles without one.
bool AwaitStartOfFrame(std::uint32_t timeout, std::uint32_t& at) {
  const std::uint32_t start = Reg(dwt::kCyccnt);
  for (;;) {
    const std::uint32_t now = Reg(dwt::kCyccnt);
    if ((Reg(otg::kGintsts) & otg::kIntSof) != 0) {
      at = now;
      Reg(otg::kGintsts) = otg::kIntSof;  // rc_w1: clears SOF only
      return true;
    }
    // Unsigned differences survive the counter's wrap (25.6 s at 168 MHz).
    if (now - start > timeout) return false;
  }
}

}  // namespace

bool CountCyclesOverFrames(std::uint32_t frames, std::uint32_t sysclk_hz, std::uint32_t& cycles) {
  // TRCENA powers the DWT (ARMv7-M ARM C1.6.5), CYCCNTENA starts the counter (C1.8.7).
  Reg(scb::kDemcr) |= scb::kDemcrTrcena;
  Reg(dwt::kCtrl) |= dwt::kCtrlCyccntEna;
  const std::uint32_t timeout = sysclk_hz / 500;  // 2 ms
  std::uint32_t first = 0;
  // The flag may be left from long ago: clear it and start at the next frame's.
  Reg(otg::kGintsts) = otg::kIntSof;
  if (!AwaitStartOfFrame(timeout, first)) return false;
  std::uint32_t last = first;
  for (std::uint32_t k = 0; k < frames; ++k) {
    if (!AwaitStartOfFrame(timeout, last)) return false;
    if (k % 100 == 0) KickWatchdog();
  }
  cycles = last - first;
  return true;
}

std::uint16_t VrefintCal() { return static_cast<std::uint16_t>(Reg(kVrefintCalWord) >> 16); }

bool ConvertVrefint(std::uint32_t sysclk_hz, std::uint32_t& mean_code) {
  // ADC registers: RM0090 §13.13 (SR EOC bit 1, CR2 SWSTART bit 30, SMPR1, SQR1 L, SQR3 SQ1,
  // CCR MULTI 4:0 and TSVREFE bit 23).
  const Address adc1 = adc::kAdc1;
  const std::uint32_t saved_ccr = Reg(adc::kCommonCcr);
  const std::uint32_t saved_cr1 = Reg(adc1 + adc::kCr1);
  const std::uint32_t saved_cr2[] = {Reg(adc::kAdc1 + adc::kCr2), Reg(adc::kAdc2 + adc::kCr2),
                                     Reg(adc::kAdc3 + adc::kCr2)};
  const std::uint32_t saved_smpr1 = Reg(adc1 + adc::kSmpr1);
  const std::uint32_t saved_sqr1 = Reg(adc1 + adc::kSqr1);
  const std::uint32_t saved_sqr3 = Reg(adc1 + adc::kSqr3);

  // The multi mode changes only with every converter off (ADC_CCR MULTI, RM0090 §13.13.17:
  // "disable the multi ADC mode before any change of configuration"): the master first, so no
  // trigger reaches a half-stopped set, and the common DMA requests off with MULTI.
  Reg(adc::kAdc1 + adc::kCr2) = 0;
  Reg(adc::kAdc2 + adc::kCr2) = 0;
  Reg(adc::kAdc3 + adc::kCr2) = 0;
  Reg(adc::kCommonCcr) =
      (saved_ccr & ~(adc::kCcrMultiMask | adc::kCcrDmaMask | adc::kCcrDds)) | adc::kCcrTsvrefe;
  Reg(adc1 + adc::kCr1) = 0;  // one channel
  Reg(adc1 + adc::kSmpr1) = adc::kSample480Cycles << adc::kSmpr1Smp17Pos;
  Reg(adc1 + adc::kSqr1) = 0;  // L = 0: one conversion
  Reg(adc1 + adc::kSqr3) = adc::Sqr3(0, adc::kChannelVrefint);
  Reg(adc1 + adc::kCr2) = adc::kCr2Adon;  // software start, no DMA
  // ADC power-up and VREFINT start-up, each at most 10 us (datasheet): wait 20 us.
  bool ok = WaitCycles(sysclk_hz / 50000);
  std::uint32_t sum = 0;
  // One conversion is (480 + 12) / 21 MHz = 23.4 us; allow 100 us.
  const std::uint32_t timeout = sysclk_hz / 10000;
  for (std::uint32_t k = 0; ok && k < kVrefintConversions; ++k) {
    Reg(adc1 + adc::kSr) = 0;
    Reg(adc1 + adc::kCr2) = adc::kCr2Adon | adc::kCr2Swstart;
    const std::uint32_t start = Reg(dwt::kCyccnt);
    while ((Reg(adc1 + adc::kSr) & adc::kSrEoc) == 0) {
      if (Reg(dwt::kCyccnt) - start > timeout) {
        ok = false;
        break;
      }
    }
    if (ok) sum += Reg(adc1 + adc::kDr) & 0xFFF;  // reading DR clears EOC
  }

  // Back with every converter off again: ADC1's set-up, then the multi mode, then the slaves
  // before the master. The sampler's Start re-arms the whole interleave anyway (sampler.hpp).
  Reg(adc1 + adc::kCr2) = 0;
  Reg(adc1 + adc::kCr1) = saved_cr1;
  Reg(adc1 + adc::kSmpr1) = saved_smpr1;
  Reg(adc1 + adc::kSqr1) = saved_sqr1;
  Reg(adc1 + adc::kSqr3) = saved_sqr3;
  Reg(adc::kCommonCcr) = saved_ccr;
  Reg(adc1 + adc::kSr) = 0;
  Reg(adc::kAdc3 + adc::kCr2) = saved_cr2[2];
  Reg(adc::kAdc2 + adc::kCr2) = saved_cr2[1];
  Reg(adc::kAdc1 + adc::kCr2) = saved_cr2[0];
  if (!ok) return false;
  mean_code = (sum + kVrefintConversions / 2) / kVrefintConversions;
  return true;
}

namespace {

// Adds one channel's code of each frame, from the sampler's interrupt, until it has `wanted`.
class IdleCodeSink final : public FrameSink {
 public:
  IdleCodeSink(unsigned channel, std::uint32_t wanted, CodeSums& sums)
      : channel_(channel), wanted_(wanted), sums_(sums) {}
  void OnFrame(const SampleFrame& frame) override {
    if (taken_ >= wanted_) return;
    sums_.Add(static_cast<std::uint32_t>(frame.raw[channel_]));
    taken_ = taken_ + 1;
  }
  std::uint32_t taken() const { return taken_; }

 private:
  unsigned channel_;
  std::uint32_t wanted_;
  CodeSums& sums_;
  volatile std::uint32_t taken_ = 0;  // written by the interrupt, polled by the main loop
};

}  // namespace

IdleSampling SampleIdleChannel(FrameSource& sampler, std::uint32_t sample_period_us,
                               unsigned channel, std::uint32_t frames, CodeSums& sums) {
  const std::uint64_t frames_us = std::uint64_t{frames} * sample_period_us;
  if (frames_us > kMaxIdleSamplingUs) return IdleSampling::kTooLong;
  IdleCodeSink sink(channel, frames, sums);
  if (sampler.Start(sample_period_us, sink) != Status::kOk) return IdleSampling::kRefused;
  const std::uint64_t start = MicrosecondsSinceBoot();
  while (sink.taken() < frames &&
         MicrosecondsSinceBoot() - start < frames_us + kIdleSamplingSlackUs)
    KickWatchdog();
  sampler.Stop();
  // The interrupt wrote the sums; after Stop it adds nothing more. Keep the compiler from
  // reading them before the loop's last look at the count.
  std::atomic_signal_fence(std::memory_order_seq_cst);
  return sink.taken() < frames ? IdleSampling::kIncomplete : IdleSampling::kOk;
}

}  // namespace vibid::fw::stm32
