#include "vibid/fw/calibration_store.hpp"

#include <algorithm>

#include "vibid/shared/wire/byte_order.hpp"
#include "vibid/shared/wire/crc32.hpp"

namespace vibid::fw {
namespace {

using Slot = CalibrationFlash::Slot;

constexpr Slot Other(Slot s) { return s == Slot::kA ? Slot::kB : Slot::kA; }

// Serial-number order, so the sequence may wrap after 2^32 commits.
constexpr bool Newer(std::uint32_t a, std::uint32_t b) {
  return static_cast<std::int32_t>(a - b) > 0;
}

}  // namespace

wire::CalibrationRecord UncalibratedRecord() {
  wire::CalibrationRecord r;
  r.dof_count = 1;
  r.mass_kg[0] = 1.0f;
  return r;
}

CalibrationStore::SlotInfo CalibrationStore::Inspect(Slot slot) {
  std::array<std::uint8_t, kSlotHeaderBytes> header{};
  if (flash_.Read(slot, 0, header) != Status::kOk) return {};
  const std::uint32_t magic = wire::LoadU32(header, 0);
  const std::uint32_t sequence = wire::LoadU32(header, 4);
  const std::uint32_t length = wire::LoadU32(header, 8);
  const std::uint32_t record_crc = wire::LoadU32(header, 12);
  const std::uint32_t header_crc = wire::LoadU32(header, 16);
  if (magic != kSlotMagic || length != wire::kCalRecordBytes ||
      wire::ComputeCrc32(std::span<const std::uint8_t>(header).first(16)) != header_crc) {
    return {};
  }
  if (flash_.Read(slot, kSlotRecordOffset, scratch_) != Status::kOk ||
      wire::ComputeCrc32(scratch_) != record_crc ||
      wire::DecodeCalibrationRecord(scratch_, scratch_record_) != Status::kOk) {
    return {};
  }
  return SlotInfo{.valid = true, .sequence = sequence};
}

wire::SelfTestSlot CalibrationStore::CheckSlot(Slot slot) {
  if (Inspect(slot).valid) return wire::SelfTestSlot::kValid;
  // Not valid: erased only if every byte of the header and the record reads as erased flash.
  std::array<std::uint8_t, kSlotHeaderBytes> header{};
  if (flash_.Read(slot, 0, header) != Status::kOk ||
      flash_.Read(slot, kSlotRecordOffset, scratch_) != Status::kOk) {
    return wire::SelfTestSlot::kDamaged;
  }
  const auto erased = [](std::span<const std::uint8_t> bytes) {
    for (const std::uint8_t b : bytes) {
      if (b != CalibrationFlash::kErasedByte) return false;
    }
    return true;
  };
  return erased(header) && erased(scratch_) ? wire::SelfTestSlot::kErased
                                            : wire::SelfTestSlot::kDamaged;
}

Status CalibrationStore::Load() {
  calibrated_ = false;
  record_ = UncalibratedRecord();
  bytes_.fill(0);
  if (flash_.SlotBytes() < kSlotBytesNeeded) return Status::kOutOfRange;
  const SlotInfo a = Inspect(Slot::kA);
  const SlotInfo b = Inspect(Slot::kB);
  if (!a.valid && !b.valid) return Status::kDataLoss;
  const Slot chosen =
      (a.valid && (!b.valid || !Newer(b.sequence, a.sequence))) ? Slot::kA : Slot::kB;
  // scratch_ holds the slot inspected last (B); re-read if A won.
  if (chosen == Slot::kA) (void)Inspect(Slot::kA);
  calibrated_ = true;
  slot_ = chosen;
  sequence_ = chosen == Slot::kA ? a.sequence : b.sequence;
  bytes_ = scratch_;
  record_ = scratch_record_;
  record_crc_ = wire::StoredRecordCrc(bytes_);
  return Status::kOk;
}

Status CalibrationStore::WriteSlot(Slot slot, std::uint32_t sequence,
                                   std::span<const std::uint8_t, wire::kCalRecordBytes> record) {
  if (flash_.Erase(slot) != Status::kOk) return Status::kInternal;
  if (flash_.Program(slot, kSlotRecordOffset, record) != Status::kOk) return Status::kInternal;
  if (flash_.Read(slot, kSlotRecordOffset, scratch_) != Status::kOk ||
      !std::equal(scratch_.begin(), scratch_.end(), record.begin())) {
    return Status::kInternal;
  }
  std::array<std::uint8_t, kSlotHeaderBytes> header{};
  wire::StoreU32(header, 0, kSlotMagic);
  wire::StoreU32(header, 4, sequence);
  wire::StoreU32(header, 8, static_cast<std::uint32_t>(wire::kCalRecordBytes));
  wire::StoreU32(header, 12, wire::ComputeCrc32(record));
  wire::StoreU32(header, 16, wire::ComputeCrc32(std::span<const std::uint8_t>(header).first(16)));
  if (flash_.Program(slot, 0, header) != Status::kOk) return Status::kInternal;
  std::array<std::uint8_t, kSlotHeaderBytes> check{};
  if (flash_.Read(slot, 0, check) != Status::kOk || check != header) return Status::kInternal;
  return Status::kOk;
}

Status CalibrationStore::Commit(std::span<const std::uint8_t, wire::kCalRecordBytes> record_bytes,
                                const wire::CalibrationRecord& record) {
  if (flash_.SlotBytes() < kSlotBytesNeeded) return Status::kOutOfRange;
  const Slot target = calibrated_ ? Other(slot_) : Slot::kA;
  const std::uint32_t sequence = calibrated_ ? sequence_ + 1 : 1;
  if (WriteSlot(target, sequence, record_bytes) != Status::kOk) {
    ++flash_errors_;
    return Status::kInternal;
  }
  calibrated_ = true;
  slot_ = target;
  sequence_ = sequence;
  std::copy(record_bytes.begin(), record_bytes.end(), bytes_.begin());
  record_ = record;
  record_crc_ = wire::StoredRecordCrc(bytes_);
  return Status::kOk;
}

}  // namespace vibid::fw
