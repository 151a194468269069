// The USB/IP wire format (Linux Documentation/usb/usbip_protocol.rst, protocol v1.1.1).
//
// Two phases share one TCP connection. The operation phase (OP_REQ/REP_DEVLIST, OP_REQ/REP_IMPORT)
// lists and imports devices; after a successful import the same connection carries URB traffic
// (USBIP_CMD_SUBMIT/RET_SUBMIT, USBIP_CMD_UNLINK/RET_UNLINK). Every integer is big-endian
// (network order); the USB setup packet inside CMD_SUBMIT keeps its own little-endian layout.
//
// The codecs are pure: they write into or read from byte spans and validate lengths and codes.
// A malformed message is a ProtocolError naming the field.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace vibid::usbip {

/// Malformed or unexpected bytes from the peer.
class ProtocolError : public std::runtime_error {
 public:
  explicit ProtocolError(const std::string& message) : std::runtime_error(message) {}
};

inline constexpr std::uint16_t kVersion = 0x0111;
inline constexpr std::uint16_t kDefaultPort = 3240;

enum class OpCode : std::uint16_t {
  kReqDevlist = 0x8005,
  kRepDevlist = 0x0005,
  kReqImport = 0x8003,
  kRepImport = 0x0003,
};

enum class UrbCommand : std::uint32_t {
  kCmdSubmit = 1,
  kCmdUnlink = 2,
  kRetSubmit = 3,
  kRetUnlink = 4,
};

enum class Direction : std::uint32_t { kOut = 0, kIn = 1 };

/// Linux `enum usb_device_speed` values carried in the device record.
enum class Speed : std::uint32_t {
  kUnknown = 0,
  kLow = 1,
  kFull = 2,
  kHigh = 3,
  kWireless = 4,
  kSuper = 5
};

// Sizes and offsets (usbip_protocol.rst "Message Format").
inline constexpr std::size_t kOpHeaderBytes = 8;  ///< version, code, status
inline constexpr std::size_t kPathBytes = 256;
inline constexpr std::size_t kBusIdBytes = 32;
inline constexpr std::size_t kUsbDeviceBytes = 312;   ///< struct usbip_usb_device
inline constexpr std::size_t kUsbInterfaceBytes = 4;  ///< struct usbip_usb_interface
inline constexpr std::size_t kReqImportBytes = kOpHeaderBytes + kBusIdBytes;
inline constexpr std::size_t kRepImportBytes = kOpHeaderBytes + kUsbDeviceBytes;
inline constexpr std::size_t kUrbHeaderBytes = 48;  ///< every CMD_/RET_ header, padded
static_assert(kPathBytes + kBusIdBytes + 3 * 4 + 3 * 2 + 6 == kUsbDeviceBytes);
static_assert(kReqImportBytes == 40 && kRepImportBytes == 320);

/// number_of_packets of a non-isochronous URB.
inline constexpr std::uint32_t kNotIsochronous = 0xFFFFFFFFu;

/// URB status values (negated Linux errno, as the kernel's stub driver sends them).
inline constexpr std::int32_t kStatusOk = 0;
inline constexpr std::int32_t kStatusStall = -32;  ///< -EPIPE: endpoint stalled / request refused
inline constexpr std::int32_t kStatusUnlinked =
    -104;  ///< -ECONNRESET: RET_UNLINK of a cancelled URB
inline constexpr std::int32_t kStatusShutdown = -108;  ///< -ESHUTDOWN: device went away
inline constexpr std::int32_t kStatusNoDevice = -19;   ///< -ENODEV

/// Status of OP_REP_IMPORT: 0 OK, 1 error (usbip_protocol.rst).
inline constexpr std::uint32_t kOpStatusOk = 0;
inline constexpr std::uint32_t kOpStatusError = 1;

struct OpHeader {
  std::uint16_t version = kVersion;
  OpCode code = OpCode::kReqDevlist;
  std::uint32_t status = 0;
};

struct UsbInterface {
  std::uint8_t interface_class = 0;
  std::uint8_t interface_subclass = 0;
  std::uint8_t interface_protocol = 0;
};

/// struct usbip_usb_device, plus the interface list OP_REP_DEVLIST appends to it.
struct UsbDevice {
  std::string path;   ///< at most 255 characters
  std::string busid;  ///< at most 31 characters, e.g. "1-1"
  std::uint32_t busnum = 0;
  std::uint32_t devnum = 0;
  Speed speed = Speed::kFull;
  std::uint16_t id_vendor = 0;
  std::uint16_t id_product = 0;
  std::uint16_t bcd_device = 0;
  std::uint8_t device_class = 0;
  std::uint8_t device_subclass = 0;
  std::uint8_t device_protocol = 0;
  std::uint8_t configuration_value = 0;
  std::uint8_t num_configurations = 0;
  std::uint8_t num_interfaces = 0;
  std::vector<UsbInterface> interfaces;  ///< OP_REP_DEVLIST only; num_interfaces entries

  /// (busnum << 16) | devnum: the devid a client puts in its URB headers.
  std::uint32_t devid() const { return (busnum << 16) | (devnum & 0xFFFFu); }
};

