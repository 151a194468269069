// A core on a fake port, and helpers that speak the wire protocol to it as a host would.
#pragma once

#include <array>
#include <cstdint>
#include <span>

#include "fake_port.hpp"
#include "vibid/fw/core.hpp"
#include "vibid/shared/wire/commands.hpp"
#include "vibid/shared/wire/report.hpp"
#include "vibid/shared/wire/stream.hpp"

namespace vibid::fw::testing {

struct Response {
  bool received = false;
  wire::Header header;
  wire::Report report{};
  std::span<const std::uint8_t> payload() const { return wire::PayloadOf(report); }
  Status status() const { return header.status; }
};

class CoreHarness {
 public:
  static constexpr std::size_t kLogBytes = 2048;

  explicit CoreHarness(PortCommandHandler* port_commands = nullptr)
      : core(fake.port(), link, log_storage, port_commands) {}

  /// Sends one request and returns the first report the core answers with.
  Response Request(wire::Command command, std::span<const std::uint8_t> payload = {},
                   std::uint16_t sequence = 0);
  template <typename Payload>
  requires requires { Payload::kBytes; }
  Response Request(wire::Command command, const Payload& payload) {
    return Request(command, wire::EncodedBytes(payload));
  }
  /// Sends a raw report (malformed ones included).
  Response Raw(const wire::Report& report);

  /// Polls until the core has nothing more to send; returns how many reports arrived since.
  std::size_t Drain();

  /// Uploads a record with cal-put; returns the status of the last answer.
  Status Upload(std::span<const std::uint8_t> record);

  /// Configures and starts an acquisition.
  Status StartAcquisition(const wire::AcqConfigureRequest& config);

  /// Emits `n` frames whose channel c reads base[c] + k * step[c] at the k-th frame.
  void EmitRamp(std::uint32_t n, const std::array<std::int32_t, wire::kChannelCount>& base,
                std::int32_t step);

  FakePort fake;
  FakeLink link;
  std::array<std::uint8_t, kLogBytes> log_storage{};
  Core core;
  std::uint16_t next_token = 0x100;
  std::uint16_t last_token = 0;
  std::uint32_t emitted = 0;
};

/// A log stream pulled and decoded the way the host's device layer does it.
struct PulledLog {
  wire::StreamDecoder::Event last_event = wire::StreamDecoder::Event::kError;
  Status status = Status::kOk;  ///< kOk, or why the stream was refused or broken.
  wire::LogTrailer trailer;
  std::array<wire::LogRecord, 160> records{};
  std::size_t count = 0;  ///< Records decoded from data reports accepted before the end/error.
};

/// Sends log-read(first, max) and decodes every report that comes back. `lose_report` drops the
/// data report with that sequence number on its way to the host (a lost report).
PulledLog PullLog(CoreHarness& h, std::uint32_t first, std::uint32_t max, int lose_report = -1);

}  // namespace vibid::fw::testing
