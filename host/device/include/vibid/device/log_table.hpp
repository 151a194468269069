// A pulled log as a recording (CSV, format in README section device): time, each logged channel
// in SI units through the board's own calibration arithmetic, and the observer output.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "vibid/device/connection.hpp"
#include "vibid/shared/wire/calibration_record.hpp"

namespace vibid::device {

/// Column stem of a channel: force1, force2, acc1, acc2, x1, x2.
const char* ChannelStem(wire::Channel channel);
/// Column unit suffix of a unit: n, m_s2, m, m_s, counts.
const char* UnitSuffix(wire::Unit unit);
/// Channel by stem; false if none.
bool ChannelFromStem(const std::string& stem, wire::Channel& channel);

struct LogTable {
  std::vector<std::string> names;
  std::vector<Eigen::VectorXd> columns;
};

/// Columns: t_s (sample_index x sample period, the exact decimal: the tick count in us over
/// 10^6, correctly rounded), one `<stem>_<unit>` column per logged channel
/// (calibrated exactly as the board does: ScaleChannel, then x full_scale / 2^31, held as the
/// shortest decimal that still rounds to the board's Q31 word, ShortestQ31Decimal, so a reader
/// recovers that word as the observer's replay does), and with the observer logged
/// `d_hat_q31` (the board's integer output) and `d_hat_n`; with the residual test's word logged,
/// `model_g` (its CUSUM statistic, in spreads) and `model_stale` (0 or 1).
/// `calibration` is the active record (has_record false: uncalibrated, columns in counts).
LogTable MakeLogTable(const LogPull& pull, const wire::CalibrationRecord& calibration,
                      bool has_record);

/// When each logged channel was sampled after the timer edge, in us (whole ns, so the decimal
/// is exact): channel columns only, in the table's order, for the recording's sidecar.
std::vector<std::pair<std::string, double>> SampleInstantsUs(
    const LogTable& table, const LogPull& pull, const wire::SamplingInfoResponse& instants);

/// The recording's header row (column names): `format` gives the layout and trailer, its records
/// are not read. With FormatLogCsvRows, a recording is written as its records arrive: header +
/// rows of every block in order is FormatLogCsv's text.
std::string FormatLogCsvHeader(const LogPull& format, const wire::CalibrationRecord& calibration,
                               bool has_record);
/// The rows of `block`'s records (its layout and trailer as the whole recording's).
std::string FormatLogCsvRows(const LogPull& block, const wire::CalibrationRecord& calibration,
                             bool has_record);

/// MakeLogTable formatted with vibid::FormatCsv: one header row, then rows, as every CSV reader
/// expects.
std::string FormatLogCsv(const LogPull& pull, const wire::CalibrationRecord& calibration,
                         bool has_record);

/// Writes the sidecar of the recording at `csv_path` (log_facts.hpp, ident::WriteRecordingFacts):
/// its columns' units, rails and sensitivities from `calibration`, the rate and the instants the
/// board stated (`instants` empty for a board of protocol 2.0); the board, the start and the
/// acquisition are not stated (LogFacts states them where the caller ran the acquisition).
void WriteLogSidecar(const std::string& csv_path, const LogPull& format,
                     const wire::CalibrationRecord& calibration, bool has_record,
                     const std::optional<wire::SamplingInfoResponse>& instants);

}  // namespace vibid::device
