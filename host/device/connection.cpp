#include "vibid/device/connection.hpp"

#include <algorithm>
#include <random>

#include "vibid/device/error.hpp"
#include "vibid/device/refusal_text.hpp"
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
                       std::uint16_t sequence) {
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
    if (Await(id, token, options_.timeout, reply)) return reply;
  }
  throw DeviceError("no answer to " + CommandText(id) + " from " + Describe() + " after " +
                    std::to_string(options_.retries + 1) + " tries of " +
                    std::to_string(options_.timeout.count()) + " ms");
}

Reply Connection::Expect(Command command, std::span<const std::uint8_t> payload,
                         std::uint16_t sequence) {
  Reply r = Call(command, payload, sequence);
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

wire::SelfTestResponse Connection::SelfTest(std::uint8_t check) {
  return DecodeAnswer<wire::SelfTestResponse>(
      Expect(Command::kSelfTest, wire::SelfTestRequest{.check = check}), "self-test");
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

bool Connection::ReadLogOnce(std::uint32_t first, std::uint32_t max, LogPull& pull) {
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
  return ReceiveLogStream(token, first, pull, {}) == StreamEnd::kComplete;
}

Connection::StreamEnd Connection::ReceiveLogStream(std::uint16_t token, std::uint32_t first,
                                                   LogPull& pull, const Progress& progress,
                                                   const StopRequest& stop) {
  // Records are kept only from a stream whose trailer checked out (byte count and CRC-32 over
  // every data payload): a report corrupted in a way its header does not show is caught there.
  // The layout comes with the trailer, so payloads are kept whole until then.
  wire::StreamDecoder decoder(Command::kLogRead, token);
  std::vector<std::vector<std::uint8_t>> payloads;
  std::uint64_t bytes = 0;
  const auto id = static_cast<std::uint8_t>(Command::kLogRead);
  wire::LogTrailer trailer;
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
    if (stop && stop(nullptr)) {
      AppendPartialStream(payloads, first, pull);
      return StreamEnd::kStopped;
    }
    if (!got) return StreamEnd::kBroken;
    const auto step = decoder.Feed(r.report);
    if (step.event == wire::StreamDecoder::Event::kData) {
      payloads.emplace_back(step.payload.begin(), step.payload.end());
      bytes += step.payload.size();
      if (progress) progress(bytes, 0);
    } else if (step.event == wire::StreamDecoder::Event::kEnd) {
      if (wire::Decode(step.payload, trailer) != Status::kOk) return StreamEnd::kBroken;
      break;
    } else if (step.event == wire::StreamDecoder::Event::kRefused) {
      throw DeviceError(
          RefusalMessage(static_cast<std::uint8_t>(Command::kLogRead), step.status, step.payload) +
          " (log-read from record " + std::to_string(first) + ")");
    } else if (step.event == wire::StreamDecoder::Event::kError) {
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
  std::array<wire::LogRecord, wire::kMaxRecordsPerReport> batch{};
  for (const auto& p : payloads) {
    std::size_t n = 0;
    if (wire::DecodeLogPayload(layout, trailer.decimation, p, batch, n) != Status::kOk) {
      throw DeviceError("malformed log data report from the device");
    }
    records.insert(records.end(), batch.begin(), batch.begin() + static_cast<std::ptrdiff_t>(n));
  }
  if (records.size() != trailer.record_count)
    throw DeviceError("malformed log-read trailer from the device");
  if (pull.records.empty()) pull.first_record = first;
  pull.layout = layout;
  pull.trailer = trailer;
  pull.records.insert(pull.records.end(), records.begin(), records.end());
  return StreamEnd::kComplete;
}

void Connection::AppendPartialStream(const std::vector<std::vector<std::uint8_t>>& payloads,
                                     std::uint32_t first, LogPull& pull) const {
  // Without the trailer the layout is the configured one; the decoder has checked the reports'
  // sequence numbers. A payload that does not decode ends what is kept: the log-read that
  // follows starts again from the first record missing.
  if (!configured_) return;
  wire::LogLayout layout;
  layout.channel_mask = configured_->channel_mask;
  layout.flags = configured_->flags;
  if (!layout.Valid() || configured_->decimation == 0) return;
  if (pull.records.empty()) pull.first_record = first;
  pull.layout = layout;
  std::array<wire::LogRecord, wire::kMaxRecordsPerReport> batch{};
  for (const auto& p : payloads) {
    std::size_t n = 0;
    if (wire::DecodeLogPayload(layout, configured_->decimation, p, batch, n) != Status::kOk) return;
    pull.records.insert(pull.records.end(), batch.begin(),
                        batch.begin() + static_cast<std::ptrdiff_t>(n));
  }
}

void Connection::StopForKeeps(LogPull& pull) {
  // acq-stop is one short exchange, not cancellable: the board must be left idle.
  static_cast<void>(StopAcquisition());
  pull.stopped = true;
}

LogPull Connection::AcquireStreamed(const Progress& progress, const StopRequest& stop) {
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
  const StreamEnd end = ReceiveLogStream(token, 0, pull, progress, stop);
  if (end == StreamEnd::kComplete) return pull;
  if (end == StreamEnd::kStopped) {
    // The rest of what was recorded (records in flight when the stop went out, and any the
    // stream had not reached) is in the board's log.
    StopForKeeps(pull);
  } else {
    // The stream broke off (a lost or corrupted report, or a long wait for the trigger): the
    // records are still in the board's log; pull them, and the rest, with log-read.
    std::lock_guard lock(mutex_);
    ++counters_.stream_resumes;
  }
  PullLogInto(pull, 0, progress, 8, stop);
  return pull;
}

LogPull Connection::PullLog(std::uint32_t first, const Progress& progress, int max_resumes) {
  LogPull pull;
  pull.first_record = first;
  PullLogInto(pull, first, progress, max_resumes, {});
  return pull;
}

void Connection::PullLogInto(LogPull& pull, std::uint32_t first, const Progress& progress,
                             int max_resumes, const StopRequest& stop) {
  int failures = 0;
  for (;;) {
    CheckCancel();
    const std::uint32_t next = first + static_cast<std::uint32_t>(pull.records.size());
    const std::size_t before = pull.records.size();
    const bool complete = ReadLogOnce(next, kLogChunkRecords, pull);
    if (!complete) {
      std::lock_guard lock(mutex_);
      ++counters_.stream_resumes;
    }
    if (pull.records.size() > before)
      failures = 0;
    else if (!complete && ++failures > max_resumes) {
      throw DeviceError("log-read from record " + std::to_string(next) + " kept breaking off (" +
                        std::to_string(max_resumes) + " resumes without progress)");
    }
    if (!complete) continue;
    const wire::LogTrailer& t = pull.trailer;
    const std::uint32_t have = first + static_cast<std::uint32_t>(pull.records.size());
    const bool sampling =
        t.acq_state == wire::AcqState::kArmed || t.acq_state == wire::AcqState::kAcquiring;
    if (progress) progress(have, std::max(have, t.records_written));
    if (sampling && !pull.stopped && stop && stop(&t)) {
      // Read on: the next trailer says how many records the stopped acquisition left.
      StopForKeeps(pull);
      continue;
    }
    if (!sampling && have >= t.records_written) return;
    if (t.record_count == 0) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

}  // namespace vibid::device
