#include "calibration_flash.hpp"

#include <algorithm>

#include "regs/core_m4.hpp"
#include "regs/rcc.hpp"

namespace vibid::fw::stm32 {
namespace {

// Sector erase is at most 500 ms (datasheet, 16 KiB); a status poll takes a few cycles at
// 168 MHz, so this bound is several seconds. Byte programming takes at most 100 us.
constexpr std::uint32_t kErasePolls = 200000000;
constexpr std::uint32_t kBytePolls = 100000;

bool WaitIdle(std::uint32_t polls) {
  if (!WaitFor(flash::kSr, flash::kSrBsy, 0, polls)) return false;
  return (Reg(flash::kSr) & flash::kSrErrors) == 0;
}

/// Unlocked for the scope, with stale error flags cleared first; locked again on exit.
class Unlocked {
 public:
  Unlocked() {
    if ((Reg(flash::kCr) & flash::kCrLock) != 0) {
      Reg(flash::kKeyr) = flash::kKey1;
      Reg(flash::kKeyr) = flash::kKey2;
    }
    Reg(flash::kSr) = flash::kSrErrors | flash::kSrEop;
  }
  ~Unlocked() { Reg(flash::kCr) = flash::kCrLock; }
  Unlocked(const Unlocked&) = delete;
  Unlocked& operator=(const Unlocked&) = delete;
};

const volatile std::uint8_t* SlotBytesAt(CalibrationFlash::Slot slot, std::size_t offset) {
  return reinterpret_cast<const volatile std::uint8_t*>(
      InternalCalibrationFlash::kSlotAddress[static_cast<std::size_t>(slot)] + offset);
}

}  // namespace

Status InternalCalibrationFlash::Erase(Slot slot) {
  Unlocked unlocked;
  bool ok = WaitIdle(kBytePolls);
  if (ok) {
    Reg(flash::kCr) = flash::kCrSer | Field(kSector[static_cast<std::size_t>(slot)], flash::kCrSnbPos);
    Reg(flash::kCr) |= flash::kCrStrt;
    ok = WaitIdle(kErasePolls);
    Reg(flash::kCr) = 0;
  }
  if (!ok) {
    ++errors_;
    return Status::kInternal;
  }
  return Status::kOk;
}

Status InternalCalibrationFlash::Program(Slot slot, std::size_t offset, std::span<const std::uint8_t> data) {
  if (offset > kSlotBytes || data.size() > kSlotBytes - offset) return Status::kOutOfRange;
  Unlocked unlocked;
  bool ok = WaitIdle(kBytePolls);
  Reg(flash::kCr) = flash::kCrPg;  // PSIZE 00: x8.
  for (std::size_t i = 0; ok && i < data.size(); ++i) {
    auto* cell = const_cast<volatile std::uint8_t*>(SlotBytesAt(slot, offset + i));
    const std::uint8_t expected = static_cast<std::uint8_t>(*cell & data[i]);
    *cell = data[i];
    DataSyncBarrier();
    ok = WaitIdle(kBytePolls) && *cell == expected;
  }
  Reg(flash::kCr) = 0;
  if (!ok) {
    ++errors_;
    return Status::kInternal;
  }
  return Status::kOk;
}

Status InternalCalibrationFlash::Read(Slot slot, std::size_t offset, std::span<std::uint8_t> out) const {
  if (offset > kSlotBytes || out.size() > kSlotBytes - offset) return Status::kOutOfRange;
  const volatile std::uint8_t* src = SlotBytesAt(slot, offset);
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = src[i];
  return Status::kOk;
}

}  // namespace vibid::fw::stm32
