#include "vibid/usbip/protocol.hpp"

#include <algorithm>
#include <cstdio>

namespace vibid::usbip {
namespace {

void Put16(std::uint8_t* p, std::uint16_t v) {
  p[0] = static_cast<std::uint8_t>(v >> 8);
  p[1] = static_cast<std::uint8_t>(v);
}
void Put32(std::uint8_t* p, std::uint32_t v) {
  p[0] = static_cast<std::uint8_t>(v >> 24);
  p[1] = static_cast<std::uint8_t>(v >> 16);
  p[2] = static_cast<std::uint8_t>(v >> 8);
  p[3] = static_cast<std::uint8_t>(v);
}
std::uint16_t Get16(const std::uint8_t* p) {
  return static_cast<std::uint16_t>((p[0] << 8) | p[1]);
}
std::uint32_t Get32(const std::uint8_t* p) {
  return (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) |
         std::uint32_t{p[3]};
}
std::int32_t GetS32(const std::uint8_t* p) { return static_cast<std::int32_t>(Get32(p)); }

void PutString(std::uint8_t* p, std::size_t field_bytes, const std::string& s, const char* what) {
  if (s.size() >= field_bytes) {
    throw ProtocolError(std::string(what) + " longer than " + std::to_string(field_bytes - 1) +
                        " characters");
  }
  std::fill(p, p + field_bytes, std::uint8_t{0});
  std::copy(s.begin(), s.end(), p);
}
std::string GetString(const std::uint8_t* p, std::size_t field_bytes, const char* what) {
  const auto* end = std::find(p, p + field_bytes, std::uint8_t{0});
  if (end == p + field_bytes) throw ProtocolError(std::string(what) + " is not zero-terminated");
  return std::string(p, end);
}

// Offsets inside usbip_usb_device (usbip_protocol.rst, OP_REP_IMPORT table minus its 8-byte
// header).
constexpr std::size_t kOffBusId = 0x100;
constexpr std::size_t kOffBusnum = 0x120;
constexpr std::size_t kOffDevnum = 0x124;
constexpr std::size_t kOffSpeed = 0x128;
constexpr std::size_t kOffIdVendor = 0x12C;
constexpr std::size_t kOffIdProduct = 0x12E;
constexpr std::size_t kOffBcdDevice = 0x130;
constexpr std::size_t kOffDeviceClass = 0x132;
static_assert(kOffDeviceClass + 6 == kUsbDeviceBytes);

void PutBasic(const UrbBasic& b, std::uint8_t* p) {
  Put32(p + 0, static_cast<std::uint32_t>(b.command));
  Put32(p + 4, b.seqnum);
  Put32(p + 8, b.devid);
  Put32(p + 12, static_cast<std::uint32_t>(b.direction));
  Put32(p + 16, b.ep);
}

}  // namespace

void EncodeOpHeader(const OpHeader& h, std::span<std::uint8_t, kOpHeaderBytes> out) {
  Put16(out.data(), h.version);
  Put16(out.data() + 2, static_cast<std::uint16_t>(h.code));
  Put32(out.data() + 4, h.status);
}

OpHeader DecodeOpHeader(std::span<const std::uint8_t, kOpHeaderBytes> in) {
  OpHeader h;
  h.version = Get16(in.data());
  if (h.version != kVersion) {
    char text[8];
    std::snprintf(text, sizeof text, "0x%04x", static_cast<unsigned>(h.version));
    throw ProtocolError(std::string("USB/IP version ") + text +
                        " is not the supported 0x0111 (v1.1.1)");
  }
  const std::uint16_t code = Get16(in.data() + 2);
  switch (static_cast<OpCode>(code)) {
    case OpCode::kReqDevlist:
    case OpCode::kRepDevlist:
    case OpCode::kReqImport:
    case OpCode::kRepImport: break;
    default: throw ProtocolError("unknown USB/IP operation code " + std::to_string(code));
  }
  h.code = static_cast<OpCode>(code);
  h.status = Get32(in.data() + 4);
  return h;
}

void EncodeUsbDevice(const UsbDevice& d, std::span<std::uint8_t, kUsbDeviceBytes> out) {
  std::uint8_t* p = out.data();
  PutString(p, kPathBytes, d.path, "device path");
  PutString(p + kOffBusId, kBusIdBytes, d.busid, "bus id");
  Put32(p + kOffBusnum, d.busnum);
  Put32(p + kOffDevnum, d.devnum);
  Put32(p + kOffSpeed, static_cast<std::uint32_t>(d.speed));
  Put16(p + kOffIdVendor, d.id_vendor);
  Put16(p + kOffIdProduct, d.id_product);
  Put16(p + kOffBcdDevice, d.bcd_device);
  p[kOffDeviceClass + 0] = d.device_class;
  p[kOffDeviceClass + 1] = d.device_subclass;
  p[kOffDeviceClass + 2] = d.device_protocol;
  p[kOffDeviceClass + 3] = d.configuration_value;
  p[kOffDeviceClass + 4] = d.num_configurations;
  p[kOffDeviceClass + 5] = d.num_interfaces;
}

UsbDevice DecodeUsbDevice(std::span<const std::uint8_t, kUsbDeviceBytes> in) {
  const std::uint8_t* p = in.data();
  UsbDevice d;
  d.path = GetString(p, kPathBytes, "device path");
  d.busid = GetString(p + kOffBusId, kBusIdBytes, "bus id");
  d.busnum = Get32(p + kOffBusnum);
  d.devnum = Get32(p + kOffDevnum);
  const std::uint32_t speed = Get32(p + kOffSpeed);
  if (speed > static_cast<std::uint32_t>(Speed::kSuper)) {
    throw ProtocolError("unknown device speed " + std::to_string(speed));
  }
  d.speed = static_cast<Speed>(speed);
  d.id_vendor = Get16(p + kOffIdVendor);
  d.id_product = Get16(p + kOffIdProduct);
  d.bcd_device = Get16(p + kOffBcdDevice);
  d.device_class = p[kOffDeviceClass + 0];
  d.device_subclass = p[kOffDeviceClass + 1];
  d.device_protocol = p[kOffDeviceClass + 2];
  d.configuration_value = p[kOffDeviceClass + 3];
  d.num_configurations = p[kOffDeviceClass + 4];
  d.num_interfaces = p[kOffDeviceClass + 5];
  return d;
}

void EncodeUsbInterface(const UsbInterface& i, std::span<std::uint8_t, kUsbInterfaceBytes> out) {
  out[0] = i.interface_class;
  out[1] = i.interface_subclass;
  out[2] = i.interface_protocol;
  out[3] = 0;
}

UsbInterface DecodeUsbInterface(std::span<const std::uint8_t, kUsbInterfaceBytes> in) {
  return UsbInterface{in[0], in[1], in[2]};
}

std::vector<std::uint8_t> EncodeReqDevlist() {
  std::vector<std::uint8_t> out(kOpHeaderBytes);
  EncodeOpHeader({kVersion, OpCode::kReqDevlist, 0}, std::span<std::uint8_t, kOpHeaderBytes>(out));
  return out;
}

std::vector<std::uint8_t> EncodeRepDevlist(const std::vector<UsbDevice>& devices) {
  std::size_t bytes = kOpHeaderBytes + 4;
  for (const UsbDevice& d : devices) {
    if (d.interfaces.size() != d.num_interfaces) {
      throw ProtocolError("device " + d.busid + " lists " + std::to_string(d.interfaces.size()) +
                          " interfaces but bNumInterfaces is " + std::to_string(d.num_interfaces));
    }
    bytes += kUsbDeviceBytes + kUsbInterfaceBytes * d.interfaces.size();
  }
  std::vector<std::uint8_t> out(bytes);
  EncodeOpHeader({kVersion, OpCode::kRepDevlist, kOpStatusOk},
                 std::span<std::uint8_t, kOpHeaderBytes>(out.data(), kOpHeaderBytes));
  Put32(out.data() + kOpHeaderBytes, static_cast<std::uint32_t>(devices.size()));
  std::size_t at = kOpHeaderBytes + 4;
  for (const UsbDevice& d : devices) {
    EncodeUsbDevice(d, std::span<std::uint8_t, kUsbDeviceBytes>(out.data() + at, kUsbDeviceBytes));
    at += kUsbDeviceBytes;
    for (const UsbInterface& i : d.interfaces) {
      EncodeUsbInterface(
          i, std::span<std::uint8_t, kUsbInterfaceBytes>(out.data() + at, kUsbInterfaceBytes));
      at += kUsbInterfaceBytes;
    }
  }
  return out;
}

std::vector<UsbDevice> DecodeRepDevlist(std::span<const std::uint8_t> in) {
  if (in.size() < kOpHeaderBytes + 4)
    throw ProtocolError("device list reply shorter than 12 bytes");
  const OpHeader h = DecodeOpHeader(in.first<kOpHeaderBytes>());
  if (h.code != OpCode::kRepDevlist)
    throw ProtocolError("expected a device list reply (OP_REP_DEVLIST)");
  if (h.status != kOpStatusOk)
    throw ProtocolError("device list refused, status " + std::to_string(h.status));
  const std::uint32_t count = Get32(in.data() + kOpHeaderBytes);
  std::vector<UsbDevice> devices;
  std::size_t at = kOpHeaderBytes + 4;
  for (std::uint32_t n = 0; n < count; ++n) {
    if (in.size() < at + kUsbDeviceBytes) throw ProtocolError("device list reply truncated");
    UsbDevice d = DecodeUsbDevice(
        std::span<const std::uint8_t, kUsbDeviceBytes>(in.data() + at, kUsbDeviceBytes));
    at += kUsbDeviceBytes;
    if (in.size() < at + kUsbInterfaceBytes * d.num_interfaces)
      throw ProtocolError("device list reply truncated");
    for (std::uint8_t i = 0; i < d.num_interfaces; ++i) {
      d.interfaces.push_back(DecodeUsbInterface(
          std::span<const std::uint8_t, kUsbInterfaceBytes>(in.data() + at, kUsbInterfaceBytes)));
      at += kUsbInterfaceBytes;
    }
    devices.push_back(std::move(d));
  }
  if (at != in.size())
    throw ProtocolError("device list reply has " + std::to_string(in.size() - at) + " extra bytes");
  return devices;
}

std::vector<std::uint8_t> EncodeReqImport(const std::string& busid) {
  std::vector<std::uint8_t> out(kReqImportBytes);
  EncodeOpHeader({kVersion, OpCode::kReqImport, 0},
                 std::span<std::uint8_t, kOpHeaderBytes>(out.data(), kOpHeaderBytes));
  PutString(out.data() + kOpHeaderBytes, kBusIdBytes, busid, "bus id");
  return out;
}

std::string DecodeBusId(std::span<const std::uint8_t, kBusIdBytes> in) {
  return GetString(in.data(), kBusIdBytes, "bus id");
}

std::vector<std::uint8_t> EncodeRepImport(const UsbDevice* device) {
  std::vector<std::uint8_t> out(device != nullptr ? kRepImportBytes : kOpHeaderBytes);
  EncodeOpHeader({kVersion, OpCode::kRepImport, device != nullptr ? kOpStatusOk : kOpStatusError},
                 std::span<std::uint8_t, kOpHeaderBytes>(out.data(), kOpHeaderBytes));
  if (device != nullptr) {
    EncodeUsbDevice(*device, std::span<std::uint8_t, kUsbDeviceBytes>(out.data() + kOpHeaderBytes,
                                                                      kUsbDeviceBytes));
  }
  return out;
}

void Encode(const CmdSubmit& v, std::span<std::uint8_t, kUrbHeaderBytes> out) {
  std::uint8_t* p = out.data();
  UrbBasic b = v.basic;
  b.command = UrbCommand::kCmdSubmit;
  PutBasic(b, p);
  Put32(p + 0x14, v.transfer_flags);
  Put32(p + 0x18, v.transfer_buffer_length);
  Put32(p + 0x1C, v.start_frame);
  Put32(p + 0x20, v.number_of_packets);
  Put32(p + 0x24, v.interval);
  std::copy(v.setup.begin(), v.setup.end(), p + 0x28);
}

void Encode(const RetSubmit& v, std::span<std::uint8_t, kUrbHeaderBytes> out) {
  std::uint8_t* p = out.data();
  UrbBasic b = v.basic;
  b.command = UrbCommand::kRetSubmit;
  PutBasic(b, p);
  Put32(p + 0x14, static_cast<std::uint32_t>(v.status));
  Put32(p + 0x18, v.actual_length);
  Put32(p + 0x1C, v.start_frame);
  Put32(p + 0x20, v.number_of_packets);
  Put32(p + 0x24, v.error_count);
  std::fill(p + 0x28, p + kUrbHeaderBytes, std::uint8_t{0});
}

void Encode(const CmdUnlink& v, std::span<std::uint8_t, kUrbHeaderBytes> out) {
  std::uint8_t* p = out.data();
  UrbBasic b = v.basic;
  b.command = UrbCommand::kCmdUnlink;
  PutBasic(b, p);
  Put32(p + 0x14, v.unlink_seqnum);
  std::fill(p + 0x18, p + kUrbHeaderBytes, std::uint8_t{0});
}

void Encode(const RetUnlink& v, std::span<std::uint8_t, kUrbHeaderBytes> out) {
  std::uint8_t* p = out.data();
  UrbBasic b = v.basic;
  b.command = UrbCommand::kRetUnlink;
  PutBasic(b, p);
  Put32(p + 0x14, static_cast<std::uint32_t>(v.status));
  std::fill(p + 0x18, p + kUrbHeaderBytes, std::uint8_t{0});
}

UrbHeader DecodeUrbHeader(std::span<const std::uint8_t, kUrbHeaderBytes> in) {
  const std::uint8_t* p = in.data();
  UrbHeader h;
  const std::uint32_t command = Get32(p);
  if (command < 1 || command > 4)
    throw ProtocolError("unknown USB/IP URB command " + std::to_string(command));
  const std::uint32_t direction = Get32(p + 12);
  if (direction > 1)
    throw ProtocolError("URB direction " + std::to_string(direction) +
                        " is neither OUT (0) nor IN (1)");
  h.basic.command = static_cast<UrbCommand>(command);
  h.basic.seqnum = Get32(p + 4);
  h.basic.devid = Get32(p + 8);
  h.basic.direction = static_cast<Direction>(direction);
  h.basic.ep = Get32(p + 16);
  switch (h.basic.command) {
    case UrbCommand::kCmdSubmit:
      h.cmd_submit.basic = h.basic;
      h.cmd_submit.transfer_flags = Get32(p + 0x14);
      h.cmd_submit.transfer_buffer_length = Get32(p + 0x18);
      h.cmd_submit.start_frame = Get32(p + 0x1C);
      h.cmd_submit.number_of_packets = Get32(p + 0x20);
      h.cmd_submit.interval = Get32(p + 0x24);
      std::copy(p + 0x28, p + 0x30, h.cmd_submit.setup.begin());
      break;
    case UrbCommand::kRetSubmit:
      h.ret_submit.basic = h.basic;
      h.ret_submit.status = GetS32(p + 0x14);
      h.ret_submit.actual_length = Get32(p + 0x18);
      h.ret_submit.start_frame = Get32(p + 0x1C);
      h.ret_submit.number_of_packets = Get32(p + 0x20);
      h.ret_submit.error_count = Get32(p + 0x24);
      break;
    case UrbCommand::kCmdUnlink:
      h.cmd_unlink.basic = h.basic;
      h.cmd_unlink.unlink_seqnum = Get32(p + 0x14);
      break;
    case UrbCommand::kRetUnlink:
      h.ret_unlink.basic = h.basic;
      h.ret_unlink.status = GetS32(p + 0x14);
      break;
  }
  return h;
}

std::size_t SubmitPayloadBytes(const CmdSubmit& v) {
  // Non-isochronous URBs carry kNotIsochronous or (as captured from Linux for interrupt URBs) 0.
  if (v.number_of_packets != kNotIsochronous && v.number_of_packets != 0) {
    throw ProtocolError("isochronous URBs are not supported");
  }
  return v.basic.direction == Direction::kOut ? v.transfer_buffer_length : 0;
}

}  // namespace vibid::usbip
