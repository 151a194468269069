// Back-pressure at full speed: a host pulling the log while the emulator samples flat out makes
// simulated time wait instead of losing records; with nobody pulling, a full log drops records
// exactly as a board's does.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>

#include "emulator.hpp"
#include "test_client.hpp"
#include "vibid/shared/wire/commands.hpp"

namespace vibid::emu {
namespace {

// Load cell 1 only: 8-byte records (u32 index + one i32), so a 16 KiB log holds 2048.
constexpr std::size_t kRecordBytes = 8;
constexpr std::size_t kLogBytes = 16 * 1024;
constexpr std::uint32_t kCapacity = kLogBytes / kRecordBytes;
// Ten times the log: 4 simulated seconds at 5 kHz.
constexpr std::uint32_t kRecords = 10 * kCapacity;

class LogPacing : public ::testing::Test {
 protected:
  void SetUp() override {
    EmulatorOptions o;
    o.port = 0;
    o.seed = 3;
    o.log_bytes = kLogBytes;  // speed 0: as fast as possible
    emulator_ = std::make_unique<Emulator>(o);
    thread_ = std::thread([this] { emulator_->Run(stop_); });
  }
  void TearDown() override {
    stop_ = true;
    thread_.join();
  }

  static void Start(testing::DeviceSession& s) {
    ASSERT_EQ(s.Request(wire::Command::kSelectScenario, testing::ScenarioOf("hammer", {2, 0, 0.2f, 0})).header.status,
              Status::kOk);
    wire::AcqConfigureRequest c;
    c.sample_period_us = 200;
    c.channel_mask = 0b000001;
    c.record_limit = kRecords;
    const auto configured = s.Request(wire::Command::kAcqConfigure, c);
    ASSERT_EQ(configured.header.status, Status::kOk);
    wire::AcqConfigureResponse r;
    ASSERT_EQ(wire::Decode(configured.payload, r), Status::kOk);
    ASSERT_EQ(r.record_bytes, kRecordBytes);
    ASSERT_EQ(r.capacity_records, kCapacity);
    ASSERT_EQ(s.Request(wire::Command::kAcqStart).header.status, Status::kOk);
  }

  std::unique_ptr<Emulator> emulator_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

TEST_F(LogPacing, PullingHostLosesNothing) {
  testing::DeviceSession s(emulator_->port());
  Start(s);
  const std::vector<std::uint8_t> log = s.FollowLog(kRecordBytes);
  ASSERT_EQ(log.size(), std::size_t{kRecords} * kRecordBytes);
  // Every tick's record, in order: no gap in the sample index.
  for (std::uint32_t i = 0; i < kRecords; ++i) {
    const std::uint8_t* p = log.data() + std::size_t{i} * kRecordBytes;
    const std::uint32_t sample = static_cast<std::uint32_t>(p[0] | p[1] << 8 | p[2] << 16 | p[3] << 24);
    ASSERT_EQ(sample, i);
  }
  const wire::StatusResponse st = s.GetStatus();
  EXPECT_EQ(st.acq_state, wire::AcqState::kDone);
  EXPECT_EQ(st.dropped_records, 0u);
  EXPECT_EQ(st.records_written, kRecords);
  EXPECT_EQ(st.ticks, kRecords);
}

TEST_F(LogPacing, WithoutAPullAFullLogDrops) {
  testing::DeviceSession s(emulator_->port());
  Start(s);
  wire::StatusResponse st = s.GetStatus();
  for (int i = 0; i < 1000 && st.acq_state != wire::AcqState::kDone; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    st = s.GetStatus();
  }
  ASSERT_EQ(st.acq_state, wire::AcqState::kDone);
  // Nothing released: the log keeps its first kCapacity records and drops every later one.
  // The record limit counts records kept or dropped after the trigger: the acquisition ends
  // after kRecords ticks all the same.
  EXPECT_EQ(st.records_written, kCapacity);
  EXPECT_EQ(st.dropped_records, kRecords - kCapacity);
  EXPECT_EQ(st.oldest_record, 0u);
}

}  // namespace
}  // namespace vibid::emu
