// The calibration record in flash, in two slots A and B so a power cut never leaves the board
// without a valid one.
//
// Slot layout (little-endian):
//   0   u32  magic          kSlotMagic: bytes 'V','S','L','T'
//   4   u32  sequence       +1 per commit; the newest valid slot wins (serial-number order)
//   8   u32  record_bytes   wire::kCalRecordBytes
//   12  u32  record_crc     CRC-32 of the record bytes
//   16  u32  header_crc     CRC-32 of bytes [0, 16)
//   20  ...  erased up to kSlotRecordOffset
//   32  the calibration record (wire layout)
//
// Commit writes the slot that does not hold the active record (the older or the invalid one):
// erase, program the record, read it back, program the header last, read it back. A cut at any
// step leaves that slot without a valid header (erased bytes or a header CRC that does not
// match) and the other slot, the previous newest, untouched. Boot (Load) reads both slots and
// takes the valid one with the newer sequence; with none valid the board runs on defaults,
// flagged uncalibrated.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "vibid/fw/port.hpp"
#include "vibid/shared/status.hpp"
#include "vibid/shared/wire/calibration_record.hpp"
#include "vibid/shared/wire/commands.hpp"

namespace vibid::fw {

class CalibrationStore {
 public:
  static constexpr std::uint32_t kSlotMagic = 0x544C5356u;  // bytes 'V','S','L','T'
  static constexpr std::size_t kSlotHeaderBytes = 20;
  static constexpr std::size_t kSlotRecordOffset = 32;
  static constexpr std::size_t kSlotBytesNeeded = kSlotRecordOffset + wire::kCalRecordBytes;

  explicit CalibrationStore(CalibrationFlash& flash) : flash_(flash) {}

  /// Reads both slots and activates the newest valid record, or the uncalibrated defaults.
  /// @returns kOk if a record was loaded; kDataLoss if neither slot holds a valid one;
  ///          kOutOfRange if the port's slots are smaller than kSlotBytesNeeded.
  Status Load();

  /// Writes a record that already passed DecodeCalibrationRecord to the
  /// slot not holding the active record, then activates it.
  /// @returns kOk; kOutOfRange if the slots are too small; kInternal if the flash reported an
  ///          error or the read-back differs (counted in flash_errors(); the active record and
  ///          the other slot are unchanged).
  Status Commit(std::span<const std::uint8_t, wire::kCalRecordBytes> record_bytes,
                const wire::CalibrationRecord& record);

  bool calibrated() const { return calibrated_; }
  /// 0 for slot A, 1 for slot B, wire::kNoSlot when uncalibrated.
  std::uint8_t slot() const {
    return calibrated_ ? static_cast<std::uint8_t>(slot_) : wire::kNoSlot;
  }
  std::uint32_t sequence() const { return calibrated_ ? sequence_ : 0; }
  /// The active record's own CRC-32 field (what the host computed when it built the record).
  std::uint32_t record_crc() const { return calibrated_ ? record_crc_ : 0; }
  std::uint32_t flash_errors() const { return flash_errors_; }

  /// What a slot holds (self-test): erased, a valid record, or anything else (damaged). Reads
  /// the slot again; the active record is untouched.
  wire::SelfTestSlot CheckSlot(CalibrationFlash::Slot slot);

  /// The active record (defaults when uncalibrated: raw counts, no filter).
  const wire::CalibrationRecord& record() const { return record_; }
  /// Its encoded bytes (meaningful only when calibrated()).
  std::span<const std::uint8_t, wire::kCalRecordBytes> record_bytes() const { return bytes_; }

 private:
  struct SlotInfo {
    bool valid = false;
    std::uint32_t sequence = 0;
  };
  // Reads and checks one slot into scratch_/scratch_record_.
  SlotInfo Inspect(CalibrationFlash::Slot slot);
  Status WriteSlot(CalibrationFlash::Slot slot, std::uint32_t sequence,
                   std::span<const std::uint8_t, wire::kCalRecordBytes> record_bytes);

  CalibrationFlash& flash_;
  bool calibrated_ = false;
  CalibrationFlash::Slot slot_ = CalibrationFlash::Slot::kA;
  std::uint32_t sequence_ = 0;
  std::uint32_t record_crc_ = 0;
  std::uint32_t flash_errors_ = 0;
  wire::CalibrationRecord record_{};
  std::array<std::uint8_t, wire::kCalRecordBytes> bytes_{};
  std::array<std::uint8_t, wire::kCalRecordBytes> scratch_{};
  wire::CalibrationRecord scratch_record_{};
};

/// The record an uncalibrated board runs on: one mass, default scaling, no filter.
wire::CalibrationRecord UncalibratedRecord();

}  // namespace vibid::fw
