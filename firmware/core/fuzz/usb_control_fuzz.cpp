// Fuzzes the core's USB device stack (chapter 9 control transfers, the HID class, the DFU
// run-time class) through the controller-driver interface, as the host's USB stack drives it.
// The input is a script (FuzzedDataProvider) of:
//   - control transfers the test host runs by the rules (SETUP, data stage to wLength or a short
//     packet, status stage), with request type, request, value, index and length picked from the
//     values chapter 9, HID 1.11 and DFU 1.1 define, now and then arbitrary;
//   - raw controller events in any order the hardware can produce them (a SETUP without the rest,
//     a pending transfer completing out of the host's order, bus resets, suspend and resume, more
//     events than the queue holds);
//   - HID reports both ways on the interrupt endpoints.
// Invariants: a control transfer run by the rules either stalls or completes its stages (the
// device always arms the stage the host expects, never sends more than wLength, never a packet
// over the endpoint size); a descriptor answers with its own length and type; reports that go in
// on the OUT endpoint come out of the HID link unchanged.
#include <fuzzer/FuzzedDataProvider.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "usb_test_host.hpp"

namespace {

using namespace vibid::fw::usb;
using vibid::Status;

void Require(bool condition) {
  if (!condition) __builtin_trap();
}

constexpr std::array<std::uint8_t, 10> kRequestTypes = {0x80, 0x00, 0x81, 0x01, 0x82,
                                                        0x02, 0xA1, 0x21, 0xC0, 0x40};
constexpr std::array<std::uint8_t, 14> kRequests = {0, 1, 3, 5, 6, 7, 8, 9, 10, 11, 12, 2, 4, 0xFF};
constexpr std::array<std::uint16_t, 12> kValues = {0x0100, 0x0200, 0x0300, 0x0301, 0x0302, 0x0303,
                                                   0x0304, 0x2100, 0x2200, 0x0600, 0x0001, 0x0000};
constexpr std::array<std::uint16_t, 8> kIndexes = {0, 1, 2, 0x81, 0x01, 0x82, 0x80, 0x0409};
constexpr std::array<std::uint16_t, 13> kLengths = {0,  1,  2,  7,   8,   9,     18,
                                                    63, 64, 65, 128, 255, 0xFFFF};

struct Fixture {
  testing::Rig rig;
  std::uint8_t address = 0;
};

void RunControl(FuzzedDataProvider& in, Fixture& f) {
  std::array<std::uint8_t, 8> setup{};
  const bool arbitrary = in.ConsumeIntegralInRange<int>(0, 15) == 0;
  const std::uint8_t type =
      arbitrary ? in.ConsumeIntegral<std::uint8_t>() : in.PickValueInArray(kRequestTypes);
  std::uint8_t request =
      arbitrary ? in.ConsumeIntegral<std::uint8_t>() : in.PickValueInArray(kRequests);
  std::uint16_t value =
      arbitrary ? in.ConsumeIntegral<std::uint16_t>() : in.PickValueInArray(kValues);
  const std::uint16_t index =
      arbitrary ? in.ConsumeIntegral<std::uint16_t>() : in.PickValueInArray(kIndexes);
  const std::uint16_t length =
      arbitrary ? in.ConsumeIntegral<std::uint16_t>() : in.PickValueInArray(kLengths);
  if (!arbitrary && request == 5)
    value = in.ConsumeIntegralInRange<std::uint16_t>(0, 130);  // SET_ADDRESS
  if (!arbitrary && request == 9 && (type & 0x60) == 0)
    value = in.ConsumeIntegralInRange<std::uint16_t>(0, 2);
  setup = {type,
           request,
           static_cast<std::uint8_t>(value),
           static_cast<std::uint8_t>(value >> 8),
           static_cast<std::uint8_t>(index),
           static_cast<std::uint8_t>(index >> 8),
           static_cast<std::uint8_t>(length),
           static_cast<std::uint8_t>(length >> 8)};
  std::vector<std::uint8_t> out;
  if ((type & 0x80) == 0) {
    out = in.ConsumeBytes<std::uint8_t>(
        in.ConsumeIntegralInRange<std::size_t>(0, std::min<std::size_t>(length, 300)));
    out.resize(std::min<std::size_t>(length, 300));
  }
  const std::uint32_t overflows = f.rig.device.counters().event_overflows;
  const testing::ControlResult r = f.rig.host.Control(setup, out);
  // A SETUP that found the event queue full is lost (and counted), as on the board when Task()
  // runs too late; the host's transfer then times out. Nothing else may leave it hanging.
  if (f.rig.device.counters().event_overflows != overflows) return;
  Require(!r.protocol_error);
  if (r.stalled) return;
  Require(r.length <= length);
  // A GET_DESCRIPTOR answer starts with its own length and type and is cut only by wLength.
  if (type == 0x80 && request == 6 && r.length >= 2) {
    const auto kind = static_cast<std::uint8_t>(value >> 8);
    Require(r.data[1] == kind || kind == 0x22 || (kind == 2 && r.data[1] == 2));
    if (kind != 2 && kind != 0x22) Require(r.length == std::min<std::size_t>(r.data[0], length));
  }
}

void RunRawEvent(FuzzedDataProvider& in, Fixture& f) {
  UsbDevice& d = f.rig.device;
  switch (in.ConsumeIntegralInRange<int>(0, 6)) {
    case 0: {
      std::array<std::uint8_t, 8> setup{};
      const auto bytes = in.ConsumeBytes<std::uint8_t>(8);
      std::copy(bytes.begin(), bytes.end(), setup.begin());
      f.rig.dcd.OnSetupHardware();
      d.OnSetupReceived(setup);
      break;
    }
    case 1: {
      // A transfer the controller has finishes now, out of the host's usual order (an IN sent
      // whole, an OUT with any length up to its buffer): hardware reports no other completion.
      constexpr std::array<std::uint8_t, 4> kEps = {0x00, 0x80, 0x01, 0x81};
      const std::uint8_t ep = in.PickValueInArray(kEps);
      auto& pending = f.rig.dcd.PendingOn(ep);
      if (!pending.active) break;
      const auto n = (ep & 0x80) != 0
                         ? pending.buffer.size()
                         : in.ConsumeIntegralInRange<std::size_t>(0, pending.buffer.size());
      pending = {};
      d.OnTransferComplete(ep, static_cast<std::uint16_t>(n));
      break;
    }
    case 2: d.OnBusReset(); break;
    case 3: d.OnSuspend(); break;
    case 4: d.OnResume(); break;
    case 5:  // a burst the queue cannot hold: counted, never overwritten
      for (int i = in.ConsumeIntegralInRange<int>(1, 40); i > 0; --i) d.OnResume();
      break;
    default: break;
  }
  if (in.ConsumeBool()) d.Task();
}

// HID reports: the host sends one on the OUT endpoint, the device queues one for IN.
void RunReports(FuzzedDataProvider& in, Fixture& f) {
  HidClass& hid = f.rig.hid;
  // Reports already queued (SET_REPORT, earlier completions) come out first.
  vibid::wire::Report queued{};
  while (hid.Receive(queued) == Status::kOk) {
  }
  auto& out_ep = f.rig.dcd.PendingOn(kHidOutEndpoint);
  if (out_ep.active && !out_ep.buffer.empty()) {
    const std::size_t n = in.ConsumeIntegralInRange<std::size_t>(0, out_ep.buffer.size());
    const auto bytes = in.ConsumeBytes<std::uint8_t>(n);
    std::fill(out_ep.buffer.begin(), out_ep.buffer.end(), 0);
    std::copy(bytes.begin(), bytes.end(), out_ep.buffer.begin());
    std::array<std::uint8_t, 64> sent{};
    std::copy_n(out_ep.buffer.begin(), std::min<std::size_t>(64, out_ep.buffer.size()),
                sent.begin());
    out_ep = {};
    f.rig.device.OnTransferComplete(kHidOutEndpoint, static_cast<std::uint16_t>(n));
    f.rig.device.Task();
    vibid::wire::Report got{};
    if (n == vibid::wire::kReportBytes && hid.Receive(got) == Status::kOk) {
      Require(std::equal(got.begin(), got.end(), sent.begin()));
    }
  }
  vibid::wire::Report report{};
  report[0] = in.ConsumeIntegral<std::uint8_t>();
  const bool could = hid.CanSend();
  const Status s = hid.Send(report);
  Require(could == (s == Status::kOk));
  auto& in_ep = f.rig.dcd.PendingOn(kHidInEndpoint);
  if (in_ep.active && in.ConsumeBool()) {
    Require(in_ep.buffer.size() <= 64);
    const auto n = static_cast<std::uint16_t>(in_ep.buffer.size());
    in_ep = {};
    f.rig.device.OnTransferComplete(kHidInEndpoint, n);
    f.rig.device.Task();
  }
  vibid::wire::Report drained{};
  while (hid.Receive(drained) == Status::kOk) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  Fixture f;
  // Most scripts start from a configured device, the state the host leaves it in.
  if (in.ConsumeBool()) f.rig.host.Enumerate(in.ConsumeIntegralInRange<std::uint8_t>(1, 127));
  for (int step = 0; step < 48 && in.remaining_bytes() > 0; ++step) {
    switch (in.ConsumeIntegralInRange<int>(0, 5)) {
      case 0:
      case 1:
      case 2: RunControl(in, f); break;
      case 3: RunRawEvent(in, f); break;
      case 4: RunReports(in, f); break;
      default: f.rig.host.BusReset(); break;
    }
  }
  f.rig.device.Task();
  return 0;
}
