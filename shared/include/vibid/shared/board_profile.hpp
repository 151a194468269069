// The board as a data path: how much it can buffer, how fast the link drains it, how fast it
// samples, and the format of each channel in the log. Defined once; the board port, the QEMU image
// (log size), the emulator (every limit) and the host's preflight all read it from here, and
// get-info carries it so a host never assumes a limit it did not ask for.
//
// The link: USB 2.0 full speed, HID interrupt endpoints with 64-byte reports and bInterval 1. An
// interrupt endpoint moves at most one transaction per 1 ms frame, so one IN report per frame:
//   64 000 B/s of reports; a log data report (a stream data report, 6-byte header) carries 58 B
//   of payload, 54 B of them log records after the 4-byte tick of its first record.
#pragma once

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
};
static_assert(kBoardProfile.link_bytes_per_s() == 64000);
static_assert(kBoardProfile.frame_us() == 1000);

}  // namespace vibid
