// DFU 1.1 run-time interface (DFU 1.1 §4.1): lets a host switch the running firmware to the
// bootloader with DFU_DETACH. The functional descriptor sets bitWillDetach, so after the request's
// status stage the handler leaves for the bootloader without waiting for a bus reset.
#pragma once

#include <cstdint>
#include <span>

#include "vibid/fw/usb/class_driver.hpp"
#include "vibid/shared/dfu.hpp"

namespace vibid::fw::usb {

/// What the port does on DFU_DETACH: typically a jump to the ROM bootloader.
class DfuDetachHandler {
 public:
  /// Called in thread context after the host acknowledged DFU_DETACH. `timeout_ms` is wValue.
  virtual void OnDetach(std::uint16_t timeout_ms) = 0;

 protected:
  ~DfuDetachHandler() = default;
};

class DfuRuntime final : public ClassDriver {
 public:
  explicit DfuRuntime(DfuDetachHandler& handler) : handler_(handler) {}

  dfu::State state() const { return state_; }

  bool OwnsInterface(std::uint8_t interface_number) const override;
  bool OwnsEndpoint(std::uint8_t) const override { return false; }
  Status Open(Dcd&) override { return Status::kOk; }
  void Close() override { state_ = dfu::State::kAppIdle; }
  ControlReply OnControlRequest(const SetupPacket& setup, std::span<std::uint8_t> scratch) override;
  bool OnControlData(const SetupPacket&, std::span<const std::uint8_t>) override { return false; }
  void OnControlComplete(const SetupPacket& setup) override;
  void OnTransferComplete(std::uint8_t, std::uint16_t) override {}
  void OnEndpointHalt(std::uint8_t, bool) override {}

 private:
  DfuDetachHandler& handler_;
  dfu::State state_ = dfu::State::kAppIdle;
};

}  // namespace vibid::fw::usb
