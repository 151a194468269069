#include "vibid/common/csv.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>

#include "csv_detail.hpp"
#include "vibid/common/error.hpp"
#include "vibid/common/text_input.hpp"

namespace vibid {
namespace csv_detail {

std::string_view Trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '\r'))
    s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r'))
    s.remove_suffix(1);
  return s;
}

std::optional<double> ParseNumber(std::string_view cell) {
  if (!cell.empty() && cell.front() == '+') cell.remove_prefix(1);
  double value = 0.0;
  const auto* end = cell.data() + cell.size();
  const auto [ptr, ec] = std::from_chars(cell.data(), end, value);
  if (ec != std::errc() || ptr != end || cell.empty()) return std::nullopt;
  return value;
}

namespace {

std::vector<std::string_view> SplitCells(std::string_view line) {
  std::vector<std::string_view> cells;
  std::size_t start = 0;
  while (true) {
    const auto comma = line.find(',', start);
    if (comma == std::string_view::npos) {
      cells.push_back(Trim(line.substr(start)));
      return cells;
    }
    cells.push_back(Trim(line.substr(start, comma - start)));
    start = comma + 1;
  }
}

}  // namespace

void CheckHeader(std::string_view line, const std::string& where, std::vector<std::string>& names) {
  for (const auto c : SplitCells(line)) {
    if (c.empty()) throw InputError(where + "empty column name in the header");
    // Only the file's first bytes may be a byte-order mark (ParseCsv skips it there); one before a
    // later header line would become part of the name, invisibly, and not survive a rewrite.
    if (c.starts_with("\xEF\xBB\xBF"))
      throw InputError(where + "a column name starts with a byte-order mark (U+FEFF)");
    if (ParseNumber(c)) {
      throw InputError(where +
                       "the first row must be a header of column names, found the number '" +
                       std::string(c) + "'");
    }
    names.emplace_back(c);
  }
  for (std::size_t i = 0; i < names.size(); ++i) {
    for (std::size_t j = i + 1; j < names.size(); ++j) {
      if (names[i] == names[j]) throw InputError(where + "duplicate column '" + names[i] + "'");
    }
  }
}

void ExplainBadRow(std::string_view line, const std::string& where,
                   const std::vector<std::string>& names, const std::vector<bool>& keep) {
  const std::vector<std::string_view> cells = SplitCells(line);
  if (cells.size() != names.size()) {
    throw InputError(where + "expected " + std::to_string(names.size()) + " cells, found " +
                     std::to_string(cells.size()));
  }
  for (std::size_t c = 0; c < cells.size(); ++c) {
    if (!keep.empty() && !keep[c]) continue;
    const std::string column = "column " + std::to_string(c + 1) + " '" + names[c] + "': ";
    const auto v = ParseNumber(cells[c]);
    if (!v) throw InputError(where + column + "'" + Printable(cells[c]) + "' is not a number");
    if (!std::isfinite(*v))
      throw InputError(where + column + "non-finite value '" + Printable(cells[c]) + "'");
  }
  // The fast parser refused a line this checker accepts: a defect, reported rather than hidden.
  throw InputError(where + "cannot read the row '" + Printable(line) + "'");
}

}  // namespace csv_detail

namespace {

using csv_detail::ParseNumber;
using csv_detail::Trim;

std::string JoinNames(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

}  // namespace

bool CsvTable::Has(std::string_view name) const {
  for (const auto& n : names) {
    if (n == name) return true;
  }
  return false;
}

std::size_t CsvTable::Index(std::string_view name) const {
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (names[i] == name) return i;
  }
  throw InputError(source + ": no column '" + Printable(name) + "' (columns: " + JoinNames(names) +
                   ")");
}

std::string FormatCsv(const std::vector<std::string>& names,
                      const std::vector<Eigen::VectorXd>& columns) {
  Require(names.size() == columns.size(), "FormatCsv: names and columns differ in count");
  return FormatCsvHeader(names) + FormatCsvRows(columns);
}

