// Which board to talk to: the `--device` option and the listing behind `vibid devices`.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "vibid/device/connection.hpp"
#include "vibid/device/transport.hpp"

namespace vibid::device {

/// A parsed `--device` value.
///   hid            the only board on USB HID        hid:SERIAL   that board
///   usbip://HOST:PORT   a USB/IP server (vibid-emu; port 3240 when omitted)
///   serial:PATH    a framed serial link (a tty, or the Unix socket QEMU's USART1 is on)
///   qemu           the QEMU board image's USART1 socket named by $VIBID_QEMU_SOCKET
struct DeviceSpec {
  enum class Kind { kAny, kHid, kUsbip, kSerial };
  Kind kind = Kind::kAny;
  std::string serial;  ///< kHid: iSerialNumber, empty for any.
  std::string host;    ///< kUsbip.
  int port = 3240;     ///< kUsbip.
  std::string path;    ///< kSerial.
};

/// Parses a `--device` value ("" is kAny). InputError naming the value, and `origin` (the option
/// or the variable it came from), when malformed.
DeviceSpec ParseDeviceSpec(const std::string& text, const std::string& origin = "--device");

/// The device value in force and where it came from.
struct DeviceChoice {
  std::string text;    ///< "" when nothing names a device (kAny).
  std::string origin;  ///< "--device", "VIBID_DEVICE", or "" with an empty text.
};

/// The `--device` option's value when given, else the VIBID_DEVICE environment variable's: the
/// option wins over the variable.
DeviceChoice ChooseDevice(const std::string& option_value);

/// A device seen by ListDevices, with the `--device` value that selects it.
struct Listing {
  std::string spec;
  std::string description;
};

/// Boards on USB HID, and USB/IP servers answering on 127.0.0.1:3240 (the emulator's default).
std::vector<Listing> ListDevices();

/// Opens the transport a spec names; kAny picks the only device ListDevices finds. Throws
/// DeviceError when there is none or more than one.
std::unique_ptr<Transport> OpenTransport(const DeviceSpec& spec);

}  // namespace vibid::device
