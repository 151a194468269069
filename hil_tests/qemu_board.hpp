// The `qemu` target: the netduinoplus2 board image (VIBID_QEMU_IMAGE, built by the firmware
// preset) booted in qemu-system-arm with USART1 on a Unix socket, reached by the host's serial
// transport. Its samples arrive over the link (inject-frames), its calibration slots are in RAM.
#pragma once

#include <sys/types.h>

#include <memory>
#include <string>

#include "vibid/device/transport.hpp"

namespace vibid::hil {

class QemuBoard {
 public:
  /// Boots the image and waits until it reports ready. Throws std::runtime_error on failure.
  explicit QemuBoard(const std::string& image);
  ~QemuBoard();
  QemuBoard(const QemuBoard&) = delete;
  QemuBoard& operator=(const QemuBoard&) = delete;

  /// The serial transport to USART1 (one at a time: QEMU's socket takes one client).
  std::unique_ptr<device::Transport> Connect();

 private:
  std::string dir_;
  std::string socket_;
  std::string diagnostics_;
  pid_t pid_ = -1;
};

}  // namespace vibid::hil
