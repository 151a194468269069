// The QEMU board image (or a board on a UART): 64-byte reports in the shared serial framing
// (vibid/shared/wire/serial_frame.hpp) over a tty or a Unix socket (QEMU's `-chardev socket`).
#pragma once

#include <memory>
#include <string>

#include "vibid/device/transport.hpp"

namespace vibid::device {

/// Opens `path`: a Unix socket is connected, anything else is opened as a tty in raw mode at
/// 115200 baud. Throws DeviceError naming the path when it cannot be opened.
std::unique_ptr<Transport> OpenSerial(const std::string& path);

}  // namespace vibid::device
