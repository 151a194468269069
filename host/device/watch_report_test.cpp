// The watch page as `vibid info` shows it, from the golden report of scripts/golden/wire_vectors.py
// (stale at tick 811 999 with g 8.5 over h 8.25, g now 12.25).
#include "vibid/device/watch_report.hpp"

#include <gtest/gtest.h>

#include "golden_vectors.hpp"
#include "vibid/shared/wire/report.hpp"

namespace vibid::device {
namespace {

wire::WatchInfoResponse Golden() {
  wire::WatchInfoResponse w;
  EXPECT_EQ(wire::Decode(wire::PayloadOf(wire::testing::GoldenReport("watch_info_response")), w),
            Status::kOk);
  return w;
}

TEST(WatchReport, StaleBoardInJson) {
  // 200 us a sample (5 kHz): tick 811 999 is 162.3998 s into the acquisition.
  const nlohmann::json j = WatchJson(Golden(), 200);
  EXPECT_EQ(j["state"], "watching");
  EXPECT_EQ(j["stale"], true);
  EXPECT_DOUBLE_EQ(j["statistic"].get<double>(), 12.25);
  EXPECT_DOUBLE_EQ(j["threshold"].get<double>(), 8.25);
  EXPECT_DOUBLE_EQ(j["last_z"].get<double>(), -1.0);
  EXPECT_EQ(j["windows"], 812);
  EXPECT_EQ(j["window_samples"], 1000);
  EXPECT_EQ(j["tripped_at_tick"], 811999);
  EXPECT_NEAR(j["tripped_at_s"].get<double>(), 162.3998, 1e-9);
  EXPECT_DOUBLE_EQ(j["trip_statistic"].get<double>(), 8.5);
  EXPECT_EQ(j["clamps"], 0);
}

TEST(WatchReport, StaleBoardInWords) {
  EXPECT_EQ(WatchText(Golden(), 200),
            "STALE since tick 811999 (162.40 s, g 8.50 > h 8.25); g now 12.25");
}

TEST(WatchReport, InControlAndIdle) {
  wire::WatchInfoResponse w = Golden();
  w.stale = 0;
  w.trip_tick = 0;
  w.statistic = 65536 + 16384;
  w.state = wire::WatchState::kIdle;
  const nlohmann::json j = WatchJson(w, 200);
  EXPECT_EQ(j["state"], "idle");
  EXPECT_EQ(j["stale"], false);
  EXPECT_TRUE(j["tripped_at_tick"].is_null());
  EXPECT_TRUE(j["tripped_at_s"].is_null());
  EXPECT_EQ(WatchText(w, 200),
            "in control: g 1.25 of h 8.25 after 812 windows of 1000 samples (observer stopped)");
  // Right after `dob start` on an idle board (get-status's dob_running set): not "stopped".
  EXPECT_EQ(WatchText(w, 200, /*observer_on=*/true),
            "in control: g 1.25 of h 8.25 after 812 windows of 1000 samples (observer on: the "
            "test runs while the board samples)");
}

TEST(WatchReport, NoTestIsNullAndSaysWhy) {
  EXPECT_TRUE(WatchJson(std::nullopt, 200).is_null());
  EXPECT_TRUE(WatchJson(wire::WatchInfoResponse{}, 200).is_null());
  EXPECT_EQ(WatchText(std::nullopt, 200), "none (this firmware has no residual test)");
  EXPECT_EQ(WatchText(wire::WatchInfoResponse{}, 200),
            "none (the calibration carries no residual test)");
}

}  // namespace
}  // namespace vibid::device
