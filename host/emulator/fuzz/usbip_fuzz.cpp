// Fuzzes the emulator's USB/IP server (vibid-emu's network face) and the USB/IP codecs both
// sides share. The server runs as it does in the emulator, on a loopback socket, exporting the
// DfuSe bootloader (a device that completes every URB at once). The input is a script
// (FuzzedDataProvider) turned into what one client connection sends: an operation request
// (device list, import of "1-1" or another bus id), then URB messages (CMD_SUBMIT with a control
// setup and its OUT data, CMD_UNLINK), with a controlled share of damaged ones: a wrong version
// or code, an unknown command, an isochronous packet count, a length that claims more than
// follows, arbitrary bytes, a message cut short. The client half-closes and reads everything the
// server sends until it closes. Invariants:
//   - the server never blocks or dies on what a client sends; it closes the connection instead;
//   - its answers decode with the client's codecs: a device list, an import reply, then one
//     RET_SUBMIT per submitted URB (same sequence number, in order) and one RET_UNLINK per unlink,
//     each IN completion followed by exactly its data;
//   - the codecs round-trip: a header or device record that decodes encodes back to the same
//     fields.
#include <fuzzer/FuzzedDataProvider.h>
#include <sys/socket.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <vector>

#include "dfuse_bootloader.hpp"
#include "flash_image.hpp"
#include "usbip_server.hpp"
#include "vibid/device/usb_control.hpp"
#include "vibid/usbip/protocol.hpp"
#include "vibid/usbip/socket.hpp"

