// Timer-triggered sampling, the board's FrameSource.
//
// Every TIM2 update edge (the sample instant) does three things in hardware at once:
//   - TRGO starts ADC1, ADC2 and ADC3 together (triple regular simultaneous mode, RM0090
//     §13.9.2): force1 (PA0, IN0), acc1 (PA2, IN2) and acc2 (PA3, IN3) are sampled at the same
//     instant, 56 ADC clocks after the edge; force2 (PA1, IN1) is ADC1's second conversion,
//     68 clocks later. ADC2 and ADC3 convert their channel again meanwhile (the sequences must be
//     as long as ADC1's), a result the frame drops. DMA2 stream 0 moves the six results, in the
//     order ADC1, ADC2, ADC3 of each rank, from the common data register ADC_CDR to RAM.
//     The instants are in the board profile (board_profile.hpp).
//   - 224 timer clocks later, when the converters end that sampling phase, TIM2's compare
//     channels 3 and 4 raise DMA requests (DMA1 stream 1 and stream 7, channel 3) that copy the
//     TIM3 (PA6/PA7) and TIM4 (PB6/PB7) encoder counts to RAM: both encoders are latched at the
//     hammer channels' instant, within a few bus cycles, not when the interrupt runs.
//   - TIM5 counts the edge: the frame tick comes from the timer, not from counting interrupts,
//     so scans merged into one interrupt or lost to an ADC overrun leave a gap the core counts.
// The DMA2 stream 0 transfer-complete interrupt assembles the frame for the core.
//
// ADC overrun (OVR stops the ADC's DMA requests for good) and DMA transfer errors are caught by
// interrupt and by a check every frame; EOCS is set on all three converters, without which
// RM0090 §13.8.1 never raises OVR in this mode (CR2 DMA unused). Should an item still be lost
// unflagged, the buffer rotates and every frame tears: kTornFramesBeforeRecovery torn frames in
// a row run the same recovery. Every Start re-arms the whole interleave first (ArmConverters).
// Recovery follows RM0090's multi-ADC overrun steps (the common DMA request logic restarted through
// ADC_CCR's DMA bits, the stream re-armed, OVR cleared, DMA and DDS set again) with the converters
// switched off and on, so the next scan starts at ADC1's first rank and the channels cannot rotate
// in the buffer; the converters get their 3 us stabilisation time, and the first frame after a
// recovery is dropped (the edge may have come while they settled), which the core counts as an
// overrun.
#pragma once

#include <array>
#include <cstdint>

#include "clock.hpp"
#include "vibid/fw/port.hpp"

namespace vibid::fw::stm32 {

struct SamplerCounters {
  std::uint32_t adc_overruns = 0;  ///< ADC OVR: a conversion was lost (DMA too late).
  std::uint32_t dma_errors = 0;    ///< Transfer errors on the ADC or an encoder latch stream.
  std::uint32_t recoveries = 0;    ///< ADC + DMA re-arms after either.
  std::uint32_t dropped_after_recovery = 0;  ///< First frames after a recovery, not delivered.
  std::uint32_t torn_frames = 0;  ///< Interrupts dropped because the next scan had begun.
  /// Re-arms after kTornFramesBeforeRecovery torn frames in a row (buffer and scans out of step).
  std::uint32_t torn_recoveries = 0;
};

/// The DMA targets, in SRAM (the CCM is not reachable by DMA); named here for the host tests.
namespace sampler_dma {
extern volatile std::uint16_t adc[6];
extern volatile std::uint16_t encoders[2];
}  // namespace sampler_dma

class Sampler final : public FrameSource {
 public:
  static constexpr unsigned kAnalogChannels = 4;
  /// Three converters with two conversions each; DMA items per frame.
  static constexpr unsigned kConverters = 3;
  static constexpr unsigned kRanks = 2;
  static constexpr unsigned kDmaItems = kConverters * kRanks;
  /// A frame's conversions take 2 x (56 sampling + 12 conversion) ADC clocks.
  static constexpr std::uint32_t kSamplingCycles = 56;
  static constexpr std::uint32_t kScanAdcClocks = kRanks * (kSamplingCycles + 12);
  /// ADCCLK = PCLK2 / 4 (ADC common prescaler).
  static constexpr std::uint32_t kAdcPrescaler = 4;
  /// A converter switched on (ADON) needs t_STAB before it converts (STM32F405 datasheet, ADC
  /// characteristics; ST's HAL waits 3 us, ADC_STAB_DELAY_US).
  static constexpr std::uint32_t kStabilisationUs = 3;
  /// Torn frames in a row that make the sampler re-arm the converters and the stream: one late
  /// interrupt tears a frame or two, a rotated buffer tears every one.
  static constexpr std::uint32_t kTornFramesBeforeRecovery = 3;

  /// Configures pins, encoders, frame counter, ADC scan and the DMA streams once at boot;
  /// sampling starts with Start().
  void Init(const ClockConfig& clocks);

  /// @returns kOk; kInvalidArgument when the period is not a whole number of timer clocks or is
  ///          shorter than MinPeriodUs(); kFailedPrecondition if running.
  Status Start(std::uint32_t sample_period_us, FrameSink& sink) override;
  void Stop() override;

  /// The shortest period: one scan plus room for the DMA and the interrupt (14 us at 168 MHz).
  std::uint32_t min_period_us() const { return min_period_us_; }
  const SamplerCounters& counters() const { return counters_; }
  /// Core cycles spent in the frame sink, summed over all frames (DWT cycle counter).
  std::uint64_t sink_cycles() const { return sink_cycles_; }
  /// Frames handed to the core since Start.
  std::uint32_t frames() const { return delivered_; }

  /// The DMA2 stream 0 interrupt handler body.
  void HandleDmaInterrupt();
  /// The ADC interrupt handler body (overrun).
  void HandleAdcInterrupt();
  /// Extends the two 16-bit encoder counters into 32-bit counts; called every millisecond (the
  /// SysTick handler), so a counter moving less than 2^15 counts per millisecond is never
  /// misread, whatever the sample period (up to 1 s, where a latch-to-latch difference alone
  /// would wrap above 32 768 counts per period).
  void TrackEncoders();

 private:
  void Recover();
  void CheckEncoderStreams();

  std::uint32_t timer_clock_hz_ = 0;
  std::uint32_t sysclk_hz_ = 16000000;
  std::uint32_t scan_timer_ticks_ = 0;   ///< Timer clocks the scan's conversions take at least.
  std::uint32_t latch_timer_ticks_ = 0;  ///< Edge to the encoder latch (the sampling phase).
  std::uint32_t min_period_us_ = 20;
  FrameSink* sink_ = nullptr;
  volatile bool running_ = false;
  std::uint32_t next_tick_ = 0;
  std::uint32_t delivered_ = 0;
  volatile bool drop_next_frame_ = false;  ///< Set by Recover: the next scan is not trusted.
  std::uint32_t torn_in_a_row_ = 0;
  /// The encoders' 32-bit counts as of the last TrackEncoders (written by SysTick only; the low
  /// 16 bits are the counter's value then), and their values at Start (frames count from 0).
  volatile std::uint32_t tracked_[2] = {0, 0};
  std::array<std::uint32_t, 2> encoder_origin_{};
  SamplerCounters counters_{};
  std::uint64_t sink_cycles_ = 0;
};

}  // namespace vibid::fw::stm32
