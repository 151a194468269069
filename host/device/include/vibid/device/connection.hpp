// The protocol client: one RAII connection to one board over any Transport.
//
// A reader thread drains the transport continuously (a HID input queue holds a few reports only;
// a log stream must never stall on it) and checks every report it takes: wrong magic, a truncated
// report or a malformed header is counted and dropped, a report from another protocol major
// fails the exchange with a message naming both versions. Requests carry a token the device
// echoes; an answer with another token is stale and ignored. A request that times out is sent
// again with the same token (retries), so a late answer to the first copy still matches.
//
// Streams (log-read, cal-get) are checked with the shared StreamDecoder (sequence numbers, byte
// count, CRC-32). A log pull that breaks off (lost report, CRC mismatch, timeout) resumes from
// the first record it did not receive intact, so nothing is lost or duplicated. The stream of a
// running acquisition is the exception to "intact": the board releases each record as it sends
// it, so when that stream breaks off, what arrived in sequence before the break is kept (the
// board may already have overwritten it) and the pull resumes after it. Records the board
// overwrote before any of them could be pulled are skipped, the rest is still pulled, and the
// pull ends with IncompleteLog, which carries everything received.
//
// Construction performs get-info and refuses a device whose protocol major differs. The
// destructor stops the reader thread; it does not change the device's state.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "vibid/device/error.hpp"
#include "vibid/device/transport.hpp"
#include "vibid/shared/wire/commands.hpp"
#include "vibid/shared/wire/log_record.hpp"
#include "vibid/shared/wire/report.hpp"
#include "vibid/shared/wire/watch_info.hpp"

namespace vibid::device {

struct ConnectionOptions {
  std::chrono::milliseconds timeout{1000};  ///< Per answer (per report inside a stream).
  int retries = 2;                          ///< Extra sends of a request that got no answer.
  /// Checked between reports of long transfers; when it becomes true they throw Interrupted.
  const std::atomic<bool>* cancel = nullptr;
};

/// Counters of what the reader thread discarded.
struct LinkCounters {
  std::uint64_t reports = 0;         ///< Whole reports taken from the transport.
  std::uint64_t truncated = 0;       ///< Shorter than 64 bytes.
  std::uint64_t corrupted = 0;       ///< Wrong magic or malformed header.
  std::uint64_t stale = 0;           ///< Answers nobody waited for (old token, late duplicate).
  std::uint64_t retries = 0;         ///< Requests sent again after a timeout.
  std::uint64_t stream_resumes = 0;  ///< Log pulls restarted after a broken stream.
};

/// One answer report.
struct Reply {
  wire::Header header;  ///< For stream data: token, sequence and length (no command).
  wire::Report report{};
  bool stream_data = false;  ///< A stream data report (wire::IsStreamData).
  std::span<const std::uint8_t> payload() const { return wire::PayloadOf(report); }
};

/// Log indices [first, end).
struct LogRange {
  std::uint32_t first = 0;
  std::uint32_t end = 0;
};

/// Records of a log pull, in log order, and the last trailer seen.
struct LogPull {
  std::vector<wire::LogRecord> records;
  std::uint32_t first_record = 0;  ///< Log index of records[0].
  wire::LogTrailer trailer;        ///< From the last stream (acq_state, counters, layout).
  wire::LogLayout layout;
  /// The acquisition was stopped (acq-stop) before it ended on its own: the records are what it
  /// had recorded until then.
  bool stopped = false;
  /// Ranges the board's log wrapped over before they could be pulled, in order; records holds
  /// everything else from first_record on. Empty in every pull that returns normally.
  std::vector<LogRange> missing;
};

/// A pull that lost records: the board overwrote them before they could be pulled (the host
/// fell a whole log behind; everything else was pulled), or the pull of a running acquisition
/// gave up (`why`). pull() holds every record received; the message names the records kept and
/// the ranges lost.
class IncompleteLog : public DeviceError {
 public:
  explicit IncompleteLog(LogPull pull, const std::string& why = {});
  const LogPull& pull() const { return pull_; }

