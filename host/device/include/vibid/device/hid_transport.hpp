// A real board through the operating system's HID driver (hidapi, hidraw backend on Linux).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "vibid/device/transport.hpp"
#include "vibid/device/usb_control.hpp"

namespace vibid::device {

struct HidListing {
  std::string path;    ///< OS path (/dev/hidrawN).
  std::string serial;  ///< iSerialNumber.
  std::string product;
  std::uint16_t release = 0;  ///< bcdDevice.
};

/// Every attached vibid board (VID, PID and usage page 0xFF00 match).
std::vector<HidListing> ListHidDevices();

/// Opens the board with that serial number, or the only one when `serial` is empty.
/// Throws DeviceError when none (or, without a serial, more than one) is attached.
std::unique_ptr<Transport> OpenHid(const std::string& serial);

}  // namespace vibid::device