std::string FormatCsvHeader(const std::vector<std::string>& names) {
  std::string out;
  for (std::size_t i = 0; i < names.size(); ++i) out += (i ? "," : "") + names[i];
  out += '\n';
  return out;
}

std::string FormatCsvRows(const std::vector<Eigen::VectorXd>& columns) {
  std::string out;
  const Eigen::Index rows = columns.empty() ? 0 : columns[0].size();
  for (const auto& c : columns) Require(c.size() == rows, "FormatCsv: columns differ in length");
  char buf[64];
  for (Eigen::Index r = 0; r < rows; ++r) {
    for (std::size_t c = 0; c < columns.size(); ++c) {
      if (c) out += ',';
      const auto res = std::to_chars(buf, buf + sizeof buf, columns[c][r]);
      out.append(buf, res.ptr);
    }
    out += '\n';
  }
  return out;
}

double UnitToSi(std::string_view unit) {
  struct Entry {
    std::string_view name;
    double factor;
  };
  // Standard gravity per ISO 80000-3 / CGPM 1901: 9.80665 m/s^2.
  static constexpr Entry kUnits[] = {
      {"m", 1.0},   {"cm", 1e-2},   {"mm", 1e-3}, {"um", 1e-6}, {"g", 9.80665}, {"m/s2", 1.0},
      {"m/s", 1.0}, {"mm/s", 1e-3}, {"N", 1.0},   {"kN", 1e3},  {"s", 1.0},     {"ms", 1e-3},
      {"V", 1.0},   {"mV", 1e-3},   {"A", 1.0},   {"mA", 1e-3},
  };
  for (const auto& e : kUnits) {
    if (e.name == unit) return e.factor;
  }
  std::string known;
  for (const auto& e : kUnits) known += (known.empty() ? "" : ", ") + std::string(e.name);
  throw InputError("unknown unit '" + std::string(unit) + "' (known: " + known + ")");
}

ColumnSpec ParseColumnSpec(std::string_view spec) {
  spec = Trim(spec);
  Require(!spec.empty(), "empty column name");
  // No header cell holds one (a CSV line ends at a line break), and echoed in a message it would
  // break the message's one line.
  Require(std::none_of(spec.begin(), spec.end(),
                       [](char c) { return static_cast<unsigned char>(c) < 0x20 || c == 0x7F; }),
          "a column spec holds a control character (a line break?)");
  ColumnSpec out;
  if (const auto star = spec.rfind('*'); star != std::string_view::npos) {
    const auto factor = ParseNumber(Trim(spec.substr(star + 1)));
    if (!factor || !std::isfinite(*factor) || *factor == 0.0) {
      throw InputError("column '" + std::string(spec) +
                       "': the factor after '*' must be a nonzero number");
    }
    out.name = std::string(Trim(spec.substr(0, star)));
    out.scale = *factor;
  } else if (const auto colon = spec.rfind(':'); colon != std::string_view::npos) {
    out.name = std::string(Trim(spec.substr(0, colon)));
    out.unit = std::string(Trim(spec.substr(colon + 1)));
    try {
      out.scale = UnitToSi(out.unit);
    } catch (const InputError& e) {
      throw InputError("column '" + Printable(spec) + "': " + e.what());
    }
  } else {
    out.name = std::string(spec);
  }
  Require(!out.name.empty(), "column '" + std::string(spec) + "' has no name");
  return out;
}

std::vector<std::string> SplitList(std::string_view list) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (true) {
    const auto comma = list.find(',', start);
    out.emplace_back(
        list.substr(start, comma == std::string_view::npos ? list.npos : comma - start));
    if (comma == std::string_view::npos) return out;
    start = comma + 1;
  }
}

std::vector<ColumnSpec> ParseColumnList(std::string_view list) {
  std::vector<ColumnSpec> out;
  for (const std::string& item : SplitList(list)) out.push_back(ParseColumnSpec(item));
  return out;
}

Eigen::VectorXd Recording::Signal(const ColumnSpec& spec) const {
  const Eigen::VectorXd& column = table.Column(spec.name);
  Eigen::VectorXd out(column.size());
  csv_detail::AdviseHugePages(out.data(), static_cast<std::size_t>(out.size()) * sizeof(double));
  out = column * spec.scale;
  return out;
}

