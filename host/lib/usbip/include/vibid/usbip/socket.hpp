// Small blocking TCP helpers for USB/IP (POSIX sockets, IPv4).
//
// A Socket owns one connected stream; a Listener owns one bound, listening socket. Calls block
// unless a timeout is given; a peer that closes mid-message is an IoError, as is any socket error.
// Shutdown() may be called from another thread to wake a thread blocked in a receive.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "vibid/usbip/protocol.hpp"

namespace vibid::usbip {

/// The connection failed, timed out or was closed by the peer.
class IoError : public std::runtime_error {
 public:
  explicit IoError(const std::string& message) : std::runtime_error(message) {}
};

class Socket {
 public:
  Socket() = default;
  explicit Socket(int fd) : fd_(fd) {}
  ~Socket();
  Socket(Socket&& other) noexcept;
  Socket& operator=(Socket&& other) noexcept;
  Socket(const Socket&) = delete;
  Socket& operator=(const Socket&) = delete;

  bool valid() const { return fd_ >= 0; }
  int fd() const { return fd_; }

  /// Sends every byte (TCP_NODELAY is set: URBs are small and latency-bound).
  /// @throws IoError if the connection broke.
  void SendAll(std::span<const std::uint8_t> data);

  /// Receives exactly data.size() bytes.
  /// @throws IoError on a socket error or when the peer closed before all bytes arrived.
  void ReceiveExact(std::span<std::uint8_t> data);

  /// Like ReceiveExact, but returns false instead of throwing when the peer closed cleanly before
  /// the first byte (the normal end of a connection). A close mid-message still throws.
  bool ReceiveExactOrEof(std::span<std::uint8_t> data);

  /// Waits until a receive would not block (data or EOF) for at most `timeout`.
  /// @returns true if readable, false on timeout.
  bool WaitReadable(std::chrono::milliseconds timeout) const;

  /// Shuts down both directions: a blocked receive in another thread returns (EOF).
  void Shutdown();

  void Close();

 private:
  int fd_ = -1;
};

class Listener {
 public:
  /// Binds `address` (dotted IPv4, e.g. "127.0.0.1" or "0.0.0.0") and `port` (0 = any free port)
  /// with SO_REUSEADDR and listens. @throws IoError (address in use, bad address, ...).
  Listener(const std::string& address, std::uint16_t port);
  ~Listener();
  Listener(const Listener&) = delete;
  Listener& operator=(const Listener&) = delete;

  /// The bound port (the chosen one when 0 was asked for).
  std::uint16_t port() const { return port_; }
  /// The listening descriptor, for a caller that polls it together with its connections.
  int fd() const { return fd_; }

  /// Waits up to `timeout` for a connection. @returns the connection, or an invalid Socket on
  /// timeout. @throws IoError on a socket error.
  Socket Accept(std::chrono::milliseconds timeout);

 private:
  int fd_ = -1;
  std::uint16_t port_ = 0;
};

/// Connects to host:port (IPv4 literal or resolvable name) within `timeout`.
/// @throws IoError naming the address when the connection cannot be made.
Socket ConnectTcp(const std::string& host, std::uint16_t port, std::chrono::milliseconds timeout);

// ---- Client-side exchanges (one connection each, as the usbip tools do) ----------------------

/// Sends OP_REQ_DEVLIST and reads the whole OP_REP_DEVLIST.
std::vector<UsbDevice> RequestDeviceList(Socket& socket);

/// Sends OP_REQ_IMPORT for `busid` and reads OP_REP_IMPORT. On success the connection is now in
/// the URB phase. @throws ProtocolError if the server refused (status != 0) or answered garbage.
UsbDevice RequestImport(Socket& socket, const std::string& busid);

/// Reads one 48-byte URB header. @returns false on a clean EOF before the header.
bool ReceiveUrbHeader(Socket& socket, UrbHeader& out);

}  // namespace vibid::usbip
