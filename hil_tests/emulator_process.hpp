// The `emu` target's device: a vibid-emu process on a free port, its flash in a file that outlives
// restarts, reached through the host's own USB/IP client.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <string>
#include <vector>

namespace vibid::hil {

class EmulatorProcess {
 public:
  /// Starts `binary --port 0 --flash DIR/flash.bin -v [extra_args...]` and reads the port it
  /// prints; its stderr (personality changes, USB/IP imports) goes to DIR/emu.log.
  /// Throws std::runtime_error when it does not come up.
  explicit EmulatorProcess(std::string binary, std::vector<std::string> extra_args = {});
  ~EmulatorProcess();
  EmulatorProcess(const EmulatorProcess&) = delete;
  EmulatorProcess& operator=(const EmulatorProcess&) = delete;

  int port() const { return port_; }
  /// `usbip://127.0.0.1:PORT`, the CLI's --device for it.
  std::string device_spec() const;
  pid_t pid() const { return pid_; }
  /// The first stdout line: "vibid-emu: USB/IP on 127.0.0.1:PORT, bus id 1-1, serial ..., ...".
  const std::string& banner() const { return banner_; }
  /// The board's 1 MiB flash image file (calibration slots and firmware).
  std::string flash_path() const { return dir_ + "/flash.bin"; }
  /// Everything the process wrote on stderr so far.
  std::string Log() const;
  /// Waits until the stderr log holds `text` `count` times. False on timeout.
  bool AwaitLog(const std::string& text, int count, std::chrono::milliseconds timeout) const;
  /// Kills the process (SIGKILL: no goodbye on the socket) and starts it again on the same flash.
  void Restart();
  /// Kills the process for good.
  void Kill();

 private:
  void Start();
  std::string binary_;
  std::vector<std::string> extra_args_;
  std::string dir_;
  pid_t pid_ = -1;
  int port_ = 0;
  std::string banner_;
};

}  // namespace vibid::hil
