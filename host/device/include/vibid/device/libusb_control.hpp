// Control transfers to a real board's ROM bootloader through libusb (the bootloader is not a HID
// device, so hidapi cannot reach it).
#pragma once

#include <cstdint>
#include <memory>

#include "vibid/device/usb_control.hpp"

namespace vibid::device {

/// Opens the first device with that VID/PID and claims `interface`. Throws DeviceError when there
/// is none or it cannot be opened (permissions: see README).
std::unique_ptr<UsbControl> OpenLibusbControl(std::uint16_t vendor_id, std::uint16_t product_id,
                                              std::uint8_t interface);

}  // namespace vibid::device