 private:
  LogPull pull_;
};

/// Progress of a long transfer: done and total in the transfer's own unit (records, bytes).
using Progress = std::function<void(std::uint64_t done, std::uint64_t total)>;

/// Asked while a streamed acquisition runs (at least every 100 ms): true stops it now and keeps
/// what it recorded. `state` is the last log-read trailer seen (acq_state armed or acquiring,
/// records_written), null while the acquisition's own stream runs.
using StopRequest = std::function<bool(const wire::LogTrailer* state)>;

/// Records of a running acquisition as their report arrives (log index of the first, then the
/// records), decoded with the configured layout before the stream's CRC has vouched for them:
/// for a live display and a journal, while the returned LogPull stays the checked record. A stream
/// that breaks off is resumed from its first missing record, so a record may come again with the
/// same log index: a consumer keeps the first of each index.
using LiveRecords =
    std::function<void(std::uint32_t first_index, std::span<const wire::LogRecord> records)>;

class Connection {
 public:
  /// Starts the reader and performs get-info. Throws DeviceError if the device does not answer or
  /// speaks another protocol major.
  explicit Connection(std::unique_ptr<Transport> transport, ConnectionOptions options = {});
  ~Connection();
  Connection(const Connection&) = delete;
  Connection& operator=(const Connection&) = delete;

  const wire::InfoResponse& info() const { return info_; }
  std::string Describe() const { return transport_->Describe(); }
  /// The board's USB serial number; empty where the link has none.
  std::string SerialNumber() const { return transport_->SerialNumber(); }
  LinkCounters counters() const;

  /// One request, one answer (retried with the same token on timeout). The answer may be a
  /// refusal: its header.status says so. Throws DeviceError on timeout or a lost link.
  /// `extra_wait` lengthens the answer timeout for a request the device takes long to answer.
  Reply Call(wire::Command command, std::span<const std::uint8_t> payload = {},
             std::uint16_t sequence = 0,
             std::chrono::milliseconds extra_wait = std::chrono::milliseconds{0});
  /// Call that throws DeviceError naming the command and status unless the answer is kOk.
  Reply Expect(wire::Command command, std::span<const std::uint8_t> payload = {},
               std::uint16_t sequence = 0,
               std::chrono::milliseconds extra_wait = std::chrono::milliseconds{0});
  template <typename Payload>
  requires requires { Payload::kBytes; }
  Reply Expect(wire::Command command, const Payload& payload) {
    return Expect(command, wire::EncodedBytes(payload));
  }

  wire::InfoResponse GetInfo();
  /// get-info's sampling page: when the board samples each channel after its timer edge. Empty
  /// for a board of protocol 2.0, which does not say.
  std::optional<wire::SamplingInfoResponse> GetSamplingInfo();
  /// get-info's health page: brown-out level and reset cause. Empty for a board of protocol 2.0.
  std::optional<wire::HealthInfoResponse> GetHealthInfo();
  /// get-info's watch page: the board's residual test ("model stale" flag, statistic, trip
  /// tick). Empty for a board of protocol 2.0 or firmware without the page.
  std::optional<wire::WatchInfoResponse> GetWatchInfo();
  /// get-info's fault page: what the fault handler recorded before the reset (reset cause
  /// fault); nullopt from a board of protocol 2.0 or firmware without the page.
  std::optional<wire::FaultInfoResponse> GetFaultInfo();
  /// self-test of one check (protocol 2.1); throws the board's refusal (busy while sampling).
  wire::SelfTestResponse SelfTest(std::uint8_t check);
  wire::StatusResponse GetStatus();
  void Ping();

  /// The active calibration record (kCalRecordBytes), checked against its stream CRC.
  std::vector<std::uint8_t> CalGet(wire::CalGetTrailer* trailer = nullptr);
  /// Uploads and stages a record; throws DeviceError with the device's verdict if refused.
  void CalPut(std::span<const std::uint8_t> record, const Progress& progress = {});
  wire::CalCommitResponse CalCommit();

  wire::AcqConfigureResponse Configure(const wire::AcqConfigureRequest& request);
  void StartAcquisition();
  wire::AcqStopResponse StopAcquisition();
  wire::LatestResponse ReadLatest();
  /// Clipped samples per channel of the current or last acquisition; nullopt from a 2.0 board,
  /// which does not count them per channel.
  std::optional<wire::ClipResponse> GetClips();
  void DobControl(bool run);
  /// Emulator only (kCapScenarioSelect).
  void SelectScenario(const std::string& name, std::span<const float> params);

  /// Starts the acquisition this connection configured (with kAcqFlagStream) and receives the
  /// log the board streams while it samples, to its end. If the stream breaks off, the records
  /// that arrived in sequence are kept and the rest comes as by PullLog. `progress` gets payload
  /// bytes received. Throws DeviceError if acq-start is refused, IncompleteLog if the board
  /// overwrote records before they could be pulled.
  /// When `stop` asks for it, sends acq-stop and pulls the rest of what was recorded: the records
  /// of the stream so far are kept as those of a broken stream are, and the log is read on from
  /// the first one missing. The result is marked `stopped`. The cancel flag still interrupts
  /// (Interrupted), keeping nothing.
  /// `live` gets every data report's records as it arrives (the resumed streams' too).
  LogPull AcquireStreamed(const Progress& progress = {}, const StopRequest& stop = {},
                          const LiveRecords& live = {});

