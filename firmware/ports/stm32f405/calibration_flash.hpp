// The two calibration slots in internal flash: sector 2 (0x08008000) and sector 3 (0x0800C000),
// 16 KiB each, reserved by the linker script so no code lands there. Erase is per sector;
// program and erase run with x32 parallelism (PSIZE 10), which needs a 2.7-3.6 V supply (RM0090
// §3.6.2): the board runs at 3.3 V. Programming is word-wide, so an unaligned offset or length
// is padded with 0xFF bytes, which leave the flash as it was.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "vibid/fw/port.hpp"

namespace vibid::fw::stm32 {

class InternalCalibrationFlash final : public CalibrationFlash {
 public:
  static constexpr std::size_t kSlotBytes = 16 * 1024;
  static constexpr std::array<std::uintptr_t, 2> kSlotAddress = {0x08008000, 0x0800C000};
  static constexpr std::array<unsigned, 2> kSector = {2, 3};
  /// Worst-case 16 KiB sector erase at x32 (datasheet, flash characteristics: 250 ms typical,
  /// 500 ms max; x8 would be 800 ms max). The watchdog (>= 1 s at any LSI) is fed right before
  /// the erase starts, so one erase fits in one watchdog period with margin.
  static constexpr std::uint32_t kEraseMaxMs = 500;
  /// Words programmed between two watchdog feeds: 256 x 100 us (max word program time) = 26 ms.
  static constexpr std::size_t kWordsPerFeed = 256;

  std::size_t SlotBytes() const override { return kSlotBytes; }
  /// Sector erase, then the flash instruction and data caches are reset as ST's HAL does after
  /// an erase, so no stale line of the old contents is served.
  /// @returns kOk; kInternal on a flash error or a timeout.
  Status Erase(Slot slot) override;
  /// @returns kOk; kOutOfRange past the slot end; kInternal on a flash error, a timeout, or a
  ///          read-back that is not (old AND new), the only result NOR programming can give.
  Status Program(Slot slot, std::size_t offset, std::span<const std::uint8_t> data) override;
  Status Read(Slot slot, std::size_t offset, std::span<std::uint8_t> out) const override;

  std::uint32_t Errors() const { return errors_; }

 private:
  std::uint32_t errors_ = 0;
};

}  // namespace vibid::fw::stm32
