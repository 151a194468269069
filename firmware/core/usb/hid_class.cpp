#include "vibid/fw/usb/hid_class.hpp"

#include <algorithm>

namespace vibid::fw::usb {

bool HidClass::OwnsInterface(std::uint8_t interface_number) const {
  return interface_number == kHidInterface;
}

bool HidClass::OwnsEndpoint(std::uint8_t ep_addr) const {
  return ep_addr == kHidInEndpoint || ep_addr == kHidOutEndpoint;
}

Status HidClass::Open(Dcd& dcd) {
  dcd_ = &dcd;
  if (Status s = dcd.EndpointOpen(kHidInEndpoint, EndpointType::kInterrupt, kHidReportSize);
      s != Status::kOk) {
    return s;
  }
  if (Status s = dcd.EndpointOpen(kHidOutEndpoint, EndpointType::kInterrupt, kHidReportSize);
      s != Status::kOk) {
    return s;
  }
  open_ = true;
  tx_busy_ = false;
  out_armed_ = false;
  out_halted_ = false;
  rx_count_ = 0;
  ArmOut();
  return Status::kOk;
}

void HidClass::Close() {
  open_ = false;
  tx_busy_ = false;
  out_armed_ = false;
  rx_count_ = 0;
  idle_rate_ = 0;
}

Status HidClass::Send(const wire::Report& report) {
  if (!open_ || tx_busy_) return Status::kUnavailable;
  std::copy(report.begin(), report.end(), tx_buffer_.begin());
  const Status s = dcd_->Transfer(kHidInEndpoint, tx_buffer_);
  if (s != Status::kOk) return s;
  tx_busy_ = true;
  last_input_ = tx_buffer_;
  return Status::kOk;
}

Status HidClass::Receive(wire::Report& out) {
  if (rx_count_ == 0) return Status::kUnavailable;
  out = rx_[rx_head_];
  rx_head_ = (rx_head_ + 1) % kRxSlots;
  --rx_count_;
  ArmOut();
  return Status::kOk;
}

void HidClass::PushRx(std::span<const std::uint8_t> report) {
  auto& slot = rx_[(rx_head_ + rx_count_) % kRxSlots];
  std::copy_n(report.begin(), kHidReportSize, slot.begin());
  ++rx_count_;
  ++counters_.reports_out;
}

void HidClass::ArmOut() {
  if (!open_ || out_armed_ || out_halted_ || !RxSlotFree()) return;
  if (dcd_->Transfer(kHidOutEndpoint, out_buffer_) == Status::kOk) out_armed_ = true;
}

void HidClass::OnTransferComplete(std::uint8_t ep_addr, std::uint16_t length) {
  if (ep_addr == kHidInEndpoint) {
    tx_busy_ = false;
    ++counters_.reports_in;
    return;
  }
  out_armed_ = false;
  if (length == kHidReportSize) {
    PushRx(out_buffer_);
  } else {
    ++counters_.short_reports;
  }
  ArmOut();
}

void HidClass::OnEndpointHalt(std::uint8_t ep_addr, bool halted) {
  // A halt abandons the transfer in flight: an input report being sent is lost to the host (the
  // command server's request will time out and be repeated), and the OUT endpoint is re-armed
  // only once the halt is cleared. Clearing a halt that was never set (CLEAR_FEATURE is allowed
  // on a running endpoint) abandons nothing: a report still in flight keeps the IN side busy.
  if (ep_addr == kHidInEndpoint) {
    if (halted) tx_busy_ = false;
    return;
  }
  out_halted_ = halted;
  out_armed_ = false;
  ArmOut();
}

ControlReply HidClass::OnControlRequest(const SetupPacket& setup, std::span<std::uint8_t> scratch) {
  if (setup.Type() == RequestType::kStandard) {
    // GET_DESCRIPTOR to the interface: the HID class descriptor or the report descriptor
    // (HID 1.11 §7.1.1).
    if (!setup.DeviceToHost()) return ControlReply::Stall();
    switch (static_cast<DescriptorType>(setup.ValueHigh())) {
      case DescriptorType::kHid: return ControlReply::Data(kHidDescriptor);
      case DescriptorType::kHidReport: return ControlReply::Data(kHidReportDescriptor);
      default: return ControlReply::Stall();
    }
  }
  const auto type = static_cast<HidReportType>(setup.ValueHigh());
  const std::uint8_t report_id = setup.ValueLow();
  switch (static_cast<HidRequest>(setup.b_request)) {
    case HidRequest::kGetReport:
      if (!setup.DeviceToHost() || report_id != 0 || type != HidReportType::kInput) break;
      return ControlReply::Data(last_input_);
    case HidRequest::kSetReport:
      // Output reports only, exactly one report long, and only when a receive slot is free (the
      // host retries a stalled SET_REPORT; it never silently loses a report).
      if (setup.DeviceToHost() || report_id != 0 || type != HidReportType::kOutput ||
          setup.w_length != kHidReportSize || !RxSlotFree()) {
        break;
      }
      return ControlReply::Accept();
    case HidRequest::kGetIdle:
      if (!setup.DeviceToHost() || report_id != 0) break;
      scratch[0] = idle_rate_;
      return ControlReply::Data(scratch.first(1));
    case HidRequest::kSetIdle:
      // The duration (4 ms units) is kept for GET_IDLE; input reports are only sent when the
      // firmware has something to say, so no periodic repeat is generated.
      if (setup.DeviceToHost() || report_id != 0) break;
      idle_rate_ = setup.ValueHigh();
      return ControlReply::Accept();
    default: break;  // GET/SET_PROTOCOL: boot protocol not supported (bInterfaceSubClass 0).
  }
  return ControlReply::Stall();
}

bool HidClass::OnControlData(const SetupPacket& setup, std::span<const std::uint8_t> data) {
  if (setup.b_request != static_cast<std::uint8_t>(HidRequest::kSetReport) ||
      data.size() != kHidReportSize || !RxSlotFree()) {
    return false;
  }
  PushRx(data);
  return true;
}

void HidClass::OnControlComplete(const SetupPacket&) {}

}  // namespace vibid::fw::usb
