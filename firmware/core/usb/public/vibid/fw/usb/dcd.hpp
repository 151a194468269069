// The device-controller-driver contract: what the USB device stack needs from a port's USB
// peripheral (STM32 OTG_FS, the emulator's USB/IP export, a test fake), and the events the
// peripheral reports back. The stack never touches registers; a port never parses a request.
//
// Threading: the DcdEvents entry points are called from the port's USB interrupt and only queue
// the event; UsbDevice::Task() (thread context) handles it and calls back into the driver. Driver
// calls therefore come from thread context, so a driver masks its own interrupt around the
// register updates an event could race with.
#pragma once

#include <cstdint>
#include <span>

#include "vibid/fw/usb/usb_types.hpp"
#include "vibid/shared/status.hpp"

namespace vibid::fw::usb {

enum class EndpointType : std::uint8_t {
  kControl = 0,
  kIsochronous = 1,
  kBulk = 2,
  kInterrupt = 3
};

/// Events a driver reports (from its interrupt handler).
class DcdEvents {
 public:
  /// The host reset the bus: address 0, unconfigured, only endpoint 0 open.
  virtual void OnBusReset() = 0;
  /// A SETUP packet arrived on endpoint 0. A new SETUP aborts any control transfer in progress.
  virtual void OnSetupReceived(std::span<const std::uint8_t, 8> setup) = 0;
  /// A transfer submitted with Dcd::Transfer finished: IN sent completely, or OUT received
  /// `length` bytes (a short packet or the requested length ends an OUT transfer).
  virtual void OnTransferComplete(std::uint8_t ep_addr, std::uint16_t length) = 0;
  virtual void OnSuspend() = 0;
  virtual void OnResume() = 0;

 protected:
  ~DcdEvents() = default;
};

/// The controller driver a port implements.
class Dcd {
 public:
  /// Brings up the peripheral, endpoint 0 ready for SETUP. Events go to `events` from now on.
  /// @returns kOk, or kUnavailable when the peripheral does not come out of reset.
  virtual Status Init(DcdEvents& events) = 0;
  /// Attaches to the bus (pull-up on D+) / detaches.
  virtual void Connect() = 0;
  virtual void Disconnect() = 0;
  /// Called when SET_ADDRESS is received, before its status stage. The driver applies the address
  /// at the moment its hardware requires (OTG_FS: immediately, the core answers the status stage
  /// with the old address; others: after the status IN completes).
  virtual void SetAddress(std::uint8_t address) = 0;
  /// Opens a non-control endpoint after SET_CONFIGURATION. Data toggle starts at DATA0.
  /// @returns kOk, or kResourceExhausted when the endpoint number or FIFO space is not available.
  virtual Status EndpointOpen(std::uint8_t ep_addr, EndpointType type,
                              std::uint16_t max_packet) = 0;
  /// Closes every non-control endpoint (bus reset, SET_CONFIGURATION 0).
  virtual void EndpointCloseAll() = 0;
  /// Halts an endpoint (STALL handshake) and abandons its pending transfer, which then never
  /// completes. Endpoint 0's stall clears itself on the next SETUP.
  virtual void EndpointStall(std::uint8_t ep_addr) = 0;
  /// Clears a halt and resets the data toggle to DATA0 (USB 2.0 §9.4.5).
  virtual void EndpointClearStall(std::uint8_t ep_addr) = 0;
  /// Starts a transfer. IN: sends `buffer` (a zero length sends a ZLP); OUT: receives up to
  /// buffer.size() bytes into `buffer`. The buffer stays owned by the driver until
  /// OnTransferComplete for that endpoint. Endpoint 0 transfers are at most one packet.
  /// @returns kOk, kUnavailable when a transfer is already pending on the endpoint,
  ///          kInvalidArgument when the endpoint is not open.
  virtual Status Transfer(std::uint8_t ep_addr, std::span<std::uint8_t> buffer) = 0;

 protected:
  ~Dcd() = default;
};

}  // namespace vibid::fw::usb
