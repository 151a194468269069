#include "vibid/device/connection.hpp"

#include <algorithm>
#include <random>
#include <thread>

#include "vibid/device/error.hpp"
#include "vibid/device/refusal_text.hpp"
#include "vibid/shared/wire/refusal.hpp"
#include "vibid/shared/wire/stream.hpp"

namespace vibid::device {
namespace {

using wire::Command;

std::string CommandText(std::uint8_t command) { return wire::CommandName(command); }

std::string VersionMessage(std::uint8_t device_major) {
  return "the device speaks protocol " + std::to_string(device_major) + ".x, this host speaks " +
         std::to_string(wire::kProtocolMajor) + "." + std::to_string(wire::kProtocolMinor) +
         ": flash firmware that matches this host (vibid flash) or use a matching host";
}

constexpr std::chrono::milliseconds kReaderPoll{20};
/// Records per log-read request in a pull: a broken stream costs at most this many again.
constexpr std::uint32_t kLogChunkRecords = 4096;
/// Resumes in a row without progress before a streamed acquisition's pull gives up.
constexpr int kMaxResumes = 8;
/// Records a resume skips beyond the oldest one the board holds after its first refusal in a
/// row (then twice as many each time), and at most: a sampling board overwrites the oldest
/// record next.
constexpr std::uint32_t kFirstResumeMargin = 64;
constexpr std::uint32_t kMaxResumeMargin = 1u << 20;
/// How often a streamed acquisition asks whether to stop while no report arrives.
constexpr std::chrono::milliseconds kStopPoll{100};

}  // namespace

Connection::Connection(std::unique_ptr<Transport> transport, ConnectionOptions options)
    : transport_(std::move(transport)), options_(options) {
  // A random first token keeps answers meant for an earlier process on the same device from
  // matching this one's requests.
  std::random_device rd;
  token_ = static_cast<std::uint16_t>(rd());
  reader_ = std::thread([this] { ReaderLoop(); });
  try {
    info_ = GetInfo();
  } catch (...) {
    stop_ = true;
    reader_.join();
    throw;
  }
  if (info_.protocol_major != wire::kProtocolMajor) {
    stop_ = true;
    reader_.join();
    throw DeviceError(VersionMessage(info_.protocol_major));
  }
}

Connection::~Connection() {
  stop_ = true;
  if (reader_.joinable()) reader_.join();
}

LinkCounters Connection::counters() const {
  std::lock_guard lock(mutex_);
  return counters_;
}

void Connection::ReaderLoop() {
  wire::Report report{};
  while (!stop_) {
    std::size_t n = 0;
    try {
      n = transport_->Receive(report, kReaderPoll);
    } catch (const std::exception& e) {
      std::lock_guard lock(mutex_);
      link_error_ = e.what();
      arrived_.notify_all();
      return;
    }
    if (n == 0) continue;
    std::lock_guard lock(mutex_);
    if (n != wire::kReportBytes) {
      ++counters_.truncated;
      continue;
    }
    ++counters_.reports;
    Reply reply;
    reply.report = report;
    if (wire::IsStreamData(report)) {
      // A stream's data: it names its request by token only (see wire/report.hpp).
      wire::StreamDataHeader d;
      if (wire::DecodeStreamData(report, d) != Status::kOk) {
        ++counters_.corrupted;
        continue;
      }
      reply.stream_data = true;
      reply.header.token = d.token;
      reply.header.sequence = d.sequence;
      reply.header.payload_length = d.payload_length;
      reply.header.flags = wire::kFlagResponse;
      inbox_.push_back(reply);
      arrived_.notify_all();
      continue;
    }
    const Status st = wire::DecodeHeader(report, reply.header);
    if (st == Status::kVersionMismatch) {
      version_error_ = VersionMessage(reply.header.protocol_major);
      arrived_.notify_all();
      continue;
    }
    if (st != Status::kOk || (reply.header.flags & wire::kFlagResponse) == 0) {
      ++counters_.corrupted;
      continue;
    }
    inbox_.push_back(reply);
    arrived_.notify_all();
  }
}

std::uint16_t Connection::NextToken() {
  std::lock_guard lock(mutex_);
  return ++token_;
}

void Connection::ThrowIfLinkFailed() {
  std::lock_guard lock(mutex_);
  if (!link_error_.empty())
    throw DeviceError("lost the device (" + Describe() + "): " + link_error_);
  if (!version_error_.empty()) throw DeviceError(version_error_);
}

void Connection::CheckCancel() const {
  if (options_.cancel != nullptr && options_.cancel->load()) throw Interrupted("interrupted");
}

void Connection::Send(const wire::Report& report) {
  ThrowIfLinkFailed();
  try {
    transport_->Send(report);
  } catch (const DeviceError& e) {
    throw DeviceError("lost the device (" + Describe() + "): " + e.what());
  }
}

bool Connection::Await(std::uint8_t command, std::uint16_t token, std::chrono::milliseconds timeout,
                       Reply& out) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  std::unique_lock lock(mutex_);
  for (;;) {
    while (!inbox_.empty()) {
      Reply r = inbox_.front();
      inbox_.pop_front();
      if (r.header.token == token && (r.header.command == command || r.stream_data)) {
        out = r;
        return true;
      }
      ++counters_.stale;
    }
    if (!link_error_.empty()) {
      const std::string e = link_error_;
      lock.unlock();
      throw DeviceError("lost the device during " + CommandText(command) + " (" + Describe() +
                        "): " + e);
    }
    if (!version_error_.empty()) {
      const std::string e = version_error_;
      lock.unlock();
      throw DeviceError(e);
    }
    if (arrived_.wait_until(lock, deadline) == std::cv_status::timeout && inbox_.empty())
      return false;
  }
}

