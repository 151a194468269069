// The `core` target of the hil suite: the real firmware core (vibid_fw_core) on the unit tests'
// fake port, in a thread of the test process, reached through a Transport that hands the 64-byte
// reports straight across. It stands in for the USB or serial wire only; every byte the host
// sees is produced by the core's command server. Faults are injected on the device-to-host path.
#pragma once

#include <atomic>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <vector>
#include <optional>
#include <thread>

#include "fake_port.hpp"
#include "vibid/device/transport.hpp"
#include "vibid/fw/core.hpp"

namespace vibid::hil {

class CoreLoopback {
 public:
  static constexpr std::size_t kLogBytes = 64 * 1024;

  CoreLoopback();
  ~CoreLoopback();
  CoreLoopback(const CoreLoopback&) = delete;
  CoreLoopback& operator=(const CoreLoopback&) = delete;

  /// A transport to the core. Several may exist; each sees every device report.
  std::unique_ptr<device::Transport> Connect();

  /// Power cycle: a new core boots from the same flash (the calibration slots survive).
  void Restart();
  /// The device vanishes: every transport's next call throws DeviceError.
  void Kill();

  // Faults on the device-to-host path, applied to the next reports the core sends.
  void CorruptNext(int reports) { corrupt_.store(reports); }    ///< Flips the magic.
  void TruncateNext(int reports) { truncate_.store(reports); }  ///< Delivers 40 of 64 bytes.
  void DropNext(int reports) { drop_.store(reports); }          ///< Never delivered.
  /// Drops the data report with this sequence number in the next stream.
  void DropStreamReport(int sequence) { DropStreamReports(sequence, 1); }
  /// Drops `count` data reports in a row from this sequence number on in the next stream (a host
  /// that stops taking reports while the board goes on sending); a later stream ends the drops.
  void DropStreamReports(int first_sequence, int count) {
    drop_count_.store(count);
    drop_token_.store(-1);
    drop_sequence_.store(first_sequence);
  }
  /// Rewrites the protocol major of every report (a device of another protocol generation).
  void SetProtocolMajor(std::uint8_t major) { major_.store(major); }
  /// True while injected corruptions, truncations or drops have not all been applied yet.
  bool FaultsPending() const { return corrupt_ > 0 || truncate_ > 0 || drop_ > 0; }
  /// Frames the simulated sensors produce per device-loop step while sampling.
  void SetFramesPerStep(int frames) { frames_per_step_.store(frames); }

  /// The raw samples frame `tick` carries (a deterministic test signal: hammer-like half-sine
  /// force pulses on channel 0 from tick 200, every 500 ticks, slow ramps on the others).
  static std::array<std::int32_t, wire::kChannelCount> FrameAt(std::uint32_t tick);

  class Link;

 private:
  void Loop();
  void Deliver(const wire::Report& r);

  fw::testing::FakePort port_;
  fw::testing::FakeLink link_;
  std::unique_ptr<std::array<std::uint8_t, kLogBytes>> log_;
  std::optional<fw::Core> core_;
  std::uint32_t tick_ = 0;

  std::mutex mutex_;
  std::deque<wire::Report> to_device_;
  std::vector<Link*> links_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> dead_{false};
  std::atomic<int> corrupt_{0};
  std::atomic<int> truncate_{0};
  std::atomic<int> drop_{0};
  std::atomic<int> drop_sequence_{-1};
  std::atomic<int> drop_count_{1};
  std::atomic<int> drop_token_{-1};  // the stream the drops began in
  std::atomic<std::uint8_t> major_{wire::kProtocolMajor};
  std::atomic<int> frames_per_step_{20};
  std::thread thread_;
};

}  // namespace vibid::hil
