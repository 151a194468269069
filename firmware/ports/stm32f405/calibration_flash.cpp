#include "calibration_flash.hpp"

#include <algorithm>

#include "regs/core_m4.hpp"
#include "regs/rcc.hpp"
#include "system.hpp"
#include "vibid/fw/calibration_store.hpp"

namespace vibid::fw::stm32 {

// A slot (one 16 KiB sector) holds the slot header and the calibration record.
static_assert(CalibrationStore::kSlotBytesNeeded <= InternalCalibrationFlash::kSlotBytes);
namespace {

// A single program takes at most 100 us; 100 000 status polls, a few cycles each at 168 MHz, are
// well above that.
constexpr std::uint32_t kWordPolls = 100000;
// The erase's bound, best-effort: above the datasheet's worst 16 KiB sector erase at either
// parallelism (x32 500 ms, x8 800 ms) and below the watchdog's shortest period (1.0 s, fed right
// before the erase starts). It can only fire when the wait loop runs (from the ART cache, not
// stalled on a flash fetch) and it is timed by the millisecond clock, which misses the SysTick
// interrupts of a stalled bus; a sector that never finishes is ended by the watchdog, the real
// bound.
constexpr std::uint64_t kEraseTimeoutUs = 900000;
static_assert(kEraseTimeoutUs > 1000ULL * InternalCalibrationFlash::kEraseMaxMsX8);
static_assert(kEraseTimeoutUs < 1000ULL * kWatchdogTimeoutMs);

bool WaitIdle(std::uint32_t polls) {
  if (!WaitFor(flash::kSr, flash::kSrBsy, 0, polls)) return false;
  return (Reg(flash::kSr) & flash::kSrErrors) == 0;
}

/// No watchdog feeding in here: while the erase runs, every read of the flash array stalls the
/// bus until it ends (RM0090 §3.5, erase and program operations), and this code, its
/// constants, the vector table and the handlers all sit in that array. Whether the loop spins
/// (from the ART cache) or stalls on its next fetch, the erase has the full watchdog period the
/// feed before STRT gave it.
bool WaitEraseDone() {
  const std::uint64_t start_us = MicrosecondsSinceBoot();
  while ((Reg(flash::kSr) & flash::kSrBsy) != 0) {
    if (MicrosecondsSinceBoot() - start_us > kEraseTimeoutUs) return false;
  }
  return (Reg(flash::kSr) & flash::kSrErrors) == 0;
}

/// Resets a cache that is enabled: disable, pulse the reset bit, enable (RM0090 §3.5.2: the
/// reset works only on a disabled cache; ST's HAL FLASH_FlushCaches does the same).
void ResetCache(std::uint32_t enable_bit, std::uint32_t reset_bit) {
  if ((Reg(flash::kAcr) & enable_bit) == 0) return;
  Reg(flash::kAcr) &= ~enable_bit;
  Reg(flash::kAcr) |= reset_bit;
  Reg(flash::kAcr) &= ~reset_bit;
  Reg(flash::kAcr) |= enable_bit;
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

Address SlotAddress(CalibrationFlash::Slot slot, std::size_t offset) {
  return InternalCalibrationFlash::kSlotAddress[static_cast<std::size_t>(slot)] + offset;
}

}  // namespace

std::uint32_t InternalCalibrationFlash::Psize() const {
  return parallelism_ == Parallelism::kX32 ? flash::kCrPsizeX32 : flash::kCrPsizeX8;
}

Status InternalCalibrationFlash::Erase(Slot slot) {
  bool ok = false;
  {
    Unlocked unlocked;
    ok = WaitIdle(kWordPolls);
    if (ok) {
      Reg(flash::kCr) = flash::kCrSer | Psize() |
                        Field(kSector[static_cast<std::size_t>(slot)], flash::kCrSnbPos);
      // A full watchdog period for the erase, whatever the main loop last did.
      KickWatchdog();
      Reg(flash::kCr) |= flash::kCrStrt;
      ok = WaitEraseDone();
      KickWatchdog();
      Reg(flash::kCr) = 0;
    }
  }
  ResetCache(flash::kAcrIcen, flash::kAcrIcrst);
  ResetCache(flash::kAcrDcen, flash::kAcrDcrst);
  if (!ok) {
    ++errors_;
    return Status::kInternal;
  }
  return Status::kOk;
}

Status InternalCalibrationFlash::Program(Slot slot, std::size_t offset,
                                         std::span<const std::uint8_t> data) {
  if (offset > kSlotBytes || data.size() > kSlotBytes - offset) return Status::kOutOfRange;
  if (data.empty()) return Status::kOk;
  const Status s = parallelism_ == Parallelism::kX32 ? ProgramWords(slot, offset, data)
                                                     : ProgramBytes(slot, offset, data);
  if (s != Status::kOk) ++errors_;
  return s;
}

Status InternalCalibrationFlash::ProgramWords(Slot slot, std::size_t offset,
                                              std::span<const std::uint8_t> data) {
  Unlocked unlocked;
  bool ok = WaitIdle(kWordPolls);
  // The access size must match PSIZE, or the flash refuses with PGPERR (RM0090 §3.6.2).
  Reg(flash::kCr) = flash::kCrPg | flash::kCrPsizeX32;
  const std::size_t first_word = offset / 4;
  const std::size_t end_word = (offset + data.size() + 3) / 4;
  for (std::size_t w = first_word; ok && w < end_word; ++w) {
    if ((w - first_word) % kWritesPerFeed == 0) KickWatchdog();
    // Bytes outside [offset, offset + size) stay 0xFF: programming them changes nothing.
    std::uint32_t word = 0xFFFFFFFF;
    for (std::size_t b = 0; b < 4; ++b) {
      const std::size_t at = 4 * w + b;
      if (at < offset || at >= offset + data.size()) continue;
      word &= ~(0xFFU << (8 * b));
      word |= std::uint32_t{data[at - offset]} << (8 * b);
    }
    if (word == 0xFFFFFFFF) continue;
    const Address cell = SlotAddress(slot, 4 * w);
    const std::uint32_t expected = Reg(cell) & word;
    Reg(cell) = word;
    DataSyncBarrier();
    ok = WaitIdle(kWordPolls) && Reg(cell) == expected;
  }
  Reg(flash::kCr) = 0;
  return ok ? Status::kOk : Status::kInternal;
}

Status InternalCalibrationFlash::ProgramBytes(Slot slot, std::size_t offset,
                                              std::span<const std::uint8_t> data) {
  Unlocked unlocked;
  bool ok = WaitIdle(kWordPolls);
  Reg(flash::kCr) = flash::kCrPg | flash::kCrPsizeX8;
  for (std::size_t i = 0; ok && i < data.size(); ++i) {
    if (i % kWritesPerFeed == 0) KickWatchdog();
    const Address cell = SlotAddress(slot, offset + i);
    const std::uint32_t expected = Reg8(cell) & data[i];
    Reg8(cell) = data[i];
    DataSyncBarrier();
    ok = WaitIdle(kWordPolls) && Reg8(cell) == expected;
  }
  Reg(flash::kCr) = 0;
  return ok ? Status::kOk : Status::kInternal;
}

Status InternalCalibrationFlash::Read(Slot slot, std::size_t offset,
                                      std::span<std::uint8_t> out) const {
  if (offset > kSlotBytes || out.size() > kSlotBytes - offset) return Status::kOutOfRange;
  for (std::size_t i = 0; i < out.size(); ++i)
    out[i] = static_cast<std::uint8_t>(Reg8(SlotAddress(slot, offset + i)));
  return Status::kOk;
}

}  // namespace vibid::fw::stm32