Reply Connection::Call(Command command, std::span<const std::uint8_t> payload,
                       std::uint16_t sequence, std::chrono::milliseconds extra_wait) {
  const std::uint16_t token = NextToken();
  wire::Report request{};
  if (wire::BuildReport(command, token, sequence, 0, Status::kOk, payload, request) !=
      Status::kOk) {
    throw DeviceError(CommandText(static_cast<std::uint8_t>(command)) + ": payload too long");
  }
  const auto id = static_cast<std::uint8_t>(command);
  // Not cancellable: a single exchange is short, and the stop that follows an interrupt must go
  // out.
  for (int attempt = 0; attempt <= options_.retries; ++attempt) {
    if (attempt > 0) {
      std::lock_guard lock(mutex_);
      ++counters_.retries;
    }
    Send(request);
    Reply reply;
    if (Await(id, token, options_.timeout + extra_wait, reply)) return reply;
  }
  throw DeviceError("no answer to " + CommandText(id) + " from " + Describe() + " after " +
                    std::to_string(options_.retries + 1) + " tries of " +
                    std::to_string((options_.timeout + extra_wait).count()) + " ms");
}

Reply Connection::Expect(Command command, std::span<const std::uint8_t> payload,
                         std::uint16_t sequence, std::chrono::milliseconds extra_wait) {
  Reply r = Call(command, payload, sequence, extra_wait);
  if (r.header.status != Status::kOk) {
    throw DeviceError(
        RefusalMessage(static_cast<std::uint8_t>(command), r.header.status, r.payload()));
  }
  return r;
}

namespace {
template <typename T>
T DecodeAnswer(const Reply& r, const char* what) {
  T v{};
  if (wire::Decode(r.payload(), v) != Status::kOk) {
    throw DeviceError(std::string("malformed ") + what + " answer from the device");
  }
  return v;
}

// A get-info page that firmware older than the page does not know (the watch and fault pages):
// its refusal as an unknown page is "no such page" (nullopt); any other refusal is an error.
std::optional<Reply> CallInfoPageIfKnown(Connection& c, std::uint8_t page) {
  Reply r = c.Call(Command::kGetInfo, wire::EncodedBytes(wire::InfoPageRequest{.page = page}));
  if (r.header.status == Status::kOk) return r;
  wire::Refusal why;
  if (wire::Decode(r.payload(), why) == Status::kOk &&
      why.reason == wire::Reason::kUnknownInfoPage) {
    return std::nullopt;
  }
  throw DeviceError(
      RefusalMessage(static_cast<std::uint8_t>(Command::kGetInfo), r.header.status, r.payload()));
}
}  // namespace

