// The in-process core (or any Transport) served on a Unix socket in the serial framing of
// shared/wire/serial_frame.hpp, so a separate `vibid` process reaches it as
// `--device serial:PATH` and the core target's fault injection shows at the command line.
// Reports shorter than 64 bytes (a truncation the loopback injected) go out as a cut frame.
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <string>
#include <thread>

#include "vibid/device/transport.hpp"

namespace vibid::hil {

class SerialBridge {
 public:
  using Connect = std::function<std::unique_ptr<device::Transport>()>;
  /// Listens on `path`; each client gets a fresh transport from `connect`, one client at a time.
  SerialBridge(Connect connect, std::string path);
  ~SerialBridge();
  SerialBridge(const SerialBridge&) = delete;
  SerialBridge& operator=(const SerialBridge&) = delete;

  /// `serial:PATH`, the CLI's --device for it.
  std::string device_spec() const { return "serial:" + path_; }

 private:
  void Serve();
  void Relay(int client);

  Connect connect_;
  std::string path_;
  int listener_ = -1;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace vibid::hil
