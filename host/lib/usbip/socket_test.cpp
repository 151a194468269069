// The TCP helpers over loopback: a scripted server thread answers list and import.
#include "vibid/usbip/socket.hpp"

#include <gtest/gtest.h>

#include <array>
#include <thread>

namespace vibid::usbip {
namespace {

using std::chrono::milliseconds;

UsbDevice Device() {
  UsbDevice d;
  d.path = "/vibid/emu";
  d.busid = "1-1";
  d.busnum = 1;
  d.devnum = 1;
  d.id_vendor = 0x1209;
  d.num_interfaces = 2;
  d.interfaces = {UsbInterface{3, 0, 0}, UsbInterface{0xFE, 1, 1}};
  return d;
}

TEST(UsbipSocket, ListThenImportThenUrb) {
  Listener listener("127.0.0.1", 0);
  ASSERT_NE(listener.port(), 0);
  std::thread server([&] {
    Socket list = listener.Accept(milliseconds(5000));
    std::array<std::uint8_t, kOpHeaderBytes> req{};
    list.ReceiveExact(req);
    EXPECT_EQ(DecodeOpHeader(req).code, OpCode::kReqDevlist);
    list.SendAll(EncodeRepDevlist({Device()}));
    list.Close();

    Socket import = listener.Accept(milliseconds(5000));
    std::array<std::uint8_t, kReqImportBytes> imp{};
    import.ReceiveExact(imp);
    const UsbDevice d = Device();
    import.SendAll(EncodeRepImport(&d));
    UrbHeader h;
    ASSERT_TRUE(ReceiveUrbHeader(import, h));
    RetSubmit r;
    r.basic.seqnum = h.basic.seqnum;
    r.actual_length = 2;
    std::array<std::uint8_t, kUrbHeaderBytes + 2> out{};
    Encode(r, std::span<std::uint8_t, kUrbHeaderBytes>(out.data(), kUrbHeaderBytes));
    out[48] = 0xAB;
    out[49] = 0xCD;
    import.SendAll(out);
    UrbHeader none;
    EXPECT_FALSE(ReceiveUrbHeader(import, none));  // client closed: clean EOF
  });

  Socket a = ConnectTcp("127.0.0.1", listener.port(), milliseconds(2000));
  const auto devices = RequestDeviceList(a);
  ASSERT_EQ(devices.size(), 1u);
  EXPECT_EQ(devices[0].interfaces.size(), 2u);
  EXPECT_EQ(devices[0].interfaces[1].interface_class, 0xFE);

  Socket b = ConnectTcp("127.0.0.1", listener.port(), milliseconds(2000));
  const UsbDevice imported = RequestImport(b, "1-1");
  EXPECT_EQ(imported.busid, "1-1");
  CmdSubmit s;
  s.basic.seqnum = 42;
  s.basic.devid = imported.devid();
  s.basic.direction = Direction::kIn;
  s.transfer_buffer_length = 2;
  std::array<std::uint8_t, kUrbHeaderBytes> bytes{};
  Encode(s, bytes);
  b.SendAll(bytes);
  ASSERT_TRUE(b.WaitReadable(milliseconds(5000)));
  UrbHeader h;
  ASSERT_TRUE(ReceiveUrbHeader(b, h));
  EXPECT_EQ(h.basic.command, UrbCommand::kRetSubmit);
  EXPECT_EQ(h.ret_submit.basic.seqnum, 42u);
  std::array<std::uint8_t, 2> data{};
  b.ReceiveExact(data);
  EXPECT_EQ(data[1], 0xCD);
  b.Close();
  server.join();
}

TEST(UsbipSocket, RefusedImportAndClosedPeer) {
  Listener listener("127.0.0.1", 0);
  std::thread server([&] {
    Socket s = listener.Accept(milliseconds(5000));
    std::array<std::uint8_t, kReqImportBytes> imp{};
    s.ReceiveExact(imp);
    s.SendAll(EncodeRepImport(nullptr));
  });
  Socket c = ConnectTcp("127.0.0.1", listener.port(), milliseconds(2000));
  EXPECT_THROW(RequestImport(c, "9-9"), ProtocolError);
  server.join();
  std::array<std::uint8_t, 4> more{};
  EXPECT_THROW(c.ReceiveExact(more), IoError);
}

TEST(UsbipSocket, ConnectionRefusedNamesTheAddress) {
  std::uint16_t port = 0;
  {
    Listener probe("127.0.0.1", 0);
    port = probe.port();
  }
  try {
    ConnectTcp("127.0.0.1", port, milliseconds(1000));
    FAIL() << "connected to a closed port";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("127.0.0.1:" + std::to_string(port)), std::string::npos);
  }
  EXPECT_THROW(Listener("not-an-address", 0), IoError);
}

TEST(UsbipSocket, WaitReadableTimesOut) {
  Listener listener("127.0.0.1", 0);
  Socket c = ConnectTcp("127.0.0.1", listener.port(), milliseconds(2000));
  Socket s = listener.Accept(milliseconds(2000));
  ASSERT_TRUE(s.valid());
  EXPECT_FALSE(c.WaitReadable(milliseconds(20)));
  EXPECT_FALSE(listener.Accept(milliseconds(10)).valid());
}

}  // namespace
}  // namespace vibid::usbip
