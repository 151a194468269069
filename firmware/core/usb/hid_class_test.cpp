// HID class (HID 1.11 §7.2) and DFU run-time (DFU 1.1 §6.1) requests, and the interrupt
// endpoints carrying reports between the host and the code that reads and writes them.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>

#include "usb_test_host.hpp"

namespace vibid::fw::usb {
namespace {

using testing::Rig;
using Report = HidClass::Report;

Report Pattern(std::uint8_t seed) {
  Report r{};
  for (std::size_t i = 0; i < r.size(); ++i) r[i] = static_cast<std::uint8_t>(seed + 7 * i);
  return r;
}

// The host writes an output report on the interrupt OUT endpoint.
void HostWritesOut(Rig& rig, const Report& report, std::uint16_t length = 64) {
  auto& out = rig.dcd.PendingOn(0x01);
  ASSERT_TRUE(out.active);
  ASSERT_EQ(out.buffer.size(), 64U);
  std::copy_n(report.begin(), length, out.buffer.begin());
  out = {};
  rig.device.OnTransferComplete(0x01, length);
  rig.device.Task();
}

TEST(HidClass, OutReportReachesReader) {
  Rig rig;
  rig.host.Enumerate(4);
  Report got{};
  const Status s1 = rig.hid.Receive(got);
  EXPECT_EQ(s1, Status::kUnavailable);
  const Report sent = Pattern(11);
  HostWritesOut(rig, sent);
  const Status s2 = rig.hid.Receive(got);
  ASSERT_EQ(s2, Status::kOk);
  EXPECT_EQ(got, sent);
  const Status s3 = rig.hid.Receive(got);
  EXPECT_EQ(s3, Status::kUnavailable);
  EXPECT_EQ(rig.hid.counters().reports_out, 1U);
}

TEST(HidClass, InReportGoesOut) {
  Rig rig;
  const Report report = Pattern(5);
  // Not configured yet: nothing can be sent.
  const Status s4 = rig.hid.Send(report);
  EXPECT_EQ(s4, Status::kUnavailable);
  rig.host.Enumerate(4);
  ASSERT_TRUE(rig.hid.CanSend());
  const Status s5 = rig.hid.Send(report);
  ASSERT_EQ(s5, Status::kOk);
  // One report in flight at a time.
  EXPECT_FALSE(rig.hid.CanSend());
  const Status s6 = rig.hid.Send(report);
  EXPECT_EQ(s6, Status::kUnavailable);
  auto& in = rig.dcd.PendingOn(0x81);
  ASSERT_TRUE(in.active);
  ASSERT_EQ(in.buffer.size(), 64U);
  for (std::size_t i = 0; i < 64; ++i) EXPECT_EQ(in.buffer[i], report[i]);
  in = {};
  rig.device.OnTransferComplete(0x81, 64);
  rig.device.Task();
  EXPECT_TRUE(rig.hid.CanSend());
  EXPECT_EQ(rig.hid.counters().reports_in, 1U);

  // GET_REPORT(Input, id 0) answers the latest input report (HID 1.11 §7.2.1).
  const auto r = rig.host.Control({0xA1, 0x01, 0x00, 0x01, 0x00, 0x00, 0x40, 0x00});
  ASSERT_EQ(r.length, 64U);
  for (std::size_t i = 0; i < 64; ++i) EXPECT_EQ(r.data[i], report[i]);
}

TEST(HidClass, SlowReaderMakesHostWaitNotLose) {
  Rig rig;
  rig.host.Enumerate(4);
  HostWritesOut(rig, Pattern(1));
  HostWritesOut(rig, Pattern(2));
  // Both slots full: the OUT endpoint is not re-armed, so the host's third report is NAKed.
  EXPECT_FALSE(rig.dcd.PendingOn(0x01).active);
  // SET_REPORT is refused too rather than dropping a report.
  const Report third = Pattern(3);
  EXPECT_TRUE(rig.host.Control({0x21, 0x09, 0x00, 0x02, 0x00, 0x00, 0x40, 0x00}, third).stalled);
  Report got{};
  const Status s7 = rig.hid.Receive(got);
  ASSERT_EQ(s7, Status::kOk);
  EXPECT_EQ(got, Pattern(1));
  EXPECT_TRUE(rig.dcd.PendingOn(0x01).active);
  HostWritesOut(rig, third);
  const Status s8 = rig.hid.Receive(got);
  ASSERT_EQ(s8, Status::kOk);
  EXPECT_EQ(got, Pattern(2));
  const Status s9 = rig.hid.Receive(got);
  ASSERT_EQ(s9, Status::kOk);
  EXPECT_EQ(got, third);
}

TEST(HidClass, ShortOutPacketIsDiscardedAndCounted) {
  Rig rig;
  rig.host.Enumerate(4);
  HostWritesOut(rig, Pattern(9), 10);
  Report got{};
  const Status s10 = rig.hid.Receive(got);
  EXPECT_EQ(s10, Status::kUnavailable);
  EXPECT_EQ(rig.hid.counters().short_reports, 1U);
  EXPECT_TRUE(rig.dcd.PendingOn(0x01).active);
}

TEST(HidClass, SetReportOutputDeliversToReader) {
  Rig rig;
  rig.host.Enumerate(4);
  // SET_REPORT: bmRequestType 0x21, bRequest 0x09, wValue = type Output (2) << 8 | id 0,
  // wIndex interface 0, wLength 64 (HID 1.11 §7.2.2).
  const Report report = Pattern(42);
  const auto r = rig.host.Control({0x21, 0x09, 0x00, 0x02, 0x00, 0x00, 0x40, 0x00}, report);
  ASSERT_FALSE(r.stalled);
  ASSERT_FALSE(r.protocol_error);
  Report got{};
  const Status s11 = rig.hid.Receive(got);
  ASSERT_EQ(s11, Status::kOk);
  EXPECT_EQ(got, report);
  // Feature reports and report ids do not exist; a wrong length is refused.
  EXPECT_TRUE(rig.host.Control({0x21, 0x09, 0x00, 0x03, 0x00, 0x00, 0x40, 0x00}, report).stalled);
  EXPECT_TRUE(rig.host.Control({0x21, 0x09, 0x01, 0x02, 0x00, 0x00, 0x40, 0x00}, report).stalled);
  EXPECT_TRUE(rig.host.Control({0x21, 0x09, 0x00, 0x02, 0x00, 0x00, 0x20, 0x00}, report).stalled);
}

TEST(HidClass, HaltAndClearKeepTheLinkUsable) {
  Rig rig;
  rig.host.Enumerate(4);
  const Report report = Pattern(21);
  const Status sent = rig.hid.Send(report);
  ASSERT_EQ(sent, Status::kOk);
  // SET_FEATURE(ENDPOINT_HALT) on 0x81 while the report waits for its IN token: it is
  // abandoned, and after CLEAR_FEATURE the next report goes out.
  ASSERT_FALSE(rig.host.Control({0x02, 0x03, 0x00, 0x00, 0x81, 0x00, 0x00, 0x00}).stalled);
  EXPECT_FALSE(rig.dcd.PendingOn(0x81).active);
  ASSERT_FALSE(rig.host.Control({0x02, 0x01, 0x00, 0x00, 0x81, 0x00, 0x00, 0x00}).stalled);
  const Status again = rig.hid.Send(report);
  EXPECT_EQ(again, Status::kOk);
  EXPECT_TRUE(rig.dcd.PendingOn(0x81).active);

  // The OUT endpoint is not armed while halted, and is armed again once the halt is cleared.
  ASSERT_FALSE(rig.host.Control({0x02, 0x03, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00}).stalled);
  EXPECT_FALSE(rig.dcd.PendingOn(0x01).active);
  ASSERT_FALSE(rig.host.Control({0x02, 0x01, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00}).stalled);
  EXPECT_TRUE(rig.dcd.PendingOn(0x01).active);
  HostWritesOut(rig, Pattern(8));
  Report got{};
  const Status received = rig.hid.Receive(got);
  ASSERT_EQ(received, Status::kOk);
  EXPECT_EQ(got, Pattern(8));
}

TEST(HidClass, IdleRateAndProtocol) {
  Rig rig;
  rig.host.Enumerate(4);
  // SET_IDLE duration 0 (indefinite), as Linux' usbhid sends at probe (HID 1.11 §7.2.4).
  EXPECT_FALSE(rig.host.Control({0x21, 0x0A, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}).stalled);
  // SET_IDLE 500 ms = 125 x 4 ms, then GET_IDLE reads it back.
  EXPECT_FALSE(rig.host.Control({0x21, 0x0A, 0x00, 0x7D, 0x00, 0x00, 0x00, 0x00}).stalled);
  const auto idle = rig.host.Control({0xA1, 0x02, 0x00, 0x00, 0x00, 0x00, 0x01, 0x00});
  ASSERT_EQ(idle.length, 1U);
  EXPECT_EQ(idle.data[0], 125);
  EXPECT_EQ(rig.hid.idle_rate(), 125);
  // GET_PROTOCOL / SET_PROTOCOL are for boot devices only (§7.2.5, §7.2.6): stall.
  EXPECT_TRUE(rig.host.Control({0xA1, 0x03, 0x00, 0x00, 0x00, 0x00, 0x01, 0x00}).stalled);
  EXPECT_TRUE(rig.host.Control({0x21, 0x0B, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}).stalled);
  // GET_REPORT for an output or feature report: none readable.
  EXPECT_TRUE(rig.host.Control({0xA1, 0x01, 0x00, 0x02, 0x00, 0x00, 0x40, 0x00}).stalled);
  EXPECT_TRUE(rig.host.Control({0xA1, 0x01, 0x00, 0x03, 0x00, 0x00, 0x40, 0x00}).stalled);
}

TEST(HidClass, ClassRequestsNeedConfiguration) {
  Rig rig;
  rig.host.BusReset();
  ASSERT_FALSE(rig.host.Control({0x00, 0x05, 0x04, 0x00, 0x00, 0x00, 0x00, 0x00}).stalled);
  EXPECT_TRUE(rig.host.Control({0x21, 0x0A, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00}).stalled);
  EXPECT_TRUE(rig.host.Control({0x81, 0x06, 0x00, 0x22, 0x00, 0x00, 0x19, 0x00}).stalled);
}

TEST(DfuRuntime, StatusStateAndDetach) {
  Rig rig;
  rig.host.Enumerate(4);
  // DFU_GETSTATUS to interface 1: bStatus OK, poll timeout 0, bState appIDLE, iString 0.
  const auto st = rig.host.Control({0xA1, 0x03, 0x00, 0x00, 0x01, 0x00, 0x06, 0x00});
  ASSERT_EQ(st.length, 6U);
  const std::array<std::uint8_t, 6> want = {0x00, 0x00, 0x00, 0x00, 0x00, 0x00};
  for (std::size_t i = 0; i < 6; ++i) EXPECT_EQ(st.data[i], want[i]);
  const auto state = rig.host.Control({0xA1, 0x05, 0x00, 0x00, 0x01, 0x00, 0x01, 0x00});
  ASSERT_EQ(state.length, 1U);
  EXPECT_EQ(state.data[0], 0);  // appIDLE
  // Download/upload belong to the bootloader, not the run-time interface.
  EXPECT_TRUE(rig.host.Control({0x21, 0x01, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00}).stalled);
  EXPECT_TRUE(rig.host.Control({0xA1, 0x02, 0x00, 0x00, 0x01, 0x00, 0x40, 0x00}).stalled);

  // DFU_DETACH, wValue = timeout 1000 ms: the handler runs only after the status stage.
  rig.dcd.OnSetupHardware();
  const std::array<std::uint8_t, 8> detach = {0x21, 0x00, 0xE8, 0x03, 0x01, 0x00, 0x00, 0x00};
  rig.device.OnSetupReceived(detach);
  rig.device.Task();
  EXPECT_EQ(rig.detach.calls, 0);
  auto& status = rig.dcd.PendingOn(0x80);
  ASSERT_TRUE(status.active);
  EXPECT_TRUE(status.buffer.empty());
  status = {};
  rig.device.OnTransferComplete(0x80, 0);
  rig.device.Task();
  EXPECT_EQ(rig.detach.calls, 1);
  EXPECT_EQ(rig.detach.last_timeout_ms, 1000);
  EXPECT_EQ(rig.dfu.state(), dfu::State::kAppDetach);
}

}  // namespace
}  // namespace vibid::fw::usb
