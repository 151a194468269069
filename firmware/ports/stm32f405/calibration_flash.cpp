#include "calibration_flash.hpp"

#include <array>
#include <cstring>

#include "regs/core_m4.hpp"
#include "regs/rcc.hpp"

namespace vibid::fw::stm32 {
namespace {

constexpr std::array<unsigned, CalibrationFlash::kSlots> kSectors = {2, 3};
constexpr std::array<Address, CalibrationFlash::kSlots> kSlotAddress = {0x08008000, 0x0800C000};
// Sector erase is at most 500 ms (datasheet, 16 KiB, x32); a status poll takes a few cycles at
// 168 MHz, so this bound is several seconds.
constexpr std::uint32_t kErasePolls = 200000000;
constexpr std::uint32_t kWordPolls = 100000;

Status WaitIdle(std::uint32_t polls) {
  if (!WaitFor(flash::kSr, flash::kSrBsy, 0, polls)) return Status::kUnavailable;
  if ((Reg(flash::kSr) & flash::kSrErrors) != 0) return Status::kInternal;
  return Status::kOk;
}

/// Unlocked for the scope; clears stale error flags first.
class Unlocked {
 public:
  Unlocked() {
    if ((Reg(flash::kCr) & flash::kCrLock) != 0) {
      Reg(flash::kKeyr) = flash::kKey1;
      Reg(flash::kKeyr) = flash::kKey2;
    }
    Reg(flash::kSr) = flash::kSrErrors | flash::kSrEop;
  }
  ~Unlocked() {
    Reg(flash::kCr) = flash::kCrLock;
  }
  Unlocked(const Unlocked&) = delete;
  Unlocked& operator=(const Unlocked&) = delete;
};

}  // namespace

std::span<const std::uint8_t> CalibrationFlash::Read(std::size_t slot) const {
  if (slot >= kSlots) return {};
  return {reinterpret_cast<const std::uint8_t*>(kSlotAddress[slot]), kSlotSize};
}

Status CalibrationFlash::Erase(std::size_t slot) {
  if (slot >= kSlots) return Status::kOutOfRange;
  Unlocked unlocked;
  if (Status s = WaitIdle(kWordPolls); s != Status::kOk) return s;
  Reg(flash::kCr) = flash::kCrSer | Field(kSectors[slot], flash::kCrSnbPos) | flash::kCrPsizeX32;
  Reg(flash::kCr) |= flash::kCrStrt;
  const Status s = WaitIdle(kErasePolls);
  Reg(flash::kCr) = 0;
  return s;
}

Status CalibrationFlash::Program(std::size_t slot, std::size_t offset, std::span<const std::uint8_t> data) {
  if (slot >= kSlots) return Status::kOutOfRange;
  if (offset % kProgramUnit != 0 || data.size() % kProgramUnit != 0) return Status::kInvalidArgument;
  if (offset > kSlotSize || data.size() > kSlotSize - offset) return Status::kOutOfRange;
  Unlocked unlocked;
  if (Status s = WaitIdle(kWordPolls); s != Status::kOk) return s;
  Reg(flash::kCr) = flash::kCrPg | flash::kCrPsizeX32;
  Status result = Status::kOk;
  for (std::size_t i = 0; i < data.size(); i += kProgramUnit) {
    std::uint32_t word = 0;
    std::memcpy(&word, data.data() + i, sizeof word);
    Reg(kSlotAddress[slot] + offset + i) = word;
    DataSyncBarrier();
    result = WaitIdle(kWordPolls);
    if (result != Status::kOk) break;
  }
  Reg(flash::kCr) = 0;
  if (result != Status::kOk) return result;
  const auto written = Read(slot).subspan(offset, data.size());
  return std::memcmp(written.data(), data.data(), data.size()) == 0 ? Status::kOk : Status::kDataLoss;
}

}  // namespace vibid::fw::stm32
