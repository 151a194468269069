// The words for the board's clip counters and for what read-latest holds when it is not sampling.
#include "vibid/device/board_report.hpp"

#include <gtest/gtest.h>

namespace vibid::device {
namespace {

TEST(BoardReport, NoClipsSaysNothing) {
  wire::ClipResponse clips;
  clips.ticks = 50000;
  EXPECT_EQ(DescribeClips(clips, nullptr), "");
}

TEST(BoardReport, ClipsNameChannelCountAndFullScale) {
  wire::ClipResponse clips;
  clips.ticks = 50000;
  clips.clipped = {1234, 0, 0, 7, 0, 0};
  wire::CalibrationRecord rec;
  rec.channels[0].unit = wire::Unit::kNewton;
  rec.channels[0].full_scale = 100.0f;
  rec.channels[3].unit = wire::Unit::kMeterPerSecond2;
  rec.channels[3].full_scale = 200.0f;
  EXPECT_EQ(DescribeClips(clips, &rec),
            "clipped samples: force1 1234, acc2 7 of 50000 (at an end of the converter's range or "
            "beyond the calibrated full scale: force1 100 N, acc2 200 m/s2); the values there are "
            "not the signal: use a sensor range that covers it");
  EXPECT_EQ(DescribeClips(clips, nullptr),
            "clipped samples: force1 1234, acc2 7 of 50000 (at an end of the converter's range or "
            "beyond the calibrated full scale); the values there are not the signal: use a sensor "
            "range that covers it");
}

TEST(BoardReport, LatestIsLiveOnlyWhileSampling) {
  wire::LatestResponse latest;
  wire::StatusResponse status;
  latest.acq_state = wire::AcqState::kIdle;
  status.ticks = 0;  // nothing sampled since boot: read-latest's zeros are not a frame
  EXPECT_EQ(ClassifyLatest(latest, status), LatestKind::kNoFrame);
  status.ticks = 8000;  // an acquisition ran: its last frame
  EXPECT_EQ(ClassifyLatest(latest, status), LatestKind::kStopped);
  latest.acq_state = wire::AcqState::kDone;
  EXPECT_EQ(ClassifyLatest(latest, status), LatestKind::kStopped);
  latest.acq_state = wire::AcqState::kAcquiring;
  EXPECT_EQ(ClassifyLatest(latest, status), LatestKind::kLive);
  latest.acq_state = wire::AcqState::kArmed;
  status.ticks = 0;  // started, first frame not yet in
  EXPECT_EQ(ClassifyLatest(latest, status), LatestKind::kNoFrame);
}

}  // namespace
}  // namespace vibid::device
