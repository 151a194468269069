// The two calibration slots in internal flash: sector 2 (0x08008000) and sector 3 (0x0800C000),
// 16 KiB each, reserved by the linker script so no code lands there. Erase is per sector;
// programming is byte-wide (PSIZE x8), so any offset and length work and the supply voltage
// range is the widest (1.8-3.6 V).
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

  std::size_t SlotBytes() const override { return kSlotBytes; }
  /// Sector erase, typically 250 ms, at most 500 ms.
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
