// What the USB/IP server exports: a USB device that takes URBs and completes them, now or later.
// Two personalities implement it: the application (the core's USB stack behind an emulated
// device controller) and the DfuSe bootloader.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "vibid/usbip/protocol.hpp"

namespace vibid::emu {

/// One submitted URB, as the host described it.
struct Urb {
  std::uint32_t seqnum = 0;
  std::uint8_t endpoint = 0;  ///< number, without the direction bit
  usbip::Direction direction = usbip::Direction::kOut;
  std::array<std::uint8_t, 8> setup{};  ///< endpoint 0 only
  std::uint32_t length = 0;             ///< transfer_buffer_length
  std::vector<std::uint8_t> out_data;   ///< OUT: the data to deliver
  std::uint32_t start_frame = 0;
  std::uint32_t number_of_packets = usbip::kNotIsochronous;
};

struct UrbResult {
  std::int32_t status = usbip::kStatusOk;
  std::uint32_t actual_length = 0;    ///< OUT: bytes taken; IN: in_data.size()
  std::vector<std::uint8_t> in_data;  ///< IN only
};

/// Receives completed URBs (the server turns them into RET_SUBMIT).
class UrbSink {
 public:
  virtual void Complete(const Urb& urb, const UrbResult& result) = 0;

 protected:
  ~UrbSink() = default;
};

class ExportedDevice {
 public:
  virtual ~ExportedDevice() = default;
  /// The record OP_REP_DEVLIST / OP_REP_IMPORT carry (busid, ids, interfaces).
  virtual usbip::UsbDevice Describe() const = 0;
  /// A client imported the device: from now on completions go to `sink`. The device is reset
  /// and addressed, as the exporting host's own enumeration leaves it.
  virtual void Attach(UrbSink& sink) = 0;
  /// The client went away: pending URBs are dropped without completion.
  virtual void Detach() = 0;
  virtual void Submit(Urb urb) = 0;
  /// @returns true if the URB was still pending and is now cancelled (never completed).
  virtual bool Unlink(std::uint32_t seqnum) = 0;
  /// Completes whatever can be completed now (called by the emulator loop after the firmware ran).
  virtual void Service() = 0;
};

}  // namespace vibid::emu
