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

/// Identifies the exact source the image was built from: the first 8 hex digits of the git
/// commit at build time (0 when the tree is not a git checkout).
std::uint32_t BuildId();

}  // namespace vibid::fw
