#include "usb_app_device.hpp"

#include <algorithm>

#include "vibid/fw/usb/usb_types.hpp"

namespace vibid::emu {

using fw::usb::kEp0Size;
using fw::usb::SetupPacket;

namespace {
constexpr std::uint8_t kEp0In = EmuDcd::kEp0In;
constexpr std::uint8_t kEp0Out = EmuDcd::kEp0Out;
// A device that does not arm the stage the host expects would make a real host time out; the
// URB completes with this status instead (-ETIMEDOUT).
constexpr std::int32_t kStatusTimedOut = -110;
}  // namespace

void UsbAppDevice::Attach(UrbSink& sink) {
  sink_ = &sink;
  // The exporting host has enumerated the device before it offers it: reset and address it.
  stack_.OnBusReset();
  stack_.Task();
  const std::array<std::uint8_t, 8> set_address = {
      0x00, 0x05, static_cast<std::uint8_t>(record_.devnum), 0, 0, 0, 0, 0};
  (void)Control(set_address, {}, 0);
}

void UsbAppDevice::Detach() {
  sink_ = nullptr;
  in_urbs_.clear();
  out_urbs_.clear();
  stack_.OnBusReset();
  stack_.Task();
}

UrbResult UsbAppDevice::Control(const std::array<std::uint8_t, 8>& setup_bytes,
                                std::span<const std::uint8_t> out_data, std::uint32_t length) {
  UrbResult r;
  const SetupPacket setup = SetupPacket::Decode(setup_bytes);
  const std::uint32_t w_length = std::min<std::uint32_t>(setup.w_length, length);
  auto stalled = [&] { return dcd_.Stalled(kEp0In) || dcd_.Stalled(kEp0Out); };
  auto fail = [&](std::int32_t status) {
    r.status = status;
    r.actual_length = 0;
    r.in_data.clear();
    return r;
  };
  // Completes the transfer pending on `ep` with `n` bytes and lets the stack react.
  auto complete = [&](std::uint8_t ep, std::size_t n) {
    dcd_.PendingOn(ep) = {};
    stack_.OnTransferComplete(ep, static_cast<std::uint16_t>(n));
    stack_.Task();
  };

  dcd_.OnSetupArrived();
  stack_.OnSetupReceived(setup_bytes);
  stack_.Task();

  if (setup.DeviceToHost() && w_length > 0) {
    for (;;) {
      if (stalled()) return fail(usbip::kStatusStall);
      EmuDcd::Pending& in = dcd_.PendingOn(kEp0In);
      if (!in.active) return fail(kStatusTimedOut);
      const std::size_t packet = in.buffer.size();
      const std::size_t n = std::min<std::size_t>(packet, w_length - r.in_data.size());
      r.in_data.insert(r.in_data.end(), in.buffer.begin(),
                       in.buffer.begin() + static_cast<std::ptrdiff_t>(n));
      complete(kEp0In, packet);
      if (packet < kEp0Size || r.in_data.size() >= w_length) break;
    }
    // Status stage: a zero-length OUT packet from the host.
    if (stalled()) return fail(usbip::kStatusStall);
    if (!dcd_.PendingOn(kEp0Out).active) return fail(kStatusTimedOut);
    complete(kEp0Out, 0);
    r.actual_length = static_cast<std::uint32_t>(r.in_data.size());
    return r;
  }
  if (!setup.DeviceToHost() && w_length > 0) {
    std::size_t sent = 0;
    const std::size_t total = std::min<std::size_t>(w_length, out_data.size());
    while (sent < total) {
      if (stalled()) return fail(usbip::kStatusStall);
      EmuDcd::Pending& out = dcd_.PendingOn(kEp0Out);
      if (!out.active) return fail(kStatusTimedOut);
      const std::size_t n = std::min<std::size_t>({kEp0Size, total - sent, out.buffer.size()});
      std::copy_n(out_data.begin() + static_cast<std::ptrdiff_t>(sent), n, out.buffer.begin());
      sent += n;
      complete(kEp0Out, n);
    }
    r.actual_length = static_cast<std::uint32_t>(sent);
  }
  // Status stage: a zero-length IN packet from the device.
  if (stalled()) return fail(usbip::kStatusStall);
  if (!dcd_.PendingOn(kEp0In).active) return fail(kStatusTimedOut);
  complete(kEp0In, 0);
  return r;
}

void UsbAppDevice::Submit(Urb urb) {
  if (urb.endpoint == 0) {
    const UrbResult r = Control(urb.setup, urb.out_data, urb.length);
    if (sink_ != nullptr) sink_->Complete(urb, r);
    return;
  }
  const auto ep_addr = static_cast<std::uint8_t>(
      urb.endpoint | (urb.direction == usbip::Direction::kIn ? 0x80 : 0x00));
  if (!dcd_.IsOpen(ep_addr) || dcd_.Stalled(ep_addr)) {
    UrbResult r;
    r.status = usbip::kStatusStall;
    if (sink_ != nullptr) sink_->Complete(urb, r);
    return;
  }
  (urb.direction == usbip::Direction::kIn ? in_urbs_ : out_urbs_).push_back(std::move(urb));
  Service();
}

bool UsbAppDevice::Unlink(std::uint32_t seqnum) {
  for (auto* queue : {&in_urbs_, &out_urbs_}) {
    const auto it = std::find_if(queue->begin(), queue->end(),
                                 [&](const Urb& u) { return u.seqnum == seqnum; });
    if (it != queue->end()) {
      queue->erase(it);
      return true;
    }
  }
  return false;
}

void UsbAppDevice::FailStalled() {
  std::vector<Urb> failed;
  for (auto* queue : {&in_urbs_, &out_urbs_}) {
    for (auto it = queue->begin(); it != queue->end();) {
      const auto ep_addr = static_cast<std::uint8_t>(
          it->endpoint | (it->direction == usbip::Direction::kIn ? 0x80 : 0));
      if (dcd_.IsOpen(ep_addr) && !dcd_.Stalled(ep_addr)) {
        ++it;
      } else {
        failed.push_back(std::move(*it));
        it = queue->erase(it);
      }
    }
  }
  UrbResult r;
  r.status = usbip::kStatusStall;
  for (const Urb& urb : failed) {
    if (sink_ != nullptr) sink_->Complete(urb, r);
  }
}

void UsbAppDevice::StartFrame(bool limit, std::uint64_t frame_start_us) {
  frame_limit_ = limit;
  frame_start_us_ = frame_start_us;
  in_left_ = 1;
  out_left_ = 1;
}

void UsbAppDevice::EndFrame() {
  in_left_ = 0;
  out_left_ = 0;
}

bool UsbAppDevice::WaitingForInUrb() const {
  if (sink_ == nullptr) return false;
  for (std::uint8_t ep = 1; ep < 16; ++ep) {
    const auto ep_addr = static_cast<std::uint8_t>(ep | 0x80);
    if (!dcd_.IsOpen(ep_addr) || !dcd_.PendingOnConst(ep_addr).active) continue;
    const bool queued = std::any_of(in_urbs_.begin(), in_urbs_.end(),
                                    [&](const Urb& u) { return (u.endpoint | 0x80) == ep_addr; });
    if (!queued) return true;
  }
  return false;
}

bool UsbAppDevice::NeedsFrame() const {
  for (std::uint8_t ep = 1; ep < 16; ++ep) {
    const auto in = static_cast<std::uint8_t>(ep | 0x80);
    if (dcd_.IsOpen(in) && dcd_.PendingOnConst(in).active) return true;
    if (dcd_.IsOpen(ep) && dcd_.PendingOnConst(ep).active &&
        std::any_of(out_urbs_.begin(), out_urbs_.end(),
                    [&](const Urb& u) { return u.endpoint == ep; })) {
      return true;
    }
  }
  return false;
}

bool UsbAppDevice::ServiceIn(std::uint8_t ep_addr) {
  EmuDcd::Pending& p = dcd_.PendingOn(ep_addr);
  const auto it = std::find_if(in_urbs_.begin(), in_urbs_.end(),
                               [&](const Urb& u) { return (u.endpoint | 0x80) == ep_addr; });
  if (!p.active || it == in_urbs_.end()) return false;
  if (frame_limit_ && in_left_ == 0) return false;
  --in_left_;
  const Urb urb = std::move(*it);
  in_urbs_.erase(it);
  UrbResult r;
  const std::size_t n = std::min<std::size_t>(p.buffer.size(), urb.length);
  r.in_data.assign(p.buffer.begin(), p.buffer.begin() + static_cast<std::ptrdiff_t>(n));
  r.actual_length = static_cast<std::uint32_t>(n);
  const std::size_t sent = p.buffer.size();
  p = {};
  if (in_stamp_ != nullptr) in_stamp_->store(frame_start_us_, std::memory_order_release);
  if (sink_ != nullptr) sink_->Complete(urb, r);
  stack_.OnTransferComplete(ep_addr, static_cast<std::uint16_t>(sent));
  stack_.Task();
  return true;
}

bool UsbAppDevice::ServiceOut(std::uint8_t ep_addr) {
  EmuDcd::Pending& p = dcd_.PendingOn(ep_addr);
  const auto it = std::find_if(out_urbs_.begin(), out_urbs_.end(),
                               [&](const Urb& u) { return u.endpoint == ep_addr; });
  if (!p.active || it == out_urbs_.end()) return false;
  if (frame_limit_ && out_left_ == 0) return false;
  --out_left_;
  const Urb urb = std::move(*it);
  out_urbs_.erase(it);
  UrbResult r;
  const std::size_t n = std::min(p.buffer.size(), urb.out_data.size());
  std::copy_n(urb.out_data.begin(), n, p.buffer.begin());
  r.actual_length = static_cast<std::uint32_t>(n);
  // More data than the endpoint buffer takes is babble on a real bus (-EOVERFLOW).
  if (urb.out_data.size() > p.buffer.size()) r.status = -75;
  p = {};
  if (sink_ != nullptr) sink_->Complete(urb, r);
  stack_.OnTransferComplete(ep_addr, static_cast<std::uint16_t>(n));
  stack_.Task();
  return true;
}

void UsbAppDevice::Service() {
  stack_.Task();
  bool progress = true;
  while (progress) {
    FailStalled();
    progress = false;
    for (std::uint8_t ep = 1; ep < 16; ++ep) {
      if (!in_urbs_.empty()) progress = ServiceIn(static_cast<std::uint8_t>(ep | 0x80)) || progress;
      if (!out_urbs_.empty()) progress = ServiceOut(ep) || progress;
    }
  }
}

}  // namespace vibid::emu
