// The application personality as USB/IP exports it: the core's USB stack behind the emulator
// port's device controller (EmuDcd). The controller's packet view is reproduced from the host's
// transfer view: a control URB becomes SETUP, data packets of at most 64 bytes until wLength or a
// short packet, and the status stage; an interrupt IN URB waits until the HID class queued a
// report (the host polls, the device NAKs until then); an interrupt OUT URB waits until the class
// armed its endpoint (flow control: a full receive queue NAKs).
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <deque>
#include <span>

#include "emu_dcd.hpp"
#include "exported_device.hpp"
#include "vibid/fw/usb/device.hpp"

namespace vibid::emu {

/// The application personality as USB/IP exports it: the core's USB stack behind EmuDcd.
class UsbAppDevice final : public ExportedDevice {
 public:
  /// `stack` and `dcd` outlive this object; `record` is what the device list shows.
  UsbAppDevice(fw::usb::UsbDevice& stack, EmuDcd& dcd, usbip::UsbDevice record)
      : stack_(stack), dcd_(dcd), record_(std::move(record)) {}

  usbip::UsbDevice Describe() const override { return record_; }
  void Attach(UrbSink& sink) override;
  void Detach() override;
  void Submit(Urb urb) override;
  bool Unlink(std::uint32_t seqnum) override;
  void Service() override;

  /// A 1 ms USB frame's transactions: each interrupt endpoint may move one transaction (one
  /// 64-byte report), as on a full-speed bus with bInterval 1, between StartFrame and EndFrame
  /// and at no other time, so when a report goes out depends only on simulated time, never on
  /// when the host's URB happened to arrive. With `limit` false (experiments beyond the board)
  /// interrupt transfers are not limited at all.
  void StartFrame(bool limit, std::uint64_t frame_start_us);
  void EndFrame();
  /// The HID IN endpoint holds a report and no IN URB of the host waits for it: a host that polls
  /// every frame (the kernel's HID driver) would have one queued.
  bool WaitingForInUrb() const;
  bool Attached() const { return sink_ != nullptr; }
  /// Each interrupt IN transaction stores its frame's start time here before the host can see
  /// the report, so another thread that has the report also sees when it left.
  void StampInTransactions(std::atomic<std::uint64_t>& frame_start_us) {
    in_stamp_ = &frame_start_us;
  }
  /// A transaction is due in the next frame: an armed IN report, or a host's OUT report the
  /// armed OUT endpoint has not taken yet.
  bool NeedsFrame() const;

  /// Runs one control transfer through the stack: SETUP, data stage, status stage.
  UrbResult Control(const std::array<std::uint8_t, 8>& setup,
                    std::span<const std::uint8_t> out_data, std::uint32_t length);

 private:
  bool ServiceIn(std::uint8_t ep_addr);
  bool ServiceOut(std::uint8_t ep_addr);
  void FailStalled();

  fw::usb::UsbDevice& stack_;
  EmuDcd& dcd_;
  usbip::UsbDevice record_;
  UrbSink* sink_ = nullptr;
  std::deque<Urb> in_urbs_;   // interrupt IN, oldest first
  std::deque<Urb> out_urbs_;  // interrupt OUT, oldest first
  // Transactions left in the current frame, per interrupt direction.
  bool frame_limit_ = true;
  int in_left_ = 0;
  int out_left_ = 0;
  std::uint64_t frame_start_us_ = 0;
  std::atomic<std::uint64_t>* in_stamp_ = nullptr;
};

}  // namespace vibid::emu