wire::InfoResponse Connection::GetInfo() {
  return DecodeAnswer<wire::InfoResponse>(Expect(Command::kGetInfo), "get-info");
}

std::optional<wire::SamplingInfoResponse> Connection::GetSamplingInfo() {
  if (info_.protocol_minor < 1) return std::nullopt;
  return DecodeAnswer<wire::SamplingInfoResponse>(
      Expect(Command::kGetInfo, wire::InfoPageRequest{.page = wire::kInfoPageSampling}),
      "get-info sampling page");
}

std::optional<wire::HealthInfoResponse> Connection::GetHealthInfo() {
  if (info_.protocol_minor < 1) return std::nullopt;
  return DecodeAnswer<wire::HealthInfoResponse>(
      Expect(Command::kGetInfo, wire::InfoPageRequest{.page = wire::kInfoPageHealth}),
      "get-info health page");
}

std::optional<wire::WatchInfoResponse> Connection::GetWatchInfo() {
  if (info_.protocol_minor < 1) return std::nullopt;
  // Firmware from before the residual test does not know the page: it has no test to report.
  const std::optional<Reply> r = CallInfoPageIfKnown(*this, wire::kInfoPageWatch);
  if (!r) return std::nullopt;
  return DecodeAnswer<wire::WatchInfoResponse>(*r, "get-info watch page");
}

std::optional<wire::FaultInfoResponse> Connection::GetFaultInfo() {
  if (info_.protocol_minor < 1) return std::nullopt;
  // Firmware from before the fault record does not know the page: it keeps no record.
  const std::optional<Reply> r = CallInfoPageIfKnown(*this, wire::kInfoPageFault);
  if (!r) return std::nullopt;
  return DecodeAnswer<wire::FaultInfoResponse>(*r, "get-info fault page");
}

wire::SelfTestResponse Connection::SelfTest(std::uint8_t check) {
  return DecodeAnswer<wire::SelfTestResponse>(
      Expect(Command::kSelfTest, wire::EncodedBytes(wire::SelfTestRequest{.check = check}), 0,
             std::chrono::milliseconds{wire::kSelfTestLongestCheckMs}),
      "self-test");
}

wire::StatusResponse Connection::GetStatus() {
  return DecodeAnswer<wire::StatusResponse>(Expect(Command::kGetStatus), "get-status");
}

void Connection::Ping() {
  const std::array<std::uint8_t, 4> probe{'v', 'i', 'b', 'd'};
  const Reply r = Expect(Command::kPing, probe);
  const auto p = r.payload();
  if (!std::equal(p.begin(), p.end(), probe.begin(), probe.end())) {
    throw DeviceError("ping: the device echoed other bytes");
  }
}

std::vector<std::uint8_t> Connection::CalGet(wire::CalGetTrailer* trailer) {
  for (int attempt = 0; attempt <= options_.retries; ++attempt) {
    const std::uint16_t token = NextToken();
    wire::Report request{};
    static_cast<void>(wire::BuildReport(Command::kCalGet, token, 0, 0, Status::kOk, {}, request));
    Send(request);
    wire::StreamDecoder decoder(Command::kCalGet, token);
    std::vector<std::uint8_t> bytes;
    for (;;) {
      CheckCancel();
      Reply r;
      if (!Await(static_cast<std::uint8_t>(Command::kCalGet), token, options_.timeout, r)) break;
      const auto step = decoder.Feed(r.report);
      if (step.event == wire::StreamDecoder::Event::kData) {
        bytes.insert(bytes.end(), step.payload.begin(), step.payload.end());
      } else if (step.event == wire::StreamDecoder::Event::kEnd) {
        wire::CalGetTrailer t;
        if (wire::Decode(step.payload, t) != Status::kOk)
          throw DeviceError("malformed cal-get trailer");
        if (trailer != nullptr) *trailer = t;
        return bytes;
      } else if (step.event == wire::StreamDecoder::Event::kRefused) {
        throw DeviceError(
            RefusalMessage(static_cast<std::uint8_t>(Command::kCalGet), step.status, step.payload));
      } else if (step.event == wire::StreamDecoder::Event::kError) {
        break;
      }
    }
    std::lock_guard lock(mutex_);
    ++counters_.retries;
  }
  throw DeviceError("cal-get: the calibration stream from " + Describe() + " kept breaking off");
}