Eigen::VectorXd Recording::Time() const {
  const auto n = static_cast<Eigen::Index>(samples());
  return Eigen::VectorXd::LinSpaced(n, 0.0, static_cast<double>(n - 1)) / fs_hz +
         Eigen::VectorXd::Constant(n, t0_s);
}

namespace {

// "112.94": a rate to type, six significant digits.
std::string ShortestRate(double hz) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", hz);
  return buf;
}

// ": the time stamps are rounded to 0.001 s" when every stamp is a whole multiple of a decimal
// step coarse enough to explain the jitter (a logger writing milliseconds at 113 Hz); else "".
std::string RoundedStampsNote(const Eigen::VectorXd& t) {
  for (double step : {1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6}) {
    bool whole = true;
    for (Eigen::Index i = 0; i < t.size() && whole; ++i) {
      const double k = t[i] / step;
      whole = std::abs(k - std::round(k)) < 1e-6 * std::max(1.0, std::abs(k));
    }
    if (whole) {
      char buf[96];
      std::snprintf(buf, sizeof buf, ": the time stamps are rounded to %g s", step);
      return buf;
    }
  }
  return "";
}

}  // namespace

Recording MakeRecording(CsvTable table, const RecordingOptions& options) {
  for (const std::string& name : options.channels) static_cast<void>(table.Index(name));
  Recording rec;
  const std::size_t n = table.rows();
  if (n < options.min_samples) {
    throw InputError(table.source + ": too short: " + std::to_string(n) + " samples, at least " +
                     std::to_string(options.min_samples) + " needed");
  }
  if (options.fs_hz) {
    Require(std::isfinite(*options.fs_hz) && *options.fs_hz > 0.0,
            "sample rate must be a positive number of Hz");
    rec.fs_hz = *options.fs_hz;
    rec.t0_s = table.Has(options.time_column) ? table.Column(options.time_column)[0] : 0.0;
  } else {
    if (!table.Has(options.time_column)) {
      throw InputError(table.source + ": no time column '" + Printable(options.time_column) +
                       "'; name it or give the sample rate (--fs-hz)");
    }
    const Eigen::VectorXd& t = table.Column(options.time_column);
    const double mean_dt = (t[t.size() - 1] - t[0]) / static_cast<double>(n - 1);
    // The header is line 1, so sample i sits on line i + 2 (comment lines aside).
    for (Eigen::Index i = 1; i < t.size(); ++i) {
      const double dt = t[i] - t[i - 1];
      if (!(dt > 0.0)) {
        throw InputError(table.source + ":" + std::to_string(i + 2) + ": time does not increase (" +
                         std::to_string(t[i - 1]) + " then " + std::to_string(t[i]) + ")");
      }
    }
    // Uniformity is checked only once time is known to increase: a repeated stamp is the clearer
    // report.
    for (Eigen::Index i = 1; i < t.size(); ++i) {
      const double dt = t[i] - t[i - 1];
      if (std::abs(dt - mean_dt) > options.uniform_tolerance * mean_dt) {
        throw InputError(table.source + ":" + std::to_string(i + 2) +
                         ": non-uniform sampling (step " + std::to_string(dt) + " s, mean step " +
                         std::to_string(mean_dt) + " s)" + RoundedStampsNote(t) +
                         "; if the samples were taken at a steady rate, --fs-hz " +
                         ShortestRate(1.0 / mean_dt) +
                         " reads them at the mean step's rate (the time column then gives only "
                         "the start)");
      }
    }
    rec.fs_hz = 1.0 / mean_dt;
    rec.t0_s = t[0];
  }
  rec.table = std::move(table);
  return rec;
}

Recording LoadRecording(const std::string& path, const RecordingOptions& options) {
  if (options.channels.empty()) return MakeRecording(ReadCsv(path), options);
  return MakeRecording(ReadCsvColumns(path, {options.channels, {options.time_column}}), options);
}

}  // namespace vibid
