// The get-info watch page against the golden report of scripts/golden/wire_vectors.py.
#include "vibid/shared/wire/watch_info.hpp"

#include <gtest/gtest.h>

#include "golden_vectors.hpp"
#include "vibid/shared/wire/commands.hpp"
#include "vibid/shared/wire/report.hpp"

namespace vibid::wire {
namespace {

using testing::GoldenReport;

TEST(WatchInfo, PageRequestIsGolden) {
  Report out{};
  ASSERT_EQ(BuildReport(Command::kGetInfo, 0x0105, 0, 0, Status::kOk,
                        InfoPageRequest{.page = kInfoPageWatch}, out),
            Status::kOk);
  EXPECT_TRUE(out == GoldenReport("watch_page_request"));
}

// A run that went stale: 812 windows of 1000 samples, tripped at the window that ended on tick
// 811 999 with g = 8.5, now at 12.25 with h = 8.25.
TEST(WatchInfo, EncodesAndDecodesLikeGolden) {
  const WatchInfoResponse v{.state = WatchState::kWatching,
                            .stale = 1,
                            .window_samples = 1000,
                            .windows = 812,
                            .statistic = 12 * 65536 + 16384,
                            .threshold = 8 * 65536 + 16384,
                            .last_z = -65536,
                            .trip_tick = 811999,
                            .trip_statistic = 8 * 65536 + 32768,
                            .clamps = 0};
  Report out{};
  ASSERT_EQ(BuildReport(Command::kGetInfo, 0x0105, 0, kFlagResponse, Status::kOk, v, out),
            Status::kOk);
  const Report golden = GoldenReport("watch_info_response");
  EXPECT_TRUE(out == golden);
  WatchInfoResponse back;
  ASSERT_EQ(Decode(PayloadOf(golden), back), Status::kOk);
  EXPECT_EQ(back.state, WatchState::kWatching);
  EXPECT_EQ(back.stale, 1);
  EXPECT_EQ(back.windows, 812u);
  EXPECT_EQ(back.statistic, 12 * 65536 + 16384);
  EXPECT_EQ(back.last_z, -65536);
  EXPECT_EQ(back.trip_tick, 811999u);
  EXPECT_EQ(Decode(PayloadOf(golden).first(35), back), Status::kInvalidArgument);
}

TEST(WatchInfo, RefusesUnknownValues) {
  std::array<std::uint8_t, WatchInfoResponse::kBytes> b{};
  WatchInfoResponse v;
  EXPECT_EQ(Decode(b, v), Status::kOk);
  b[0] = 3;  // no such state
  EXPECT_EQ(Decode(b, v), Status::kInvalidArgument);
  b[0] = 2;
  b[1] = 2;  // stale is 0 or 1
  EXPECT_EQ(Decode(b, v), Status::kInvalidArgument);
  b[1] = 0;
  b[3] = 1;  // reserved
  EXPECT_EQ(Decode(b, v), Status::kInvalidArgument);
}

}  // namespace
}  // namespace vibid::wire
