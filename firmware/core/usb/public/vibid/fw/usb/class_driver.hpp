// A class driver (HID, DFU run-time) as the device stack sees it: it owns some interfaces and
// endpoints, answers the control requests addressed to them, and gets its endpoints' completions.
#pragma once

#include <cstdint>
#include <span>

#include "vibid/fw/usb/dcd.hpp"
#include "vibid/fw/usb/usb_types.hpp"

namespace vibid::fw::usb {

/// What a driver wants done with a control request after its SETUP stage.
struct ControlReply {
  enum class Kind : std::uint8_t {
    kStall,   ///< Not supported or not valid now: STALL the data/status stage.
    kAccept,  ///< No data stage, or an OUT data stage to receive into the stack's buffer.
    kData,    ///< IN data stage: send `data` (truncated to wLength by the stack).
  };
  Kind kind = Kind::kStall;
  std::span<const std::uint8_t> data{};

  static ControlReply Stall() { return {}; }
  static ControlReply Accept() { return {Kind::kAccept, {}}; }
  static ControlReply Data(std::span<const std::uint8_t> d) { return {Kind::kData, d}; }
};

class ClassDriver {
 public:
  /// True when the interface number belongs to this driver.
  virtual bool OwnsInterface(std::uint8_t interface_number) const = 0;
  /// True when the endpoint address belongs to this driver.
  virtual bool OwnsEndpoint(std::uint8_t ep_addr) const = 0;
  /// SET_CONFIGURATION with a nonzero value: open endpoints, arm OUT transfers.
  /// @returns kOk, or the driver's EndpointOpen failure (the configuration is then refused).
  virtual Status Open(Dcd& dcd) = 0;
  /// Bus reset or SET_CONFIGURATION 0: drop transfers in flight, endpoints are closed.
  virtual void Close() = 0;
  /// A class request, or a standard GET_DESCRIPTOR to one of its interfaces. `scratch` is the
  /// stack's control buffer, usable for a reply built on the fly.
  virtual ControlReply OnControlRequest(const SetupPacket& setup,
                                        std::span<std::uint8_t> scratch) = 0;
  /// The OUT data stage of an accepted request arrived complete (before the status stage).
  /// @returns false to STALL the status stage.
  virtual bool OnControlData(const SetupPacket& setup, std::span<const std::uint8_t> data) = 0;
  /// The status stage of an accepted request completed (the host has seen the acknowledgement).
  virtual void OnControlComplete(const SetupPacket& setup) = 0;
  /// A transfer on one of its endpoints completed.
  virtual void OnTransferComplete(std::uint8_t ep_addr, std::uint16_t length) = 0;
  /// The host halted one of its endpoints (SET_FEATURE, the pending transfer is abandoned) or
  /// cleared the halt (CLEAR_FEATURE, the endpoint is usable again from DATA0).
  virtual void OnEndpointHalt(std::uint8_t ep_addr, bool halted) = 0;

 protected:
  ~ClassDriver() = default;
};

}  // namespace vibid::fw::usb
