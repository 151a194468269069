// USB/IP codec against the byte layouts of Linux Documentation/usb/usbip_protocol.rst.
#include "vibid/usbip/protocol.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace vibid::usbip {
namespace {

std::vector<std::uint8_t> Hex(const std::string& text) {
  std::vector<std::uint8_t> out;
  std::string digits;
  for (char c : text) {
    if (c != ' ') digits.push_back(c);
  }
  for (std::size_t i = 0; i + 1 < digits.size(); i += 2) {
    out.push_back(static_cast<std::uint8_t>(std::stoul(digits.substr(i, 2), nullptr, 16)));
  }
  return out;
}

std::span<const std::uint8_t, kUrbHeaderBytes> Header(const std::vector<std::uint8_t>& bytes) {
  return std::span<const std::uint8_t, kUrbHeaderBytes>(bytes.data(), kUrbHeaderBytes);
}

// The four HID URBs of usbip_protocol.rst's "EXAMPLE" section (captured from the wire by the
// kernel's authors), one 32-bit big-endian word per group.
const char* const kCmdIntrIn =
    "00000001 00000d05 0001000f 00000001 00000001 00000200 00000040 ffffffff 00000000 00000004 "
    "00000000 00000000";
const char* const kCmdIntrOut =
    "00000001 00000d06 0001000f 00000000 00000001 00000000 00000040 ffffffff 00000000 00000004 "
    "00000000 00000000";
const char* const kRetIntrOut =
    "00000003 00000d06 00000000 00000000 00000000 00000000 00000040 ffffffff 00000000 00000000 "
    "00000000 00000000";

TEST(UsbipUrb, DecodesTheDocumentedInterruptInSubmit) {
  const auto bytes = Hex(kCmdIntrIn);
  ASSERT_EQ(bytes.size(), kUrbHeaderBytes);
  const UrbHeader h = DecodeUrbHeader(Header(bytes));
  EXPECT_EQ(h.basic.command, UrbCommand::kCmdSubmit);
  EXPECT_EQ(h.cmd_submit.basic.seqnum, 0xd05u);
  EXPECT_EQ(h.cmd_submit.basic.devid, 0x0001000fu);  // busnum 1, devnum 15
  EXPECT_EQ(h.cmd_submit.basic.direction, Direction::kIn);
  EXPECT_EQ(h.cmd_submit.basic.ep, 1u);
  EXPECT_EQ(h.cmd_submit.transfer_flags, 0x200u);  // URB_DIR_IN in the capture
  EXPECT_EQ(h.cmd_submit.transfer_buffer_length, 64u);
  EXPECT_EQ(h.cmd_submit.start_frame, 0xffffffffu);
  EXPECT_EQ(h.cmd_submit.number_of_packets, 0u);
  EXPECT_EQ(h.cmd_submit.interval, 4u);
  EXPECT_EQ(SubmitPayloadBytes(h.cmd_submit), 0u);  // IN carries no data towards the device

  std::array<std::uint8_t, kUrbHeaderBytes> again{};
  Encode(h.cmd_submit, again);
  EXPECT_TRUE(std::equal(again.begin(), again.end(), bytes.begin()));
}

TEST(UsbipUrb, OutSubmitIsFollowedByItsData) {
  const auto bytes = Hex(kCmdIntrOut);
  const UrbHeader h = DecodeUrbHeader(Header(bytes));
  EXPECT_EQ(h.cmd_submit.basic.direction, Direction::kOut);
  EXPECT_EQ(h.cmd_submit.transfer_flags, 0u);
  EXPECT_EQ(SubmitPayloadBytes(h.cmd_submit), 64u);
}

TEST(UsbipUrb, EncodesTheDocumentedRetSubmit) {
  RetSubmit r;
  r.basic.seqnum = 0xd06;
  r.status = 0;
  r.actual_length = 64;
  r.start_frame = 0xffffffff;
  r.number_of_packets = 0;
  std::array<std::uint8_t, kUrbHeaderBytes> out{};
  Encode(r, out);
  const auto expected = Hex(kRetIntrOut);
  EXPECT_TRUE(std::equal(out.begin(), out.end(), expected.begin()));

  const UrbHeader h = DecodeUrbHeader(out);
  EXPECT_EQ(h.basic.command, UrbCommand::kRetSubmit);
  EXPECT_EQ(h.ret_submit.actual_length, 64u);
}

TEST(UsbipUrb, UnlinkLayoutAndNegativeStatus) {
  // usbip_protocol.rst: CMD_UNLINK = basic header (command 2), unlink_seqnum at 0x14, 24 bytes of
  // padding; RET_UNLINK = command 4, status at 0x14 (-ECONNRESET = -104 = 0xffffff98).
  CmdUnlink u;
  u.basic.seqnum = 7;
  u.basic.devid = 0x00010002;
  u.unlink_seqnum = 5;
  std::array<std::uint8_t, kUrbHeaderBytes> out{};
  Encode(u, out);
  const auto expected = Hex(
      "00000002 00000007 00010002 00000000 00000000 00000005 00000000 00000000 00000000 00000000 "
      "00000000 00000000");
  EXPECT_TRUE(std::equal(out.begin(), out.end(), expected.begin()));

  RetUnlink r;
  r.basic.seqnum = 7;
  r.status = kStatusUnlinked;
  Encode(r, out);
  const auto ret = Hex(
      "00000004 00000007 00000000 00000000 00000000 ffffff98 00000000 00000000 00000000 00000000 "
      "00000000 00000000");
  EXPECT_TRUE(std::equal(out.begin(), out.end(), ret.begin()));
  EXPECT_EQ(DecodeUrbHeader(out).ret_unlink.status, -104);
}

TEST(UsbipUrb, SetupPacketKeepsItsByteOrder) {
  CmdSubmit s;
  s.basic.seqnum = 1;
  s.basic.direction = Direction::kIn;
  s.transfer_buffer_length = 18;
  s.setup = {0x80, 0x06, 0x00, 0x01, 0x00, 0x00, 0x12, 0x00};  // GET_DESCRIPTOR(device), 18 bytes
  std::array<std::uint8_t, kUrbHeaderBytes> out{};
  Encode(s, out);
  EXPECT_EQ(out[0x28], 0x80);
  EXPECT_EQ(out[0x2B], 0x01);
  EXPECT_EQ(out[0x2E], 0x12);
  EXPECT_EQ(out[0x20], 0xff);  // number_of_packets defaults to "not isochronous"
}

TEST(UsbipUrb, RejectsGarbage) {
  auto bytes = Hex(kCmdIntrIn);
  bytes[3] = 9;
  EXPECT_THROW(DecodeUrbHeader(Header(bytes)), ProtocolError);
  bytes = Hex(kCmdIntrIn);
  bytes[15] = 2;  // direction
  EXPECT_THROW(DecodeUrbHeader(Header(bytes)), ProtocolError);
  CmdSubmit iso;
  iso.number_of_packets = 3;
  EXPECT_THROW(SubmitPayloadBytes(iso), ProtocolError);
}

UsbDevice ExampleDevice() {
  UsbDevice d;
  d.path = "/sys/devices/vibid/1-1";
  d.busid = "1-1";
  d.busnum = 1;
  d.devnum = 2;
  d.speed = Speed::kFull;
  d.id_vendor = 0x1209;
  d.id_product = 0x7a10;
  d.bcd_device = 0x0100;
  d.configuration_value = 1;
  d.num_configurations = 1;
  d.num_interfaces = 1;
  d.interfaces = {UsbInterface{0x03, 0x00, 0x00}};
  return d;
}

TEST(UsbipOp, DevlistRequestBytes) {
  // usbip_protocol.rst: version 0x0111, code 0x8005, status 0.
  EXPECT_EQ(EncodeReqDevlist(), Hex("0111 8005 00000000"));
}

TEST(UsbipOp, DevlistReplyOffsets) {
  const auto bytes = EncodeRepDevlist({ExampleDevice()});
  // 12-byte head + 312-byte device + one 4-byte interface (usbip_protocol.rst OP_REP_DEVLIST).
  ASSERT_EQ(bytes.size(), 12u + 312u + 4u);
  EXPECT_EQ(bytes[2], 0x00);
  EXPECT_EQ(bytes[3], 0x05);
  EXPECT_EQ(bytes[11], 1);  // one device
  EXPECT_EQ(bytes[0x0C], '/');
  EXPECT_EQ(bytes[0x10C], '1');  // busid
  EXPECT_EQ(bytes[0x10D], '-');
  EXPECT_EQ(bytes[0x12F], 1);     // busnum (big-endian at 0x12C)
  EXPECT_EQ(bytes[0x133], 2);     // devnum at 0x130
  EXPECT_EQ(bytes[0x137], 2);     // speed at 0x134: USB_SPEED_FULL
  EXPECT_EQ(bytes[0x138], 0x12);  // idVendor at 0x138
  EXPECT_EQ(bytes[0x139], 0x09);
  EXPECT_EQ(bytes[0x13A], 0x7a);  // idProduct
  EXPECT_EQ(bytes[0x13C], 0x01);  // bcdDevice
  EXPECT_EQ(bytes[0x141], 1);     // bConfigurationValue
  EXPECT_EQ(bytes[0x143], 1);     // bNumInterfaces
  EXPECT_EQ(bytes[0x144], 0x03);  // bInterfaceClass HID

  const auto back = DecodeRepDevlist(bytes);
  ASSERT_EQ(back.size(), 1u);
  EXPECT_EQ(back[0].busid, "1-1");
  EXPECT_EQ(back[0].path, "/sys/devices/vibid/1-1");
  EXPECT_EQ(back[0].id_product, 0x7a10);
  EXPECT_EQ(back[0].devid(), 0x00010002u);
  ASSERT_EQ(back[0].interfaces.size(), 1u);
  EXPECT_EQ(back[0].interfaces[0].interface_class, 0x03);

  auto truncated = bytes;
  truncated.pop_back();
  EXPECT_THROW(DecodeRepDevlist(truncated), ProtocolError);
}

TEST(UsbipOp, EmptyDevlist) {
  const auto bytes = EncodeRepDevlist({});
  EXPECT_EQ(bytes, Hex("0111 0005 00000000 00000000"));
  EXPECT_TRUE(DecodeRepDevlist(bytes).empty());
}

TEST(UsbipOp, ImportRequestAndReply) {
  const auto req = EncodeReqImport("1-1");
  ASSERT_EQ(req.size(), 40u);
  EXPECT_EQ(req[2], 0x80);
  EXPECT_EQ(req[3], 0x03);
  EXPECT_EQ(req[8], '1');
  EXPECT_EQ(req[10], '1');
  EXPECT_EQ(req[11], 0);
  EXPECT_EQ(DecodeBusId(std::span<const std::uint8_t, kBusIdBytes>(req.data() + 8, kBusIdBytes)),
            "1-1");

  const UsbDevice d = ExampleDevice();
  const auto rep = EncodeRepImport(&d);
  ASSERT_EQ(rep.size(), 320u);
  EXPECT_EQ(rep[0x108], '1');   // busid at 0x108 (usbip_protocol.rst OP_REP_IMPORT)
  EXPECT_EQ(rep[0x12B], 1);     // busnum at 0x128
  EXPECT_EQ(rep[0x134], 0x12);  // idVendor at 0x134
  EXPECT_EQ(rep[0x13F], 1);     // bNumInterfaces at 0x13F
  EXPECT_EQ(EncodeRepImport(nullptr), Hex("0111 0003 00000001"));

  EXPECT_THROW(EncodeReqImport(std::string(32, 'x')), ProtocolError);
}

TEST(UsbipOp, RejectsOtherVersionsAndCodes) {
  auto bytes = Hex("0110 8005 00000000");
  EXPECT_THROW(DecodeOpHeader(std::span<const std::uint8_t, kOpHeaderBytes>(bytes.data(), 8)),
               ProtocolError);
  bytes = Hex("0111 8004 00000000");
  EXPECT_THROW(DecodeOpHeader(std::span<const std::uint8_t, kOpHeaderBytes>(bytes.data(), 8)),
               ProtocolError);
  std::array<std::uint8_t, kUsbDeviceBytes> unterminated{};
  unterminated.fill('a');
  EXPECT_THROW(DecodeUsbDevice(unterminated), ProtocolError);
}

}  // namespace
}  // namespace vibid::usbip