namespace {

using namespace vibid;
namespace ip = vibid::usbip;

void Require(bool condition) {
  if (!condition) __builtin_trap();
}

struct Expected {
  enum class Kind { kSubmit, kUnlink } kind;
  std::uint32_t seqnum;
  bool in;
  std::uint32_t length;
};

struct Message {
  std::vector<std::uint8_t> bytes;
  std::vector<Expected> expected;  // answers, when every message so far was well-formed
  bool device_list = false;
  bool import = false;
  bool well_formed = true;
};

// Control setups the bootloader knows (and a few it refuses), as a client sends them.
std::array<std::uint8_t, 8> Setup(FuzzedDataProvider& in, bool& to_host) {
  // bmRequestType, bRequest, wValue; wLength is picked below.
  constexpr std::array<device::Setup, 12> kSetups = {{{0x80, 0x06, 0x0100},
                                                      {0x80, 0x06, 0x0200},
                                                      {0x80, 0x06, 0x0302},
                                                      {0x00, 0x09, 1},
                                                      {0xA1, 0x03, 0},
                                                      {0xA1, 0x05, 0},
                                                      {0x21, 0x01, 0},
                                                      {0x21, 0x01, 2},
                                                      {0xA1, 0x02, 0},
                                                      {0xA1, 0x02, 2},
                                                      {0x21, 0x06, 0},
                                                      {0x21, 0x04, 0}}};
  device::Setup s = in.PickValueInArray(kSetups);
  s.length = in.PickValueInArray<std::uint16_t>({0, 1, 5, 6, 18, 64, 255, 2048});
  to_host = s.In();
  return s.Bytes();
}

Message Script(FuzzedDataProvider& in) {
  Message m;
  std::array<std::uint8_t, ip::kOpHeaderBytes> op{};
  switch (in.ConsumeIntegralInRange<int>(0, 5)) {
    case 0: {
      m.bytes = ip::EncodeReqDevlist();
      m.device_list = true;
      return m;
    }
    case 1: {
      const std::string busid = in.ConsumeRandomLengthString(40);
      try {
        m.bytes = ip::EncodeReqImport(busid);
      } catch (const ip::ProtocolError&) {
        Require(busid.size() > 31);
        m.bytes = ip::EncodeReqImport("1-1");
      }
      m.import = busid == "1-1";
      m.well_formed = m.import;
      break;
    }
    case 2:  // an operation with the version or code wrong
      ip::EncodeOpHeader({ip::kVersion, ip::OpCode::kReqImport, 0}, op);
      m.bytes.assign(op.begin(), op.end());
      m.bytes[in.ConsumeIntegralInRange<std::size_t>(0, 3)] ^=
          in.ConsumeIntegralInRange<std::uint8_t>(1, 255);
      m.well_formed = false;
      break;
    default:
      m.bytes = ip::EncodeReqImport("1-1");
      m.import = true;
      break;
  }
  if (!m.import) {
    const auto tail = in.ConsumeBytes<std::uint8_t>(in.ConsumeIntegralInRange<std::size_t>(0, 128));
    m.bytes.insert(m.bytes.end(), tail.begin(), tail.end());
    return m;
  }
  std::uint32_t seqnum = 0;
  for (int k = 0; k < 24 && in.remaining_bytes() > 0 && m.well_formed; ++k) {
    std::array<std::uint8_t, ip::kUrbHeaderBytes> h{};
    const int what = in.ConsumeIntegralInRange<int>(0, 9);
    if (what <= 5) {  // a control URB
      ip::CmdSubmit c;
      bool to_host = false;
      c.basic.seqnum = ++seqnum;
      c.basic.devid = (1u << 16) | 2u;
      c.setup = Setup(in, to_host);
      c.basic.direction = to_host ? ip::Direction::kIn : ip::Direction::kOut;
      c.basic.ep = in.ConsumeIntegralInRange<int>(0, 7) == 0 ? 1 : 0;
      c.transfer_buffer_length = static_cast<std::uint32_t>(c.setup[6] | (c.setup[7] << 8));
      if (in.ConsumeIntegralInRange<int>(0, 7) == 0) c.number_of_packets = 0;
      ip::Encode(c, h);
      m.bytes.insert(m.bytes.end(), h.begin(), h.end());
      if (!to_host) {
        auto data = in.ConsumeBytes<std::uint8_t>(c.transfer_buffer_length);
        data.resize(c.transfer_buffer_length);
        if (c.transfer_buffer_length >= 1 && c.setup[1] == 0x01 && c.setup[2] == 0)
          data[0] = 0x41;  // a DfuSe erase
        m.bytes.insert(m.bytes.end(), data.begin(), data.end());
      }
      m.expected.push_back(
          {Expected::Kind::kSubmit, c.basic.seqnum, to_host, c.transfer_buffer_length});
    } else if (what == 6) {
      ip::CmdUnlink u;
      u.basic.seqnum = ++seqnum;
      u.unlink_seqnum = in.ConsumeIntegralInRange<std::uint32_t>(0, seqnum);
      ip::Encode(u, h);
      m.bytes.insert(m.bytes.end(), h.begin(), h.end());
      m.expected.push_back({Expected::Kind::kUnlink, u.basic.seqnum, false, 0});
    } else {  // damaged: the server must drop the connection, or answer it as what it decodes to
      ip::CmdSubmit c;
      c.basic.seqnum = ++seqnum;
      c.basic.direction = ip::Direction::kIn;
      ip::Encode(c, h);
      switch (what) {
        case 7:
          h[in.ConsumeIntegralInRange<std::size_t>(0, 11)] ^=
              in.ConsumeIntegralInRange<std::uint8_t>(1, 255);
          break;
        case 8:  // isochronous, or an OUT length longer than what follows
          if (in.ConsumeBool()) {
            h[35] = 7;
          } else {
            h[15] = 0;     // direction OUT
            h[25] = 0x10;  // transfer_buffer_length 0x100000
          }
          break;
        default: {
          const auto bytes = in.ConsumeBytes<std::uint8_t>(h.size());
          std::copy(bytes.begin(), bytes.end(), h.begin());
          break;
        }
      }
      m.bytes.insert(m.bytes.end(), h.begin(), h.end());
      m.well_formed = false;
    }
  }
  // Now and then the last message is cut short.
  if (in.ConsumeIntegralInRange<int>(0, 7) == 7 && !m.bytes.empty()) {
    m.bytes.resize(in.ConsumeIntegralInRange<std::size_t>(0, m.bytes.size() - 1));
    m.well_formed = false;
    if (m.bytes.size() < ip::kReqImportBytes) m.import = false;
  }
  return m;
}

struct Server {
  Server() : server("127.0.0.1", 0) {}
  emu::FlashImage flash{""};
  emu::UsbIpServer server;
};

Server& TheServer() {
  static Server s;
  return s;
}

// Reads what the server sends until it closes, polling it in between (one thread: the server
// must never wait for the client).
std::vector<std::uint8_t> Exchange(const std::vector<std::uint8_t>& request) {
  Server& s = TheServer();
  ip::UsbDevice record;
  record.busid = emu::UsbIpServer::kBusId;
  record.busnum = 1;
  record.devnum = 2;
  for (int sector = 0; sector < emu::FlashImage::kSectorCount; ++sector)
    (void)s.flash.EraseSector(sector);
  emu::DfuSeBootloader device(s.flash, record, "FUZZ");
  s.server.SetDevice(&device);

  ip::Socket client = ip::ConnectTcp("127.0.0.1", s.server.port(), std::chrono::milliseconds(1000));
  const int big = 8 << 20;
  (void)::setsockopt(client.fd(), SOL_SOCKET, SO_RCVBUF, &big, sizeof big);
  // Closed with a reset: a connection per input would otherwise leave the loopback's ports in
  // TIME_WAIT faster than they come back.
  const linger reset{1, 0};
  (void)::setsockopt(client.fd(), SOL_SOCKET, SO_LINGER, &reset, sizeof reset);
  if (!request.empty()) client.SendAll(request);
  Require(::shutdown(client.fd(), SHUT_WR) == 0);

  std::vector<std::uint8_t> received;
  std::array<std::uint8_t, 65536> chunk{};
  for (int polls = 0; polls < 20000; ++polls) {
    (void)s.server.Poll(std::chrono::milliseconds(0));
    bool closed = false;
    while (client.WaitReadable(std::chrono::milliseconds(0))) {
      const ssize_t n = ::recv(client.fd(), chunk.data(), chunk.size(), MSG_DONTWAIT);
      if (n <= 0) {
        closed = n == 0;
        break;
      }
      received.insert(received.end(), chunk.begin(), chunk.begin() + n);
    }
    if (closed) break;
    Require(polls + 1 < 20000);  // the server kept the connection open after the client's end
  }
  s.server.SetDevice(nullptr);
  return received;
}

void CheckCodecs(FuzzedDataProvider& in) {
  const auto bytes = in.ConsumeBytes<std::uint8_t>(ip::kUsbDeviceBytes + ip::kUrbHeaderBytes);
  std::vector<std::uint8_t> buf(bytes);
  buf.resize(ip::kUsbDeviceBytes + ip::kUrbHeaderBytes);
  try {
    const ip::UrbHeader h = ip::DecodeUrbHeader(
        std::span<const std::uint8_t, ip::kUrbHeaderBytes>(buf.data(), ip::kUrbHeaderBytes));
    std::array<std::uint8_t, ip::kUrbHeaderBytes> again{};
    switch (h.basic.command) {
      case ip::UrbCommand::kCmdSubmit: ip::Encode(h.cmd_submit, again); break;
      case ip::UrbCommand::kRetSubmit: ip::Encode(h.ret_submit, again); break;
      case ip::UrbCommand::kCmdUnlink: ip::Encode(h.cmd_unlink, again); break;
      case ip::UrbCommand::kRetUnlink: ip::Encode(h.ret_unlink, again); break;
    }
    const ip::UrbHeader back = ip::DecodeUrbHeader(again);
    Require(back.basic.command == h.basic.command && back.basic.seqnum == h.basic.seqnum &&
            back.basic.direction == h.basic.direction && back.basic.ep == h.basic.ep);
  } catch (const ip::ProtocolError&) {
  }
  try {
    const ip::UsbDevice d = ip::DecodeUsbDevice(std::span<const std::uint8_t, ip::kUsbDeviceBytes>(
        buf.data() + ip::kUrbHeaderBytes, ip::kUsbDeviceBytes));
    std::array<std::uint8_t, ip::kUsbDeviceBytes> again{};
    ip::EncodeUsbDevice(d, again);
    const ip::UsbDevice back = ip::DecodeUsbDevice(again);
    Require(back.path == d.path && back.busid == d.busid && back.devid() == d.devid() &&
            back.speed == d.speed && back.id_vendor == d.id_vendor &&
            back.num_interfaces == d.num_interfaces);
  } catch (const ip::ProtocolError&) {
  }
  try {
    (void)ip::DecodeRepDevlist(bytes);
  } catch (const ip::ProtocolError&) {
  }
}

void CheckAnswers(const Message& m, const std::vector<std::uint8_t>& got) {
  std::size_t at = 0;
  if (m.device_list) {
    const std::vector<ip::UsbDevice> list = ip::DecodeRepDevlist(got);
    Require(list.size() == 1 && list[0].busid == "1-1" &&
            list[0].interfaces.size() == list[0].num_interfaces);
    return;
  }
  if (!m.import) return;
  Require(got.size() >= ip::kRepImportBytes);
  const ip::OpHeader op = ip::DecodeOpHeader(
      std::span<const std::uint8_t, ip::kOpHeaderBytes>(got.data(), ip::kOpHeaderBytes));
  Require(op.code == ip::OpCode::kRepImport && op.status == ip::kOpStatusOk);
  const ip::UsbDevice d = ip::DecodeUsbDevice(std::span<const std::uint8_t, ip::kUsbDeviceBytes>(
      got.data() + ip::kOpHeaderBytes, ip::kUsbDeviceBytes));
  Require(d.busid == "1-1");
  at = ip::kRepImportBytes;
  // After a damaged message the server may have answered some of it before dropping the
  // connection; only a well-formed conversation has answers that can be told apart.
  if (!m.well_formed) return;
  std::size_t answered = 0;
  while (at < got.size()) {
    Require(got.size() - at >= ip::kUrbHeaderBytes && answered < m.expected.size());
    const ip::UrbHeader h = ip::DecodeUrbHeader(
        std::span<const std::uint8_t, ip::kUrbHeaderBytes>(got.data() + at, ip::kUrbHeaderBytes));
    at += ip::kUrbHeaderBytes;
    const Expected& e = m.expected[answered++];
    Require(h.basic.seqnum == e.seqnum);
    if (e.kind == Expected::Kind::kSubmit) {
      Require(h.basic.command == ip::UrbCommand::kRetSubmit);
      if (e.in) {
        Require(h.ret_submit.actual_length <= e.length);
        at += h.ret_submit.actual_length;
      }
    } else {
      Require(h.basic.command == ip::UrbCommand::kRetUnlink &&
              h.ret_unlink.status == ip::kStatusOk);
    }
    Require(at <= got.size());
  }
  if (m.well_formed) Require(answered == m.expected.size());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  if (in.ConsumeIntegralInRange<int>(0, 3) == 0) {
    CheckCodecs(in);
    return 0;
  }
  const Message m = Script(in);
  const std::vector<std::uint8_t> got = Exchange(m.bytes);
  try {
    CheckAnswers(m, got);
  } catch (const ip::ProtocolError&) {
    // The server's own answers must decode.
    __builtin_trap();
  }
  return 0;
}
