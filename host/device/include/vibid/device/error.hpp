// Failures of the link to a board: no device, a transfer that timed out or broke off, a device that
// refused a request or speaks another protocol major. One line each, naming what failed; the CLI
// maps them to its device exit code.
#pragma once

#include <stdexcept>
#include <string>

namespace vibid::device {

class DeviceError : public std::runtime_error {
 public:
  explicit DeviceError(const std::string& message) : std::runtime_error(message) {}
};

/// The user interrupted a long transfer (Ctrl-C); the device was left idle.
class Interrupted : public DeviceError {
 public:
  explicit Interrupted(const std::string& message) : DeviceError(message) {}
};

}  // namespace vibid::device
