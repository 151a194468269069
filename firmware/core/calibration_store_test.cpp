#include "vibid/fw/calibration_store.hpp"

#include <gtest/gtest.h>

#include "fake_port.hpp"
#include "test_records.hpp"
#include "vibid/shared/wire/byte_order.hpp"
#include "vibid/shared/wire/crc32.hpp"

namespace vibid::fw {
namespace {

using testing::Encoded;
using testing::FakeFlash;
using testing::TestRecord;
using Slot = CalibrationFlash::Slot;

// Steps of one commit in FakeFlash units: one erase, 1020 / 4 record words, 20 / 4 header words.
constexpr std::uint32_t kCommitSteps = 1 + wire::kCalRecordBytes / 4 + 20 / 4;

Status CommitTag(CalibrationStore& store, std::uint32_t tag) {
  const auto record = TestRecord(tag);
  return store.Commit(Encoded(record), record);
}

TEST(CalibrationStore, EmptyFlashIsUncalibrated) {
  FakeFlash flash;
  CalibrationStore store(flash);
  EXPECT_EQ(store.Load(), Status::kDataLoss);
  EXPECT_FALSE(store.calibrated());
  EXPECT_EQ(store.slot(), wire::kNoSlot);
  EXPECT_EQ(store.record_crc(), 0u);
  EXPECT_EQ(store.record().channels[0].gain, 1);  // default scaling: raw counts
  EXPECT_EQ(store.record().flags, 0);             // no filter
}

TEST(CalibrationStore, CommitsAlternateSlotsAndSurviveReboot) {
  FakeFlash flash;
  {
    CalibrationStore store(flash);
    (void)store.Load();
    ASSERT_EQ(CommitTag(store, 1), Status::kOk);
    EXPECT_EQ(store.slot(), 0);
    EXPECT_EQ(store.sequence(), 1u);
    ASSERT_EQ(CommitTag(store, 2), Status::kOk);
    EXPECT_EQ(store.slot(), 1);
    ASSERT_EQ(CommitTag(store, 3), Status::kOk);
    EXPECT_EQ(store.slot(), 0);  // the oldest slot is written next
    EXPECT_EQ(flash.steps(), 3 * kCommitSteps);
  }
  CalibrationStore rebooted(flash);
  ASSERT_EQ(rebooted.Load(), Status::kOk);
  EXPECT_EQ(rebooted.slot(), 0);
  EXPECT_EQ(rebooted.sequence(), 3u);
  EXPECT_EQ(rebooted.record().created_unix_s, 1700000003);
  const auto expected = Encoded(TestRecord(3));
  EXPECT_EQ(rebooted.record_crc(), wire::StoredRecordCrc(expected));
}

// The acceptance test: from each starting state, cut the power before every single flash step
// of a commit (and within it: the cut step is left half done) and reboot. Boot must always find
// a valid record, and it must be the newest one whose commit completed.
TEST(CalibrationStore, PowerCutAtEveryStepKeepsNewestCompletedRecord) {
  for (std::uint32_t committed_before = 0; committed_before <= 3; ++committed_before) {
    FakeFlash prepared;
    {
      CalibrationStore store(prepared);
      (void)store.Load();
      for (std::uint32_t tag = 1; tag <= committed_before; ++tag) {
        ASSERT_EQ(CommitTag(store, tag), Status::kOk);
      }
    }
    const std::uint32_t new_tag = committed_before + 1;
    for (std::uint32_t cut = 0; cut <= kCommitSteps; ++cut) {
      FakeFlash flash = prepared;
      flash.PowerOn();
      CalibrationStore store(flash);
      (void)store.Load();
      flash.steps_before_cut = cut;
      const Status commit = CommitTag(store, new_tag);
      const bool completed = cut == kCommitSteps;
      EXPECT_EQ(commit == Status::kOk, completed) << "cut " << cut;

      flash.PowerOn();
      flash.steps_before_cut = FakeFlash::kNoCut;
      CalibrationStore rebooted(flash);
      const Status load = rebooted.Load();
      const std::uint32_t newest = completed ? new_tag : committed_before;
      if (newest == 0) {
        EXPECT_EQ(load, Status::kDataLoss) << "cut " << cut;
        EXPECT_FALSE(rebooted.calibrated());
      } else {
        ASSERT_EQ(load, Status::kOk) << "before " << committed_before << " cut " << cut;
        EXPECT_EQ(rebooted.sequence(), newest) << "cut " << cut;
        EXPECT_EQ(rebooted.record().created_unix_s, 1700000000 + newest) << "cut " << cut;
      }
    }
  }
}

TEST(CalibrationStore, CorruptNewestFallsBackToOlder) {
  FakeFlash flash;
  CalibrationStore store(flash);
  (void)store.Load();
  ASSERT_EQ(CommitTag(store, 1), Status::kOk);  // slot A
  ASSERT_EQ(CommitTag(store, 2), Status::kOk);  // slot B
  flash.bytes(Slot::kB)[CalibrationStore::kSlotRecordOffset + 100] ^= 0x04;
  CalibrationStore rebooted(flash);
  ASSERT_EQ(rebooted.Load(), Status::kOk);
  EXPECT_EQ(rebooted.slot(), 0);
  EXPECT_EQ(rebooted.sequence(), 1u);
  // The next commit overwrites the broken slot, not the good one.
  ASSERT_EQ(CommitTag(rebooted, 3), Status::kOk);
  EXPECT_EQ(rebooted.slot(), 1);
  EXPECT_EQ(rebooted.sequence(), 2u);
}

// A slot image written by hand from the documented layout, with sequence numbers that wrap:
// 0 is newer than 0xFFFFFFFF in serial-number order.
TEST(CalibrationStore, HandWrittenSlotsAndSequenceWrap) {
  FakeFlash flash;
  const auto write_slot = [&](Slot slot, std::uint32_t sequence, std::uint32_t tag) {
    const auto record = Encoded(TestRecord(tag));
    std::array<std::uint8_t, 20> header{};
    wire::StoreU32(header, 0, 0x544C5356u);  // "VSLT"
    wire::StoreU32(header, 4, sequence);
    wire::StoreU32(header, 8, wire::kCalRecordBytes);
    wire::StoreU32(header, 12, wire::ComputeCrc32(record));
    wire::StoreU32(header, 16, wire::ComputeCrc32(std::span<const std::uint8_t>(header).first(16)));
    auto bytes = flash.bytes(slot);
    for (std::size_t i = 0; i < header.size(); ++i) bytes[i] = header[i];
    for (std::size_t i = 0; i < record.size(); ++i) bytes[32 + i] = record[i];
  };
  write_slot(Slot::kA, 0xFFFFFFFFu, 10);
  write_slot(Slot::kB, 0u, 11);
  CalibrationStore store(flash);
  ASSERT_EQ(store.Load(), Status::kOk);
  EXPECT_EQ(store.slot(), 1);
  EXPECT_EQ(store.record().created_unix_s, 1700000011);

  // A broken header CRC invalidates the slot even though the record is intact.
  flash.bytes(Slot::kB)[16] ^= 1;
  CalibrationStore again(flash);
  ASSERT_EQ(again.Load(), Status::kOk);
  EXPECT_EQ(again.slot(), 0);
  EXPECT_EQ(again.record().created_unix_s, 1700000010);
}

TEST(CalibrationStore, FlashErrorIsCountedAndChangesNothing) {
  FakeFlash flash;
  CalibrationStore store(flash);
  (void)store.Load();
  ASSERT_EQ(CommitTag(store, 1), Status::kOk);
  flash.fail_program = true;
  EXPECT_EQ(CommitTag(store, 2), Status::kInternal);
  EXPECT_EQ(store.flash_errors(), 1u);
  EXPECT_EQ(store.sequence(), 1u);
  EXPECT_EQ(store.record().created_unix_s, 1700000001);
}

TEST(CalibrationStore, RefusesSlotsTooSmall) {
  FakeFlash flash;
  flash.slot_bytes = CalibrationStore::kSlotBytesNeeded - 1;
  CalibrationStore store(flash);
  EXPECT_EQ(store.Load(), Status::kOutOfRange);
  EXPECT_EQ(CommitTag(store, 1), Status::kOutOfRange);
}

}  // namespace
}  // namespace vibid::fw
