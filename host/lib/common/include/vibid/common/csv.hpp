// CSV tables and time-series recordings.
//
// A recording is a CSV file with a header row and numeric cells, one column per channel. The first
// column is usually the time `t_s` (seconds, uniform sampling); records without a time column (for
// example a sample index `k`) need an explicit sample rate. Every problem is reported as an
// InputError that names the file and, where there is one, the line.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

namespace vibid {

struct CsvTable {
  std::string source;                    ///< File path or label, for messages.
  std::vector<std::string> names;        ///< Header cells, trimmed.
  std::vector<Eigen::VectorXd> columns;  ///< One vector per header cell, all of rows() length.

  std::size_t rows() const {
    return columns.empty() ? 0 : static_cast<std::size_t>(columns[0].size());
  }
  bool Has(std::string_view name) const;
  /// Index of a column; InputError listing the available names when absent.
  std::size_t Index(std::string_view name) const;
  const Eigen::VectorXd& Column(std::string_view name) const { return columns[Index(name)]; }
};

/// Parses CSV text (comma separated, header first, '#' and empty lines ignored). `source` names it
/// in errors, which give the line (1-based, comment lines counted) and, for a bad cell, the column
/// (1-based index and name). Rows are parsed on `threads` threads (0: one per core; small texts use
/// one); the result and every message are the same for any thread count.
CsvTable ParseCsv(std::string_view text, const std::string& source, std::size_t threads = 0);

/// The columns a reader asks for. Only they are parsed, so only their cells must be numbers (a
/// recording may carry a text column, such as a note, that no command reads); the table holds
/// them alone, in the file's order. A `required` name the header lacks is an InputError listing
/// the file's columns; an `optional` one (the time column) is taken when it is there.
struct CsvColumns {
  std::vector<std::string> required;
  std::vector<std::string> optional;
};

/// ParseCsv for the asked-for columns only; every other cell is skipped unread (a row must still
/// have as many cells as the header).
CsvTable ParseCsvColumns(std::string_view text, const std::string& source, const CsvColumns& wanted,
                         std::size_t threads = 0);

/// Reads (memory-mapped where the file allows it) and parses a CSV file.
CsvTable ReadCsv(const std::string& path);
/// ReadCsv for the asked-for columns only (see ParseCsvColumns).
CsvTable ReadCsvColumns(const std::string& path, const CsvColumns& wanted);

/// Formats columns as CSV with a header; numbers in shortest round-trip form, so a written file
/// reads back bit-identical.
std::string FormatCsv(const std::vector<std::string>& names,
                      const std::vector<Eigen::VectorXd>& columns);
/// FormatCsv in two parts, for a file written as its rows arrive: the header line, and rows
/// (FormatCsv is FormatCsvHeader + FormatCsvRows of all of them; rows split anywhere join to the
/// same text).
std::string FormatCsvHeader(const std::vector<std::string>& names);
std::string FormatCsvRows(const std::vector<Eigen::VectorXd>& columns);

/// A column selected by the user, with a conversion to SI:
///   `NAME`           taken as it is (already SI)
///   `NAME:UNIT`      UNIT one of m, cm, mm, um, g (standard gravity), m/s2, N, kN, s, ms, V, A
///   `NAME*FACTOR`    multiplied by FACTOR (e.g. encoder counts to metres: `X*1.7857e-5`)
struct ColumnSpec {
  std::string name;
  double scale = 1.0;
  std::string unit;  ///< As written by the user; empty when none.
};

ColumnSpec ParseColumnSpec(std::string_view spec);
/// "a,b,c" -> {"a", "b", "c"}; empty items are kept ("a,,b" has three), "" gives one empty item.
std::vector<std::string> SplitList(std::string_view list);
/// Splits "a,b,c" into specs.
std::vector<ColumnSpec> ParseColumnList(std::string_view list);

/// SI factor for a unit name; InputError listing the known units otherwise.
double UnitToSi(std::string_view unit);

struct RecordingOptions {
  std::string time_column = "t_s";
  /// Sample rate when the file has no time column (or to override one). Hz.
  std::optional<double> fs_hz;
  /// Fewer samples than this is an error: nothing sensible can be estimated from them.
  std::size_t min_samples = 8;
  /// Allowed deviation of each time step from the mean step, relative to the mean step.
  double uniform_tolerance = 0.01;
  /// The channels the command reads (column names, no unit or factor). Not empty: only these and
  /// the time column are read and must be numeric, other columns are skipped (ParseCsvColumns);
  /// empty: every column must be numeric.
  std::vector<std::string> channels;
};

/// A uniformly sampled recording.
struct Recording {
  CsvTable table;
  double fs_hz = 0.0;  ///< Derived from the time column (checked uniform) or given.
  double t0_s = 0.0;   ///< Time of the first sample.

  std::size_t samples() const { return table.rows(); }
  double dt_s() const { return 1.0 / fs_hz; }
  /// A channel converted to SI by its spec.
  Eigen::VectorXd Signal(const ColumnSpec& spec) const;
  /// Time of each sample, t0_s + i / fs_hz.
  Eigen::VectorXd Time() const;
};

Recording MakeRecording(CsvTable table, const RecordingOptions& options);
Recording LoadRecording(const std::string& path, const RecordingOptions& options = {});

}  // namespace vibid
