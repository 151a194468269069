#include "vibid/fw/usb/device.hpp"

#include <algorithm>

namespace vibid::fw::usb {
namespace {

constexpr std::uint8_t kEp0Out = 0x00;
constexpr std::uint8_t kEp0In = 0x80;

}  // namespace

UsbDevice::UsbDevice(Dcd& dcd, std::span<ClassDriver* const> drivers,
                     const DescriptorSet& descriptors)
    : dcd_(dcd), descriptors_(descriptors) {
  driver_count_ = std::min(drivers.size(), kMaxDrivers);
  std::copy_n(drivers.begin(), driver_count_, drivers_.begin());
}

Status UsbDevice::Start() {
  const Status s = dcd_.Init(*this);
  if (s != Status::kOk) return s;
  state_ = DeviceState::kPowered;
  dcd_.Connect();
  return Status::kOk;
}

// ---- Event queue (interrupt side) -------------------------------------------------------------

void UsbDevice::Push(const Event& e) {
  const std::uint8_t head = head_.load(std::memory_order_relaxed);
  const auto next = static_cast<std::uint8_t>((head + 1U) % kEventQueueSize);
  if (next == tail_.load(std::memory_order_acquire)) {
    ++counters_.event_overflows;
    return;
  }
  events_[head] = e;
  head_.store(next, std::memory_order_release);
}

void UsbDevice::OnBusReset() { Push(Event{EventKind::kBusReset, 0, 0, {}}); }

void UsbDevice::OnSetupReceived(std::span<const std::uint8_t, 8> setup) {
  Event e{EventKind::kSetup, 0, 0, {}};
  std::copy(setup.begin(), setup.end(), e.setup.begin());
  Push(e);
}

void UsbDevice::OnTransferComplete(std::uint8_t ep_addr, std::uint16_t length) {
  Push(Event{EventKind::kTransferComplete, ep_addr, length, {}});
}

void UsbDevice::OnSuspend() { Push(Event{EventKind::kSuspend, 0, 0, {}}); }
void UsbDevice::OnResume() { Push(Event{EventKind::kResume, 0, 0, {}}); }

// ---- Event handling (thread side) -------------------------------------------------------------

void UsbDevice::Task() {
  std::uint8_t tail = tail_.load(std::memory_order_relaxed);
  while (tail != head_.load(std::memory_order_acquire)) {
    const Event e = events_[tail];
    tail = static_cast<std::uint8_t>((tail + 1U) % kEventQueueSize);
    tail_.store(tail, std::memory_order_release);
    switch (e.kind) {
      case EventKind::kBusReset: HandleBusReset(); break;
      case EventKind::kSetup:
        // The controller abandoned this SETUP's transfer when a newer SETUP or a bus reset
        // arrived (USB 2.0 §8.5.3; the drivers drop endpoint 0's pending data then). Answering it
        // now would arm its data or its stall on the newer transfer.
        if (NewerSetupQueued(tail)) {
          ++counters_.superseded_setups;
          break;
        }
        HandleSetup(SetupPacket::Decode(e.setup));
        break;
      case EventKind::kTransferComplete:
        // An endpoint 0 completion of a transfer a newer SETUP (or a bus reset) abandoned: going
        // on would arm that old transfer's next stage on endpoint 0 under the newer one.
        if (EpNumber(e.ep_addr) == 0 && NewerSetupQueued(tail)) {
          ++counters_.superseded_completions;
          break;
        }
        HandleTransferComplete(e.ep_addr, e.length);
        break;
      case EventKind::kSuspend:
        suspended_ = true;
        ++counters_.suspends;
        break;
      case EventKind::kResume: suspended_ = false; break;
    }
  }
}

bool UsbDevice::NewerSetupQueued(std::uint8_t from) const {
  // Only the interrupt writes events, and only at head: the slots up to head are stable here.
  const std::uint8_t head = head_.load(std::memory_order_acquire);
  for (std::uint8_t i = from; i != head;
       i = static_cast<std::uint8_t>((i + 1U) % kEventQueueSize)) {
    if (events_[i].kind == EventKind::kSetup || events_[i].kind == EventKind::kBusReset)
      return true;
  }
  return false;
}

void UsbDevice::HandleBusReset() {
  ++counters_.bus_resets;
  for (std::size_t i = 0; i < driver_count_; ++i) drivers_[i]->Close();
  dcd_.EndpointCloseAll();
  state_ = DeviceState::kDefault;
  suspended_ = false;
  address_ = 0;
  configuration_ = 0;
  halted_.fill(false);
  stage_ = ControlStage::kIdle;
}

void UsbDevice::HandleSetup(const SetupPacket& setup) {
  ++counters_.setups;
  // A SETUP always starts a new control transfer, abandoning any unfinished one (USB 2.0 §8.5.3).
  setup_ = setup;
  stage_ = ControlStage::kIdle;
  control_owner_ = nullptr;
  in_sent_ = 0;
  out_received_ = 0;

  ControlReply reply = ControlReply::Stall();
  const std::uint8_t target = static_cast<std::uint8_t>(setup.w_index & 0xFF);
  switch (setup.Type()) {
    case RequestType::kStandard:
      if (setup.To() == Recipient::kInterface &&
          setup.b_request == static_cast<std::uint8_t>(StandardRequest::kGetDescriptor)) {
        // Class descriptors (HID, report) are fetched with a standard request to the interface.
        control_owner_ = Configured() ? DriverForInterface(target) : nullptr;
        if (control_owner_ != nullptr)
          reply = control_owner_->OnControlRequest(setup, control_buffer_);
      } else {
        reply = StandardRequest(setup);
      }
      break;
    case RequestType::kClass:
      if (Configured()) {
        if (setup.To() == Recipient::kInterface) control_owner_ = DriverForInterface(target);
        if (setup.To() == Recipient::kEndpoint) control_owner_ = DriverForEndpoint(target);
      }
      if (control_owner_ != nullptr)
        reply = control_owner_->OnControlRequest(setup, control_buffer_);
      break;
    case RequestType::kVendor:
    case RequestType::kReserved: break;
  }

  switch (reply.kind) {
    case ControlReply::Kind::kStall: StallControl(); return;
    case ControlReply::Kind::kData:
      if (!setup.DeviceToHost()) {
        StallControl();
        return;
      }
      if (setup.w_length == 0) {
        SendStatusIn();
        return;
      }
      // Never more than the host asked for; a shorter answer that fills whole packets needs a
      // zero-length packet so the host sees the data stage end (USB 2.0 §5.5.3).
      in_data_ = reply.data.first(std::min<std::size_t>(reply.data.size(), setup.w_length));
      in_needs_zlp_ = in_data_.size() < setup.w_length && in_data_.size() % kEp0Size == 0;
      stage_ = ControlStage::kDataIn;
      SendNextInPacket();
      return;
    case ControlReply::Kind::kAccept:
      if (setup.w_length == 0) {
        SendStatusIn();
        return;
      }
      if (setup.DeviceToHost() || setup.w_length > control_buffer_.size()) {
        StallControl();
        return;
      }
      stage_ = ControlStage::kDataOut;
      ArmOutPacket();
      return;
  }
}

void UsbDevice::HandleTransferComplete(std::uint8_t ep_addr, std::uint16_t length) {
  if (EpNumber(ep_addr) != 0) {
    if (ClassDriver* d = DriverForEndpoint(ep_addr); d != nullptr && Configured()) {
      d->OnTransferComplete(ep_addr, length);
    }
    return;
  }
  if (ep_addr == kEp0In) {
    switch (stage_) {
      case ControlStage::kDataIn:
        if (in_sent_ < in_data_.size() || in_needs_zlp_) {
          SendNextInPacket();
        } else {
          ArmStatusOut();
        }
        return;
      case ControlStage::kStatusIn:
        stage_ = ControlStage::kIdle;
        if (setup_.Type() == RequestType::kStandard &&
            setup_.b_request == static_cast<std::uint8_t>(StandardRequest::kSetAddress)) {
          address_ = pending_address_;
          state_ = address_ != 0 ? DeviceState::kAddress : DeviceState::kDefault;
        }
        if (control_owner_ != nullptr) control_owner_->OnControlComplete(setup_);
        return;
      default: return;  // A completion left over from a transfer a new SETUP abandoned.
    }
  }
  switch (stage_) {
    case ControlStage::kDataOut: {
      out_received_ += length;
      if (out_received_ < setup_.w_length && length == kEp0Size) {
        ArmOutPacket();
        return;
      }
      const auto data = std::span<const std::uint8_t>(control_buffer_).first(out_received_);
      if (control_owner_ == nullptr || !control_owner_->OnControlData(setup_, data)) {
        StallControl();
        return;
      }
      SendStatusIn();
      return;
    }
    case ControlStage::kStatusOut:
      stage_ = ControlStage::kIdle;
      if (control_owner_ != nullptr) control_owner_->OnControlComplete(setup_);
      return;
    default: return;
  }
}

// ---- Endpoint 0 stages ------------------------------------------------------------------------

void UsbDevice::StallControl() {
  ++counters_.stalled_requests;
  stage_ = ControlStage::kIdle;
  dcd_.EndpointStall(kEp0In);
  dcd_.EndpointStall(kEp0Out);
}

void UsbDevice::SendNextInPacket() {
  const std::size_t chunk = std::min<std::size_t>(kEp0Size, in_data_.size() - in_sent_);
  if (chunk == 0) in_needs_zlp_ = false;
  std::copy_n(in_data_.begin() + static_cast<std::ptrdiff_t>(in_sent_), chunk, ep0_packet_.begin());
  in_sent_ += chunk;
  (void)dcd_.Transfer(kEp0In, std::span<std::uint8_t>(ep0_packet_).first(chunk));
}

void UsbDevice::ArmOutPacket() {
  const std::size_t chunk = std::min<std::size_t>(kEp0Size, setup_.w_length - out_received_);
  (void)dcd_.Transfer(kEp0Out,
                      std::span<std::uint8_t>(control_buffer_).subspan(out_received_, chunk));
}

void UsbDevice::SendStatusIn() {
  stage_ = ControlStage::kStatusIn;
  (void)dcd_.Transfer(kEp0In, std::span<std::uint8_t>(ep0_packet_).first(0));
}

void UsbDevice::ArmStatusOut() {
  stage_ = ControlStage::kStatusOut;
  (void)dcd_.Transfer(kEp0Out, std::span<std::uint8_t>(ep0_packet_).first(0));
}

// ---- Standard requests (USB 2.0 §9.4) ---------------------------------------------------------

ControlReply UsbDevice::StandardRequest(const SetupPacket& setup) {
  switch (setup.To()) {
    case Recipient::kDevice: return DeviceRequest(setup);
    case Recipient::kInterface: return InterfaceRequest(setup);
    case Recipient::kEndpoint: return EndpointRequest(setup);
    default: return ControlReply::Stall();
  }
}

ControlReply UsbDevice::DeviceRequest(const SetupPacket& setup) {
  auto& buf = control_buffer_;
  switch (static_cast<usb::StandardRequest>(setup.b_request)) {
    case StandardRequest::kGetStatus:
      if (!setup.DeviceToHost() || setup.w_value != 0 || setup.w_index != 0) break;
      buf[0] = 0;  // Bus powered, remote wakeup not enabled.
      buf[1] = 0;
      return ControlReply::Data(std::span<const std::uint8_t>(buf).first(2));
    case StandardRequest::kSetAddress:
      if (setup.DeviceToHost() || setup.w_value > 127 || setup.w_index != 0 ||
          setup.w_length != 0 || state_ == DeviceState::kConfigured) {
        break;
      }
      pending_address_ = static_cast<std::uint8_t>(setup.w_value);
      dcd_.SetAddress(pending_address_);
      return ControlReply::Accept();
    case StandardRequest::kGetDescriptor:
      if (!setup.DeviceToHost()) break;
      return GetDescriptor(setup);
    case StandardRequest::kGetConfiguration:
      if (!setup.DeviceToHost() || state_ == DeviceState::kDefault) break;
      buf[0] = configuration_;
      return ControlReply::Data(std::span<const std::uint8_t>(buf).first(1));
    case StandardRequest::kSetConfiguration:
      if (setup.DeviceToHost() || setup.w_length != 0 || setup.ValueHigh() != 0 ||
          (state_ != DeviceState::kAddress && state_ != DeviceState::kConfigured)) {
        break;
      }
      return SetConfiguration(setup.ValueLow());
    default:
      // CLEAR/SET_FEATURE: no remote wakeup (bmAttributes bit 5 clear) and no test modes at full
      // speed; SET_DESCRIPTOR: descriptors are fixed. All are request errors.
      break;
  }
  return ControlReply::Stall();
}

ControlReply UsbDevice::SetConfiguration(std::uint8_t value) {
  // bConfigurationValue is byte 5 of the configuration descriptor (USB 2.0 table 9-10).
  const std::uint8_t configuration_value =
      descriptors_.configuration.size() > 5 ? descriptors_.configuration[5] : 0;
  if (value != 0 && value != configuration_value) return ControlReply::Stall();
  for (std::size_t i = 0; i < driver_count_; ++i) drivers_[i]->Close();
  dcd_.EndpointCloseAll();
  halted_.fill(false);
  configuration_ = 0;
  state_ = DeviceState::kAddress;
  if (value == 0) return ControlReply::Accept();
  // Drivers may arm transfers as soon as they open, so the state is configured before Open.
  configuration_ = value;
  state_ = DeviceState::kConfigured;
  for (std::size_t i = 0; i < driver_count_; ++i) {
    if (drivers_[i]->Open(dcd_) != Status::kOk) {
      for (std::size_t j = 0; j <= i; ++j) drivers_[j]->Close();
      dcd_.EndpointCloseAll();
      configuration_ = 0;
      state_ = DeviceState::kAddress;
      return ControlReply::Stall();
    }
  }
  return ControlReply::Accept();
}

ControlReply UsbDevice::GetDescriptor(const SetupPacket& setup) {
  const std::uint8_t index = setup.ValueLow();
  switch (static_cast<DescriptorType>(setup.ValueHigh())) {
    case DescriptorType::kDevice:
      if (index != 0) break;
      return ControlReply::Data(descriptors_.device);
    case DescriptorType::kConfiguration:
      if (index != 0) break;
      return ControlReply::Data(descriptors_.configuration);
    case DescriptorType::kString: {
      auto out = std::span<std::uint8_t, kMaxStringDescriptorSize>(control_buffer_.data(),
                                                                   kMaxStringDescriptorSize);
      std::size_t n = 0;
      if (index == kStringLanguages) {
        out[0] = 4;
        out[1] = static_cast<std::uint8_t>(DescriptorType::kString);
        out[2] = 0x09;  // wLANGID[0] = 0x0409, English (United States)
        out[3] = 0x04;
        n = 4;
      } else if (index <= descriptors_.strings.size() &&
                 descriptors_.strings[index - 1U] != nullptr) {
        n = BuildStringDescriptor(descriptors_.strings[index - 1U], kMaxSerialLength, out);
      } else {
        return ControlReply::Stall();
      }
      return ControlReply::Data(std::span<const std::uint8_t>(out).first(n));
    }
    default:
      // Includes DEVICE_QUALIFIER: a full-speed-only device answers it with a request error
      // (USB 2.0 §9.6.2).
      break;
  }
  return ControlReply::Stall();
}

ControlReply UsbDevice::InterfaceRequest(const SetupPacket& setup) {
  const auto interface_number = static_cast<std::uint8_t>(setup.w_index & 0xFF);
  if (!Configured() || DriverForInterface(interface_number) == nullptr)
    return ControlReply::Stall();
  auto& buf = control_buffer_;
  switch (static_cast<usb::StandardRequest>(setup.b_request)) {
    case StandardRequest::kGetStatus:
      if (!setup.DeviceToHost() || setup.w_value != 0) break;
      buf[0] = 0;  // Interface status is reserved, all zero (USB 2.0 figure 9-5).
      buf[1] = 0;
      return ControlReply::Data(std::span<const std::uint8_t>(buf).first(2));
    case StandardRequest::kGetInterface:
      if (!setup.DeviceToHost() || setup.w_value != 0) break;
      buf[0] = 0;  // Only alternate setting 0 exists.
      return ControlReply::Data(std::span<const std::uint8_t>(buf).first(1));
    case StandardRequest::kSetInterface:
      if (setup.DeviceToHost() || setup.w_value != 0) break;
      return ControlReply::Accept();
    default: break;  // No interface features are defined.
  }
  return ControlReply::Stall();
}

bool UsbDevice::EndpointValid(std::uint8_t ep_addr) const {
  if ((ep_addr & 0x70) != 0) return false;
  if (EpNumber(ep_addr) == 0) return state_ == DeviceState::kAddress || Configured();
  return Configured() && DriverForEndpoint(ep_addr) != nullptr;
}

std::size_t UsbDevice::HaltIndex(std::uint8_t ep_addr) const {
  return EpNumber(ep_addr) + (IsIn(ep_addr) ? 16U : 0U);
}

ControlReply UsbDevice::EndpointRequest(const SetupPacket& setup) {
  const auto ep = static_cast<std::uint8_t>(setup.w_index & 0xFF);
  if (!EndpointValid(ep)) return ControlReply::Stall();
  auto& buf = control_buffer_;
  switch (static_cast<usb::StandardRequest>(setup.b_request)) {
    case StandardRequest::kGetStatus:
      if (!setup.DeviceToHost() || setup.w_value != 0) break;
      buf[0] = halted_[HaltIndex(ep)] ? 1 : 0;  // Bit 0: Halt (USB 2.0 figure 9-6).
      buf[1] = 0;
      return ControlReply::Data(std::span<const std::uint8_t>(buf).first(2));
    case StandardRequest::kClearFeature:
      if (setup.DeviceToHost() || setup.w_value != kFeatureEndpointHalt || setup.w_length != 0)
        break;
      halted_[HaltIndex(ep)] = false;
      if (EpNumber(ep) != 0) {
        dcd_.EndpointClearStall(ep);
        DriverForEndpoint(ep)->OnEndpointHalt(ep, false);
      }
      return ControlReply::Accept();
    case StandardRequest::kSetFeature:
      // Halting the default control pipe is neither required nor recommended (USB 2.0 §9.4.5).
      if (setup.DeviceToHost() || setup.w_value != kFeatureEndpointHalt || setup.w_length != 0 ||
          EpNumber(ep) == 0) {
        break;
      }
      dcd_.EndpointStall(ep);
      halted_[HaltIndex(ep)] = true;
      DriverForEndpoint(ep)->OnEndpointHalt(ep, true);
      return ControlReply::Accept();
    default: break;  // SYNCH_FRAME is for isochronous endpoints only.
  }
  return ControlReply::Stall();
}

ClassDriver* UsbDevice::DriverForInterface(std::uint8_t interface_number) const {
  for (std::size_t i = 0; i < driver_count_; ++i) {
    if (drivers_[i]->OwnsInterface(interface_number)) return drivers_[i];
  }
  return nullptr;
}

ClassDriver* UsbDevice::DriverForEndpoint(std::uint8_t ep_addr) const {
  for (std::size_t i = 0; i < driver_count_; ++i) {
    if (drivers_[i]->OwnsEndpoint(ep_addr)) return drivers_[i];
  }
  return nullptr;
}

}  // namespace vibid::fw::usb
