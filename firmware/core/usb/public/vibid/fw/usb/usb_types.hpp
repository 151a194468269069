// USB 2.0 chapter 9 vocabulary: the SETUP packet, request codes, descriptor types, endpoint
// addresses. Values are the specification's (USB 2.0 tables 9-2, 9-4, 9-5, 9-6).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

namespace vibid::fw::usb {

/// Endpoint 0 packet size; full speed allows 8, 16, 32 or 64. 64 keeps descriptors in one packet.
inline constexpr std::uint16_t kEp0Size = 64;

/// Endpoint address: bit 7 is the direction (1 = IN, device to host), bits 3..0 the number.
inline constexpr std::uint8_t kDirIn = 0x80;
constexpr bool IsIn(std::uint8_t ep_addr) { return (ep_addr & kDirIn) != 0; }
constexpr std::uint8_t EpNumber(std::uint8_t ep_addr) { return ep_addr & 0x0F; }

/// bmRequestType fields (USB 2.0 table 9-2).
enum class RequestType : std::uint8_t { kStandard = 0, kClass = 1, kVendor = 2, kReserved = 3 };
enum class Recipient : std::uint8_t { kDevice = 0, kInterface = 1, kEndpoint = 2, kOther = 3 };

/// Standard request codes (USB 2.0 table 9-4).
enum class StandardRequest : std::uint8_t {
  kGetStatus = 0,
  kClearFeature = 1,
  kSetFeature = 3,
  kSetAddress = 5,
  kGetDescriptor = 6,
  kSetDescriptor = 7,
  kGetConfiguration = 8,
  kSetConfiguration = 9,
  kGetInterface = 10,
  kSetInterface = 11,
  kSynchFrame = 12,
};

/// Feature selectors (USB 2.0 table 9-6).
inline constexpr std::uint16_t kFeatureEndpointHalt = 0;
inline constexpr std::uint16_t kFeatureDeviceRemoteWakeup = 1;

/// Descriptor types (USB 2.0 table 9-5; HID 1.11 §7.1; DFU 1.1 §4.1.3).
enum class DescriptorType : std::uint8_t {
  kDevice = 1,
  kConfiguration = 2,
  kString = 3,
  kInterface = 4,
  kEndpoint = 5,
  kDeviceQualifier = 6,
  kHid = 0x21,
  kHidReport = 0x22,
  kDfuFunctional = 0x21,
};

/// The 8-byte SETUP packet (USB 2.0 §9.3), decoded from its little-endian wire form.
struct SetupPacket {
  std::uint8_t bm_request_type = 0;
  std::uint8_t b_request = 0;
  std::uint16_t w_value = 0;
  std::uint16_t w_index = 0;
  std::uint16_t w_length = 0;

  static SetupPacket Decode(std::span<const std::uint8_t, 8> raw) {
    auto le16 = [&](std::size_t i) {
      return static_cast<std::uint16_t>(raw[i] | (raw[i + 1] << 8));
    };
    return SetupPacket{raw[0], raw[1], le16(2), le16(4), le16(6)};
  }

  bool DeviceToHost() const { return (bm_request_type & 0x80) != 0; }
  RequestType Type() const { return static_cast<RequestType>((bm_request_type >> 5) & 0x03); }
  Recipient To() const { return static_cast<Recipient>(bm_request_type & 0x1F); }
  std::uint8_t ValueHigh() const { return static_cast<std::uint8_t>(w_value >> 8); }
  std::uint8_t ValueLow() const { return static_cast<std::uint8_t>(w_value & 0xFF); }
};

}  // namespace vibid::fw::usb
