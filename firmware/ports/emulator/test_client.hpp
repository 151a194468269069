// A small USB/IP client for the emulator's tests: imports the device and runs control and
// interrupt URBs, keeping completions that arrive for other URBs until they are asked for.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "vibid/usbip/socket.hpp"

namespace vibid::emu::testing {

struct Completion {
  std::int32_t status = 0;
  std::vector<std::uint8_t> data;  // IN data
  std::uint32_t actual_length = 0;
};

class TestClient {
 public:
  explicit TestClient(std::uint16_t port)
      : socket_(usbip::ConnectTcp("127.0.0.1", port, std::chrono::milliseconds(2000))) {
    device_ = usbip::RequestImport(socket_, "1-1");
  }

  const usbip::UsbDevice& device() const { return device_; }

  std::uint32_t Submit(std::uint8_t ep, usbip::Direction dir, std::uint32_t length,
                       std::array<std::uint8_t, 8> setup = {}, const std::vector<std::uint8_t>& out = {}) {
    usbip::CmdSubmit s;
    s.basic.seqnum = ++seqnum_;
    s.basic.devid = device_.devid();
    s.basic.direction = dir;
    s.basic.ep = ep;
    s.transfer_buffer_length = length;
    s.setup = setup;
    std::vector<std::uint8_t> bytes(usbip::kUrbHeaderBytes);
    usbip::Encode(s, std::span<std::uint8_t, usbip::kUrbHeaderBytes>(bytes.data(), usbip::kUrbHeaderBytes));
    bytes.insert(bytes.end(), out.begin(), out.end());
    directions_[s.basic.seqnum] = dir;
    socket_.SendAll(bytes);
    return s.basic.seqnum;
  }

  /// Sends CMD_UNLINK for `target`; returns the RET_UNLINK status.
  std::int32_t Unlink(std::uint32_t target) {
    usbip::CmdUnlink u;
    u.basic.seqnum = ++seqnum_;
    u.basic.devid = device_.devid();
    u.unlink_seqnum = target;
    std::array<std::uint8_t, usbip::kUrbHeaderBytes> bytes{};
    usbip::Encode(u, bytes);
    socket_.SendAll(bytes);
    const std::uint32_t mine = u.basic.seqnum;
    while (unlinks_.count(mine) == 0) ReadOne();
    return unlinks_.at(mine);
  }

  /// Waits for the completion of `seqnum`.
  Completion Wait(std::uint32_t seqnum) {
    while (done_.count(seqnum) == 0) ReadOne();
    Completion c = done_.at(seqnum);
    done_.erase(seqnum);
    return c;
  }

  bool Completed(std::uint32_t seqnum) const { return done_.count(seqnum) != 0; }

  /// Reads what is already on the wire (up to `timeout` for the first message).
  void Drain(std::chrono::milliseconds timeout) {
    while (socket_.WaitReadable(timeout)) {
      ReadOne();
      timeout = std::chrono::milliseconds(20);
    }
  }

  Completion Control(std::array<std::uint8_t, 8> setup, std::uint32_t length, const std::vector<std::uint8_t>& out = {}) {
    const bool in = (setup[0] & 0x80) != 0;
    return Wait(Submit(0, in ? usbip::Direction::kIn : usbip::Direction::kOut, length, setup, out));
  }

  /// True if the server closed the connection (the device re-enumerated).
  bool Closed(std::chrono::milliseconds timeout) {
    if (!socket_.WaitReadable(timeout)) return false;
    usbip::UrbHeader h;
    try {
      if (!usbip::ReceiveUrbHeader(socket_, h)) return true;
    } catch (const usbip::IoError&) {
      return true;
    }
    throw std::runtime_error("unexpected URB message before the disconnect");
  }

  usbip::Socket& socket() { return socket_; }

 private:
  void ReadOne() {
    usbip::UrbHeader h;
    if (!usbip::ReceiveUrbHeader(socket_, h)) throw usbip::IoError("server closed the connection");
    if (h.basic.command == usbip::UrbCommand::kRetUnlink) {
      unlinks_[h.basic.seqnum] = h.ret_unlink.status;
      return;
    }
    if (h.basic.command != usbip::UrbCommand::kRetSubmit) throw usbip::ProtocolError("unexpected command");
    Completion c;
    c.status = h.ret_submit.status;
    c.actual_length = h.ret_submit.actual_length;
    if (directions_.at(h.basic.seqnum) == usbip::Direction::kIn) {
      c.data.resize(h.ret_submit.actual_length);
      socket_.ReceiveExact(c.data);
    }
    done_[h.basic.seqnum] = c;
  }

  usbip::Socket socket_;
  usbip::UsbDevice device_;
  std::uint32_t seqnum_ = 0;
  std::map<std::uint32_t, usbip::Direction> directions_;
  std::map<std::uint32_t, Completion> done_;
  std::map<std::uint32_t, std::int32_t> unlinks_;
};

inline std::array<std::uint8_t, 8> Req(std::uint8_t type, std::uint8_t request, std::uint16_t value,
                                         std::uint16_t index, std::uint16_t length) {
  return {type, request, static_cast<std::uint8_t>(value & 0xFF), static_cast<std::uint8_t>(value >> 8),
          static_cast<std::uint8_t>(index & 0xFF), static_cast<std::uint8_t>(index >> 8),
          static_cast<std::uint8_t>(length & 0xFF), static_cast<std::uint8_t>(length >> 8)};
}

}  // namespace vibid::emu::testing
