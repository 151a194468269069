// The emulator (vibid-emu) as a USB device over USB/IP (TCP, default port 3240), reached without
// the kernel's vhci-hcd: this client imports the exported device, enumerates it (device and
// configuration descriptors, SET_CONFIGURATION) and moves HID reports as interrupt URBs, so the
// firmware's USB stack runs exactly as it does behind a real host controller.
//
// Protocol: Linux Documentation/usb/usbip_protocol.rst (OP_REQ_DEVLIST / OP_REQ_IMPORT, then
// USBIP_CMD_SUBMIT / USBIP_RET_SUBMIT / USBIP_CMD_UNLINK on the same connection).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "vibid/device/transport.hpp"
#include "vibid/device/usb_control.hpp"
#include "vibid/usbip/protocol.hpp"

namespace vibid::device {

/// One device a USB/IP server exports (OP_REP_DEVLIST).
struct UsbipExport {
  std::string busid;
  std::uint16_t vendor_id = 0;
  std::uint16_t product_id = 0;
  std::uint16_t release = 0;
  std::uint8_t interfaces = 0;
  std::vector<usbip::UsbInterface>
      interface_classes;  ///< class, subclass, protocol per interface, in order
};

/// What a user is told when the server at host:port lists the board but will not export it: it
/// is in use, by the local process that holds it when this machine can tell (the server is
/// local and the process readable), and the way out.
std::string UsbipBusyMessage(const std::string& host, int port);

/// Lists what the server at host:port exports. Throws DeviceError if it cannot be reached.
std::vector<UsbipExport> ListUsbipExports(
    const std::string& host, int port,
    std::chrono::milliseconds timeout = std::chrono::milliseconds(1000));

/// An imported device: control transfers, and the HID report pipe as a Transport.
class UsbipDevice final : public Transport, public UsbControl {
 public:
  /// Connects, imports `busid` (when empty: the only export with that VID/PID, by default the
  /// vibid application), enumerates and configures. HID reports flow when the device has a HID
  /// interface (the DFU bootloader has none: control transfers only). Throws DeviceError naming
  /// the server on any failure.
  static std::unique_ptr<UsbipDevice> Open(const std::string& host, int port,
                                           const std::string& busid = {},
                                           std::uint16_t vendor_id = kUsbVendorId,
                                           std::uint16_t product_id = kUsbProductId);
  ~UsbipDevice() override;

  void Send(const wire::Report& report) override;
  std::size_t Receive(std::span<std::uint8_t, wire::kReportBytes> out,
                      std::chrono::milliseconds timeout) override;
  std::string Describe() const override;
  std::string SerialNumber() const override;

  std::vector<std::uint8_t> Control(const Setup& setup, std::span<const std::uint8_t> out,
                                    std::chrono::milliseconds timeout) override;

  const std::vector<std::uint8_t>& device_descriptor() const;
  const std::vector<std::uint8_t>& configuration_descriptor() const;

  class Impl;

 private:
  explicit UsbipDevice(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace vibid::device
