#include "emu_dcd.hpp"

namespace vibid::emu {

Status EmuDcd::Init(fw::usb::DcdEvents& events) {
  events_ = &events;
  open_.fill(false);
  open_[Index(kEp0In)] = open_[Index(kEp0Out)] = true;
  return Status::kOk;
}

Status EmuDcd::EndpointOpen(std::uint8_t ep_addr, fw::usb::EndpointType, std::uint16_t max_packet) {
  if ((ep_addr & 0x0F) == 0 || max_packet > 64) return Status::kResourceExhausted;
  open_[Index(ep_addr)] = true;
  stalled_[Index(ep_addr)] = false;
  pending_[Index(ep_addr)] = {};
  return Status::kOk;
}

void EmuDcd::EndpointCloseAll() {
  for (std::size_t i = 0; i < 32; ++i) {
    if (i % 16 == 0) continue;
    open_[i] = false;
    stalled_[i] = false;
    pending_[i] = {};
  }
}

void EmuDcd::EndpointStall(std::uint8_t ep_addr) {
  stalled_[Index(ep_addr)] = true;
  pending_[Index(ep_addr)] = {};
}

void EmuDcd::EndpointClearStall(std::uint8_t ep_addr) { stalled_[Index(ep_addr)] = false; }

Status EmuDcd::Transfer(std::uint8_t ep_addr, std::span<std::uint8_t> buffer) {
  if (!open_[Index(ep_addr)]) return Status::kInvalidArgument;
  Pending& p = pending_[Index(ep_addr)];
  if (p.active) return Status::kUnavailable;
  p = Pending{true, buffer};
  return Status::kOk;
}

void EmuDcd::OnSetupArrived() {
  for (std::uint8_t ep : {kEp0In, kEp0Out}) {
    stalled_[Index(ep)] = false;
    pending_[Index(ep)] = {};
  }
}

}  // namespace vibid::emu
