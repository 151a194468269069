// Timer-triggered sampling, the board's FrameSource: TIM2 update events trigger an ADC1 scan of
// the four analog channels (two load cells, two accelerometers on PA0..PA3); DMA2 stream 0 moves
// the four results to RAM and its transfer-complete interrupt latches both quadrature encoders
// (TIM3 on PA6/PA7, TIM4 on PB6/PB7) into one frame for the core. The sample instant is the
// timer edge, so the sampling jitter is the ADC's, not the interrupt latency's.
#pragma once

#include <array>
#include <cstdint>

#include "vibid/fw/port.hpp"

namespace vibid::fw::stm32 {

struct SamplerCounters {
  std::uint32_t adc_overruns = 0;  ///< ADC OVR: a conversion was lost (DMA too late).
  std::uint32_t dma_errors = 0;
};

class Sampler final : public FrameSource {
 public:
  /// Configures pins, encoders, ADC scan and DMA once at boot; sampling starts with Start().
  /// `timer_clock_hz` is the TIM2 kernel clock (84 MHz at full speed).
  void Init(std::uint32_t timer_clock_hz);

  /// @returns kOk; kInvalidArgument when the period is not a whole number of timer clocks or is
  ///          shorter than the 13 us a four-channel scan takes; kFailedPrecondition if running.
  Status Start(std::uint32_t sample_period_us, FrameSink& sink) override;
  void Stop() override;

  const SamplerCounters& Counters() const { return counters_; }
  /// Core cycles spent in the frame sink, summed over all frames (DWT cycle counter).
  std::uint64_t SinkCycles() const { return sink_cycles_; }
  std::uint32_t Frames() const { return tick_; }

  /// The DMA2 stream 0 interrupt handler body.
  void HandleDmaInterrupt();

 private:
  std::uint32_t timer_clock_hz_ = 0;
  FrameSink* sink_ = nullptr;
  volatile bool running_ = false;
  std::uint32_t tick_ = 0;
  std::array<std::uint16_t, 2> last_encoder_raw_{};
  std::array<std::int32_t, 2> encoder_{};
  SamplerCounters counters_{};
  std::uint64_t sink_cycles_ = 0;
};

}  // namespace vibid::fw::stm32
