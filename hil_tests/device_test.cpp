// Hardware-in-the-loop suite: the host device layer against a running firmware (VIBID_TARGET).
#include <gtest/gtest.h>

#include <cmath>
#include <thread>

#include "state_wait.hpp"
#include "target.hpp"
#include "test_records.hpp"
#include "vibid/device/error.hpp"
#include "vibid/shared/board_profile.hpp"
#include "vibid/shared/wire/calibration_record.hpp"
#include "vibid/shared/wire/log_record.hpp"

namespace vibid::hil {
namespace {

using device::Connection;
using device::DeviceError;
using wire::Command;

std::vector<std::uint8_t> RecordBytes(std::uint32_t tag) {
  const auto a = fw::testing::Encoded(fw::testing::TestRecord(tag));
  return {a.begin(), a.end()};
}

wire::AcqConfigureRequest AllChannels(std::uint32_t record_limit) {
  wire::AcqConfigureRequest c;
  c.sample_period_us = 200;
  c.channel_mask = wire::kAllChannelsMask;
  c.decimation = 1;
  c.record_limit = record_limit;
  return c;
}

/// The test signal's frame at `tick` as the log holds it: converter codes in 12.4, counts.
std::array<std::int32_t, wire::kChannelCount> LoggedAt(std::uint32_t tick) {
  auto v = CoreLoopback::FrameAt(tick);
  for (std::size_t c = 0; c < wire::kChannelCount; ++c) {
    if (wire::LogValueBytes(static_cast<wire::Channel>(c)) == 2)
      v[c] *= 1 << wire::kLogAdcFractionBits;
  }
  return v;
}

/// Waits until the acquisition ended on its record limit.
void AwaitDone(Connection& c) {
  const auto deadline = std::chrono::steady_clock::now() + hil::kStateWait;
  while (std::chrono::steady_clock::now() < deadline) {
    if (c.GetStatus().acq_state == wire::AcqState::kDone) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  FAIL() << "waited " << hil::kStateWait.count()
         << " s for the acquisition to reach its record limit";
}

/// Records the board's log holds with every channel on.
std::uint32_t LogCapacityRecords(const Connection& c) {
  return c.info().log_capacity_bytes /
         static_cast<std::uint32_t>(wire::LogLayout{wire::kAllChannelsMask, 0}.StoredRecordBytes());
}

class DeviceTest : public ::testing::Test {
 protected:
  void SetUp() override { target = MakeTarget(); }

  /// Connects for an acquisition pulled while it runs: the loopback samples two frames a step.
  std::unique_ptr<Connection> ConnectToFollow() {
    if (CoreLoopback* loop = target->loopback()) loop->SetFramesPerStep(2);
    return target->Connect();
  }

  /// Starts an acquisition of every channel to pull while it runs; returns its record limit. A
  /// target fed by the test can only be fed ahead of the pull, so it gets what fits. The
  /// loopback's sampling waits for nobody, so twice its log (it wraps) must pass through a pull
  /// that keeps up; a rig running at its own pace gets a fixed length.
  std::uint32_t StartFollowedAcquisition(Connection& c) {
    const std::uint32_t fits = LogCapacityRecords(c);
    const std::uint32_t n = target->NeedsFeed() ? fits
                            : target->loopback() != nullptr
                                ? std::max<std::uint32_t>(3000, 2 * fits)
                                : std::min<std::uint32_t>(3000, fits);
    c.Configure(AllChannels(n));
    c.StartAcquisition();
    target->Feed(c, 0, n);
    return n;
  }

  std::unique_ptr<Target> target;
};

TEST_F(DeviceTest, InfoNamesProtocolChannelsAndCapabilities) {
  auto c = target->Connect();
  const wire::InfoResponse& info = c->info();
  EXPECT_EQ(info.protocol_major, wire::kProtocolMajor);
  EXPECT_EQ(info.link_reports_per_s, kBoardProfile.link_reports_per_s);
  EXPECT_EQ(info.adc_bits, kBoardProfile.adc_bits);
  for (std::size_t i = 0; i < wire::kChannelCount; ++i) {
    EXPECT_EQ(info.channel_kind[i], wire::KindOf(static_cast<wire::Channel>(i))) << "channel " << i;
  }
  EXPECT_NE(info.capabilities & wire::kCapDob, 0u);
  EXPECT_NE(info.capabilities & wire::kCapForceTrigger, 0u);
  EXPECT_GT(info.log_capacity_bytes, 0u);
  EXPECT_NO_THROW(c->Ping());
}

TEST_F(DeviceTest, CalibrationRoundTripAndPersistenceAcrossRestart) {
  const std::vector<std::uint8_t> record = RecordBytes(41);
  {
    auto c = target->Connect();
    std::size_t last_chunk = 0;
    c->CalPut(record, [&](std::uint64_t done, std::uint64_t total) {
      last_chunk = done;
      EXPECT_EQ(total, wire::CalPutChunkCount(record.size()));
    });
    EXPECT_EQ(last_chunk, wire::CalPutChunkCount(record.size()));
    const wire::CalCommitResponse commit = c->CalCommit();
    EXPECT_NE(commit.slot, wire::kNoSlot);
    wire::CalGetTrailer trailer;
    EXPECT_EQ(c->CalGet(&trailer), record);
    EXPECT_EQ(trailer.sequence, commit.sequence);
    EXPECT_EQ(c->GetInfo().cal_crc,
              wire::StoredRecordCrc(std::span<const std::uint8_t, wire::kCalRecordBytes>(
                  record.data(), record.size())));
  }
  if (!target->Restart()) GTEST_SKIP() << "target cannot be power cycled by the test";
  auto c = target->Connect();
  EXPECT_EQ(c->info().cal_state, wire::CalState::kCalibrated);
  EXPECT_EQ(c->CalGet(), record);
}

TEST_F(DeviceTest, CorruptedCalibrationUploadIsRefusedWithTheDevicesVerdict) {
  auto c = target->Connect();
  std::vector<std::uint8_t> record = RecordBytes(5);
  record[100] ^= 0x01;  // inside the channel scaling: the record CRC no longer matches
  try {
    c->CalPut(record);
    FAIL() << "a record with a wrong CRC was accepted";
  } catch (const DeviceError& e) {
    EXPECT_NE(std::string(e.what()).find("data-loss"), std::string::npos) << e.what();
  }
}

TEST_F(DeviceTest, CommitIsRefusedWhileAcquiring) {
  auto c = target->Connect();
  c->CalPut(RecordBytes(7));
  c->Configure(AllChannels(0));
  c->StartAcquisition();
  const device::Reply r = c->Call(Command::kCalCommit);
  EXPECT_EQ(r.header.status, Status::kFailedPrecondition);
  try {
    c->CalCommit();
    FAIL() << "commit accepted while acquiring";
  } catch (const DeviceError& e) {
    EXPECT_NE(std::string(e.what()).find("refused cal-commit"), std::string::npos) << e.what();
  }
  c->StopAcquisition();
  EXPECT_NO_THROW(c->CalCommit());
}

TEST_F(DeviceTest, ForceTriggerKeepsThePretriggerRecords) {
  auto c = target->Connect();
  c->CalPut(RecordBytes(9));
  c->CalCommit();
  // Load cell 1: full scale 100 N over 2048 counts (TestRecord). 20 N rising.
  wire::AcqConfigureRequest cfg = AllChannels(400);
  cfg.trigger_mode = wire::TriggerMode::kRising;
  cfg.trigger_channel = 0;
  cfg.trigger_threshold = static_cast<std::int32_t>(std::lround(20.0 / 100.0 * 2147483648.0));
  cfg.pretrigger_records = 50;
  const bool simulated_rig = (c->info().capabilities & wire::kCapScenarioSelect) != 0;
  if (simulated_rig)
    c->SelectScenario("hammer", std::vector<float>{2.0f, 100.0f, 0.5f});  // hits on mass 2
  c->Configure(cfg);
  c->StartAcquisition();
  target->Feed(*c, 0, 1000);
  AwaitDone(*c);
  const device::LogPull pull = c->PullLog();
  ASSERT_EQ(pull.records.size(), 450u);
  EXPECT_EQ(pull.trailer.trigger_record, 50u);
  // Calibrated force of a record in N, as the board computes it.
  const auto force_n = [](const wire::LogRecord& r) {
    std::uint32_t clips = 0;
    const auto scaling = fw::testing::TestRecord(9).channels[0];
    return wire::ScaleChannel(r.raw[0] >> wire::kLogAdcFractionBits, scaling, clips) /
           2147483648.0 * 100.0;
  };
  // The test signal's pulse starts at tick 200; 1500 sin(2 pi / 20) counts = 22.6 N is its first
  // sample above (a simulated rig's hammer hits at its own times).
  if (!simulated_rig) {
    EXPECT_EQ(pull.records[50].sample_index, 202u);
  }
  EXPECT_GE(force_n(pull.records[50]), 20.0);
  EXPECT_LT(force_n(pull.records[49]), 20.0);
  for (std::size_t i = 1; i < pull.records.size(); ++i) {
    ASSERT_EQ(pull.records[i].sample_index, pull.records[i - 1].sample_index + 1) << "record " << i;
  }
}

TEST_F(DeviceTest, InterruptedLogPullResumesWithNothingLostOrDuplicated) {
  CoreLoopback* loop = target->loopback();
  if (loop == nullptr) GTEST_SKIP() << "needs fault injection";
  auto c = target->Connect(device::ConnectionOptions{.timeout = std::chrono::milliseconds(200)});
  c->Configure(AllChannels(1800));
  c->StartAcquisition();
  AwaitDone(*c);
  loop->DropStreamReport(7);  // a lost data report in the first stream
  const device::LogPull pull = c->PullLog();
  ASSERT_EQ(pull.records.size(), 1800u);
  for (std::size_t i = 0; i < pull.records.size(); ++i) {
    ASSERT_EQ(pull.records[i].sample_index, i);
    ASSERT_EQ(pull.records[i].raw, LoggedAt(static_cast<std::uint32_t>(i))) << "record " << i;
  }
  EXPECT_GE(c->counters().stream_resumes, 1u);
}

/// Records per data report with every channel on.
std::uint32_t RecordsPerReport() {
  return static_cast<std::uint32_t>(wire::LogLayout{wire::kAllChannelsMask, 0}.RecordsPerReport());
}

// The board releases each record of an acquisition's stream as it sends it, and its log wraps
// over released records: once the stream breaks off after the log wrapped, record 0 is gone. What
// arrived in sequence is kept and the pull resumes from the first record that did not.
TEST_F(DeviceTest, BrokenAcquisitionStreamResumesAfterTheLastRecordReceived) {
  CoreLoopback* loop = target->loopback();
  if (loop == nullptr) GTEST_SKIP() << "needs fault injection";
  loop->SetFramesPerStep(2);
  // The lost report shows as a gap in the next one; no timeout needs to fire.
  auto c = target->Connect(device::ConnectionOptions{.timeout = std::chrono::seconds(2)});
  const std::uint32_t fits = LogCapacityRecords(*c);
  // Every report carries at least one record, so report `fits` starts past the log's first
  // wrap; the acquisition goes on for as long again.
  const std::uint32_t lost_report = fits;
  const std::uint32_t n = (RecordsPerReport() + 1) * (fits + 1);
  wire::AcqConfigureRequest cfg = AllChannels(n);
  cfg.flags = wire::kAcqFlagStream;
  c->Configure(cfg);
  loop->DropStreamReport(static_cast<int>(lost_report));
  const device::LogPull pull = c->AcquireStreamed();
  EXPECT_GE(c->counters().stream_resumes, 1u);
  ASSERT_EQ(pull.records.size(), n);
  EXPECT_EQ(pull.first_record, 0u);
  EXPECT_TRUE(pull.missing.empty());
  for (std::uint32_t i = 0; i < n; ++i) {
    ASSERT_EQ(pull.records[i].sample_index, i);
    ASSERT_EQ(pull.records[i].raw, LoggedAt(i)) << "record " << i;
  }
  EXPECT_EQ(pull.trailer.dropped_records, 0u);
  EXPECT_EQ(pull.trailer.acq_state, wire::AcqState::kDone);
}

/// Every record of `pull` is the test signal at its log index (the loopback logs from tick 0),
/// and the records and missing ranges cover [first_record, first_record + n) once each.
void ExpectTheTestSignal(const device::LogPull& pull, std::uint32_t n) {
  std::uint32_t index = pull.first_record;
  std::size_t gap = 0;
  for (const wire::LogRecord& r : pull.records) {
    if (gap < pull.missing.size() && index == pull.missing[gap].first)
      index = pull.missing[gap++].end;
    ASSERT_EQ(r.sample_index, index);
    ASSERT_EQ(r.raw, LoggedAt(index)) << "record " << index;
    ++index;
  }
  EXPECT_EQ(gap, pull.missing.size());
  EXPECT_EQ(index, pull.first_record + n);
}

// A host that falls a whole log behind the stream loses what the board overwrote meanwhile, and
// only that: the pull goes on from the oldest record the board still holds, and ends with an
// error that carries every record received and names what was kept and what was lost.
TEST_F(DeviceTest, RecordsOverwrittenBeforeTheyArrivedAreNamedAndTheRestIsPulled) {
  CoreLoopback* loop = target->loopback();
  if (loop == nullptr) GTEST_SKIP() << "needs fault injection";
  loop->SetFramesPerStep(2);
  // The host waits out the lost reports: it learns of them from the first one after them.
  auto c = target->Connect(device::ConnectionOptions{.timeout = std::chrono::seconds(10)});
  const std::uint32_t fits = LogCapacityRecords(*c);
  // More reports than the log holds records never arrive (each carries at least one record):
  // the board sent them, released their records and wrapped over most of them.
  const std::uint32_t lost_reports = fits + 100;
  const std::uint32_t n = 3 * RecordsPerReport() * lost_reports;
  wire::AcqConfigureRequest cfg = AllChannels(n);
  cfg.flags = wire::kAcqFlagStream;
  c->Configure(cfg);
  loop->DropStreamReports(100, static_cast<int>(lost_reports));
  try {
    static_cast<void>(c->AcquireStreamed());
    FAIL() << "the pull did not say that records were lost";
  } catch (const device::IncompleteLog& e) {
    const device::LogPull& pull = e.pull();
    ASSERT_FALSE(pull.missing.empty());
    const device::LogRange lost = pull.missing[0];
    EXPECT_GE(lost.first, 100u) << "reports 0..99 arrived";
    std::uint32_t lost_count = 0;
    for (const device::LogRange& m : pull.missing) lost_count += m.end - m.first;
    EXPECT_GE(lost_count, 100u) << "at least the excess over the log's capacity";
    EXPECT_EQ(pull.records.size() + lost_count, n);
    ExpectTheTestSignal(pull, n);
    EXPECT_EQ(pull.trailer.acq_state, wire::AcqState::kDone);
    EXPECT_EQ(pull.trailer.dropped_records, 0u);
    const std::string why = e.what();
    EXPECT_EQ(why.rfind("the board's log wrapped over records " + std::to_string(lost.first) +
                            ".." + std::to_string(lost.end - 1),
                        0),
              0u)
        << why;
    EXPECT_NE(why.find("(" + std::to_string(lost_count) + ") before they could be pulled; kept " +
                       std::to_string(pull.records.size()) + " records: 0.." +
                       std::to_string(lost.first - 1) + ", " + std::to_string(lost.end) + ".."),
              std::string::npos)
        << why;
    EXPECT_NE(why.find(".." + std::to_string(n - 1)), std::string::npos) << why;
  }
}

TEST_F(DeviceTest, PullWhileAcquiringFollowsTheLog) {
  auto c = ConnectToFollow();
  const std::uint32_t n = StartFollowedAcquisition(*c);
  const device::LogPull pull = c->PullLog();
  ASSERT_EQ(pull.records.size(), n);
  EXPECT_EQ(pull.records.back().sample_index, n - 1);
  EXPECT_EQ(pull.trailer.dropped_records, 0u);
  EXPECT_EQ(pull.trailer.acq_state, wire::AcqState::kDone);
}

// A pull while sampling releases what it received, but the records stay on the board until the
// log wraps over them: a second pull from the oldest record get-status names returns exactly
// what the first one got from there, and anything older is refused.
TEST_F(DeviceTest, LogPulledWhileAcquiringCanBePulledAgain) {
  auto c = ConnectToFollow();
  // The loopback's log is small: it wraps, so the refusal below is exercised there.
  const std::uint32_t n = StartFollowedAcquisition(*c);
  const std::uint32_t fits = LogCapacityRecords(*c);
  const device::LogPull first = c->PullLog();
  ASSERT_EQ(first.records.size(), n);

  const wire::StatusResponse st = c->GetStatus();
  EXPECT_EQ(st.records_written, n);
  if (n <= fits) {
    EXPECT_EQ(st.oldest_record, 0u);
  }
  ASSERT_LT(st.oldest_record, n);
  const device::LogPull again = c->PullLog(st.oldest_record);
  ASSERT_EQ(again.records.size(), n - st.oldest_record);
  for (std::size_t i = 0; i < again.records.size(); ++i) {
    const wire::LogRecord& a = first.records[st.oldest_record + i];
    const wire::LogRecord& b = again.records[i];
    ASSERT_EQ(a.sample_index, b.sample_index) << "record " << st.oldest_record + i;
    ASSERT_EQ(a.raw, b.raw) << "record " << st.oldest_record + i;
  }
  if (st.oldest_record > 0) {
    EXPECT_THROW(c->PullLog(st.oldest_record - 1), DeviceError);
  }
}

TEST_F(DeviceTest, CorruptedAndTruncatedReportsAreDroppedAndTheRequestRetried) {
  CoreLoopback* loop = target->loopback();
  if (loop == nullptr) GTEST_SKIP() << "needs fault injection";
  auto c = target->Connect(device::ConnectionOptions{.timeout = std::chrono::milliseconds(200)});
  loop->CorruptNext(1);
  EXPECT_NO_THROW(c->GetStatus());
  loop->TruncateNext(1);
  EXPECT_NO_THROW(c->GetStatus());
  const device::LinkCounters n = c->counters();
  EXPECT_EQ(n.corrupted, 1u);
  EXPECT_EQ(n.truncated, 1u);
  EXPECT_EQ(n.retries, 2u);
}

TEST_F(DeviceTest, LostAnswersFailWithAOneLineMessageAfterTheRetries) {
  CoreLoopback* loop = target->loopback();
  if (loop == nullptr) GTEST_SKIP() << "needs fault injection";
  auto c = target->Connect(
      device::ConnectionOptions{.timeout = std::chrono::milliseconds(50), .retries = 2});
  loop->DropNext(3);
  try {
    c->GetStatus();
    FAIL() << "no error although every answer was lost";
  } catch (const DeviceError& e) {
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("no answer to get-status"), std::string::npos) << e.what();
  }
}

TEST_F(DeviceTest, WrongProtocolMajorIsRefusedNamingBothVersions) {
  CoreLoopback* loop = target->loopback();
  if (loop == nullptr) GTEST_SKIP() << "needs fault injection";
  loop->SetProtocolMajor(wire::kProtocolMajor + 1);
  try {
    target->Connect(device::ConnectionOptions{.timeout = std::chrono::milliseconds(200)});
    FAIL() << "connected to a device of another protocol major";
  } catch (const DeviceError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("protocol 3.x"), std::string::npos) << m;
    EXPECT_NE(m.find("this host speaks 2."), std::string::npos) << m;
  }
}

TEST_F(DeviceTest, UnknownCommandIsRefusedAsUnimplemented) {
  auto c = target->Connect();
  const device::Reply r = c->Call(static_cast<Command>(0x5A));
  EXPECT_EQ(r.header.status, Status::kUnimplemented);
  try {
    c->Expect(static_cast<Command>(0x5A));
    FAIL();
  } catch (const DeviceError& e) {
    EXPECT_NE(std::string(e.what()).find("does not know this command"), std::string::npos)
        << e.what();
  }
}

TEST_F(DeviceTest, DeviceVanishingMidPullIsReported) {
  if (target->Name() != "emu" && target->Name() != "core")
    GTEST_SKIP() << "the test cannot remove this device";
  CoreLoopback* loop = target->loopback();
  if (loop != nullptr) loop->SetFramesPerStep(1);
  auto c = target->Connect();
  c->Configure(AllChannels(0));
  c->StartAcquisition();
  std::thread killer([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    EXPECT_TRUE(target->Kill());
  });
  try {
    c->PullLog();
    killer.join();
    FAIL() << "the pull ended although the device vanished";
  } catch (const DeviceError& e) {
    killer.join();
    EXPECT_NE(std::string(e.what()).find("lost the device"), std::string::npos) << e.what();
  }
}

TEST_F(DeviceTest, CancelledPullThrowsInterrupted) {
  std::atomic<bool> cancel{false};
  auto c = target->Connect(device::ConnectionOptions{.cancel = &cancel});
  c->Configure(AllChannels(0));
  c->StartAcquisition();
  std::thread stopper([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    cancel = true;
  });
  EXPECT_THROW(c->PullLog(), device::Interrupted);
  stopper.join();
  cancel = false;
  c->StopAcquisition();
  EXPECT_EQ(c->GetStatus().acq_state, wire::AcqState::kIdle);
}

}  // namespace
}  // namespace vibid::hil
