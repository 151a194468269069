// What a recording states about itself beyond its columns, kept in a JSON sidecar beside the CSV
// (REC.csv.json; docs/file-formats.md): the sample rate, when it started (UTC), per channel its
// unit, sensitivity, full scale in physical units and in converter codes, the values its
// converter's rails read as, when it was sampled after the clock's edge and how many samples the
// board saw clipped; the board (identity, firmware), its calibration (label, CRC) and the
// acquisition's options (the emulator's scenario and seed among them). Field names follow the
// SEP005 time-series convention where one fits (`name`, `unit_str`, `fs`, `start_timestamp`).
//
// A reader uses these facts, and a check that needs one the file lacks says it is unavailable
// rather than guessing: a clip is a sample at the converter's rail, known only from the sidecar.
// Version 1 sidecars (columns and sampling instants only) still read, with every other fact
// absent.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace vibid::ident {

/// One channel column of a recording, as its sidecar states it.
struct ChannelFacts {
  std::string name;      ///< The CSV column (force1_n, acc1_m_s2, x1_m, acc1_counts).
  std::string unit_str;  ///< SI unit of the column's values: N, m/s2, m, m/s, counts.
  /// Converter counts per unit (the sensors file's counts_per_unit) and the code that reads as
  /// zero; 0 / absent for an uncalibrated channel.
  std::optional<double> counts_per_unit;
  std::optional<double> offset_counts;
  /// The value (in unit_str) the board's full-scale number stands for (its Q31 range).
  std::optional<double> full_scale;
  /// The converter's lowest and highest code: 0 .. 2^bits - 1 for an analog input, the 32-bit
  /// counter's range for an encoder.
  std::optional<std::pair<double, double>> code_range;
  /// The values (in unit_str) the column holds when the converter sits on its rails (or the
  /// calibration saturates first): a sample at or beyond either is clipped.
  std::optional<std::pair<double, double>> rails;
  std::optional<double> sample_instant_us;       ///< After the sample clock's edge (us).
  std::optional<std::uint64_t> clipped_samples;  ///< The board's own count for the acquisition.

  bool operator==(const ChannelFacts&) const = default;
};

/// The board a recording came from.
struct BoardFacts {
  std::string board;     ///< The board kind (vibid, nucleo, emulator, ...).
  std::string serial;    ///< USB serial number; empty when the link does not give one.
  std::string firmware;  ///< MAJOR.MINOR.PATCH
  std::string protocol;  ///< MAJOR.MINOR
  std::uint32_t build_id = 0;
  std::uint32_t adc_bits = 0;

  bool operator==(const BoardFacts&) const = default;
};

/// The board's active calibration record when the recording was made.
struct CalibrationFacts {
  std::string label;
  std::uint32_t crc32 = 0;
  std::int64_t created_unix_s = 0;

  bool operator==(const CalibrationFacts&) const = default;
};

/// The acquisition as it was asked for and run.
struct AcquisitionFacts {
  double sample_rate_hz = 0.0;  ///< The board's sampling rate (the log's rate is `fs`).
  std::uint32_t decimation = 1;
  double seconds = 0.0;  ///< Asked for after the trigger; 0: not stated (a log pull).
  std::string trigger;   ///< As given (force>5), empty: immediate.
  double pretrigger_s = 0.0;
  std::uint64_t records = 0;
  std::uint64_t dropped_records = 0;
  std::uint64_t overrun_ticks = 0;
  std::string scenario;  ///< The emulator's excitation, empty for a board.
  std::vector<double> scenario_params;
  std::optional<std::uint64_t> emulator_seed;

  bool operator==(const AcquisitionFacts&) const = default;
};

/// Everything a sidecar states. Only `columns` is always there; a version 1 sidecar holds the
/// columns and the channels' sampling instants.
struct RecordingFacts {
  int version = 2;
  std::vector<std::string> columns;  ///< The CSV's header, in order.
  std::optional<double> fs;          ///< The log's sample rate (Hz).
  std::string start_timestamp;       ///< ISO 8601, UTC (2026-12-07T04:30:00.125Z); empty: unknown.
  std::optional<BoardFacts> board;
  std::optional<CalibrationFacts> calibration;  ///< Absent: uncalibrated (columns in counts).
  std::optional<AcquisitionFacts> acquisition;
  std::vector<ChannelFacts> channels;  ///< Channel columns (not t_s or derived ones).

  /// The channel facts of column `name`; null when the sidecar does not describe it.
  const ChannelFacts* Channel(std::string_view name) const;

  bool operator==(const RecordingFacts&) const = default;
};

/// The sidecar's JSON text (version 2). @throws InputError for a channel that is not a column.
std::string FormatRecordingFacts(const RecordingFacts& facts);

/// Reads a sidecar's text (version 1 or 2) for the CSV whose header is `csv_columns`.
/// @throws InputError naming `source` for a file that is not a vibid-recording sidecar, an
/// unknown key, a malformed value, or columns that are not the CSV's (a sidecar left from another
/// recording at that path).
RecordingFacts ParseRecordingFacts(std::string_view json,
                                   const std::vector<std::string>& csv_columns,
                                   const std::string& source);

/// The facts of the recording at `csv_path` from its sidecar; empty when it has none (a recording
/// from elsewhere, or one written before sidecars). Reads only the CSV's header row.
std::optional<RecordingFacts> ReadRecordingFacts(const std::string& csv_path);

/// Writes the sidecar of `csv_path` atomically (temporary file, then rename).
void WriteRecordingFacts(const std::string& csv_path, const RecordingFacts& facts);

/// The present time as ISO 8601 UTC with milliseconds (2026-12-07T04:30:00.125Z).
std::string UtcTimestampNow();

}  // namespace vibid::ident
