// Enumeration and chapter 9 behaviour driven by SETUP packets written out as bytes from the
// USB 2.0 specification (§9.3 layout, §9.4 requests) and HID 1.11 §7.2.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <vector>

#include "usb_test_host.hpp"

namespace vibid::fw::usb {
namespace {

using testing::Rig;

// bmRequestType, bRequest, wValue (LE), wIndex (LE), wLength (LE)
constexpr std::array<std::uint8_t, 8> kGetDeviceDescriptor64 = {0x80, 0x06, 0x00, 0x01,
                                                                0x00, 0x00, 0x40, 0x00};
constexpr std::array<std::uint8_t, 8> kSetAddress5 = {0x00, 0x05, 0x05, 0x00,
                                                      0x00, 0x00, 0x00, 0x00};
constexpr std::array<std::uint8_t, 8> kGetConfiguration = {0x80, 0x08, 0x00, 0x00,
                                                           0x00, 0x00, 0x01, 0x00};
constexpr std::array<std::uint8_t, 8> kSetConfiguration1 = {0x00, 0x09, 0x01, 0x00,
                                                            0x00, 0x00, 0x00, 0x00};
constexpr std::array<std::uint8_t, 8> kSetConfiguration0 = {0x00, 0x09, 0x00, 0x00,
                                                            0x00, 0x00, 0x00, 0x00};
constexpr std::array<std::uint8_t, 8> kGetDeviceStatus = {0x80, 0x00, 0x00, 0x00,
                                                          0x00, 0x00, 0x02, 0x00};
constexpr std::array<std::uint8_t, 8> kGetStatusEp81 = {0x82, 0x00, 0x00, 0x00,
                                                        0x81, 0x00, 0x02, 0x00};
constexpr std::array<std::uint8_t, 8> kSetHaltEp81 = {0x02, 0x03, 0x00, 0x00,
                                                      0x81, 0x00, 0x00, 0x00};
constexpr std::array<std::uint8_t, 8> kClearHaltEp81 = {0x02, 0x01, 0x00, 0x00,
                                                        0x81, 0x00, 0x00, 0x00};

TEST(UsbEnumeration, StartInitializesAndConnects) {
  Rig rig;
  EXPECT_TRUE(rig.dcd.connected);
  EXPECT_EQ(rig.device.state(), DeviceState::kPowered);
  rig.host.BusReset();
  EXPECT_EQ(rig.device.state(), DeviceState::kDefault);
}

TEST(UsbEnumeration, FailedControllerInitStaysDetached) {
  const Rig rig{"X", Status::kUnavailable};
  EXPECT_EQ(rig.start_status, Status::kUnavailable);
  EXPECT_FALSE(rig.dcd.connected);
  EXPECT_EQ(rig.device.state(), DeviceState::kDetached);
}

TEST(UsbEnumeration, LinuxSequenceReachesConfigured) {
  Rig rig;
  rig.host.BusReset();
  // Linux reads 64 bytes of the device descriptor at address 0; the device answers its 18.
  const auto first = rig.host.Control(kGetDeviceDescriptor64);
  ASSERT_FALSE(first.protocol_error);
  EXPECT_EQ(first.length, 18U);
  EXPECT_EQ(first.packets, 1U);

  // SET_ADDRESS: the driver is told at once (before the status stage), the device state
  // changes once the status stage completed (USB 2.0 §9.4.6).
  const auto addr = rig.host.Control(kSetAddress5);
  ASSERT_FALSE(addr.stalled);
  ASSERT_FALSE(addr.protocol_error);
  EXPECT_EQ(rig.dcd.address, 5);
  EXPECT_EQ(rig.device.address(), 5);
  EXPECT_EQ(rig.device.state(), DeviceState::kAddress);

  // In the address state GET_CONFIGURATION answers 0 (§9.4.2).
  const auto cfg0 = rig.host.Control(kGetConfiguration);
  ASSERT_EQ(cfg0.length, 1U);
  EXPECT_EQ(cfg0.data[0], 0);

  const auto set = rig.host.Control(kSetConfiguration1);
  ASSERT_FALSE(set.stalled);
  EXPECT_EQ(rig.device.state(), DeviceState::kConfigured);
  const auto cfg1 = rig.host.Control(kGetConfiguration);
  EXPECT_EQ(cfg1.data[0], 1);

  // The HID endpoints are open as the descriptors say: interrupt, 64 bytes, OUT armed.
  EXPECT_TRUE(rig.dcd.opened[testing::FakeDcd::Index(0x81)]);
  EXPECT_TRUE(rig.dcd.opened[testing::FakeDcd::Index(0x01)]);
  EXPECT_EQ(rig.dcd.open_type[testing::FakeDcd::Index(0x81)], EndpointType::kInterrupt);
  EXPECT_EQ(rig.dcd.open_size[testing::FakeDcd::Index(0x01)], 64);
  EXPECT_TRUE(rig.dcd.PendingOn(0x01).active);
  EXPECT_TRUE(rig.hid.is_open());

  // SET_CONFIGURATION 0 returns to the address state and closes the class.
  ASSERT_FALSE(rig.host.Control(kSetConfiguration0).stalled);
  EXPECT_EQ(rig.device.state(), DeviceState::kAddress);
  EXPECT_FALSE(rig.hid.is_open());
  EXPECT_FALSE(rig.dcd.opened[testing::FakeDcd::Index(0x81)]);
}

TEST(UsbEnumeration, BusResetReturnsToDefault) {
  Rig rig;
  rig.host.Enumerate(9);
  ASSERT_TRUE(rig.device.Configured());
  rig.host.BusReset();
  EXPECT_EQ(rig.device.state(), DeviceState::kDefault);
  EXPECT_EQ(rig.device.address(), 0);
  EXPECT_FALSE(rig.hid.is_open());
  EXPECT_EQ(rig.device.counters().bus_resets, 2U);
}

TEST(UsbEnumeration, SetConfigurationRequiresAnAddress) {
  Rig rig;
  rig.host.BusReset();
  // Default state: SET_CONFIGURATION is not valid (§9.4.7).
  EXPECT_TRUE(rig.host.Control(kSetConfiguration1).stalled);
  ASSERT_FALSE(rig.host.Control(kSetAddress5).stalled);
  // Configuration 2 does not exist.
  EXPECT_TRUE(rig.host.Control({0x00, 0x09, 0x02, 0x00, 0x00, 0x00, 0x00, 0x00}).stalled);
  EXPECT_EQ(rig.device.state(), DeviceState::kAddress);
}

TEST(UsbEnumeration, SetAddressOutOfRangeStalls) {
  Rig rig;
  rig.host.BusReset();
  EXPECT_TRUE(rig.host.Control({0x00, 0x05, 0x80, 0x00, 0x00, 0x00, 0x00, 0x00}).stalled);
  EXPECT_EQ(rig.device.state(), DeviceState::kDefault);
}

TEST(UsbEnumeration, DeviceStatusIsBusPoweredNoWakeup) {
  Rig rig;
  rig.host.Enumerate(3);
  const auto r = rig.host.Control(kGetDeviceStatus);
  ASSERT_EQ(r.length, 2U);
  EXPECT_EQ(r.data[0], 0);  // bit 0 self powered = 0, bit 1 remote wakeup = 0 (figure 9-4)
  EXPECT_EQ(r.data[1], 0);
}

TEST(UsbEnumeration, EndpointHaltSetGetClear) {
  Rig rig;
  rig.host.Enumerate(3);
  EXPECT_EQ(rig.host.Control(kGetStatusEp81).data[0], 0);
  ASSERT_FALSE(rig.host.Control(kSetHaltEp81).stalled);
  EXPECT_TRUE(rig.dcd.Stalled(0x81));
  EXPECT_EQ(rig.host.Control(kGetStatusEp81).data[0], 1);
  ASSERT_FALSE(rig.host.Control(kClearHaltEp81).stalled);
  EXPECT_FALSE(rig.dcd.Stalled(0x81));
  EXPECT_EQ(rig.dcd.clear_stall_calls, 1U);
  EXPECT_EQ(rig.host.Control(kGetStatusEp81).data[0], 0);
}

TEST(UsbEnumeration, EndpointRequestsNeedAnOpenEndpoint) {
  Rig rig;
  rig.host.BusReset();
  ASSERT_FALSE(rig.host.Control(kSetAddress5).stalled);
  // Address state: only endpoint 0 may be addressed (§9.4.5).
  EXPECT_TRUE(rig.host.Control(kGetStatusEp81).stalled);
  EXPECT_FALSE(rig.host.Control({0x82, 0x00, 0x00, 0x00, 0x00, 0x00, 0x02, 0x00}).stalled);
  ASSERT_FALSE(rig.host.Control(kSetConfiguration1).stalled);
  // Endpoint 2 IN is not part of the configuration.
  EXPECT_TRUE(rig.host.Control({0x82, 0x00, 0x00, 0x00, 0x82, 0x00, 0x02, 0x00}).stalled);
}

TEST(UsbEnumeration, InterfaceRequests) {
  Rig rig;
  rig.host.Enumerate(3);
  // GET_INTERFACE (§9.4.4) on interface 0: alternate setting 0.
  const auto alt = rig.host.Control({0x81, 0x0A, 0x00, 0x00, 0x00, 0x00, 0x01, 0x00});
  ASSERT_EQ(alt.length, 1U);
  EXPECT_EQ(alt.data[0], 0);
  // SET_INTERFACE alt 0 is fine, alt 1 does not exist; interface 2 does not exist.
  EXPECT_FALSE(rig.host.Control({0x01, 0x0B, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}).stalled);
  EXPECT_TRUE(rig.host.Control({0x01, 0x0B, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00}).stalled);
  EXPECT_TRUE(rig.host.Control({0x81, 0x0A, 0x00, 0x00, 0x02, 0x00, 0x01, 0x00}).stalled);
  // GET_STATUS on the interface: two zero bytes (figure 9-5).
  const auto st = rig.host.Control({0x81, 0x00, 0x00, 0x00, 0x01, 0x00, 0x02, 0x00});
  ASSERT_EQ(st.length, 2U);
  EXPECT_EQ(st.data[0], 0);
}

TEST(UsbEnumeration, UnsupportedRequestsStall) {
  Rig rig;
  rig.host.Enumerate(3);
  const std::array<std::array<std::uint8_t, 8>, 8> requests = {{
      {0x80, 0x06, 0x00, 0x06, 0x00, 0x00, 0x0A, 0x00},  // GET_DESCRIPTOR device qualifier
      {0x80, 0x06, 0x00, 0x07, 0x00, 0x00, 0x09, 0x00},  // other-speed configuration
      {0x80, 0x06, 0x01, 0x02, 0x00, 0x00, 0x09, 0x00},  // configuration index 1
      {0x00, 0x03, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00},  // SET_FEATURE device remote wakeup
      {0x00, 0x03, 0x02, 0x00, 0x00, 0x04, 0x00, 0x00},  // SET_FEATURE test mode
      {0x00, 0x07, 0x00, 0x01, 0x00, 0x00, 0x12, 0x00},  // SET_DESCRIPTOR
      {0xC0, 0x01, 0x00, 0x00, 0x00, 0x00, 0x04, 0x00},  // vendor request
      {0x82, 0x0C, 0x00, 0x00, 0x81, 0x00, 0x02, 0x00},  // SYNCH_FRAME on an interrupt endpoint
  }};
  const std::uint32_t before = rig.device.counters().stalled_requests;
  for (const auto& setup : requests) {
    const auto r = rig.host.Control(setup);
    EXPECT_TRUE(r.stalled);
  }
  EXPECT_EQ(rig.device.counters().stalled_requests, before + requests.size());
  // A stall does not break the pipe: the next request works (§8.5.3.4).
  EXPECT_EQ(rig.host.Control(kGetConfiguration).data[0], 1);
}

TEST(UsbEnumeration, ShortRequestLengthTruncatesReply) {
  Rig rig;
  rig.host.BusReset();
  // wLength 8: the host learns bMaxPacketSize0 from the first 8 bytes (old Windows behaviour).
  const auto r = rig.host.Control({0x80, 0x06, 0x00, 0x01, 0x00, 0x00, 0x08, 0x00});
  ASSERT_FALSE(r.protocol_error);
  EXPECT_EQ(r.length, 8U);
  EXPECT_EQ(r.data[7], 64);
}

TEST(UsbEnumeration, NewSetupAbandonsTransferInProgress) {
  Rig rig;
  rig.host.BusReset();
  rig.dcd.OnSetupHardware();
  rig.device.OnSetupReceived(kGetDeviceDescriptor64);
  rig.device.Task();
  ASSERT_TRUE(rig.dcd.PendingOn(0x80).active);
  // The host gives up before the status stage and starts again.
  const auto r = rig.host.Control(kSetAddress5);
  EXPECT_FALSE(r.stalled);
  EXPECT_FALSE(r.protocol_error);
  EXPECT_EQ(rig.device.address(), 5);
}

TEST(UsbEnumeration, SetupSupersededBeforeTaskRanIsDropped) {
  Rig rig;
  rig.host.Enumerate(5);
  // A GET_DESCRIPTOR waits in the queue when the host abandons it and sends SET_CONFIGURATION 1
  // (the controller drops endpoint 0's state on each SETUP): the device must answer only the
  // newer one, a zero-length status IN, not the descriptor's 18 bytes (USB 2.0 §8.5.3).
  rig.dcd.OnSetupHardware();
  rig.device.OnSetupReceived(kGetDeviceDescriptor64);
  const auto r = rig.host.Control(kSetConfiguration1);
  EXPECT_FALSE(r.stalled);
  EXPECT_FALSE(r.protocol_error);
  EXPECT_EQ(rig.device.counters().superseded_setups, 1U);
  // A bus reset queued behind a SETUP abandons it too: nothing is armed on endpoint 0.
  rig.device.OnSetupReceived(kGetDeviceDescriptor64);
  rig.device.OnBusReset();
  rig.device.Task();
  EXPECT_FALSE(rig.dcd.PendingOn(0x80).active);
  EXPECT_EQ(rig.device.counters().superseded_setups, 2U);
  EXPECT_EQ(rig.device.state(), DeviceState::kDefault);
}

TEST(UsbEnumeration, CompletionOfAnAbandonedTransferArmsNothingForTheNewerOne) {
  Rig rig;
  rig.host.Enumerate(5);
  // GET_STATUS (2 bytes IN) runs to its data stage; its IN completion waits in the queue when
  // the host abandons the transfer and sends SET_INTERFACE with a data stage (wLength 65). The
  // old completion must not arm the old transfer's status OUT (0 bytes) on endpoint 0: the new
  // transfer's first data packet (64 bytes) needs its own 64-byte buffer.
  rig.dcd.OnSetupHardware();
  const std::array<std::uint8_t, 8> get_status = {0x80, 0x00, 0x00, 0x00, 0x00, 0x00, 0x02, 0x00};
  rig.device.OnSetupReceived(get_status);
  rig.device.Task();
  ASSERT_TRUE(rig.dcd.PendingOn(0x80).active);
  rig.dcd.PendingOn(0x80) = {};
  rig.device.OnTransferComplete(0x80, 2);  // queued, not yet handled
  std::vector<std::uint8_t> data(65, 0xBA);
  const auto r = rig.host.Control({0x01, 0x0B, 0x00, 0x00, 0x01, 0x00, 0x41, 0x00}, data);
  EXPECT_FALSE(r.protocol_error);
  EXPECT_TRUE(r.stalled);  // SET_INTERFACE takes no data: the device ends it with a stall
  EXPECT_EQ(rig.device.counters().superseded_completions, 1U);
}

TEST(UsbEnumeration, EventQueueOverflowIsCounted) {
  Rig rig;
  for (std::size_t i = 0; i < UsbDevice::kEventQueueSize + 3; ++i) rig.device.OnSuspend();
  // One slot is kept empty to tell full from empty.
  EXPECT_EQ(rig.device.counters().event_overflows, 4U);
  rig.device.Task();
  EXPECT_TRUE(rig.device.suspended());
  rig.device.OnResume();
  rig.device.Task();
  EXPECT_FALSE(rig.device.suspended());
}

// A class driver answering a vendor-sized class request with more than one packet, to exercise
// multi-packet IN data stages and multi-packet OUT data stages through the device's dispatch.
class BulkyClass final : public ClassDriver {
 public:
  bool OwnsInterface(std::uint8_t n) const override { return n == 5; }
  bool OwnsEndpoint(std::uint8_t) const override { return false; }
  Status Open(Dcd&) override { return Status::kOk; }
  void Close() override {}
  ControlReply OnControlRequest(const SetupPacket& setup, std::span<std::uint8_t>) override {
    if (setup.DeviceToHost())
      return ControlReply::Data(std::span<const std::uint8_t>(payload).first(reply_length));
    return ControlReply::Accept();
  }
  bool OnControlData(const SetupPacket&, std::span<const std::uint8_t> data) override {
    received = data.size();
    checksum = 0;
    for (std::uint8_t b : data) checksum += b;
    return true;
  }
  void OnControlComplete(const SetupPacket&) override { ++completions; }
  void OnTransferComplete(std::uint8_t, std::uint16_t) override {}
  void OnEndpointHalt(std::uint8_t, bool) override {}

