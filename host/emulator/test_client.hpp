// A small USB/IP client for the emulator's tests: imports the device and runs control and
// interrupt URBs, keeping completions that arrive for other URBs until they are asked for.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "vibid/device/usb_control.hpp"
#include "vibid/shared/wire/commands.hpp"
#include "vibid/shared/wire/crc32.hpp"
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
                       std::array<std::uint8_t, 8> setup = {},
                       const std::vector<std::uint8_t>& out = {}) {
    usbip::CmdSubmit s;
    s.basic.seqnum = ++seqnum_;
    s.basic.devid = device_.devid();
    s.basic.direction = dir;
    s.basic.ep = ep;
    s.transfer_buffer_length = length;
    s.setup = setup;
    std::vector<std::uint8_t> bytes(usbip::kUrbHeaderBytes);
    usbip::Encode(
        s, std::span<std::uint8_t, usbip::kUrbHeaderBytes>(bytes.data(), usbip::kUrbHeaderBytes));
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

  Completion Control(std::array<std::uint8_t, 8> setup, std::uint32_t length,
                     const std::vector<std::uint8_t>& out = {}) {
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
    if (h.basic.command != usbip::UrbCommand::kRetSubmit)
      throw usbip::ProtocolError("unexpected command");
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
  return device::Setup{type, request, value, index, length}.Bytes();
}

/// The board's command protocol over the HID interrupt endpoints of an imported emulator:
/// one request at a time, one IN URB outstanding while an answer is expected.
class DeviceSession {
 public:
  struct Answer {
    wire::Header header;  ///< For stream data: token and sequence only.
    std::vector<std::uint8_t> payload;
    bool stream_data = false;
  };

  explicit DeviceSession(std::uint16_t port) : client_(port) {
    if (client_.Control(Req(0x00, 9, 1, 0, 0), 0).status != 0)
      throw std::runtime_error("SET_CONFIGURATION refused");
  }

  TestClient& client() { return client_; }

  Answer Request(wire::Command command, std::span<const std::uint8_t> payload = {},
                 std::uint16_t sequence = 0) {
    wire::Report r{};
    if (wire::BuildReport(command, ++token_, sequence, 0, Status::kOk, payload, r) != Status::kOk) {
      throw std::runtime_error("request does not fit a report");
    }
    Send(r);
    return Receive();
  }

  template <typename Payload>
  requires requires { Payload::kBytes; }
  Answer Request(wire::Command command, const Payload& payload) {
    return Request(command, wire::EncodedBytes(payload));
  }

  /// Uploads and commits a calibration record. @returns the commit's status.
  Status Calibrate(std::span<const std::uint8_t> record) {
    wire::CalPutBeginRequest begin;
    begin.record_bytes = static_cast<std::uint32_t>(record.size());
    begin.crc32 = wire::ComputeCrc32(record);
    Answer a = Request(wire::Command::kCalPutBegin, begin);
    if (a.header.status != Status::kOk) return a.header.status;
    std::uint16_t seq = 0;
    for (std::size_t at = 0; at < record.size(); at += wire::kMaxPayload, ++seq) {
      const std::size_t n = std::min<std::size_t>(wire::kMaxPayload, record.size() - at);
      a = Request(wire::Command::kCalPutData, record.subspan(at, n), seq);
      if (a.header.status != Status::kOk) return a.header.status;
    }
    return Request(wire::Command::kCalCommit).header.status;
  }

  /// The ticks of the records PullLog, FollowLog and StreamAcquisition brought, in order (from the
  /// tick each data report names for its first record and `decimation`).
  std::vector<std::uint32_t> ticks;
  std::uint32_t decimation = 1;
  /// A slow host: sleeps this long before submitting each IN URB.
  int receive_delay_us = 0;

  /// Pulls the whole log: the records of the streams, in order, without the ticks (see `ticks`).
  std::vector<std::uint8_t> PullLog(std::size_t record_bytes) {
    std::vector<std::uint8_t> bytes;
    while (ReadMore(bytes, record_bytes)) {
    }
    return bytes;
  }

  /// Follows a running acquisition: asks for the records after the last one received until the
  /// acquisition ended and every record written arrived. @returns the records' bytes.
  std::vector<std::uint8_t> FollowLog(std::size_t record_bytes) {
    std::vector<std::uint8_t> bytes;
    for (;;) {
      if (ReadMore(bytes, record_bytes)) continue;
      const wire::StatusResponse s = GetStatus();
      const bool sampling =
          s.acq_state == wire::AcqState::kArmed || s.acq_state == wire::AcqState::kAcquiring;
      if (!sampling && bytes.size() / record_bytes >= s.records_written) return bytes;
    }
  }

  /// One log-read stream from the first record not yet in `bytes`, appended to it.
  /// @returns true if it brought any record.
  bool ReadMore(std::vector<std::uint8_t>& bytes, std::size_t record_bytes) {
    wire::LogReadRequest req;
    req.first_record = static_cast<std::uint32_t>(bytes.size() / record_bytes);
    Answer a = Request(wire::Command::kLogRead, req);
    const std::size_t before = bytes.size();
    while ((a.header.flags & wire::kFlagStreamEnd) == 0) {
      if (a.header.status != Status::kOk) throw std::runtime_error("log-read refused");
      Append(a.payload, bytes, record_bytes);
      a = Receive();
    }
    last_trailer = a.payload;
    return bytes.size() != before;
  }

  /// acq-start of an acquisition configured with kAcqFlagStream, then the log stream that follows
  /// it to its trailer. @returns the records' bytes; `last_trailer` holds the trailer payload.
  std::vector<std::uint8_t> StreamAcquisition(std::size_t record_bytes) {
    const Answer started = Request(wire::Command::kAcqStart);
    if (started.header.status != Status::kOk) throw std::runtime_error("acq-start refused");
    std::vector<std::uint8_t> bytes;
    std::uint16_t expected = 0;
    for (;;) {
      const Answer a = Receive();
      if (a.header.token != token_ || a.header.status != Status::kOk ||
          a.header.sequence != expected++) {
        throw std::runtime_error("log stream broken");
      }
      if ((a.header.flags & wire::kFlagStreamEnd) != 0) {
        last_trailer = a.payload;
        return bytes;
      }
      if (!a.stream_data) throw std::runtime_error("log data not in a stream data report");
      Append(a.payload, bytes, record_bytes);
    }
  }

  std::vector<std::uint8_t> last_trailer;

  wire::StatusResponse GetStatus() {
    const Answer a = Request(wire::Command::kGetStatus);
    wire::StatusResponse s;
    if (wire::Decode(a.payload, s) != Status::kOk)
      throw std::runtime_error("bad get-status answer");
    return s;
  }

 private:
  void Append(const std::vector<std::uint8_t>& payload, std::vector<std::uint8_t>& bytes,
              std::size_t record_bytes) {
    if (payload.size() < 4 || (payload.size() - 4) % record_bytes != 0)
      throw std::runtime_error("bad log payload");
    const std::uint32_t first =
        static_cast<std::uint32_t>(payload[0] | payload[1] << 8 | payload[2] << 16) |
        static_cast<std::uint32_t>(payload[3]) << 24;
    for (std::size_t k = 0; k < (payload.size() - 4) / record_bytes; ++k) {
      ticks.push_back(first + static_cast<std::uint32_t>(k) * decimation);
    }
    bytes.insert(bytes.end(), payload.begin() + 4, payload.end());
  }

  void Send(const wire::Report& r) {
    const auto out =
        client_.Wait(client_.Submit(1, usbip::Direction::kOut, 64, {}, {r.begin(), r.end()}));
    if (out.status != 0) throw std::runtime_error("interrupt OUT failed");
  }
  Answer Receive() {
    if (receive_delay_us > 0)
      std::this_thread::sleep_for(std::chrono::microseconds(receive_delay_us));
    const auto in = client_.Wait(client_.Submit(1, usbip::Direction::kIn, 64));
    if (in.status != 0 || in.data.size() != wire::kReportBytes)
      throw std::runtime_error("interrupt IN failed");
    wire::Report r{};
    std::copy(in.data.begin(), in.data.end(), r.begin());
    Answer a;
    if (wire::IsStreamData(r)) {
      wire::StreamDataHeader d;
      if (wire::DecodeStreamData(r, d) != Status::kOk)
        throw std::runtime_error("malformed stream data report");
      a.stream_data = true;
      a.header.token = d.token;
      a.header.sequence = d.sequence;
      a.header.flags = wire::kFlagResponse;
    } else if (wire::DecodeHeader(r, a.header) != Status::kOk) {
      throw std::runtime_error("malformed report");
    }
    const auto p = wire::PayloadOf(r);
    a.payload.assign(p.begin(), p.end());
    return a;
  }

  TestClient client_;
  std::uint16_t token_ = 0;
};

/// A 16-byte scenario name and parameters, as select-scenario carries them.
inline wire::ScenarioRequest ScenarioOf(const char* name, std::array<float, 4> params) {
  wire::ScenarioRequest s;
  for (std::size_t i = 0; name[i] != '\0' && i < s.name.size(); ++i) s.name[i] = name[i];
  s.params = params;
  return s;
}

}  // namespace vibid::emu::testing
