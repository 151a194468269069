// The two calibration slots in internal flash: sector 2 (0x08008000) and sector 3 (0x0800C000),
// 16 KiB each, reserved by the linker script so no code lands there. Erase is per sector.
// Parallelism follows the supply (RM0090 §3.6.2): x32 (PSIZE 10) needs 2.7-3.6 V and is the
// default for a 3.3 V board; x8 (PSIZE 00) works from 1.8 V but erases slower. With x32 the
// programming is word-wide, so an unaligned offset or length is padded with 0xFF bytes, which
// leave the flash as it was.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "vibid/fw/port.hpp"

namespace vibid::fw::stm32 {

class InternalCalibrationFlash final : public CalibrationFlash {
 public:
  enum class Parallelism : std::uint8_t {
    kX8,   ///< 1.8-3.6 V: byte writes, sector erase up to 800 ms.
    kX32,  ///< 2.7-3.6 V: word writes, sector erase up to 500 ms.
  };

  explicit InternalCalibrationFlash(Parallelism parallelism = Parallelism::kX32)
      : parallelism_(parallelism) {}

  static constexpr std::size_t kSlotBytes = 16 * 1024;
  static constexpr std::array<std::uintptr_t, 2> kSlotAddress = {0x08008000, 0x0800C000};
  static constexpr std::array<unsigned, 2> kSector = {2, 3};
  /// Worst-case 16 KiB sector erase (datasheet, flash characteristics: x32 250 ms typical and
  /// 500 ms max, x8 400 / 800 ms). The watchdog (>= 1 s at any LSI) is fed right before the
  /// erase starts, so one erase fits in one watchdog period either way.
  static constexpr std::uint32_t kEraseMaxMsX32 = 500;
  static constexpr std::uint32_t kEraseMaxMsX8 = 800;
  /// Writes (words or bytes) between two watchdog feeds: 256 x 100 us (max program time of
  /// one write) = 26 ms.
  static constexpr std::size_t kWritesPerFeed = 256;

  std::size_t SlotBytes() const override { return kSlotBytes; }
  /// Sector erase, then the flash instruction and data caches are reset as ST's HAL does after
  /// an erase, so no stale line of the old contents is served.
  /// @returns kOk; kInternal on a flash error or a timeout.
  Status Erase(Slot slot) override;
  /// @returns kOk; kOutOfRange past the slot end; kInternal on a flash error, a timeout, or a
  ///          read-back that is not (old AND new), the only result NOR programming can give.
  Status Program(Slot slot, std::size_t offset, std::span<const std::uint8_t> data) override;
  Status Read(Slot slot, std::size_t offset, std::span<std::uint8_t> out) const override;

  std::uint32_t errors() const { return errors_; }

 private:
  std::uint32_t Psize() const;
  Status ProgramWords(Slot slot, std::size_t offset, std::span<const std::uint8_t> data);
  Status ProgramBytes(Slot slot, std::size_t offset, std::span<const std::uint8_t> data);

  Parallelism parallelism_;
  std::uint32_t errors_ = 0;
};

}  // namespace vibid::fw::stm32
