// The two calibration slots in internal flash: sector 2 (0x08008000) and sector 3 (0x0800C000),
// 16 KiB each, reserved by the linker script so no code lands there. Erase is per sector;
// programming is in 32-bit words (PSIZE x32 for a 2.7-3.6 V supply).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "vibid/shared/status.hpp"

namespace vibid::fw::stm32 {

class CalibrationFlash {
 public:
  static constexpr std::size_t kSlots = 2;
  static constexpr std::size_t kSlotSize = 16 * 1024;
  static constexpr std::size_t kProgramUnit = 4;

  /// Memory-mapped contents of a slot (erased bytes read 0xFF).
  /// @returns an empty span for a slot index out of range.
  std::span<const std::uint8_t> Read(std::size_t slot) const;
  /// Erases the slot's sector (typically 250 ms, up to 500 ms).
  /// @returns kOk, kOutOfRange for a bad slot, kUnavailable on timeout, kInternal when the
  ///          flash interface reports an error (write protection, sequence).
  Status Erase(std::size_t slot);
  /// Programs `data` at `offset` within the slot; offset and size must be multiples of 4.
  /// @returns kOk, kInvalidArgument for misaligned input, kOutOfRange past the slot end,
  ///          kUnavailable on timeout, kInternal on a flash error, kDataLoss when the read-back
  ///          differs (programming over bits that were not erased).
  Status Program(std::size_t slot, std::size_t offset, std::span<const std::uint8_t> data);
};

}  // namespace vibid::fw::stm32
