// The `emu` target's device: a vibid-emu process on a free port, its flash in a file that outlives
// restarts, reached through the host's own USB/IP client.
#pragma once

#include <sys/types.h>

#include <string>

namespace vibid::hil {

class EmulatorProcess {
 public:
  /// Starts `binary --port 0 --flash DIR/flash.bin` and reads the port it prints.
  /// Throws std::runtime_error when it does not come up.
  explicit EmulatorProcess(std::string binary);
  ~EmulatorProcess();
  EmulatorProcess(const EmulatorProcess&) = delete;
  EmulatorProcess& operator=(const EmulatorProcess&) = delete;

  int port() const { return port_; }
  /// Kills the process (SIGKILL: no goodbye on the socket) and starts it again on the same flash.
  void Restart();
  /// Kills the process for good.
  void Kill();

 private:
  void Start();
  std::string binary_;
  std::string dir_;
  pid_t pid_ = -1;
  int port_ = 0;
};

}  // namespace vibid::hil