void Connection::CalPut(std::span<const std::uint8_t> record, const Progress& progress) {
  // cal-put-begin restarts the staging, so a whole upload is the unit that is retried.
  const std::uint16_t token = NextToken();
  wire::Report report{};
  if (wire::BuildCalPutBegin(record, token, report) != Status::kOk) {
    throw DeviceError("calibration record of " + std::to_string(record.size()) +
                      " bytes cannot be sent");
  }
  const Reply begin = Expect(Command::kCalPutBegin, wire::PayloadOf(report));
  static_cast<void>(begin);
  const std::size_t chunks = wire::CalPutChunkCount(record.size());
  for (std::size_t c = 0; c < chunks; ++c) {
    CheckCancel();
    static_cast<void>(wire::BuildCalPutData(record, c, token, report));
    Reply r = Call(Command::kCalPutData, wire::PayloadOf(report), static_cast<std::uint16_t>(c));
    if (r.header.status != Status::kOk) {
      const bool last = c + 1 == chunks;
      throw DeviceError(std::string("the device refused the calibration record") +
                        (last ? "" : " at chunk " + std::to_string(c)) + ": " +
                        RefusalCause(r.header.status, r.payload()));
    }
    if (progress) progress(c + 1, chunks);
  }
}

wire::CalCommitResponse Connection::CalCommit() {
  return DecodeAnswer<wire::CalCommitResponse>(Expect(Command::kCalCommit), "cal-commit");
}

wire::AcqConfigureResponse Connection::Configure(const wire::AcqConfigureRequest& request) {
  const auto answer = DecodeAnswer<wire::AcqConfigureResponse>(
      Expect(Command::kAcqConfigure, request), "acq-configure");
  configured_ = request;
  return answer;
}

void Connection::StartAcquisition() { static_cast<void>(Expect(Command::kAcqStart)); }

wire::AcqStopResponse Connection::StopAcquisition() {
  return DecodeAnswer<wire::AcqStopResponse>(Expect(Command::kAcqStop), "acq-stop");
}

wire::LatestResponse Connection::ReadLatest() {
  return DecodeAnswer<wire::LatestResponse>(Expect(Command::kReadLatest), "read-latest");
}

std::optional<wire::ClipResponse> Connection::GetClips() {
  if (info_.protocol_minor < 1) return std::nullopt;  // get-clips came with protocol 2.1
  return DecodeAnswer<wire::ClipResponse>(Expect(Command::kGetClips), "get-clips");
}

void Connection::DobControl(bool run) {
  wire::DobControlRequest r;
  r.run = run ? 1 : 0;
  static_cast<void>(Expect(Command::kDobControl, r));
}

void Connection::SelectScenario(const std::string& name, std::span<const float> params) {
  wire::ScenarioRequest r;
  if (name.empty() || name.size() > r.name.size()) {
    throw DeviceError("scenario name '" + name + "' must have 1 to 16 characters");
  }
  if (params.size() > r.params.size()) throw DeviceError("a scenario takes at most 4 parameters");
  std::copy(name.begin(), name.end(), r.name.begin());
  std::copy(params.begin(), params.end(), r.params.begin());
  const Reply reply = Call(Command::kSelectScenario, wire::EncodedBytes(r));
  if (reply.header.status != Status::kOk) {
    // The scenario's name belongs in the sentence: the board does not echo it.
    throw DeviceError("the device refused select-scenario '" + name +
                      "': " + RefusalCause(reply.header.status, reply.payload()));
  }
}