/// The 20-byte usbip_header_basic.
struct UrbBasic {
  UrbCommand command = UrbCommand::kCmdSubmit;
  std::uint32_t seqnum = 0;
  std::uint32_t devid = 0;                ///< client: (busnum << 16) | devnum; server: 0
  Direction direction = Direction::kOut;  ///< server: 0
  std::uint32_t ep = 0;                   ///< endpoint number without the direction bit; server: 0
};

struct CmdSubmit {
  UrbBasic basic;
  std::uint32_t transfer_flags = 0;
  std::uint32_t transfer_buffer_length = 0;
  std::uint32_t start_frame = 0;
  std::uint32_t number_of_packets = kNotIsochronous;
  std::uint32_t interval = 0;
  std::array<std::uint8_t, 8> setup{};  ///< the USB SETUP packet for control URBs, else zero
};

struct RetSubmit {
  UrbBasic basic{UrbCommand::kRetSubmit};
  std::int32_t status = kStatusOk;
  std::uint32_t actual_length = 0;
  std::uint32_t start_frame = 0;
  std::uint32_t number_of_packets = kNotIsochronous;
  std::uint32_t error_count = 0;
};

struct CmdUnlink {
  UrbBasic basic{UrbCommand::kCmdUnlink};
  std::uint32_t unlink_seqnum = 0;
};

struct RetUnlink {
  UrbBasic basic{UrbCommand::kRetUnlink};
  std::int32_t status = kStatusOk;
};

/// Any of the four 48-byte URB headers; `basic.command` says which fields are meaningful.
struct UrbHeader {
  UrbBasic basic;
  CmdSubmit cmd_submit;  ///< valid when basic.command == kCmdSubmit
  RetSubmit ret_submit;  ///< valid when kRetSubmit
  CmdUnlink cmd_unlink;  ///< valid when kCmdUnlink
  RetUnlink ret_unlink;  ///< valid when kRetUnlink
};

// ---- Operation phase -----------------------------------------------------------------------

void EncodeOpHeader(const OpHeader& h, std::span<std::uint8_t, kOpHeaderBytes> out);
/// @throws ProtocolError if the version is not kVersion or the code is unknown.
OpHeader DecodeOpHeader(std::span<const std::uint8_t, kOpHeaderBytes> in);

/// Writes the 312-byte usbip_usb_device record (interfaces not included).
/// @throws ProtocolError if path or busid does not fit with its terminating zero.
void EncodeUsbDevice(const UsbDevice& d, std::span<std::uint8_t, kUsbDeviceBytes> out);
/// Reads a 312-byte record; `interfaces` stays empty.
/// @throws ProtocolError if path or busid is not zero-terminated or speed is unknown.
UsbDevice DecodeUsbDevice(std::span<const std::uint8_t, kUsbDeviceBytes> in);

void EncodeUsbInterface(const UsbInterface& i, std::span<std::uint8_t, kUsbInterfaceBytes> out);
UsbInterface DecodeUsbInterface(std::span<const std::uint8_t, kUsbInterfaceBytes> in);

/// OP_REQ_DEVLIST (8 bytes).
std::vector<std::uint8_t> EncodeReqDevlist();
/// OP_REP_DEVLIST: header, device count, each device followed by its interfaces.
/// @throws ProtocolError if a device's interfaces.size() != num_interfaces.
std::vector<std::uint8_t> EncodeRepDevlist(const std::vector<UsbDevice>& devices);
/// Decodes a complete OP_REP_DEVLIST.
/// @throws ProtocolError on a wrong code, nonzero status, or a length that does not match.
std::vector<UsbDevice> DecodeRepDevlist(std::span<const std::uint8_t> in);

/// OP_REQ_IMPORT (40 bytes). @throws ProtocolError if busid is longer than 31 characters.
std::vector<std::uint8_t> EncodeReqImport(const std::string& busid);
/// The busid of an OP_REQ_IMPORT's 32-byte field. @throws ProtocolError if not zero-terminated.
std::string DecodeBusId(std::span<const std::uint8_t, kBusIdBytes> in);
/// OP_REP_IMPORT: 8 bytes when `device` is null (status kOpStatusError), else 320 bytes.
std::vector<std::uint8_t> EncodeRepImport(const UsbDevice* device);

// ---- URB phase -----------------------------------------------------------------------------

void Encode(const CmdSubmit& v, std::span<std::uint8_t, kUrbHeaderBytes> out);
void Encode(const RetSubmit& v, std::span<std::uint8_t, kUrbHeaderBytes> out);
void Encode(const CmdUnlink& v, std::span<std::uint8_t, kUrbHeaderBytes> out);
void Encode(const RetUnlink& v, std::span<std::uint8_t, kUrbHeaderBytes> out);

/// Decodes any of the four URB headers.
/// @throws ProtocolError on an unknown command or a direction other than 0/1.
UrbHeader DecodeUrbHeader(std::span<const std::uint8_t, kUrbHeaderBytes> in);

/// Bytes that follow a CMD_SUBMIT header on the wire (the OUT data; IN carries none).
/// @throws ProtocolError for isochronous URBs (this implementation carries none).
std::size_t SubmitPayloadBytes(const CmdSubmit& v);

}  // namespace vibid::usbip
