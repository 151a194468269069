// The emulator is the board: its HID link moves at most one 64-byte IN report per 1 ms simulated
// frame, its log is the board's 96 KiB, and neither the host's speed nor the machine's load
// changes what is sampled, logged, dropped or delivered.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>

#include "emulator.hpp"
#include "test_client.hpp"
#include "vibid/device/link_budget.hpp"
#include "vibid/shared/board_profile.hpp"
#include "vibid/shared/wire/byte_order.hpp"
#include "vibid/shared/wire/commands.hpp"
#include "vibid/shared/wire/log_record.hpp"

namespace vibid::emu {
namespace {

struct StreamRun {
  std::vector<std::uint8_t> records;
  std::vector<std::uint32_t> ticks;
  wire::LogTrailer trailer;
  std::uint64_t sim_us =
      0;  // simulated time from the first sample to the frame the trailer left in
};

struct RunOptions {
  double speed = 0.0;
  int hog_threads = 0;    // busy threads beside the emulator (a loaded machine)
  int host_delay_us = 0;  // the test host sleeps this long before each IN URB
};

/// One streamed acquisition against a fresh emulator (seed 5, hammer on m2 every 0.3 s).
StreamRun Acquire(const wire::AcqConfigureRequest& config, const RunOptions& ro = {}) {
  EmulatorOptions o;
  o.port = 0;
  o.seed = 5;
  o.speed = ro.speed;
  Emulator emu(o);
  std::atomic<bool> stop{false};
  std::thread loop([&] { emu.Run(stop); });
  std::vector<std::thread> hogs;
  for (int i = 0; i < ro.hog_threads; ++i) {
    hogs.emplace_back([&] {
      volatile std::uint64_t x = 0;
      while (!stop.load(std::memory_order_relaxed)) x = x + 1;
    });
  }
  StreamRun run;
  {
    testing::DeviceSession s(emu.port());
    s.receive_delay_us = ro.host_delay_us;
    EXPECT_EQ(
        s.Request(wire::Command::kSelectScenario, testing::ScenarioOf("hammer", {2, 200, 0.3f, 0}))
            .header.status,
        Status::kOk);
    EXPECT_EQ(s.Request(wire::Command::kAcqConfigure, config).header.status, Status::kOk);
    const wire::LogLayout layout{config.channel_mask, config.flags};
    run.records = s.StreamAcquisition(layout.RecordBytes());
    run.sim_us = emu.LastInReportUs() - emu.SamplingStartUs();
    run.ticks = s.ticks;
    EXPECT_EQ(wire::Decode(s.last_trailer, run.trailer), Status::kOk);
  }
  stop = true;
  for (auto& t : hogs) t.join();
  loop.join();
  return run;
}

wire::AcqConfigureRequest Streamed(std::uint32_t period_us, std::uint8_t mask,
                                   std::uint32_t records) {
  wire::AcqConfigureRequest c;
  c.sample_period_us = period_us;
  c.channel_mask = mask;
  c.flags = wire::kAcqFlagStream;
  c.record_limit = records;
  return c;
}

// 5 kHz, load cell 1 and both accelerometers (the modal test): 6-byte records, 9 per report,
// 9000 records/s on the link against 5000 made: nothing dropped, every tick in order, and the
// stream ends within a few frames of the acquisition.
TEST(BoardLink, WithinTheBudgetNothingIsDropped) {
  constexpr std::uint32_t kRecords = 50000;  // 10 simulated seconds
  const StreamRun r = Acquire(Streamed(200, 0b001101, kRecords));
  ASSERT_EQ(r.ticks.size(), kRecords);
  for (std::uint32_t i = 0; i < kRecords; ++i) ASSERT_EQ(r.ticks[i], i);
  EXPECT_EQ(r.trailer.dropped_records, 0u);
  EXPECT_EQ(r.trailer.records_written, kRecords);
  EXPECT_LE(r.sim_us, 10'000'000u + 5'000u);
}

// Beyond the budget: 10 kHz, all six channels (16-byte records, 3 per report, 20 with the tick
// in RAM: 4915 in the 96 KiB log). 10 records are made per frame and 3 leave: the log fills in
// about 0.7 s and from then on each frame keeps the 3 records the last report freed and drops 7.
// Measured here: 10915 kept, 9085 dropped, as predicted.
TEST(BoardLink, BeyondTheBudgetDropsWhatTheLinkAndLogPredict) {
  constexpr std::uint32_t kRecords = 20000;  // 2 simulated seconds
  const StreamRun r = Acquire(Streamed(100, wire::kAllChannelsMask, kRecords));
  const std::uint32_t capacity = kBoardProfile.log_bytes / 20;
  ASSERT_EQ(capacity, 4915u);
  const device::StreamPrediction p = device::PredictStream(kRecords, 10, capacity, 3);
  std::printf("predicted kept %llu dropped %llu; measured kept %u dropped %u\n",
              static_cast<unsigned long long>(p.kept), static_cast<unsigned long long>(p.dropped),
              r.trailer.records_written, r.trailer.dropped_records);
  EXPECT_EQ(r.trailer.dropped_records, p.dropped);
  EXPECT_EQ(r.trailer.records_written, p.kept);
  ASSERT_EQ(r.ticks.size(), p.kept);  // every kept record reached the host
  // Closed form: what the link carried in the 2000 frames of sampling (3 records each) plus what
  // the full log still held at the end (4915) = 10915 kept, 9085 dropped.
  EXPECT_EQ(p.kept, 3u * (kRecords / 10u) + capacity);
}

// The same acquisition beyond the budget (drops are the part most sensitive to timing): flat
// out on an idle machine, flat out beside two busy threads with a host that is slow to read, and
// at wall-clock speed. The same bytes and the same counts every time.
TEST(BoardLink, NeitherLoadNorSpeedChangesWhatIsDelivered) {
  const wire::AcqConfigureRequest c = Streamed(100, wire::kAllChannelsMask, 12000);
  const StreamRun idle = Acquire(c);
  const StreamRun loaded = Acquire(c, {.speed = 0.0, .hog_threads = 2, .host_delay_us = 300});
  const StreamRun realtime = Acquire(c, {.speed = 1.0});
  EXPECT_GT(idle.trailer.dropped_records, 0u);
  for (const StreamRun* other : {&loaded, &realtime}) {
    EXPECT_EQ(other->records, idle.records);
    EXPECT_EQ(other->ticks, idle.ticks);
    EXPECT_EQ(other->trailer.dropped_records, idle.trailer.dropped_records);
    EXPECT_EQ(other->trailer.records_written, idle.trailer.records_written);
    EXPECT_EQ(other->sim_us, idle.sim_us);
  }
}

// Nobody asks for the log: it fills and drops every later record, as a board's does.
TEST(BoardLink, WithoutAHostPullingAFullLogDrops) {
  EmulatorOptions o;
  o.port = 0;
  o.seed = 3;
  Emulator emu(o);
  std::atomic<bool> stop{false};
  std::thread loop([&] { emu.Run(stop); });
  {
    testing::DeviceSession s(emu.port());
    wire::AcqConfigureRequest c = Streamed(200, 0b000001, 60000);
    c.flags = 0;  // no stream: the log only leaves on log-read
    ASSERT_EQ(s.Request(wire::Command::kAcqConfigure, c).header.status, Status::kOk);
    ASSERT_EQ(s.Request(wire::Command::kAcqStart).header.status, Status::kOk);
    wire::StatusResponse st = s.GetStatus();
    for (int i = 0; i < 2000 && st.acq_state != wire::AcqState::kDone; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
      st = s.GetStatus();
    }
    ASSERT_EQ(st.acq_state, wire::AcqState::kDone);
    // 2-byte records, 6 with the tick: 16384 fit; the rest of the 60000 are dropped.
    EXPECT_EQ(st.records_written, 16384u);
    EXPECT_EQ(st.dropped_records, 60000u - 16384u);
    EXPECT_EQ(st.oldest_record, 0u);
  }
  stop = true;
  loop.join();
}

}  // namespace
}  // namespace vibid::emu
