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

// A finished acquisition ("done": the record limit reached) is stopped, not sampling: the bench's
// status and `vibid monitor` say the same.
TEST(BoardReport, DoneIsStoppedNotSampling) {
  EXPECT_FALSE(IsSampling(wire::AcqState::kIdle));
  EXPECT_FALSE(IsSampling(wire::AcqState::kDone));
  EXPECT_TRUE(IsSampling(wire::AcqState::kArmed));
  EXPECT_TRUE(IsSampling(wire::AcqState::kAcquiring));
  wire::StatusResponse st;
  EXPECT_EQ(DescribeAcquisitionState(st), "idle: no acquisition since power-up");
  st.acq_state = wire::AcqState::kDone;
  st.ticks = 27500;
  st.records_written = 27500;
  EXPECT_EQ(DescribeAcquisitionState(st), "stopped: the last acquisition ended (27500 records)");
  st.acq_state = wire::AcqState::kIdle;
  st.records_written = 1200;
  st.dob_running = 1;
  EXPECT_EQ(DescribeAcquisitionState(st),
            "stopped: the last acquisition was stopped (1200 records), observer on");
  st.acq_state = wire::AcqState::kAcquiring;
  EXPECT_EQ(DescribeAcquisitionState(st), "sampling, observer on");
  st.acq_state = wire::AcqState::kArmed;
  st.dob_running = 0;
  EXPECT_EQ(DescribeAcquisitionState(st), "armed: waiting for the trigger");
}

}  // namespace
}  // namespace vibid::device
