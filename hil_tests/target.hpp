// The device a hil test talks to, chosen by VIBID_TARGET:
//   emu   a vibid-emu process over USB/IP (the default when the emulator is built)
//   core  the firmware core in-process over a loopback transport (core_loopback.hpp)
//   qemu  the netduinoplus2 board image in QEMU (VIBID_QEMU_IMAGE), over its framed USART
//   hid   the one real board attached over USB HID
#pragma once

#include <memory>
#include <string>

#include "core_loopback.hpp"
#include "emulator_process.hpp"
#include "vibid/device/connection.hpp"

namespace vibid::hil {

class Target {
 public:
  virtual ~Target() = default;
  virtual std::string Name() const = 0;
  virtual std::unique_ptr<device::Connection> Connect(device::ConnectionOptions options = {}) = 0;
  /// Power cycle (calibration must survive). False if the target cannot be restarted by the test.
  virtual bool Restart() = 0;
  /// The loopback for fault injection; null on targets where faults cannot be injected.
  virtual CoreLoopback* loopback() { return nullptr; }
  /// Makes the board sample `frames` ticks of CoreLoopback::FrameAt (from tick `first`) while an
  /// acquisition runs. Targets with their own sampling (core, hid) return false and sample anyway.
  virtual bool Feed(device::Connection& c, std::uint32_t first, std::uint32_t frames) {
    static_cast<void>(c), static_cast<void>(first), static_cast<void>(frames);
    return false;
  }
  /// The device disappears for good (process killed, loopback dead). False if not possible.
  virtual bool Kill() { return false; }
  /// True if samples only arrive through Feed.
  virtual bool NeedsFeed() const { return false; }
  /// The vibid-emu process behind the target (USB/IP, flash file); null on other targets.
  virtual EmulatorProcess* emulator() { return nullptr; }
};

/// The vibid-emu binary (VIBID_EMU, else the one built with the suite); empty when there is none.
std::string EmulatorBinary();

/// The target VIBID_TARGET names (a fresh one per call: a test owns its device).
std::unique_ptr<Target> MakeTarget();

}  // namespace vibid::hil
