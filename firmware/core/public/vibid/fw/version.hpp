// Firmware version as reported by get-info.
#pragma once

#include <cstdint>

namespace vibid::fw {

struct FirmwareVersion {
  std::uint8_t major;
  std::uint8_t minor;
  std::uint16_t patch;
};

/// The version this core was built as (from the project version in CMake).
FirmwareVersion CurrentFirmwareVersion();

}  // namespace vibid::fw
