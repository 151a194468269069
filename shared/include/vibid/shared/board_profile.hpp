// The board as a data path: how much it can buffer, how fast the link drains it, how fast it
// samples, and the format of each channel in the log. Defined once; the board port, the QEMU image
// (log size), the emulator (every limit) and the host's preflight all read it from here, and
// get-info carries it so a host never assumes a limit it did not ask for.
//
// The link: USB 2.0 full speed, HID interrupt endpoints with 64-byte reports and bInterval 1. An
// interrupt endpoint moves at most one transaction per 1 ms frame, so one IN report per frame:
//   64 000 B/s of reports; a log data report (a stream data report, 6-byte header) carries 58 B
//   of payload, 54 B of them log records after the 4-byte tick of its first record.
//
// Sampling instants: every timer edge starts the converters and latches the encoders. The load
// cells and accelerometers are held at the end of their converter's sampling phase, so each
// analog channel has its own instant after the edge: (slot x (sampling + 12) + sampling) ADC
// clocks, slot being its place in its converter's sequence (a conversion is the sampling time
// plus 12 clocks at 12 bits, RM0090 §13.5). The board converts force1, acc1 and acc2 on ADC1,
// ADC2 and ADC3 at once (triple regular simultaneous mode) and force2 second on ADC1:
//   ADCCLK = PCLK2 84 MHz / 4 = 21 MHz, 56-cycle sampling:
//   force1, acc1, acc2: 56 / 21 MHz = 2.667 us;  force2: (68 + 56) / 21 MHz = 5.905 us;
//   encoders: latched by a timer compare at the end of the first sampling phase, 2.667 us.
// The ADC trigger's own latency (at most 2 ADC clocks, the same for every converter) is left out.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "vibid/shared/wire/commands.hpp"
#include "vibid/shared/wire/report.hpp"

namespace vibid {

struct BoardProfile {
  std::uint32_t log_bytes = 0;           ///< RAM the acquisition log gets.
  std::uint32_t link_reports_per_s = 0;  ///< IN reports the link moves per second (one per frame).
  std::uint32_t min_sample_period_us = 0;
  std::uint8_t adc_bits = 0;  ///< Resolution of the load-cell and accelerometer ADC.
  std::uint32_t adc_clock_hz = 0;
  std::uint32_t adc_sampling_cycles = 0;    ///< Sampling (track) phase of every analog channel.
  std::uint32_t adc_conversion_cycles = 0;  ///< Successive approximation after the sampling.
  /// Each channel's place in its converter's sequence (0: converted first), in wire::Channel
  /// order; the encoders, latched when the first conversions' sampling ends, have 0.
  std::array<std::uint8_t, wire::kChannelCount> conversion_slot{};

  /// When `channel` is sampled after the timer edge, in ns (rounded to the nearest).
  constexpr std::uint32_t sample_instant_ns(std::size_t channel) const {
    const std::uint8_t slot = conversion_slot[channel];
    const std::uint64_t cycles =
        std::uint64_t{slot} * (adc_sampling_cycles + adc_conversion_cycles) + adc_sampling_cycles;
    return static_cast<std::uint32_t>((cycles * 1000000000ULL + adc_clock_hz / 2) / adc_clock_hz);
  }

  constexpr std::uint32_t link_bytes_per_s() const {
    return link_reports_per_s * static_cast<std::uint32_t>(wire::kReportBytes);
  }
  /// One USB frame: the link moves at most one IN and one OUT report in it.
  constexpr std::uint32_t frame_us() const { return 1000000u / link_reports_per_s; }
  constexpr std::uint32_t max_sample_rate_hz() const { return 1000000u / min_sample_period_us; }
};

/// The STM32F405 board: 96 KiB of SRAM for the log (the rest holds the stack, the USB stack,
/// the filter state and the calibration staging), USB full speed, 10 kHz, 12-bit ADC.
inline constexpr BoardProfile kBoardProfile{
    .log_bytes = 96 * 1024,
    .link_reports_per_s = 1000,
    .min_sample_period_us = wire::kMinSamplePeriodUs,
    .adc_bits = 12,
    .adc_clock_hz = 21000000,
    .adc_sampling_cycles = 56,
    .adc_conversion_cycles = 12,
    // force1 (ADC1 first), force2 (ADC1 second), acc1 (ADC2), acc2 (ADC3), both encoders at
    // the first conversions' sampling end.
    .conversion_slot = {0, 1, 0, 0, 0, 0},
};
static_assert(kBoardProfile.sample_instant_ns(0) == 2667);  // 56 / 21 MHz = 2666.7 ns
static_assert(kBoardProfile.sample_instant_ns(1) == 5905);  // 124 / 21 MHz = 5904.8 ns
static_assert(kBoardProfile.sample_instant_ns(4) == 2667);
static_assert(kBoardProfile.link_bytes_per_s() == 64000);
static_assert(kBoardProfile.frame_us() == 1000);

}  // namespace vibid
