#include "vibid/device/serial_transport.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <deque>

#include "vibid/device/error.hpp"
#include "vibid/shared/wire/serial_frame.hpp"

namespace vibid::device {
namespace {

class SerialTransport final : public Transport {
 public:
  SerialTransport(int fd, std::string path) : fd_(fd), path_(std::move(path)) {}
  ~SerialTransport() override { ::close(fd_); }
  SerialTransport(const SerialTransport&) = delete;
  SerialTransport& operator=(const SerialTransport&) = delete;

  void Send(const wire::Report& report) override {
    const wire::SerialFrameBytes frame = wire::EncodeSerialFrame(report);
    std::size_t done = 0;
    while (done < frame.size()) {
      const ssize_t n = ::write(fd_, frame.data() + done, frame.size() - done);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) throw DeviceError("write to " + path_ + " failed: " + std::strerror(errno));
      done += static_cast<std::size_t>(n);
    }
  }

  std::size_t Receive(std::span<std::uint8_t, wire::kReportBytes> out,
                      std::chrono::milliseconds timeout) override {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (ready_.empty()) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
          deadline - std::chrono::steady_clock::now());
      if (left.count() <= 0) return 0;
      pollfd p{fd_, POLLIN, 0};
      const int r = ::poll(&p, 1, static_cast<int>(left.count()));
      if (r < 0 && errno == EINTR) continue;
      if (r < 0) throw DeviceError("poll on " + path_ + " failed: " + std::strerror(errno));
      if (r == 0) return 0;
      std::uint8_t buf[512];
      const ssize_t n = ::read(fd_, buf, sizeof(buf));
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) throw DeviceError(path_ + " closed");
      wire::Report report{};
      for (ssize_t i = 0; i < n; ++i) {
        if (decoder_.Push(buf[i], report)) ready_.push_back(report);
      }
    }
    const wire::Report r = ready_.front();
    ready_.pop_front();
    std::copy(r.begin(), r.end(), out.begin());
    return r.size();
  }

  std::string Describe() const override { return "serial:" + path_; }

 private:
  int fd_;
  std::string path_;
  wire::SerialFrameDecoder decoder_;
  std::deque<wire::Report> ready_;
};

}  // namespace

std::unique_ptr<Transport> OpenSerial(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) throw DeviceError("no serial device or socket at " + path);
  if (S_ISSOCK(st.st_mode)) {
    const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    if (path.size() >= sizeof(addr.sun_path)) throw DeviceError("socket path too long: " + path);
    std::memcpy(addr.sun_path, path.c_str(), path.size() + 1);
    if (fd < 0 || ::connect(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof(addr)) != 0) {
      if (fd >= 0) ::close(fd);
      throw DeviceError("cannot connect to " + path + ": " + std::strerror(errno));
    }
    return std::make_unique<SerialTransport>(fd, path);
  }
  const int fd = ::open(path.c_str(), O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (fd < 0) throw DeviceError("cannot open " + path + ": " + std::strerror(errno));
  termios tio{};
  if (::tcgetattr(fd, &tio) == 0) {
    ::cfmakeraw(&tio);
    ::cfsetispeed(&tio, B115200);
    ::cfsetospeed(&tio, B115200);
    ::tcsetattr(fd, TCSANOW, &tio);
  }
  return std::make_unique<SerialTransport>(fd, path);
}

}  // namespace vibid::device
