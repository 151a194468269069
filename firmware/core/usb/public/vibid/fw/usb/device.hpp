// The USB device stack: endpoint-0 control transfers (SETUP / DATA / STATUS stages), the
// standard requests of USB 2.0 §9.4, the device state (default / address / configured), and the
// dispatch of class requests and endpoint completions to the class drivers.
//
// Driver events arrive through the DcdEvents interface (interrupt context) and are queued;
// Task() handles them in thread context, so class drivers and the code using them never run
// concurrently with the stack.
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <span>

#include "vibid/fw/usb/class_driver.hpp"
#include "vibid/fw/usb/dcd.hpp"
#include "vibid/fw/usb/descriptors.hpp"
#include "vibid/fw/usb/usb_types.hpp"

namespace vibid::fw::usb {

/// USB 2.0 §9.1.1 device states the stack distinguishes (powered = attached, not yet reset).
enum class DeviceState : std::uint8_t { kDetached, kPowered, kDefault, kAddress, kConfigured };

/// Counters a port can report in get-info; none of these conditions is silent.
struct UsbCounters {
  std::uint32_t bus_resets = 0;
  std::uint32_t setups = 0;
  std::uint32_t stalled_requests = 0;
  std::uint32_t event_overflows = 0;  ///< Events lost because Task() ran too late.
  std::uint32_t suspends = 0;
  std::uint32_t superseded_setups = 0;  ///< SETUPs dropped because a newer one was queued.
  /// Endpoint 0 completions dropped because a newer SETUP or bus reset was queued behind them.
  std::uint32_t superseded_completions = 0;
};

class UsbDevice final : public DcdEvents {
 public:
  static constexpr std::size_t kMaxDrivers = 2;
  /// Largest control OUT data stage accepted (SET_REPORT carries one 64-byte report).
  static constexpr std::size_t kControlBufferSize = 128;
  static constexpr std::size_t kEventQueueSize = 16;

  /// `descriptors` (and what it points to) must outlive the device. Drivers are consulted in
  /// order for interface and endpoint ownership. SET_CONFIGURATION accepts 0 and the
  /// bConfigurationValue of the configuration descriptor.
  UsbDevice(Dcd& dcd, std::span<ClassDriver* const> drivers, const DescriptorSet& descriptors);

  /// Initializes the driver and attaches to the bus.
  /// @returns the driver's Init status; on failure the device stays detached.
  Status Start();

  /// Handles queued events. Call from the main loop (or a low-priority task), often enough that
  /// fewer than kEventQueueSize events pile up between calls.
  void Task();

  DeviceState state() const { return state_; }
  bool Configured() const { return state_ == DeviceState::kConfigured; }
  bool suspended() const { return suspended_; }
  std::uint8_t address() const { return address_; }
  const UsbCounters& counters() const { return counters_; }

  // DcdEvents (interrupt context: queue only).
  void OnBusReset() override;
  void OnSetupReceived(std::span<const std::uint8_t, 8> setup) override;
  void OnTransferComplete(std::uint8_t ep_addr, std::uint16_t length) override;
  void OnSuspend() override;
  void OnResume() override;

 private:
  enum class EventKind : std::uint8_t { kBusReset, kSetup, kTransferComplete, kSuspend, kResume };
  struct Event {
    EventKind kind;
    std::uint8_t ep_addr;
    std::uint16_t length;
    std::array<std::uint8_t, 8> setup;
  };
  enum class ControlStage : std::uint8_t { kIdle, kDataIn, kDataOut, kStatusIn, kStatusOut };

  void Push(const Event& e);
  /// True when a SETUP or bus reset is queued at or after slot `from`.
  bool NewerSetupQueued(std::uint8_t from) const;
  void HandleBusReset();
  void HandleSetup(const SetupPacket& setup);
  void HandleTransferComplete(std::uint8_t ep_addr, std::uint16_t length);

  ControlReply StandardRequest(const SetupPacket& setup);
  ControlReply DeviceRequest(const SetupPacket& setup);
  ControlReply InterfaceRequest(const SetupPacket& setup);
  ControlReply EndpointRequest(const SetupPacket& setup);
  ControlReply GetDescriptor(const SetupPacket& setup);
  ControlReply SetConfiguration(std::uint8_t value);
  ClassDriver* DriverForInterface(std::uint8_t interface_number) const;
  ClassDriver* DriverForEndpoint(std::uint8_t ep_addr) const;
  bool EndpointValid(std::uint8_t ep_addr) const;
  std::size_t HaltIndex(std::uint8_t ep_addr) const;

  void StallControl();
  void SendNextInPacket();
  void ArmOutPacket();
  void SendStatusIn();
  void ArmStatusOut();

  Dcd& dcd_;
  std::array<ClassDriver*, kMaxDrivers> drivers_{};
  std::size_t driver_count_ = 0;
  DescriptorSet descriptors_;

  DeviceState state_ = DeviceState::kDetached;
  bool suspended_ = false;
  std::uint8_t address_ = 0;
  std::uint8_t configuration_ = 0;
  std::array<bool, 32> halted_{};  ///< Per endpoint address (number + direction) halt feature.
  UsbCounters counters_{};

  // Control transfer in progress.
  ControlStage stage_ = ControlStage::kIdle;
  SetupPacket setup_{};
  ClassDriver* control_owner_ = nullptr;  ///< Null for standard requests the stack answers.
  std::span<const std::uint8_t> in_data_{};
  std::size_t in_sent_ = 0;
  bool in_needs_zlp_ = false;
  std::size_t out_received_ = 0;
  std::uint8_t pending_address_ = 0;
  alignas(4) std::array<std::uint8_t, kControlBufferSize> control_buffer_{};
  alignas(4) std::array<std::uint8_t, kEp0Size> ep0_packet_{};

  // Single-producer (interrupt) single-consumer (Task) event queue.
  std::array<Event, kEventQueueSize> events_{};
  std::atomic<std::uint8_t> head_{0};
  std::atomic<std::uint8_t> tail_{0};
};

}  // namespace vibid::fw::usb
