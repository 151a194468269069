// Firmware download to a board, start to end: the image is checked against the board's flash,
// the running application is asked into its DfuSe bootloader (enter-DFU), the bootloader is found
// once it has enumerated (over USB/IP for the emulator, libusb for a board), and FlashImage erases,
// downloads, verifies and leaves. The board's calibration sectors are never touched.
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <string>

#include "vibid/device/dfuse.hpp"
#include "vibid/device/select.hpp"

namespace vibid::device {

struct FlashBoardResult {
  FlashPlan plan;                 ///< what was erased and written
  bool from_application = false;  ///< false: the board was already in its bootloader
};

/// Flashes `image` at `address` on the board `spec` names (hid, usbip or any; serial links have no
/// bootloader). `note` receives one-line progress remarks (bootloader entered or found).
/// Throws InputError before touching the board when the image does not suit its flash (empty,
/// too large, data in the calibration sectors), DeviceError on any device failure.
FlashBoardResult FlashBoard(DeviceSpec spec, std::span<const std::uint8_t> image,
                            std::uint32_t address, const FlashProgress& progress = {},
                            const std::function<void(const std::string&)>& note = {});

}  // namespace vibid::device
