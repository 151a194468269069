// Fuzzes the recording reader (CSV text, the header, numeric cells) with the options the CLI
// passes along with it: the time column, a sample rate given or derived, and the channel specs
// with units and factors (`NAME`, `NAME:UNIT`, `NAME*FACTOR`). The input is a script
// (FuzzedDataProvider): the options first, then the file's text.
// What is accepted must survive the writer: FormatCsv of the table reads back to the same names
// and the same numbers bit for bit, and becomes a recording again with the same rate and start.
// Every channel a spec selects converts to SI without a non-finite value slipping through.
#include <fuzzer/FuzzedDataProvider.h>

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "fuzz_support.hpp"
#include "vibid/common/csv.hpp"

namespace {

using namespace vibid;
using fuzz::Accepts;
using fuzz::Require;

void CheckSameTable(const CsvTable& a, const CsvTable& b) {
  Require(a.names == b.names && a.columns.size() == b.columns.size() && a.rows() == b.rows());
  for (std::size_t c = 0; c < a.columns.size(); ++c) {
    Require(a.columns[c].size() == b.columns[c].size());
    for (Eigen::Index i = 0; i < a.columns[c].size(); ++i)
      Require(fuzz::Same(a.columns[c][i], b.columns[c][i]));
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  RecordingOptions options;
  switch (in.ConsumeIntegralInRange<int>(0, 3)) {
    case 0: break;
    case 1: options.time_column = in.ConsumeRandomLengthString(12); break;
    case 2: options.fs_hz = in.ConsumeFloatingPoint<double>(); break;
    default: options.fs_hz = in.ConsumeFloatingPointInRange<double>(0.1, 1e6); break;
  }
  const std::string specs = in.ConsumeRandomLengthString(64);
  const std::string text = in.ConsumeBytesAsString(in.remaining_bytes());

  std::optional<CsvTable> table;
  if (!Accepts([&] { table = ParseCsv(text, "fuzz.csv", 1); })) return 0;

  // The writer's text reads back to the same table.
  std::optional<CsvTable> again;
  Require(
      Accepts([&] { again = ParseCsv(FormatCsv(table->names, table->columns), "again.csv", 1); }));
  CheckSameTable(*table, *again);

  std::optional<Recording> recording;
  if (!Accepts([&] { recording = MakeRecording(*table, options); })) return 0;
  Require(std::isfinite(recording->fs_hz) && recording->fs_hz > 0.0 &&
          std::isfinite(recording->t0_s));
  std::optional<Recording> recording_again;
  Require(Accepts([&] { recording_again = MakeRecording(*again, options); }));
  Require(fuzz::Same(recording->fs_hz, recording_again->fs_hz) &&
          fuzz::Same(recording->t0_s, recording_again->t0_s));

  std::vector<ColumnSpec> list;
  if (!Accepts([&] { list = ParseColumnList(specs); })) return 0;
  for (const ColumnSpec& spec : list) {
    Require(std::isfinite(spec.scale));
    Eigen::VectorXd signal;
    if (!Accepts([&] { signal = recording->Signal(spec); })) continue;
    Require(static_cast<std::size_t>(signal.size()) == recording->samples() && signal.allFinite());
  }
  return 0;
}