  /// Pulls every record from `first` until the log holds no more and sampling has ended
  /// (while sampling, it keeps pulling as records arrive). Broken streams resume from the first
  /// missing record, up to `max_resumes` times in a row without progress. Throws DeviceError if
  /// `first` itself is no longer on the board, IncompleteLog if later records were overwritten
  /// before they could be pulled (the rest is pulled first).
  LogPull PullLog(std::uint32_t first = 0, const Progress& progress = {}, int max_resumes = 8);

 private:
  /// How a log stream ended.
  enum class StreamEnd : std::uint8_t {
    kComplete,     ///< The trailer checked out; its records were appended.
    kBroken,       ///< Broke off or timed out: ask again.
    kOverwritten,  ///< Refused out-of-range: the board's log wrapped over the first record.
    kStopped,      ///< A stop was asked for (the records so far kept, as when broken off).
  };

  void ReaderLoop();
  /// Receives one log stream answering `token` (records from `first`) to its trailer; appends
  /// its records to `pull` if the trailer checked out. With `keep_partial` (the stream of a
  /// running acquisition, whose records the board releases as they go out) the records of the
  /// data reports that arrived in sequence are appended too when it breaks off or is refused,
  /// decoded with the layout this connection configured. Throws on any other refusal.
  /// A stop asked for ends the stream with kStopped (its records kept as with `keep_partial`).
  StreamEnd ReceiveLogStream(std::uint16_t token, std::uint32_t first, LogPull& pull,
                             const Progress& progress, bool keep_partial,
                             const StopRequest& stop = {});
  /// Sends log-read for [first, first + max) and receives its stream (see ReceiveLogStream).
  StreamEnd RequestLog(std::uint32_t first, std::uint32_t max, LogPull& pull, bool keep_partial,
                       const StopRequest& stop);
  /// Appends the records of a broken stream's payloads (from log index `first`), decoded with the
  /// configured layout.
  void KeepPartialStream(std::uint32_t first,
                         const std::vector<std::vector<std::uint8_t>>& payloads,
                         LogPull& pull) const;
  /// Hands the records of `payload` (from log index `index`) to live_ and returns how many; a
  /// payload that does not decode is left to the stream's own checks (0).
  std::uint32_t ForwardLive(std::uint32_t index, std::span<const std::uint8_t> payload) const;
  static void AppendLogPayloads(const wire::LogLayout& layout, std::uint32_t decimation,
                                const std::vector<std::vector<std::uint8_t>>& payloads,
                                std::vector<wire::LogRecord>& records);
  static std::string OverwrittenMessage(std::uint32_t first);
  enum class PullMode : std::uint8_t {
    /// PullLog: log-read in chunks, each kept only whole; a first record the board no longer
    /// holds is refused.
    kChunks,
    /// The resume of a broken acquisition stream: log-read following the acquisition (records
    /// released as they go out, so a broken stream's records are kept); records the board
    /// overwrote are skipped.
    kFollow,
  };
  /// The pull loop from log index `next` into `pull`, to the end of the acquisition.
  /// Stops the acquisition (acq-stop) when `stop` asks for it, and then pulls to the log's end.
  void ContinuePull(LogPull& pull, std::uint32_t next, const Progress& progress, int max_resumes,
                    PullMode mode, const StopRequest& stop);
  /// acq-stop, and `pull` marked stopped.
  void StopForKeeps(LogPull& pull);
  std::uint16_t NextToken();
  void Send(const wire::Report& report);
  /// Waits for an answer with `token` to `command`. False on timeout.
  bool Await(std::uint8_t command, std::uint16_t token, std::chrono::milliseconds timeout,
             Reply& out);
  void ThrowIfLinkFailed();
  void CheckCancel() const;

  std::unique_ptr<Transport> transport_;
  ConnectionOptions options_;
  wire::InfoResponse info_{};
  /// The last acquisition configured through this connection (its layout decodes a broken stream).
  std::optional<wire::AcqConfigureRequest> configured_;
  /// The live sink of the AcquireStreamed call running (empty otherwise).
  LiveRecords live_;

  mutable std::mutex mutex_;
  std::condition_variable arrived_;
  std::deque<Reply> inbox_;
  std::string link_error_;     // set once by the reader when the transport fails
  std::string version_error_;  // set when a report of another protocol major arrived
  LinkCounters counters_{};
  std::atomic<bool> stop_{false};
  std::uint16_t token_ = 0;
  std::thread reader_;
};

}  // namespace vibid::device