Connection::StreamEnd Connection::RequestLog(std::uint32_t first, std::uint32_t max, LogPull& pull,
                                             bool keep_partial, const StopRequest& stop) {
  const std::uint16_t token = NextToken();
  wire::LogReadRequest req;
  req.first_record = first;
  req.max_records = max;
  std::array<std::uint8_t, wire::LogReadRequest::kBytes> payload{};
  wire::Encode(req, payload);
  wire::Report request{};
  static_cast<void>(
      wire::BuildReport(Command::kLogRead, token, 0, 0, Status::kOk, payload, request));
  Send(request);
  return ReceiveLogStream(token, first, pull, {}, keep_partial, stop);
}

Connection::StreamEnd Connection::ReceiveLogStream(std::uint16_t token, std::uint32_t first,
                                                   LogPull& pull, const Progress& progress,
                                                   bool keep_partial, const StopRequest& stop) {
  // Records are kept only from a stream whose trailer checked out (byte count and CRC-32 over
  // every data payload): a report corrupted in a way its header does not show is caught there.
  // The layout comes with the trailer, so payloads are kept whole until then.
  wire::StreamDecoder decoder(Command::kLogRead, token);
  std::vector<std::vector<std::uint8_t>> payloads;
  std::uint32_t live_index = first;  // log index of the next record handed to live_
  std::uint64_t bytes = 0;
  const auto id = static_cast<std::uint8_t>(Command::kLogRead);
  wire::LogTrailer trailer;
  // A running acquisition's stream is the exception: the board released every record it sent,
  // so when the stream ends early (broken off, refused or stopped), the reports that arrived in
  // sequence are all the host may ever get of them. They are kept (each passed the link's own
  // check and the stream's sequence and length checks; only the stream CRC, which comes last,
  // cannot vouch for them). Not after a count or CRC mismatch in the trailer: then some payload
  // is known to be wrong.
  const auto end_early = [&](StreamEnd end) {
    if (keep_partial && configured_) KeepPartialStream(first, payloads, pull);
    return end;
  };
  // With a stop to watch, the wait for a report is cut into slices so a stop is seen promptly.
  const std::chrono::milliseconds slice =
      stop ? std::min(options_.timeout, kStopPoll) : options_.timeout;
  for (;;) {
    CheckCancel();
    Reply r;
    bool got = false;
    for (auto waited = std::chrono::milliseconds(0); !got && waited < options_.timeout;
         waited += slice) {
      got = Await(id, token, slice, r);
      if (!got && stop && stop(nullptr)) break;
      CheckCancel();
    }
    if (stop && stop(nullptr)) return end_early(StreamEnd::kStopped);
    if (!got) return end_early(StreamEnd::kBroken);
    const auto step = decoder.Feed(r.report);
    if (step.event == wire::StreamDecoder::Event::kData) {
      if (keep_partial && live_ && configured_) live_index += ForwardLive(live_index, step.payload);
      payloads.emplace_back(step.payload.begin(), step.payload.end());
      bytes += step.payload.size();
      if (progress) progress(bytes, 0);
    } else if (step.event == wire::StreamDecoder::Event::kEnd) {
      if (wire::Decode(step.payload, trailer) != Status::kOk) return StreamEnd::kBroken;
      break;
    } else if (step.event == wire::StreamDecoder::Event::kRefused) {
      // Out-of-range: the board's log wrapped over a record of the stream before it went out.
      if (step.status == Status::kOutOfRange) return end_early(StreamEnd::kOverwritten);
      throw DeviceError(
          RefusalMessage(static_cast<std::uint8_t>(Command::kLogRead), step.status, step.payload) +
          " (log-read from record " + std::to_string(first) + ")");
    } else if (step.event == wire::StreamDecoder::Event::kError) {
      // A sequence gap, or a trailer that counts more bytes than arrived (the last reports were
      // lost): what came before is whole. A trailer whose count matches but whose CRC does not
      // says that some payload is wrong.
      wire::StreamTrailer sent;
      const bool lost_tail = !wire::IsStreamData(r.report) &&
                             wire::Decode(r.payload(), sent) == Status::kOk &&
                             sent.total_bytes > decoder.total_bytes();
      if (wire::IsStreamData(r.report) || lost_tail) return end_early(StreamEnd::kBroken);
      return StreamEnd::kBroken;
    }
  }
  wire::LogLayout layout;
  layout.channel_mask = trailer.channel_mask;
  layout.flags = trailer.acq_flags;
  if (!layout.Valid() || trailer.first_record != first ||
      trailer.record_bytes != layout.RecordBytes() || trailer.decimation == 0) {
    throw DeviceError("malformed log-read trailer from the device");
  }
  std::vector<wire::LogRecord> records;
  records.reserve(trailer.record_count);
  AppendLogPayloads(layout, trailer.decimation, payloads, records);
  if (records.size() != trailer.record_count)
    throw DeviceError("malformed log-read trailer from the device");
  if (pull.records.empty() && pull.missing.empty()) pull.first_record = first;
  pull.layout = layout;
  pull.trailer = trailer;
  pull.records.insert(pull.records.end(), records.begin(), records.end());
  return StreamEnd::kComplete;
}

