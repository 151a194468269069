#include "vibid/fw/usb/dfu_runtime.hpp"

#include "vibid/fw/usb/descriptors.hpp"

namespace vibid::fw::usb {

bool DfuRuntime::OwnsInterface(std::uint8_t interface_number) const {
  return interface_number == kDfuInterface;
}

ControlReply DfuRuntime::OnControlRequest(const SetupPacket& setup,
                                          std::span<std::uint8_t> scratch) {
  if (setup.Type() != RequestType::kClass) return ControlReply::Stall();
  // In appIDLE only DETACH, GETSTATUS and GETSTATE are valid (DFU 1.1 §6.1.2); the rest stall.
  switch (static_cast<dfu::Request>(setup.b_request)) {
    case dfu::Request::kDetach:
      if (setup.DeviceToHost() || setup.w_length != 0) break;
      return ControlReply::Accept();
    case dfu::Request::kGetStatus:
      if (!setup.DeviceToHost()) break;
      // The run-time interface does nothing that needs polling: no poll timeout.
      dfu::Encode(dfu::StatusReply{dfu::Status::kOk, 0, state_},
                  scratch.first<dfu::kStatusReplyBytes>());
      return ControlReply::Data(scratch.first(dfu::kStatusReplyBytes));
    case dfu::Request::kGetState:
      if (!setup.DeviceToHost()) break;
      scratch[0] = static_cast<std::uint8_t>(state_);
      return ControlReply::Data(scratch.first(1));
    default: break;
  }
  return ControlReply::Stall();
}

void DfuRuntime::OnControlComplete(const SetupPacket& setup) {
  if (setup.Type() == RequestType::kClass &&
      setup.b_request == static_cast<std::uint8_t>(dfu::Request::kDetach)) {
    state_ = dfu::State::kAppDetach;
    handler_.OnDetach(setup.w_value);
  }
}

}  // namespace vibid::fw::usb
