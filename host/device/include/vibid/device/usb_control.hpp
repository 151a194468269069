// Control transfers on endpoint 0, for what HID reports cannot carry: descriptors at enumeration
// and the DFU class requests. Implemented over USB/IP (the emulator) and libusb (a real board).
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace vibid::device {

/// USB identity of the board's application (firmware/core/usb/descriptors.hpp: pid.codes VID,
/// test PID); its HID interface uses the vendor usage page wire::kHidUsagePage.
inline constexpr std::uint16_t kUsbVendorId = 0x1209;
inline constexpr std::uint16_t kUsbProductId = 0x0001;

/// The 8-byte SETUP packet (USB 2.0 §9.3), fields in host order.
struct Setup {
  std::uint8_t request_type = 0;  ///< bmRequestType; bit 7 set = device-to-host.
  std::uint8_t request = 0;
  std::uint16_t value = 0;
  std::uint16_t index = 0;
  std::uint16_t length = 0;  ///< wLength: bytes of the data stage.
  bool In() const { return (request_type & 0x80) != 0; }
  std::array<std::uint8_t, 8> Bytes() const {
    return {request_type,
            request,
            static_cast<std::uint8_t>(value & 0xFF),
            static_cast<std::uint8_t>(value >> 8),
            static_cast<std::uint8_t>(index & 0xFF),
            static_cast<std::uint8_t>(index >> 8),
            static_cast<std::uint8_t>(length & 0xFF),
            static_cast<std::uint8_t>(length >> 8)};
  }
};

class UsbControl {
 public:
  virtual ~UsbControl() = default;
  /// Runs one control transfer. For IN, returns the data stage (at most setup.length bytes); for
  /// OUT, sends `out` (setup.length bytes) and returns nothing. Throws DeviceError on a stall,
  /// a timeout or a lost link, naming the request.
  virtual std::vector<std::uint8_t> Control(const Setup& setup, std::span<const std::uint8_t> out,
                                            std::chrono::milliseconds timeout) = 0;
};

// Standard requests and descriptor types used by the host (USB 2.0 tables 9-4, 9-5).
inline constexpr std::uint8_t kGetDescriptor = 6;
inline constexpr std::uint8_t kSetConfiguration = 9;
inline constexpr std::uint8_t kDescriptorDevice = 1;
inline constexpr std::uint8_t kDescriptorConfiguration = 2;
inline constexpr std::uint8_t kDescriptorString = 3;

/// GET_DESCRIPTOR(type, index) of up to `length` bytes.
std::vector<std::uint8_t> GetDescriptor(UsbControl& usb, std::uint8_t type, std::uint8_t index,
                                        std::uint16_t length, std::uint16_t language = 0);

/// A string descriptor as ASCII (non-ASCII characters become '?'), language 0x0409.
std::string GetStringDescriptor(UsbControl& usb, std::uint8_t index);

}  // namespace vibid::device