void Connection::KeepPartialStream(std::uint32_t first,
                                   const std::vector<std::vector<std::uint8_t>>& payloads,
                                   LogPull& pull) const {
  const wire::AcqConfigureRequest& c = *configured_;
  const wire::LogLayout layout{c.channel_mask, c.flags};
  std::vector<wire::LogRecord> records;
  AppendLogPayloads(layout, c.decimation, payloads, records);
  if (records.empty()) return;
  if (pull.records.empty() && pull.missing.empty()) pull.first_record = first;
  if (pull.trailer.decimation == 0) {
    // No trailer yet: the acquisition as configured, so the records can be written even if no
    // stream of it ever completes.
    pull.layout = layout;
    pull.trailer.record_bytes = static_cast<std::uint16_t>(layout.RecordBytes());
    pull.trailer.channel_mask = c.channel_mask;
    pull.trailer.acq_flags = c.flags;
    pull.trailer.sample_period_us = c.sample_period_us;
    pull.trailer.decimation = c.decimation;
    pull.trailer.trigger_record = wire::kNoRecord;
  }
  pull.records.insert(pull.records.end(), records.begin(), records.end());
}

void Connection::AppendLogPayloads(const wire::LogLayout& layout, std::uint32_t decimation,
                                   const std::vector<std::vector<std::uint8_t>>& payloads,
                                   std::vector<wire::LogRecord>& records) {
  std::array<wire::LogRecord, wire::kMaxRecordsPerReport> batch{};
  for (const auto& p : payloads) {
    std::size_t n = 0;
    if (wire::DecodeLogPayload(layout, decimation, p, batch, n) != Status::kOk) {
      throw DeviceError("malformed log data report from the device");
    }
    records.insert(records.end(), batch.begin(), batch.begin() + static_cast<std::ptrdiff_t>(n));
  }
}

std::string Connection::OverwrittenMessage(std::uint32_t first) {
  return "the device refused log-read from record " + std::to_string(first) + ": " +
         StatusName(Status::kOutOfRange);
}

void Connection::StopForKeeps(LogPull& pull) {
  // acq-stop is one short exchange, not cancellable: the board must be left idle.
  static_cast<void>(StopAcquisition());
  pull.stopped = true;
}

std::uint32_t Connection::ForwardLive(std::uint32_t index,
                                      std::span<const std::uint8_t> payload) const {
  const wire::AcqConfigureRequest& c = *configured_;
  const wire::LogLayout layout{c.channel_mask, c.flags};
  std::array<wire::LogRecord, wire::kMaxRecordsPerReport> batch{};
  std::size_t n = 0;
  if (wire::DecodeLogPayload(layout, c.decimation, payload, batch, n) != Status::kOk) return 0;
  live_(index, std::span<const wire::LogRecord>(batch.data(), n));
  return static_cast<std::uint32_t>(n);
}

