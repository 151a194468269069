#include "vibid/usbip/socket.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <utility>

namespace vibid::usbip {
namespace {

std::string Errno(const std::string& what) { return what + ": " + std::strerror(errno); }

int PollMs(std::chrono::milliseconds timeout) {
  return timeout.count() > 0x7FFFFFFF ? 0x7FFFFFFF : static_cast<int>(timeout.count());
}

void SetNoDelay(int fd) {
  int one = 1;
  ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
}

}  // namespace

Socket::~Socket() { Close(); }

Socket::Socket(Socket&& other) noexcept : fd_(std::exchange(other.fd_, -1)) {}

Socket& Socket::operator=(Socket&& other) noexcept {
  if (this != &other) {
    Close();
    fd_ = std::exchange(other.fd_, -1);
  }
  return *this;
}

void Socket::Close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

void Socket::Shutdown() {
  if (fd_ >= 0) ::shutdown(fd_, SHUT_RDWR);
}

void Socket::SendAll(std::span<const std::uint8_t> data) {
  std::size_t sent = 0;
  while (sent < data.size()) {
    const ssize_t n = ::send(fd_, data.data() + sent, data.size() - sent, MSG_NOSIGNAL);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw IoError(Errno("USB/IP send failed"));
    }
    sent += static_cast<std::size_t>(n);
  }
}

bool Socket::ReceiveExactOrEof(std::span<std::uint8_t> data) {
  std::size_t got = 0;
  while (got < data.size()) {
    const ssize_t n = ::recv(fd_, data.data() + got, data.size() - got, 0);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw IoError(Errno("USB/IP receive failed"));
    }
    if (n == 0) {
      if (got == 0) return false;
      throw IoError("USB/IP connection closed in the middle of a message (" + std::to_string(got) +
                    " of " + std::to_string(data.size()) + " bytes)");
    }
    got += static_cast<std::size_t>(n);
  }
  return true;
}

void Socket::ReceiveExact(std::span<std::uint8_t> data) {
  if (!ReceiveExactOrEof(data) && !data.empty())
    throw IoError("USB/IP connection closed by the peer");
}

bool Socket::WaitReadable(std::chrono::milliseconds timeout) const {
  pollfd p{fd_, POLLIN, 0};
  for (;;) {
    const int r = ::poll(&p, 1, PollMs(timeout));
    if (r < 0 && errno == EINTR) continue;
    if (r < 0) throw IoError(Errno("USB/IP poll failed"));
    return r > 0;
  }
}

Listener::Listener(const std::string& address, std::uint16_t port) {
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(port);
  if (::inet_pton(AF_INET, address.c_str(), &addr.sin_addr) != 1) {
    throw IoError("bind address '" + address + "' is not an IPv4 address");
  }
  fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd_ < 0) throw IoError(Errno("socket"));
  int one = 1;
  ::setsockopt(fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
  if (::bind(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0 || ::listen(fd_, 4) != 0) {
    const std::string message = Errno("cannot listen on " + address + ":" + std::to_string(port));
    ::close(fd_);
    fd_ = -1;
    throw IoError(message);
  }
  socklen_t len = sizeof addr;
  ::getsockname(fd_, reinterpret_cast<sockaddr*>(&addr), &len);
  port_ = ntohs(addr.sin_port);
}

Listener::~Listener() {
  if (fd_ >= 0) ::close(fd_);
}

Socket Listener::Accept(std::chrono::milliseconds timeout) {
  pollfd p{fd_, POLLIN, 0};
  const int r = ::poll(&p, 1, PollMs(timeout));
  if (r < 0 && errno != EINTR) throw IoError(Errno("poll on the listening socket"));
  if (r <= 0) return Socket();
  const int fd = ::accept4(fd_, nullptr, nullptr, SOCK_CLOEXEC);
  if (fd < 0) {
    if (errno == EINTR || errno == EAGAIN || errno == ECONNABORTED) return Socket();
    throw IoError(Errno("accept"));
  }
  SetNoDelay(fd);
  return Socket(fd);
}

Socket ConnectTcp(const std::string& host, std::uint16_t port, std::chrono::milliseconds timeout) {
  const std::string where = host + ":" + std::to_string(port);
  addrinfo hints{};
  hints.ai_family = AF_INET;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  const std::string service = std::to_string(port);
  const int gai = ::getaddrinfo(host.c_str(), service.c_str(), &hints, &found);
  if (gai != 0) throw IoError("cannot resolve " + where + ": " + ::gai_strerror(gai));
  Socket s(::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0));
  if (!s.valid()) {
    ::freeaddrinfo(found);
    throw IoError(Errno("socket"));
  }
  const int rc = ::connect(s.fd(), found->ai_addr, found->ai_addrlen);
  ::freeaddrinfo(found);
  if (rc != 0) {
    if (errno != EINPROGRESS) throw IoError(Errno("cannot connect to " + where));
    pollfd p{s.fd(), POLLOUT, 0};
    const int r = ::poll(&p, 1, PollMs(timeout));
    if (r == 0) throw IoError("timed out connecting to " + where);
    int err = 0;
    socklen_t len = sizeof err;
    ::getsockopt(s.fd(), SOL_SOCKET, SO_ERROR, &err, &len);
    if (r < 0 || err != 0) {
      errno = r < 0 ? errno : err;
      throw IoError(Errno("cannot connect to " + where));
    }
  }
  const int flags = ::fcntl(s.fd(), F_GETFL);
  ::fcntl(s.fd(), F_SETFL, flags & ~O_NONBLOCK);
  SetNoDelay(s.fd());
  return s;
}

