// The firmware core: sampling pipeline, log, calibration store and the command server, wired to
// one port and one report link. A port's main() is:
//
//   vibid::fw::Core core(port, link, log_storage);
//   core.Boot();
//   for (;;) { core.Poll(); /* sleep until an interrupt */ }
//
// and the port's FrameSource calls the sink handed to Start (the core's sampler) once per tick.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "vibid/fw/calibration_store.hpp"
#include "vibid/fw/calibration_upload.hpp"
#include "vibid/fw/dob_stage.hpp"
#include "vibid/fw/log_ring.hpp"
#include "vibid/fw/port.hpp"
#include "vibid/fw/port_commands.hpp"
#include "vibid/fw/report_link.hpp"
#include "vibid/fw/sampler.hpp"
#include "vibid/shared/status.hpp"
#include "vibid/shared/wire/commands.hpp"
#include "vibid/shared/wire/refusal.hpp"
#include "vibid/shared/wire/report.hpp"
#include "vibid/shared/wire/stream.hpp"

namespace vibid::fw {

class Core {
 public:
  /// The sample period get-info reports before the host configured an acquisition (5 kHz).
  static constexpr std::uint32_t kDefaultSamplePeriodUs = 200;
  /// Reports the server hands to the link per Poll at most (keeps the main loop responsive).
  static constexpr int kMaxReportsPerPoll = 16;

  /// `log_storage` holds the acquisition log (its size is the log capacity); it, the port
  /// objects, the link and the handler must outlive the core. `port_commands` may be null.
  Core(const Port& port, ReportLink& link, std::span<std::uint8_t> log_storage,
       PortCommandHandler* port_commands = nullptr);

  Core(const Core&) = delete;
  Core& operator=(const Core&) = delete;

  /// Loads the newest valid calibration from flash (or the uncalibrated defaults).
  /// @returns the store's Load status (kOk, kDataLoss when uncalibrated, kOutOfRange for a
  ///          port whose slots are too small); the core runs in every case.
  Status Boot();

  /// One main-loop step: sends what is waiting, takes one request and answers it, continues a
  /// stream, stops an acquisition that reached its record limit, and performs a reset or DFU
  /// entry once its answer went out. Never blocks.
  void Poll();

  /// The link lost its host (USB bus reset, serial reconnect): drops the stream and any
  /// unsent report. The acquisition keeps running.
  void OnLinkReset();

  // Observers for ports and tests.
  const Sampler& sampler() const { return sampler_; }
  const LogRing& log() const { return ring_; }
  /// A log-read stream is being sent (the host is pulling).
  bool log_streaming() const { return stream_ == StreamKind::kLog; }
  const CalibrationStore& calibration() const { return store_; }
  std::uint32_t rejected_requests() const { return rejected_requests_; }

 private:
  enum class StreamKind : std::uint8_t { kNone, kLog, kCalibration };
  enum class Deferred : std::uint8_t { kNone, kReset, kEnterDfu };

  void Handle(const wire::Report& request);
  // Each handler answers a request it accepts and returns kOk, or returns the refusal status
  // (Handle sends the refusal, with the reason Refuse recorded).
  Status Dispatch(const wire::Header& h, std::span<const std::uint8_t> payload);
  /// Records why the request is refused (sent as the refusal's payload) and returns `status`.
  Status Refuse(Status status, wire::Reason reason, std::uint32_t detail = 0);
  /// Sends an answer; a refusal (status not kOk) carries the recorded Refusal as its payload.
  void Respond(const wire::Header& request, Status status,
               std::span<const std::uint8_t> payload = {});
  template <typename Payload>
  void RespondWith(const wire::Header& request, const Payload& payload);

  Status HandleCalPutBegin(const wire::Header& h, std::span<const std::uint8_t> payload);
  Status HandleCalPutData(const wire::Header& h, std::span<const std::uint8_t> payload);
  Status HandleCalCommit(const wire::Header& h);
  Status HandleCalGet(const wire::Header& h);
  Status HandleAcqConfigure(const wire::Header& h, std::span<const std::uint8_t> payload);
  Status HandleAcqStart(const wire::Header& h);
  Status HandleLogRead(const wire::Header& h, std::span<const std::uint8_t> payload);
  Status HandleDobControl(const wire::Header& h, std::span<const std::uint8_t> payload);
  Status HandlePortCommand(const wire::Header& h, std::span<const std::uint8_t> payload);
  Status HandleSelfTest(const wire::Header& h, std::span<const std::uint8_t> payload);
  /// One self-test check (self_test.cpp); check < wire::kSelfTestCheckCount, idle only.
  wire::SelfTestResponse SelfTest(std::uint8_t check);
  Status ValidateConfig(const wire::AcqConfigureRequest& c);
  bool Sampling() const;
  void StopSampling();
  void ApplyCalibration();
  /// Builds the next report of the stream into pending_. @returns false if a following log
  /// stream has nothing to send yet.
  bool NextStreamReport();
  /// Packs the records from stream_next_ into one log data report payload.
  Status PackLogRecords(std::span<std::uint8_t, wire::kMaxStreamPayload> payload,
                        std::size_t& length);
  void StartLogStream(std::uint16_t token, std::uint32_t first, std::uint32_t end, bool follow);
  wire::InfoResponse Info() const;
  /// get-info page kInfoPageSampling: the board profile's sampling instants.
  static wire::SamplingInfoResponse SamplingInfo();
  /// get-info page kInfoPageHealth: brown-out level and reset cause from the port.
  wire::HealthInfoResponse HealthInfo() const;
  wire::StatusResponse CurrentStatus() const;

  const Port port_;
  ReportLink& link_;
  PortCommandHandler* port_commands_;
  LogRing ring_;
  DobStage dob_;
  Sampler sampler_;
  CalibrationStore store_;
  CalibrationUpload upload_;

  bool configured_ = false;
  bool sampling_ = false;
  wire::AcqConfigureRequest config_{};
  std::uint32_t rejected_requests_ = 0;
  wire::Refusal refusal_{};  // why the request being handled is refused (Refuse)

  wire::Report pending_{};
  bool has_pending_ = false;
  Deferred deferred_ = Deferred::kNone;

  StreamKind stream_ = StreamKind::kNone;
  wire::StreamEncoder encoder_;
  std::uint32_t stream_next_ = 0;   // next record (log) or byte offset (calibration)
  std::uint32_t stream_end_ = 0;    // one past the last record / byte
  std::uint32_t stream_first_ = 0;  // first record of a log stream
  std::uint16_t stream_token_ = 0;  // token of the request the stream answers
  bool stream_follows_ = false;     // a log stream started by acq-start: follows the acquisition
};

}  // namespace vibid::fw