LogPull Connection::AcquireStreamed(const Progress& progress, const StopRequest& stop,
                                    const LiveRecords& live) {
  live_ = live;
  struct ClearLive {
    LiveRecords& sink;
    ~ClearLive() { sink = {}; }
  } clear_live{live_};
  const std::uint16_t token = NextToken();
  wire::Report request{};
  static_cast<void>(wire::BuildReport(Command::kAcqStart, token, 0, 0, Status::kOk, {}, request));
  Send(request);
  Reply answer;
  if (!Await(static_cast<std::uint8_t>(Command::kAcqStart), token, options_.timeout, answer)) {
    throw DeviceError("no answer to acq-start from " + Describe());
  }
  if (answer.header.status != Status::kOk) {
    throw DeviceError(RefusalMessage(static_cast<std::uint8_t>(Command::kAcqStart),
                                     answer.header.status, answer.payload()));
  }
  LogPull pull;
  const StreamEnd end = ReceiveLogStream(token, 0, pull, progress, true, stop);
  if (end == StreamEnd::kComplete) return pull;
  if (end == StreamEnd::kStopped) {
    // The rest of what was recorded (records in flight when the stop went out, and any the
    // stream had not reached) is in the board's log: the pull below follows it to its end.
    StopForKeeps(pull);
  } else {
    // The stream broke off (a lost or corrupted report, a stall of either side, a long wait for
    // the trigger). It released every record it sent, and the log may have wrapped over the
    // first ones since: the pull goes on from the first record that did not arrive, which the
    // board keeps until the log wraps over it, with a stream that follows the acquisition
    // again. (Pulling the rest in requests would leave the link idle between them: a board
    // samples on regardless, so a slow host would drop records the stream carries.)
    std::lock_guard lock(mutex_);
    ++counters_.stream_resumes;
  }
  ContinuePull(pull, static_cast<std::uint32_t>(pull.records.size()), progress, kMaxResumes,
               PullMode::kFollow, stop);
  return pull;
}

LogPull Connection::PullLog(std::uint32_t first, const Progress& progress, int max_resumes) {
  LogPull pull;
  pull.first_record = first;
  ContinuePull(pull, first, progress, max_resumes, PullMode::kChunks, {});
  return pull;
}