std::vector<UsbDevice> RequestDeviceList(Socket& socket) {
  socket.SendAll(EncodeReqDevlist());
  std::vector<std::uint8_t> reply(kOpHeaderBytes + 4);
  socket.ReceiveExact(reply);
  const OpHeader h =
      DecodeOpHeader(std::span<const std::uint8_t, kOpHeaderBytes>(reply.data(), kOpHeaderBytes));
  if (h.code != OpCode::kRepDevlist)
    throw ProtocolError("expected a device list reply (OP_REP_DEVLIST)");
  const std::uint32_t count = (std::uint32_t{reply[8]} << 24) | (std::uint32_t{reply[9]} << 16) |
                              (std::uint32_t{reply[10]} << 8) | std::uint32_t{reply[11]};
  if (count > 64) throw ProtocolError("device list claims " + std::to_string(count) + " devices");
  for (std::uint32_t n = 0; n < count; ++n) {
    const std::size_t at = reply.size();
    reply.resize(at + kUsbDeviceBytes);
    socket.ReceiveExact(std::span<std::uint8_t>(reply.data() + at, kUsbDeviceBytes));
    const std::uint8_t interfaces = reply[at + kUsbDeviceBytes - 1];
    const std::size_t more = std::size_t{interfaces} * kUsbInterfaceBytes;
    reply.resize(at + kUsbDeviceBytes + more);
    socket.ReceiveExact(std::span<std::uint8_t>(reply.data() + at + kUsbDeviceBytes, more));
  }
  return DecodeRepDevlist(reply);
}

UsbDevice RequestImport(Socket& socket, const std::string& busid) {
  socket.SendAll(EncodeReqImport(busid));
  std::array<std::uint8_t, kOpHeaderBytes> head{};
  socket.ReceiveExact(head);
  const OpHeader h = DecodeOpHeader(head);
  if (h.code != OpCode::kRepImport) throw ProtocolError("expected an import reply (OP_REP_IMPORT)");
  if (h.status != kOpStatusOk) {
    throw ProtocolError("the server refused to export bus id '" + busid + "' (status " +
                        std::to_string(h.status) + ")");
  }
  std::array<std::uint8_t, kUsbDeviceBytes> record{};
  socket.ReceiveExact(record);
  return DecodeUsbDevice(record);
}

bool ReceiveUrbHeader(Socket& socket, UrbHeader& out) {
  std::array<std::uint8_t, kUrbHeaderBytes> bytes{};
  if (!socket.ReceiveExactOrEof(bytes)) return false;
  out = DecodeUrbHeader(bytes);
  return true;
}

}  // namespace vibid::usbip