  std::array<std::uint8_t, 200> payload{};
  std::size_t reply_length = 150;
  std::size_t received = 0;
  std::uint32_t checksum = 0;
  int completions = 0;
};

TEST(UsbControlPipe, MultiPacketDataStages) {
  testing::FakeDcd dcd;
  BulkyClass bulky;
  for (std::size_t i = 0; i < bulky.payload.size(); ++i)
    bulky.payload[i] = static_cast<std::uint8_t>(i);
  std::array<ClassDriver*, 1> drivers{&bulky};
  const DaqStrings strings = MakeDaqStrings("S");
  UsbDevice device{dcd, drivers, DaqDescriptors(strings)};
  const Status s2 = device.Start();
  ASSERT_EQ(s2, Status::kOk);
  testing::Host host{device, dcd};
  host.Enumerate(2);
  ASSERT_TRUE(device.Configured());

  // 150 bytes asked with wLength 200: 64 + 64 + 22, the short packet ends the stage.
  const auto in = host.Control({0xA1, 0x01, 0x00, 0x00, 0x05, 0x00, 0xC8, 0x00});
  ASSERT_FALSE(in.protocol_error);
  EXPECT_EQ(in.length, 150U);
  EXPECT_EQ(in.packets, 3U);
  EXPECT_EQ(in.data[149], 149);

  // 128 bytes asked with wLength 200: two full packets need a ZLP.
  bulky.reply_length = 128;
  const auto zlp = host.Control({0xA1, 0x01, 0x00, 0x00, 0x05, 0x00, 0xC8, 0x00});
  EXPECT_EQ(zlp.length, 128U);
  EXPECT_EQ(zlp.packets, 3U);

  // 100-byte OUT data stage: 64 + 36 into the stack's buffer, then the status IN.
  std::array<std::uint8_t, 100> out{};
  std::uint32_t sum = 0;
  for (std::size_t i = 0; i < out.size(); ++i) {
    out[i] = static_cast<std::uint8_t>(3 * i);
    sum += out[i];
  }
  const auto w = host.Control({0x21, 0x09, 0x00, 0x00, 0x05, 0x00, 0x64, 0x00}, out);
  ASSERT_FALSE(w.protocol_error);
  ASSERT_FALSE(w.stalled);
  EXPECT_EQ(bulky.received, 100U);
  EXPECT_EQ(bulky.checksum, sum);

  // More than the control buffer holds is refused at the SETUP stage.
  EXPECT_TRUE(host.Control({0x21, 0x09, 0x00, 0x00, 0x05, 0x00, 0x00, 0x01}).stalled);
  EXPECT_EQ(bulky.completions, 3);
}

TEST(UsbControlPipe, AnotherPersonalityBringsItsOwnDescriptors) {
  // A minimal second personality (as the emulator's DFU bootloader would be): its own device
  // descriptor, a configuration numbered 2 with no interfaces, one string.
  constexpr std::array<std::uint8_t, 18> device_descriptor = {
      18, 1, 0x00, 0x02, 0, 0, 0, 64, 0x83, 0x04, 0x11, 0xDF, 0x00, 0x02, 1, 0, 0, 1};
  constexpr std::array<std::uint8_t, 9> configuration = {9, 2, 9, 0, 0, 2, 0, 0x80, 50};
  const std::array<const char*, 1> strings = {"boot"};
  testing::FakeDcd dcd;
  UsbDevice device{dcd, {}, DescriptorSet{device_descriptor, configuration, strings}};
  ASSERT_EQ(device.Start(), Status::kOk);
  testing::Host host{device, dcd};
  host.BusReset();
  const auto d = host.Control({0x80, 0x06, 0x00, 0x01, 0x00, 0x00, 0x12, 0x00});
  ASSERT_EQ(d.length, 18U);
  EXPECT_EQ(d.data[8], 0x83);   // idVendor 0x0483 low byte, as given
  EXPECT_EQ(d.data[11], 0xDF);  // idProduct 0xDF11 high byte
  const auto s1 = host.Control({0x80, 0x06, 0x01, 0x03, 0x09, 0x04, 0xFF, 0x00});
  ASSERT_EQ(s1.length, 10U);  // "boot": 2 + 2 x 4
  EXPECT_EQ(s1.data[2], 'b');
  EXPECT_TRUE(host.Control({0x80, 0x06, 0x02, 0x03, 0x09, 0x04, 0xFF, 0x00}).stalled);
  ASSERT_FALSE(host.Control({0x00, 0x05, 0x03, 0x00, 0x00, 0x00, 0x00, 0x00}).stalled);
  // Its bConfigurationValue is 2: 1 is refused, 2 configures.
  EXPECT_TRUE(host.Control({0x00, 0x09, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00}).stalled);
  EXPECT_FALSE(host.Control({0x00, 0x09, 0x02, 0x00, 0x00, 0x00, 0x00, 0x00}).stalled);
  EXPECT_TRUE(device.Configured());
}

}  // namespace
}  // namespace vibid::fw::usb