void Connection::ContinuePull(LogPull& pull, std::uint32_t next, const Progress& progress,
                              int max_resumes, PullMode mode, const StopRequest& stop) {
  const bool follow = mode == PullMode::kFollow;
  int failures = 0;
  std::uint32_t margin = 0;
  for (;;) {
    CheckCancel();
    if (follow && stop && !pull.stopped && pull.records.empty() && pull.missing.empty()) {
      // Nothing has arrived yet: the board may be waiting for its trigger. Between two following
      // streams none is open, so one get-status tells a stop that watches the trigger (its
      // timeout, its status line) what the board is doing; the round trip costs no record, as
      // the board keeps its pretrigger in the log.
      wire::LogTrailer state;
      state.acq_state = GetStatus().acq_state;
      if (stop(&state)) StopForKeeps(pull);
    }
    const std::size_t before = pull.records.size();
    // Once stopped, the board's acquisition has ended: nothing more to watch for.
    const StopRequest watch = pull.stopped ? StopRequest{} : stop;
    const StreamEnd end =
        RequestLog(next, follow ? wire::kLogReadFollow : kLogChunkRecords, pull, follow, watch);
    const auto received = static_cast<std::uint32_t>(pull.records.size() - before);
    if (end == StreamEnd::kOverwritten) {
      if (!follow && pull.records.empty() && pull.missing.empty())
        throw DeviceError(OverwrittenMessage(next));
      // The board's log wrapped over `next` before it could be pulled (the host fell a whole
      // log behind): those records are gone, the ones it still holds are not. While the board
      // samples, the oldest one it names is the next to go: after a refusal in a row the pull
      // aims further ahead, twice as far each time, so that it overtakes the sampler instead
      // of chasing it.
      const wire::StatusResponse st = GetStatus();
      const std::uint32_t target = std::min(st.records_written, st.oldest_record + margin);
      margin = margin == 0 ? kFirstResumeMargin : std::min(2 * margin, kMaxResumeMargin);
      if (target > next) {
        if (!pull.missing.empty() && pull.missing.back().end == next)
          pull.missing.back().end = target;
        else
          pull.missing.push_back(LogRange{next, target});
        next = target;
      } else if (++failures > max_resumes) {
        throw DeviceError(OverwrittenMessage(next));
      }
      continue;
    }
    next += received;
    if (end == StreamEnd::kStopped) {
      // Read on: the stopped acquisition's log goes to its end.
      StopForKeeps(pull);
      continue;
    }
    const bool complete = end == StreamEnd::kComplete;
    if (complete) margin = 0;
    if (!complete) {
      std::lock_guard lock(mutex_);
      ++counters_.stream_resumes;
    }
    // A following stream that brought nothing yet may be waiting for the trigger. (Asking the
    // board would stop the stream: the link would idle for a round trip while it samples.)
    const bool waiting = follow && received == 0 && pull.records.empty() && pull.missing.empty();
    if (received > 0 || waiting)
      failures = 0;
    else if (!complete && ++failures > max_resumes) {
      const std::string why = "log-read from record " + std::to_string(next) +
                              " kept breaking off (" + std::to_string(max_resumes) +
                              " resumes without progress)";
      // What a following pull received was released on the board: it must not be lost here.
      if (follow && !pull.records.empty()) throw IncompleteLog(std::move(pull), why);
      throw DeviceError(why);
    }
    if (!complete) continue;
    const wire::LogTrailer& t = pull.trailer;
    const bool sampling =
        t.acq_state == wire::AcqState::kArmed || t.acq_state == wire::AcqState::kAcquiring;
    if (progress) {
      // Acquiring: payload bytes, as the stream it resumes counts them.
      if (follow)
        progress(std::uint64_t{next} * pull.layout.RecordBytes(), 0);
      else
        progress(next, std::max(next, t.records_written));
    }
    if (sampling && !pull.stopped && stop && stop(&t)) {
      StopForKeeps(pull);
      continue;
    }
    if (!sampling && next >= t.records_written) {
      if (!pull.missing.empty()) throw IncompleteLog(std::move(pull));
      return;
    }
    if (t.record_count == 0) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

namespace {

std::string RangeText(std::uint32_t first, std::uint32_t end) {
  return end == first + 1 ? std::to_string(first)
                          : std::to_string(first) + ".." + std::to_string(end - 1);
}

std::string IncompleteMessage(const LogPull& pull, const std::string& why) {
  std::string lost;
  std::string kept;
  std::uint64_t lost_count = 0;
  std::uint32_t from = pull.first_record;
  for (const LogRange& m : pull.missing) {
    if (m.first > from) kept += (kept.empty() ? "" : ", ") + RangeText(from, m.first);
    lost += (lost.empty() ? "" : ", ") + RangeText(m.first, m.end);
    lost_count += m.end - m.first;
    from = m.end;
  }
  const std::uint32_t end =
      pull.first_record + static_cast<std::uint32_t>(pull.records.size() + lost_count);
  if (end > from) kept += (kept.empty() ? "" : ", ") + RangeText(from, end);
  std::string head = why;
  if (!pull.missing.empty()) {
    head = "the board's log wrapped over records " + lost + " (" + std::to_string(lost_count) +
           ") before they could be pulled" + (why.empty() ? "" : "; " + why);
  }
  return head + "; kept " + std::to_string(pull.records.size()) +
         " records: " + (kept.empty() ? "none" : kept);
}

}  // namespace

IncompleteLog::IncompleteLog(LogPull pull, const std::string& why)
    : DeviceError(IncompleteMessage(pull, why)), pull_(std::move(pull)) {}

}  // namespace vibid::device
