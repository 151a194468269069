// What an acquisition asks of the board's data path, from the board's own profile (get-info):
// the record size, the rate records are made at, what the link carries, and how long the log
// buffers the difference. `vibid acquire` checks it before it starts the board.
//
// The link moves one 64-byte report per frame; a log data report carries the tick of its first
// record and then RecordsPerReport() whole records. While the log rate is at most what the link
// carries, the log never fills. Above it the log fills at the difference and, once full, the
// board drops what does not fit.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "vibid/shared/wire/commands.hpp"
#include "vibid/shared/wire/log_record.hpp"

namespace vibid::device {

struct LinkBudget {
  std::size_t record_bytes = 0;         ///< One record on the wire.
  std::size_t stored_record_bytes = 0;  ///< One record in the board's log RAM (with its tick).
  std::size_t records_per_report = 0;
  double sample_rate_hz = 0.0;
  double log_rate_hz = 0.0;            ///< Records made per second.
  double data_bytes_per_s = 0.0;       ///< log_rate_hz x record_bytes.
  double link_bytes_per_s = 0.0;       ///< Reports per second x 64.
  double link_records_per_s = 0.0;     ///< Reports per second x records_per_report.
  std::uint32_t log_bytes = 0;         ///< The board's log RAM.
  std::uint32_t capacity_records = 0;  ///< Records the log holds.
  /// Seconds after the trigger until the log is full and records are dropped; infinity when
  /// the link keeps up. Pre-trigger records already occupy part of the log.
  double overflow_after_s = 0.0;

  bool KeepsUp() const { return log_rate_hz <= link_records_per_s; }
  /// The log rate (a whole decimation of the sampling rate the board supports) that fits.
  double FittingLogRateHz() const;
};

/// Records a streamed acquisition keeps and drops, by the board's rules frame by frame: frame 0
/// carries acq-start's answer; in every later frame the sampler first pushes its ticks' records
/// into a log of `capacity` records (a record that finds it full is dropped), then the link
/// moves the one report armed before the frame; the main loop keeps one report armed and builds
/// the next one ahead (its records leave the log when it is built): up to `per_report` records
/// whose ticks follow each other. Records after the acquisition's end all reach the host.
struct StreamPrediction {
  std::uint64_t kept = 0;
  std::uint64_t dropped = 0;
};
StreamPrediction PredictStream(std::uint64_t records, std::uint32_t ticks_per_frame,
                               std::uint32_t capacity, std::uint32_t per_report);

/// Budget of `config` on a board that answered `info` (log size, link rate).
LinkBudget ComputeLinkBudget(const wire::InfoResponse& info,
                             const wire::AcqConfigureRequest& config);

/// Whose words the ways out of a refusal take: the command line's options, or the bench page's
/// controls (its Log rate, channel boxes and Seconds; the bench never drops records).
enum class AdviceWords : std::uint8_t { kCommandLine, kBenchPage };

/// The refusal text for an acquisition of `seconds` that would drop records, naming the figures
/// and the ways out.
std::string DescribeOverflow(const LinkBudget& budget, double seconds,
                             AdviceWords words = AdviceWords::kCommandLine);

/// The smallest decimation of `config`'s sample rate the board supports whose log holds an
/// acquisition of `seconds` (the whole of it carried, nothing dropped): 1 when every sample fits.
/// 0 when none does (not even the largest decimation).
std::uint16_t DecimationThatFits(const wire::InfoResponse& info, wire::AcqConfigureRequest config,
                                 double seconds);

/// The budget in words, one (label, text) line each: the record and the report it travels in,
/// the sample and log rates, what the link carries, what the log holds and for how long, and
/// whether an acquisition of `seconds` fits. What `vibid bench` shows beside its form.
std::vector<std::pair<std::string, std::string>> DescribeBudget(const LinkBudget& budget,
                                                                double seconds);

}  // namespace vibid::device
