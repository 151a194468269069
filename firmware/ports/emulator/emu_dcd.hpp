// The emulator's USB device controller: implements the core's controller-driver contract
// (vibid/fw/usb/dcd.hpp) as a set of endpoint buffers the emulator's bus side
// (host/emulator/usb_app_device.hpp) fills and drains, so the core's stack runs exactly as on
// the board. A transfer the stack arms stays pending until the bus side completes it.
#pragma once

#include <array>
#include <cstdint>
#include <span>

#include "vibid/fw/usb/dcd.hpp"
#include "vibid/fw/usb/usb_types.hpp"

namespace vibid::emu {

class EmuDcd final : public fw::usb::Dcd {
 public:
  /// Endpoint 0's two directions, as the bus side addresses them.
  static constexpr std::uint8_t kEp0In = fw::usb::kDirIn;
  static constexpr std::uint8_t kEp0Out = 0x00;
  struct Pending {
    bool active = false;
    std::span<std::uint8_t> buffer{};
  };

  Status Init(fw::usb::DcdEvents& events) override;
  void Connect() override { connected_ = true; }
  void Disconnect() override { connected_ = false; }
  void SetAddress(std::uint8_t address) override { address_ = address; }
  Status EndpointOpen(std::uint8_t ep_addr, fw::usb::EndpointType type,
                      std::uint16_t max_packet) override;
  void EndpointCloseAll() override;
  void EndpointStall(std::uint8_t ep_addr) override;
  void EndpointClearStall(std::uint8_t ep_addr) override;
  Status Transfer(std::uint8_t ep_addr, std::span<std::uint8_t> buffer) override;

  bool connected() const { return connected_; }
  std::uint8_t address() const { return address_; }
  bool IsOpen(std::uint8_t ep_addr) const { return open_[Index(ep_addr)]; }
  bool Stalled(std::uint8_t ep_addr) const { return stalled_[Index(ep_addr)]; }
  Pending& PendingOn(std::uint8_t ep_addr) { return pending_[Index(ep_addr)]; }
  const Pending& PendingOnConst(std::uint8_t ep_addr) const { return pending_[Index(ep_addr)]; }
  /// The controller clears endpoint 0's halt and drops its transfers when a SETUP arrives.
  void OnSetupArrived();

 private:
  static std::size_t Index(std::uint8_t ep_addr) {
    return (ep_addr & 0x0F) + ((ep_addr & 0x80) != 0 ? 16U : 0U);
  }

  fw::usb::DcdEvents* events_ = nullptr;
  bool connected_ = false;
  std::uint8_t address_ = 0;
  std::array<bool, 32> open_{};
  std::array<bool, 32> stalled_{};
  std::array<Pending, 32> pending_{};
};

}  // namespace vibid::emu
