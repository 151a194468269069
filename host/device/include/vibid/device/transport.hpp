// A transport moves whole 64-byte reports between the host and one board: HID (a real board),
// USB/IP (the emulator), a framed serial line (the QEMU board image). The protocol client above
// it knows nothing of which.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include "vibid/shared/wire/report.hpp"

namespace vibid::device {

class Transport {
 public:
  virtual ~Transport() = default;

  /// Sends one report. Throws DeviceError when the link is gone.
  virtual void Send(const wire::Report& report) = 0;

  /// Waits up to `timeout` for the next report from the device and copies it into `out`.
  /// @returns the number of bytes the device delivered (kReportBytes for a whole report; fewer
  ///          for a truncated one, which the caller discards), 0 on timeout.
  /// Throws DeviceError when the link is gone (device unplugged, emulator stopped).
  virtual std::size_t Receive(std::span<std::uint8_t, wire::kReportBytes> out,
                              std::chrono::milliseconds timeout) = 0;

  /// How the device was reached, for messages ("usbip://127.0.0.1:3240 bus 1-1").
  virtual std::string Describe() const = 0;

  /// The device's USB serial number (iSerialNumber), for the records that name their board;
  /// empty where the link does not carry one (a serial line).
  virtual std::string SerialNumber() const { return {}; }
};

}  // namespace vibid::device
