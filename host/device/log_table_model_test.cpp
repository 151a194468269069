// The board's model test in a pulled log: the word each record carries becomes `model_g` (Q16
// over 2^16) and `model_stale` (bit 31), row for row (the board has already aligned the word
// with the row's time; core_watch_test checks that side).
#include <gtest/gtest.h>

#include "vibid/device/log_table.hpp"
#include "vibid/shared/wire/log_record.hpp"

namespace vibid::device {
namespace {

TEST(LogTableModel, ColumnsFromEachRecordsWord) {
  LogPull p;
  p.layout = wire::LogLayout{1, wire::kAcqFlagLogDob | wire::kAcqFlagLogWatch};
  p.trailer.decimation = 5;
  p.trailer.sample_period_us = 1000;
  for (std::uint32_t k = 0; k < 20; ++k) {
    wire::LogRecord r;
    r.sample_index = 100 + 5 * k;
    r.raw[0] = 2048 * 16;
    r.watch = k * 0x4000u;  // g rises by a quarter spread a record
    if (k >= 12) r.watch |= wire::kLogWatchStaleBit;
    p.records.push_back(r);
  }
  const LogTable t = MakeLogTable(p, wire::CalibrationRecord{}, false);
  ASSERT_EQ(t.names.back(), "model_stale");
  ASSERT_EQ(t.names[t.names.size() - 2], "model_g");
  const Eigen::VectorXd& g = t.columns[t.columns.size() - 2];
  const Eigen::VectorXd& stale = t.columns.back();
  for (Eigen::Index i = 0; i < 20; ++i) {
    EXPECT_DOUBLE_EQ(g(i), 0.25 * static_cast<double>(i));
    EXPECT_EQ(stale(i), i >= 12 ? 1.0 : 0.0) << i;
  }
  // Without the word in the layout, no model columns.
  p.layout.flags = wire::kAcqFlagLogDob;
  const LogTable plain = MakeLogTable(p, wire::CalibrationRecord{}, false);
  EXPECT_EQ(plain.names.back(), "d_hat_q31");
}

}  // namespace
}  // namespace vibid::device
