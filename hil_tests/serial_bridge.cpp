#include "serial_bridge.hpp"

#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstring>
#include <stdexcept>

#include "vibid/device/error.hpp"
#include "vibid/shared/wire/serial_frame.hpp"

namespace vibid::hil {

SerialBridge::SerialBridge(Connect connect, std::string path)
    : connect_(std::move(connect)), path_(std::move(path)) {
  listener_ = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  if (listener_ < 0 || path_.size() >= sizeof(addr.sun_path))
    throw std::runtime_error("cannot serve " + path_);
  std::memcpy(addr.sun_path, path_.c_str(), path_.size() + 1);
  ::unlink(path_.c_str());
  if (::bind(listener_, reinterpret_cast<const sockaddr*>(&addr), sizeof(addr)) != 0 ||
      ::listen(listener_, 1) != 0) {
    ::close(listener_);
    throw std::runtime_error("cannot listen on " + path_ + ": " + std::strerror(errno));
  }
  thread_ = std::thread([this] { Serve(); });
}

SerialBridge::~SerialBridge() {
  stop_ = true;
  thread_.join();
  ::close(listener_);
  ::unlink(path_.c_str());
}

void SerialBridge::Serve() {
  while (!stop_) {
    pollfd p{listener_, POLLIN, 0};
    if (::poll(&p, 1, 10) <= 0) continue;
    const int client = ::accept4(listener_, nullptr, nullptr, SOCK_CLOEXEC);
    if (client < 0) continue;
    Relay(client);
    ::close(client);
  }
}

void SerialBridge::Relay(int client) {
  std::unique_ptr<device::Transport> device = connect_();
  wire::SerialFrameDecoder decoder;
  try {
    while (!stop_) {
      pollfd p{client, POLLIN, 0};
      if (::poll(&p, 1, 0) > 0) {
        std::uint8_t buf[512];
        const ssize_t n = ::read(client, buf, sizeof(buf));
        if (n <= 0) return;  // the CLI closed the link
        wire::Report report{};
        for (ssize_t i = 0; i < n; ++i) {
          if (decoder.Push(buf[i], report)) device->Send(report);
        }
      }
      std::array<std::uint8_t, wire::kReportBytes> report{};
      const std::size_t length = device->Receive(report, std::chrono::milliseconds(1));
      if (length == 0) continue;
      wire::SerialFrameBytes frame = wire::EncodeSerialFrame(report);
      std::size_t bytes = frame.size();
      if (length < report.size()) {
        frame[2] = static_cast<std::uint8_t>(length);  // what arrived of a cut report, and no CRC
        bytes = 3 + length;
      }
      if (::send(client, frame.data(), bytes, MSG_NOSIGNAL) != static_cast<ssize_t>(bytes)) return;
    }
  } catch (const device::DeviceError&) {
    // The core was killed: the client sees the link close.
  }
}

}  // namespace vibid::hil
