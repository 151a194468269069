// Timer-triggered sampling: TIM2 update events trigger an ADC1 scan of the four analog channels
// (two load cells, two accelerometers on PA0..PA3); DMA2 stream 0 moves the four results to RAM
// and its transfer-complete interrupt latches both quadrature encoders (TIM3 on PA6/PA7, TIM4 on
// PB6/PB7) into one frame. The sample instant is the timer edge, so jitter is the ADC's, not the
// interrupt latency's.
#pragma once

#include <array>
#include <cstdint>

#include "vibid/shared/status.hpp"

namespace vibid::fw::stm32 {

struct RawFrame {
  std::uint32_t sequence;                ///< Frame counter since Start, wraps at 2^32.
  std::array<std::uint16_t, 4> analog;   ///< 12-bit ADC codes: load cell 1, 2, accelerometer 1, 2.
  std::array<std::int32_t, 2> encoder;   ///< Quadrature counts (x4), extended from 16 to 32 bits.
};

/// Called in the DMA interrupt for every frame; must return well within one sample period.
using FrameHandler = void (*)(const RawFrame& frame, void* context);

struct SamplerCounters {
  std::uint32_t frames = 0;
  std::uint32_t adc_overruns = 0;   ///< ADC OVR: a conversion was lost (DMA too late).
  std::uint32_t dma_errors = 0;
};

class Sampler {
 public:
  /// Configures the pins, the encoders, the ADC scan and the DMA; the timer stays stopped.
  /// `timer_clock_hz` is the TIM2 kernel clock (84 MHz at full speed).
  /// @returns kInvalidArgument when `rate_hz` cannot be divided from the timer clock
  ///          (zero, above 100 kHz, or a period longer than 2^32 ticks).
  Status Configure(std::uint32_t timer_clock_hz, std::uint32_t rate_hz, FrameHandler handler, void* context);
  void Start();
  void Stop();
  const SamplerCounters& Counters() const { return counters_; }

  /// The DMA2 stream 0 interrupt handler body.
  void HandleDmaInterrupt();

 private:
  FrameHandler handler_ = nullptr;
  void* context_ = nullptr;
  std::uint32_t sequence_ = 0;
  std::array<std::uint16_t, 2> last_encoder_raw_{};
  std::array<std::int32_t, 2> encoder_{};
  SamplerCounters counters_{};
};

/// DMA target; in SRAM (the CCM is not reachable by DMA).
extern volatile std::uint16_t g_adc_dma_buffer[4];

}  // namespace vibid::fw::stm32
