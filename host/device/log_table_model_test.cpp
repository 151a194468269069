// The board's model test in a pulled log: the word each record carries becomes `model_g` (Q16
// over 2^16) and `model_stale` (bit 31), and each row takes the state as at its own time, which
// a decimated log moves back by the decimator's delay.
#include <gtest/gtest.h>

#include "vibid/device/log_table.hpp"
#include "vibid/shared/fixed/decimator.hpp"
#include "vibid/shared/wire/log_record.hpp"

namespace vibid::device {
namespace {

LogPull Pull(std::uint16_t decimation, std::size_t records, std::uint32_t trip_tick) {
  LogPull p;
  p.layout = wire::LogLayout{1, wire::kAcqFlagLogDob | wire::kAcqFlagLogWatch};
  p.trailer.decimation = decimation;
  p.trailer.sample_period_us = 1000;
  for (std::size_t k = 0; k < records; ++k) {
    wire::LogRecord r;
    r.sample_index = static_cast<std::uint32_t>(100 + k * decimation);
    r.raw[0] = 2048 * 16;
    // g rises by a quarter spread a record (0x4000 in Q16); stale from the trip on.
    r.watch = static_cast<std::uint32_t>(k) * 0x4000u;
    if (r.sample_index >= trip_tick) r.watch |= wire::kLogWatchStaleBit;
    p.records.push_back(r);
  }
  return p;
}

TEST(LogTableModel, ColumnsFromTheWordAtEachRowsTime) {
  const LogTable t = MakeLogTable(Pull(1, 20, 110), wire::CalibrationRecord{}, false);
  ASSERT_EQ(t.names.back(), "model_stale");
  ASSERT_EQ(t.names[t.names.size() - 2], "model_g");
  const Eigen::VectorXd& g = t.columns[t.columns.size() - 2];
  const Eigen::VectorXd& stale = t.columns.back();
  for (Eigen::Index i = 0; i < 20; ++i) {
    EXPECT_DOUBLE_EQ(g(i), 0.25 * static_cast<double>(i));  // undecimated: no delay
    EXPECT_EQ(stale(i), i >= 10 ? 1.0 : 0.0) << i;
  }
}

TEST(LogTableModel, ADecimatedLogKeepsTheTripsTime) {
  constexpr std::uint16_t kD = 5;
  const auto delay = static_cast<std::int64_t>(fixed::DecimatorDelayTicks(kD));
  ASSERT_GT(delay, kD);  // the case this is about: the delay spans records
  const LogPull p = Pull(kD, 40, 150);
  const LogTable t = MakeLogTable(p, wire::CalibrationRecord{}, false);
  const Eigen::VectorXd& time = t.columns[0];
  const Eigen::VectorXd& stale = t.columns.back();
  for (Eigen::Index i = 0; i < 40; ++i) {
    // The row's time in ticks; the state is the last record's at or before it.
    const auto at = static_cast<std::int64_t>(std::llround(time(i) * 1000.0));
    const bool tripped = at >= 150;
    if (at < 100) continue;  // before the first record: the first record's state
    EXPECT_EQ(stale(i), tripped ? 1.0 : 0.0) << "row " << i << " at tick " << at;
  }
  // The first stale row is the first whose time is at or after the trip, to within a record.
  Eigen::Index first = 0;
  while (stale(first) == 0.0) ++first;
  EXPECT_GE(time(first), 0.150);
  EXPECT_LT(time(first), 0.150 + kD * 1e-3);
}

}  // namespace
}  // namespace vibid::device
