// The board's USB identity: device, configuration (HID interface with interrupt IN/OUT, DFU
// run-time interface), HID report descriptor and string table. Layouts follow USB 2.0 §9.6,
// HID 1.11 §6.2 and DFU 1.1 §4.1; every size is static_assert'ed against its specification.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "vibid/fw/usb/usb_types.hpp"

namespace vibid::fw::usb {

/// pid.codes (open-source VID 0x1209); PID 0x0001 is its test product id, used until the board
/// gets its own allocation. The host's device filter reads these two constants.
inline constexpr std::uint16_t kVendorId = 0x1209;
inline constexpr std::uint16_t kProductId = 0x0001;
/// bcdDevice: hardware/firmware release in BCD.
inline constexpr std::uint16_t kDeviceRelease = 0x0010;

inline constexpr std::uint8_t kHidInterface = 0;
inline constexpr std::uint8_t kDfuInterface = 1;
inline constexpr std::uint8_t kInterfaceCount = 2;
inline constexpr std::uint8_t kHidInEndpoint = 0x81;
inline constexpr std::uint8_t kHidOutEndpoint = 0x01;
/// Every HID report is exactly this long, both directions, no report id byte.
inline constexpr std::uint16_t kHidReportSize = 64;
/// bInterval 1: at full speed one poll per 1 ms frame.
inline constexpr std::uint8_t kHidPollIntervalFrames = 1;
inline constexpr std::uint8_t kConfigurationValue = 1;

/// String descriptor indices (0 is the language table).
enum StringIndex : std::uint8_t {
  kStringLanguages = 0,
  kStringManufacturer = 1,
  kStringProduct = 2,
  kStringSerial = 3,
  kStringDfu = 4,
  kStringCount = 5,
};
inline constexpr const char* kManufacturerName = "vibid";
inline constexpr const char* kProductName = "vibid DAQ";
inline constexpr const char* kDfuInterfaceName = "vibid DFU run-time";

constexpr std::uint8_t Lo(std::uint16_t v) { return static_cast<std::uint8_t>(v & 0xFF); }
constexpr std::uint8_t Hi(std::uint16_t v) { return static_cast<std::uint8_t>(v >> 8); }

// Vendor-defined report descriptor (HID 1.11 §6.2.2 items, short form): one application
// collection with a 64-byte input report and a 64-byte output report, no report ids.
inline constexpr std::array<std::uint8_t, 25> kHidReportDescriptor = {
    0x06, 0x00, 0xFF,  // Usage Page (Vendor Defined 0xFF00)
    0x09, 0x01,        // Usage (0x01)
    0xA1, 0x01,        // Collection (Application)
    0x15, 0x00,        //   Logical Minimum (0)
    0x26, 0xFF, 0x00,  //   Logical Maximum (255)
    0x75, 0x08,        //   Report Size (8 bits)
    0x95, 0x40,        //   Report Count (64)
    0x09, 0x02,        //   Usage (0x02)
    0x81, 0x02,        //   Input (Data, Variable, Absolute)
    0x09, 0x03,        //   Usage (0x03)
    0x91, 0x02,        //   Output (Data, Variable, Absolute)
    0xC0,              // End Collection
};

inline constexpr std::size_t kDeviceDescriptorSize = 18;    // USB 2.0 table 9-8
inline constexpr std::size_t kConfigurationHeaderSize = 9;  // USB 2.0 table 9-10
inline constexpr std::size_t kInterfaceDescriptorSize = 9;  // USB 2.0 table 9-12
inline constexpr std::size_t kEndpointDescriptorSize = 7;   // USB 2.0 table 9-13
inline constexpr std::size_t kHidDescriptorSize = 9;  // HID 1.11 §6.2.1, one class descriptor
inline constexpr std::size_t kDfuFunctionalDescriptorSize = 9;  // DFU 1.1 table 4.2

inline constexpr std::array<std::uint8_t, kDeviceDescriptorSize> kDeviceDescriptor = {
    18,  // bLength
    static_cast<std::uint8_t>(DescriptorType::kDevice),
    0x00,
    0x02,      // bcdUSB 2.00
    0x00,      // bDeviceClass: per interface
    0x00,      // bDeviceSubClass
    0x00,      // bDeviceProtocol
    kEp0Size,  // bMaxPacketSize0
    Lo(kVendorId),
    Hi(kVendorId),  // idVendor
    Lo(kProductId),
    Hi(kProductId),  // idProduct
    Lo(kDeviceRelease),
    Hi(kDeviceRelease),   // bcdDevice
    kStringManufacturer,  // iManufacturer
    kStringProduct,       // iProduct
    kStringSerial,        // iSerialNumber
    1,                    // bNumConfigurations
};

inline constexpr std::size_t kConfigurationTotalSize =
    kConfigurationHeaderSize + kInterfaceDescriptorSize + kHidDescriptorSize +
    2 * kEndpointDescriptorSize + kInterfaceDescriptorSize + kDfuFunctionalDescriptorSize;
static_assert(kConfigurationTotalSize == 59,
              "config + HID if + HID + 2 EP + DFU if + DFU functional");

/// DFU run-time functional descriptor attributes (DFU 1.1 table 4.2): bitWillDetach (bit 3),
/// the device leaves for the bootloader by itself after DFU_DETACH; download and upload
/// (bits 0, 1) are what the ROM bootloader offers once it runs.
inline constexpr std::uint8_t kDfuAttributes = 0x0B;
inline constexpr std::uint16_t kDfuDetachTimeoutMs = 1000;
inline constexpr std::uint16_t kDfuTransferSize = 2048;

// The HID class descriptor: part of the configuration set, and returned alone by GET_DESCRIPTOR
// to the interface (HID 1.11 §7.1.1).
inline constexpr std::array<std::uint8_t, kHidDescriptorSize> kHidDescriptor = {
    9,  // bLength
    static_cast<std::uint8_t>(DescriptorType::kHid),
    0x11,
    0x01,  // bcdHID 1.11
    0x00,  // bCountryCode: not localized
    1,     // bNumDescriptors
    static_cast<std::uint8_t>(DescriptorType::kHidReport),
    Lo(kHidReportDescriptor.size()),
    Hi(kHidReportDescriptor.size()),  // wDescriptorLength
};

/// Joins descriptors into one configuration descriptor set at compile time.
template <std::size_t... N>
constexpr std::array<std::uint8_t, (N + ...)> Concat(const std::array<std::uint8_t, N>&... parts) {
  std::array<std::uint8_t, (N + ...)> out{};
  std::size_t at = 0;
  ((std::copy(parts.begin(), parts.end(), out.begin() + static_cast<std::ptrdiff_t>(at)), at += N),
   ...);
  return out;
}

inline constexpr std::array<std::uint8_t, kConfigurationHeaderSize> kConfigurationHeader = {
    9,
    static_cast<std::uint8_t>(DescriptorType::kConfiguration),
    Lo(kConfigurationTotalSize),
    Hi(kConfigurationTotalSize),  // wTotalLength
    kInterfaceCount,              // bNumInterfaces
    kConfigurationValue,          // bConfigurationValue
    0,                            // iConfiguration
    0x80,                         // bmAttributes: bus powered, no remote wakeup
    125,                          // bMaxPower: 250 mA in 2 mA units (sensors are bus powered)
};

// Interface 0: HID, no boot subclass.
inline constexpr std::array<std::uint8_t, kInterfaceDescriptorSize> kHidInterfaceDescriptor = {
    9,
    static_cast<std::uint8_t>(DescriptorType::kInterface),
    kHidInterface,
    0,  // bInterfaceNumber, bAlternateSetting
    2,  // bNumEndpoints
    0x03,
    0x00,
    0x00,  // bInterfaceClass HID, no subclass, no protocol
    0,     // iInterface
};

constexpr std::array<std::uint8_t, kEndpointDescriptorSize> InterruptEndpoint(
    std::uint8_t address) {
  return {7,
          static_cast<std::uint8_t>(DescriptorType::kEndpoint),
          address,
          0x03,
          Lo(kHidReportSize),
          Hi(kHidReportSize),
          kHidPollIntervalFrames};
}

// Interface 1: DFU run-time (application specific class, DFU subclass, run-time protocol).
inline constexpr std::array<std::uint8_t, kInterfaceDescriptorSize> kDfuInterfaceDescriptor = {
    9,
    static_cast<std::uint8_t>(DescriptorType::kInterface),
    kDfuInterface,
    0,
    0,  // bInterfaceNumber, bAlternateSetting, bNumEndpoints
    0xFE,
    0x01,
    0x01,        // bInterfaceClass, bInterfaceSubClass, bInterfaceProtocol
    kStringDfu,  // iInterface
};

inline constexpr std::array<std::uint8_t, kDfuFunctionalDescriptorSize> kDfuFunctionalDescriptor = {
    9,
    static_cast<std::uint8_t>(DescriptorType::kDfuFunctional),
    kDfuAttributes,
    Lo(kDfuDetachTimeoutMs),
    Hi(kDfuDetachTimeoutMs),
    Lo(kDfuTransferSize),
    Hi(kDfuTransferSize),
    0x10,
    0x01,  // bcdDFUVersion 1.1
};

inline constexpr auto kConfigurationDescriptor =
    Concat(kConfigurationHeader, kHidInterfaceDescriptor, kHidDescriptor,
           InterruptEndpoint(kHidInEndpoint), InterruptEndpoint(kHidOutEndpoint),
           kDfuInterfaceDescriptor, kDfuFunctionalDescriptor);
static_assert(kConfigurationDescriptor.size() == kConfigurationTotalSize);

/// Longest string descriptor the stack builds: 2 header bytes + 31 UTF-16 code units.
inline constexpr std::size_t kMaxStringDescriptorSize = 64;
/// Longest serial number (board id) accepted; longer ids are truncated.
inline constexpr std::size_t kMaxSerialLength = (kMaxStringDescriptorSize - 2) / 2;

/// What a device personality shows the host: its device and configuration descriptors and its
/// strings (index i >= 1 answers strings[i - 1]; index 0, the language table, is the stack's).
/// The board image runs DaqDescriptors; another personality (a DFU bootloader in the emulator)
/// brings its own set and class drivers to the same stack.
struct DescriptorSet {
  std::span<const std::uint8_t> device;
  std::span<const std::uint8_t> configuration;
  std::span<const char* const> strings;
};

/// The DAQ board's strings, in StringIndex order from kStringManufacturer; `serial` (the board
/// id, ASCII) must outlive the set.
struct DaqStrings {
  std::array<const char*, kStringCount - 1> text;
};
constexpr DaqStrings MakeDaqStrings(const char* serial) {
  return DaqStrings{{kManufacturerName, kProductName, serial, kDfuInterfaceName}};
}
/// The DAQ board's descriptor set over `strings` (which must outlive it).
constexpr DescriptorSet DaqDescriptors(const DaqStrings& strings) {
  return DescriptorSet{kDeviceDescriptor, kConfigurationDescriptor, strings.text};
}

/// Builds string descriptor `text` (ASCII) as UTF-16LE into `out`.
/// @returns the descriptor length written (bLength), at most kMaxStringDescriptorSize.
std::size_t BuildStringDescriptor(const char* text, std::size_t text_length,
                                  std::span<std::uint8_t, kMaxStringDescriptorSize> out);

}  // namespace vibid::fw::usb
