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
  switch (static_cast<DfuRequest>(setup.b_request)) {
    case DfuRequest::kDetach:
      if (setup.DeviceToHost() || setup.w_length != 0) break;
      return ControlReply::Accept();
    case DfuRequest::kGetStatus:
      if (!setup.DeviceToHost()) break;
      scratch[0] = 0;  // bStatus: OK
      scratch[1] = 0;  // bwPollTimeout (24 bit, ms): nothing to wait for
      scratch[2] = 0;
      scratch[3] = 0;
      scratch[4] = static_cast<std::uint8_t>(state_);  // bState
      scratch[5] = 0;                                  // iString
      return ControlReply::Data(scratch.first(6));
    case DfuRequest::kGetState:
      if (!setup.DeviceToHost()) break;
      scratch[0] = static_cast<std::uint8_t>(state_);
      return ControlReply::Data(scratch.first(1));
    default: break;
  }
  return ControlReply::Stall();
}

void DfuRuntime::OnControlComplete(const SetupPacket& setup) {
  if (setup.Type() == RequestType::kClass &&
      setup.b_request == static_cast<std::uint8_t>(DfuRequest::kDetach)) {
    state_ = DfuState::kAppDetach;
    handler_.OnDetach(setup.w_value);
  }
}

}  // namespace vibid::fw::usb
