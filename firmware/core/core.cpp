#include "vibid/fw/core.hpp"

#include <algorithm>
#include <array>

#include "vibid/fw/version.hpp"
#include "vibid/shared/board_profile.hpp"
#include "vibid/shared/fixed/decimator.hpp"
#include "vibid/shared/wire/byte_order.hpp"
#include "vibid/shared/wire/log_record.hpp"

namespace vibid::fw {

using wire::Command;
using wire::Header;

Core::Core(const Port& port, ReportLink& link, std::span<std::uint8_t> log_storage,
           PortCommandHandler* port_commands)
    : port_(port),
      link_(link),
      port_commands_(port_commands),
      ring_(log_storage),
      sampler_(ring_, dob_),
      store_(port.flash) {}

Status Core::Boot() {
  const Status s = store_.Load();
  ApplyCalibration();
  return s;
}

void Core::ApplyCalibration() {
  sampler_.SetScaling(store_.record().channels);
  // The record passed the same validation as the kernel's Init, so this cannot fail; if it
  // did, the filter stays unloaded and every DOB request is refused, which get-status shows.
  (void)dob_.Load(store_.record());
}

bool Core::Sampling() const {
  const wire::AcqState s = sampler_.state();
  return sampling_ && (s == wire::AcqState::kArmed || s == wire::AcqState::kAcquiring);
}

void Core::StopSampling() {
  if (sampling_) {
    port_.frames.Stop();
    sampling_ = false;
  }
  sampler_.Disarm();
}

void Core::OnLinkReset() {
  stream_ = StreamKind::kNone;
  has_pending_ = false;
}

void Core::Poll() {
  if (sampling_ && sampler_.state() == wire::AcqState::kDone) StopSampling();
  for (int i = 0; i < kMaxReportsPerPoll; ++i) {
    if (has_pending_) {
      if (link_.Send(pending_) != Status::kOk) return;
      has_pending_ = false;
      if (deferred_ != Deferred::kNone) {
        const Deferred action = deferred_;
        deferred_ = Deferred::kNone;
        StopSampling();
        if (action == Deferred::kReset) {
          port_.system.Reset();
        } else {
          port_.system.EnterDfu();
        }
        return;
      }
      continue;
    }
    wire::Report request{};
    if (link_.Receive(request) == Status::kOk) {
      // A new request means the host gave up on any stream still running.
      stream_ = StreamKind::kNone;
      Handle(request);
      continue;
    }
    if (stream_ == StreamKind::kNone || !NextStreamReport()) return;
  }
}

Status Core::Refuse(Status status, wire::Reason reason, std::uint32_t detail) {
  refusal_ = wire::Refusal{.reason = reason, .detail = detail};
  return status;
}

void Core::Respond(const Header& request, Status status, std::span<const std::uint8_t> payload) {
  std::array<std::uint8_t, wire::Refusal::kBytes> why{};
  if (status != Status::kOk) {
    ++rejected_requests_;
    wire::Encode(refusal_, why);
    payload = why;
    refusal_ = {};
  }
  wire::Header h;
  h.command = request.command;
  h.status = status;
  h.flags = wire::kFlagResponse;
  h.token = request.token;
  h.sequence = request.sequence;
  (void)wire::EncodeReport(h, payload, pending_);
  has_pending_ = true;
}

template <typename Payload>
void Core::RespondWith(const Header& request, const Payload& payload) {
  Respond(request, Status::kOk, wire::EncodedBytes(payload));
}

wire::InfoResponse Core::Info() const {
  const FirmwareVersion v = CurrentFirmwareVersion();
  wire::InfoResponse info;
  info.fw_major = v.major;
  info.fw_minor = v.minor;
  info.fw_patch = v.patch;
  info.board_id = port_.system.Board();
  info.build_id = BuildId();
  info.capabilities = port_.system.PortCapabilities() | wire::kCapForceTrigger | wire::kCapDob;
  info.sample_period_us = configured_ ? config_.sample_period_us : kDefaultSamplePeriodUs;
  info.min_sample_period_us = wire::kMinSamplePeriodUs;
  info.log_capacity_bytes = static_cast<std::uint32_t>(ring_.storage_bytes());
  info.link_reports_per_s = static_cast<std::uint16_t>(kBoardProfile.link_reports_per_s);
  info.adc_bits = kBoardProfile.adc_bits;
  for (std::size_t c = 0; c < wire::kChannelCount; ++c) {
    info.channel_kind[c] = wire::KindOf(static_cast<wire::Channel>(c));
  }
  info.reset_cause = port_.system.LastResetCause();
  info.cal_state =
      store_.calibrated() ? wire::CalState::kCalibrated : wire::CalState::kUncalibrated;
  info.cal_slot = store_.slot();
  info.cal_crc = store_.record_crc();
  info.overrun_count = sampler_.overruns();
  info.dropped_records = sampler_.dropped();
  return info;
}

wire::SamplingInfoResponse Core::SamplingInfo() {
  // Every port delivers frames as the board samples them: the emulator's rig evaluates each
  // channel at these instants, and the QEMU image's injected frames stand for the board's.
  wire::SamplingInfoResponse r;
  for (std::size_t c = 0; c < wire::kChannelCount; ++c)
    r.sample_instant_ns[c] = kBoardProfile.sample_instant_ns(c);
  return r;
}

Status Core::HandleSelfTest(const wire::Header& h, std::span<const std::uint8_t> payload) {
  wire::SelfTestRequest request;
  if (wire::Decode(payload, request) != Status::kOk)
    return Refuse(Status::kInvalidArgument, wire::Reason::kPayloadLength);
  if (request.check >= wire::kSelfTestCheckCount)
    return Refuse(Status::kInvalidArgument, wire::Reason::kUnknownCheck, request.check);
  // The noise checks sample the converters the acquisition owns.
  if (Sampling()) return Refuse(Status::kFailedPrecondition, wire::Reason::kBusySampling);
  RespondWith(h, SelfTest(request.check));
  return Status::kOk;
}

wire::HealthInfoResponse Core::HealthInfo() const {
  const SystemControl::ClockReport clock = port_.system.ClockHealth();
  return wire::HealthInfoResponse{.brown_out = port_.system.BrownOutLevel(),
                                  .reset_cause = port_.system.LastResetCause(),
                                  .clock = clock.state,
                                  .hse_measured_hz = clock.hse_measured_hz,
                                  .sampler_recoveries = port_.system.SamplerRecoveries()};
}

wire::StatusResponse Core::CurrentStatus() const {
  wire::StatusResponse s;
  s.acq_state = sampler_.state();
  // Running now, or on (started, not stopped) while the board is idle: what the next
  // acquisition runs, so a host logs d_hat by default only when the observer is on.
  s.dob_running = sampler_.dob_running() || sampler_.dob_requested() ? 1 : 0;
  s.cal_state = store_.calibrated() ? wire::CalState::kCalibrated : wire::CalState::kUncalibrated;
  s.cal_staged = upload_.staged() ? 1 : 0;
  s.uptime_us = port_.clock.NowUs();
  s.ticks = sampler_.ticks();
  s.records_written = ring_.written();
  s.oldest_record = ring_.oldest();
  s.overrun_count = sampler_.overruns();
  s.dropped_records = sampler_.dropped();
  s.rejected_requests = rejected_requests_;
  s.saturation_count = sampler_.saturations();
  s.trigger_record = ring_.triggered() ? ring_.trigger_index() : wire::kNoRecord;
  s.cal_sequence = store_.sequence();
  s.flash_errors = store_.flash_errors();
  return s;
}

void Core::Handle(const wire::Report& request) {
  refusal_ = {};
  Header h;
  const Status header_status = wire::DecodeHeader(request, h);
  if (header_status == Status::kDataLoss) {
    // Not a vibid report: answer with what the bytes claim, so a confused host learns why.
    h.command = request[wire::kOffCommand];
    h.token = wire::LoadU16(request, wire::kOffToken);
    h.sequence = 0;
  }
  if (header_status != Status::kOk) {
    Respond(h, Refuse(header_status, wire::Reason::kMalformedRequest));
    return;
  }
  if ((h.flags & wire::kFlagResponse) != 0 ||
      (h.sequence != 0 && h.command != static_cast<std::uint8_t>(Command::kCalPutData))) {
    Respond(h, Refuse(Status::kInvalidArgument, wire::Reason::kMalformedRequest));
    return;
  }
  const Status s = Dispatch(h, wire::PayloadOf(request));
  if (s != Status::kOk) Respond(h, s);
}

Status Core::Dispatch(const Header& h, std::span<const std::uint8_t> payload) {
  if (wire::IsPortCommand(h.command)) return HandlePortCommand(h, payload);
  // Commands without a request payload refuse one.
  const bool stray_payload = !payload.empty();
  const auto refuse_payload = [this] {
    return Refuse(Status::kInvalidArgument, wire::Reason::kPayloadLength);
  };
  switch (static_cast<Command>(h.command)) {
    case Command::kPing: Respond(h, Status::kOk, payload); return Status::kOk;
    case Command::kGetInfo: {
      if (!stray_payload) {
        RespondWith(h, Info());
        return Status::kOk;
      }
      wire::InfoPageRequest page;
      if (wire::Decode(payload, page) != Status::kOk) return refuse_payload();
      if (page.page == wire::kInfoPageSampling) {
        RespondWith(h, SamplingInfo());
      } else if (page.page == wire::kInfoPageHealth) {
        RespondWith(h, HealthInfo());
      } else if (page.page == wire::kInfoPageWatch) {
        RespondWith(h, dob_.WatchInfo(sampler_.dob_running()));
      } else if (page.page == wire::kInfoPageFault) {
        RespondWith(h, port_.system.LastFault());
      } else {
        return Refuse(Status::kInvalidArgument, wire::Reason::kUnknownInfoPage, page.page);
      }
      return Status::kOk;
    }
    case Command::kGetStatus:
      if (stray_payload) return refuse_payload();
      RespondWith(h, CurrentStatus());
      return Status::kOk;
    case Command::kReset:
      if (stray_payload) return refuse_payload();
      Respond(h, Status::kOk);
      deferred_ = Deferred::kReset;
      return Status::kOk;
    case Command::kEnterDfu:
      if (stray_payload) return refuse_payload();
      if ((port_.system.PortCapabilities() & wire::kCapDfu) == 0)
        return Refuse(Status::kUnimplemented, wire::Reason::kNoBootloader);
      if (Sampling()) return Refuse(Status::kFailedPrecondition, wire::Reason::kBusySampling);
      Respond(h, Status::kOk);
      deferred_ = Deferred::kEnterDfu;
      return Status::kOk;
    case Command::kSelfTest: return HandleSelfTest(h, payload);
    case Command::kCalPutBegin: return HandleCalPutBegin(h, payload);
    case Command::kCalPutData: return HandleCalPutData(h, payload);
    case Command::kCalCommit: return stray_payload ? refuse_payload() : HandleCalCommit(h);
    case Command::kCalGet: return stray_payload ? refuse_payload() : HandleCalGet(h);
    case Command::kAcqConfigure: return HandleAcqConfigure(h, payload);
    case Command::kAcqStart: return stray_payload ? refuse_payload() : HandleAcqStart(h);
    case Command::kAcqStop:
      if (stray_payload) return refuse_payload();
      StopSampling();
      RespondWith(h, wire::AcqStopResponse{.records_written = ring_.written()});
      return Status::kOk;
    case Command::kReadLatest: {
      if (stray_payload) return refuse_payload();
      wire::LatestResponse latest;
      if (!sampler_.Latest(latest)) latest.acq_state = sampler_.state();
      RespondWith(h, latest);
      return Status::kOk;
    }
    case Command::kGetClips:
      if (stray_payload) return refuse_payload();
      RespondWith(h, sampler_.Clips());
      return Status::kOk;
    case Command::kLogRead: return HandleLogRead(h, payload);
    case Command::kDobControl: return HandleDobControl(h, payload);
    case Command::kSelectScenario:
    case Command::kInjectFrames: break;  // port commands, dispatched above
  }
  return Refuse(Status::kUnimplemented, wire::Reason::kUnknownCommand);
}

Status Core::HandlePortCommand(const Header& h, std::span<const std::uint8_t> payload) {
  if (port_commands_ == nullptr)
    return Refuse(Status::kUnimplemented, wire::Reason::kUnknownCommand);
  std::array<std::uint8_t, wire::kMaxPayload> response{};
  std::size_t length = 0;
  const Status s = port_commands_->HandlePortCommand(h.command, payload, response, length);
  if (s != Status::kOk) {
    // A port names its reason with a Refusal in the response bytes; one that does not gets a
    // reason from the status alone.
    wire::Refusal why;
    const auto bytes =
        std::span<const std::uint8_t>(response).first(std::min(length, response.size()));
    if (length >= wire::Refusal::kBytes && wire::Decode(bytes, why) == Status::kOk) {
      return Refuse(s, why.reason, why.detail);
    }
    return Refuse(s, s == Status::kUnimplemented ? wire::Reason::kUnknownCommand
                                                 : wire::Reason::kPortRefused);
  }
  Respond(h, s, std::span<const std::uint8_t>(response).first(std::min(length, response.size())));
  return Status::kOk;
}

Status Core::HandleCalPutBegin(const Header& h, std::span<const std::uint8_t> payload) {
  wire::CalPutBeginRequest begin;
  if (wire::Decode(payload, begin) != Status::kOk)
    return Refuse(Status::kInvalidArgument, wire::Reason::kPayloadLength);
  const Status s = upload_.Begin(begin);
  if (s != Status::kOk) {
    return Refuse(s, wire::Reason::kRecordLength,
                  static_cast<std::uint32_t>(wire::kCalRecordBytes));
  }
  Respond(h, Status::kOk);
  return s;
}

Status Core::HandleCalPutData(const Header& h, std::span<const std::uint8_t> payload) {
  bool complete = false;
  const std::uint16_t expected = upload_.next_sequence();
  const bool active = upload_.active();
  const Status s = upload_.Data(h.sequence, payload, complete);
  if (s == Status::kOk) {
    Respond(h, Status::kOk);
    return s;
  }
  if (!active || s == Status::kOutOfRange)
    return Refuse(s, wire::Reason::kUploadSequence, expected);
  if (!upload_.assembled()) return Refuse(s, wire::Reason::kPayloadLength);
  if (s == Status::kDataLoss) return Refuse(s, wire::Reason::kRecordCrc);
  return Refuse(s, wire::Reason::kRecordInvalid, static_cast<std::uint32_t>(s));
}

Status Core::HandleCalCommit(const Header& h) {
  if (Sampling()) return Refuse(Status::kFailedPrecondition, wire::Reason::kBusySampling);
  if (!upload_.staged()) return Refuse(Status::kFailedPrecondition, wire::Reason::kNothingStaged);
  const Status s = store_.Commit(upload_.bytes(), upload_.record());
  if (s != Status::kOk) return Refuse(s, wire::Reason::kFlashWrite);
  upload_.Clear();
  ApplyCalibration();
  RespondWith(h, wire::CalCommitResponse{.slot = store_.slot(), .sequence = store_.sequence()});
  return Status::kOk;
}

Status Core::HandleCalGet(const Header& h) {
  if (!store_.calibrated())
    return Refuse(Status::kFailedPrecondition, wire::Reason::kNotCalibrated);
  encoder_.Begin(Command::kCalGet, h.token);
  stream_token_ = h.token;
  stream_ = StreamKind::kCalibration;
  stream_follows_ = false;
  stream_next_ = 0;
  stream_end_ = static_cast<std::uint32_t>(wire::kCalRecordBytes);
  (void)NextStreamReport();
  return Status::kOk;
}

Status Core::ValidateConfig(const wire::AcqConfigureRequest& c) {
  if (c.sample_period_us < wire::kMinSamplePeriodUs ||
      c.sample_period_us > wire::kMaxSamplePeriodUs) {
    return Refuse(Status::kInvalidArgument, wire::Reason::kSamplePeriod, wire::kMinSamplePeriodUs);
  }
  const wire::LogLayout layout{c.channel_mask, c.flags};
  if (!layout.Valid()) return Refuse(Status::kInvalidArgument, wire::Reason::kChannelSelection);
  if (!fixed::IsSupportedDecimation(c.decimation))
    return Refuse(Status::kInvalidArgument, wire::Reason::kDecimation, wire::kMaxDecimation);
  if (c.trigger_mode == wire::TriggerMode::kImmediate) {
    if (c.trigger_channel != 0 || c.trigger_threshold != 0 || c.pretrigger_records != 0) {
      return Refuse(Status::kInvalidArgument, wire::Reason::kTrigger);
    }
  } else if (!wire::IsLoadCell(c.trigger_channel)) {
    return Refuse(Status::kInvalidArgument, wire::Reason::kTrigger);
  }
  const std::uint32_t capacity = ring_.CapacityFor(layout.StoredRecordBytes());
  if (c.pretrigger_records >= capacity)
    return Refuse(Status::kOutOfRange, wire::Reason::kPretriggerTooLong, capacity);
  if (layout.HasDob()) {
    if (!dob_.loaded()) return Refuse(Status::kFailedPrecondition, wire::Reason::kNoObserver);
    // The filter is only right at the rate it was discretized for.
    if (static_cast<std::uint64_t>(c.sample_period_us) * dob_.sample_rate_hz() != 1000000u) {
      return Refuse(Status::kInvalidArgument, wire::Reason::kObserverRate, dob_.sample_rate_hz());
    }
    if (layout.HasWatch() && !dob_.watch_loaded())
      return Refuse(Status::kFailedPrecondition, wire::Reason::kNoModelTest);
  }
  return Status::kOk;
}

Status Core::HandleAcqConfigure(const Header& h, std::span<const std::uint8_t> payload) {
  wire::AcqConfigureRequest c;
  if (wire::Decode(payload, c) != Status::kOk)
    return Refuse(Status::kInvalidArgument, wire::Reason::kPayloadLength);
  if (Sampling()) return Refuse(Status::kFailedPrecondition, wire::Reason::kBusySampling);
  const Status s = ValidateConfig(c);
  if (s != Status::kOk) return s;
  config_ = c;
  configured_ = true;
  const wire::LogLayout layout{c.channel_mask, c.flags};
  RespondWith(h, wire::AcqConfigureResponse{
                     .record_bytes = static_cast<std::uint16_t>(layout.RecordBytes()),
                     .capacity_records = ring_.CapacityFor(layout.StoredRecordBytes())});
  return Status::kOk;
}

Status Core::HandleAcqStart(const Header& h) {
  if (!configured_) return Refuse(Status::kFailedPrecondition, wire::Reason::kNotConfigured);
  if (Sampling()) return Refuse(Status::kFailedPrecondition, wire::Reason::kBusySampling);
  // On its internal oscillator the board's sample clock is off by up to the oscillator's
  // tolerance (a few percent): every rate derived from it would be silently wrong.
  const wire::ClockState clock = port_.system.ClockHealth().state;
  if (clock != wire::ClockState::kUnknown && clock != wire::ClockState::kCrystal)
    return Refuse(Status::kFailedPrecondition, wire::Reason::kInternalClock,
                  static_cast<std::uint32_t>(clock));
  if (sampling_) StopSampling();  // a finished acquisition whose stop Poll has not seen yet
  Status s = sampler_.Arm(config_);
  // The configuration passed ValidateConfig against the same log, so these are broken
  // invariants or a port that cannot sample at the period: named by status alone.
  if (s != Status::kOk) return Refuse(s, wire::Reason::kUnspecified);
  s = port_.frames.Start(config_.sample_period_us, sampler_);
  if (s != Status::kOk) {
    sampler_.Disarm();
    // The port cannot sample at this period (the emulator's rig has slower converters): its
    // limit is its own, so no detail.
    return Refuse(s, wire::Reason::kSamplePeriod, 0);
  }
  sampling_ = true;
  Respond(h, Status::kOk);
  // The stream's first report goes out after the answer (Poll sends pending_ first).
  if ((config_.flags & wire::kAcqFlagStream) != 0) StartLogStream(h.token, 0, 0, true);
  return Status::kOk;
}

void Core::StartLogStream(std::uint16_t token, std::uint32_t first, std::uint32_t end,
                          bool follow) {
  encoder_.Begin(Command::kLogRead, token);
  stream_token_ = token;
  stream_ = StreamKind::kLog;
  stream_follows_ = follow;
  stream_first_ = first;
  stream_next_ = first;
  stream_end_ = end;
}

Status Core::HandleLogRead(const Header& h, std::span<const std::uint8_t> payload) {
  wire::LogReadRequest r;
  if (wire::Decode(payload, r) != Status::kOk)
    return Refuse(Status::kInvalidArgument, wire::Reason::kPayloadLength);
  if (ring_.record_bytes() == 0)  // nothing acquired yet
    return Refuse(Status::kFailedPrecondition, wire::Reason::kNoLog);
  // Any record still intact can be read again, released or not (a second pull of a log pulled
  // while sampling); from first_record == written() the stream is empty (a host waiting for
  // more). The release only lets the sampler reuse space below first_record; it never moves back.
  const std::uint32_t written = ring_.written();
  if (r.first_record != written && !ring_.Intact(r.first_record))
    return Refuse(Status::kOutOfRange, wire::Reason::kLogOverwritten, ring_.oldest());
  if (ring_.Release(r.first_record) != Status::kOk)
    return Refuse(Status::kOutOfRange, wire::Reason::kLogOverwritten, ring_.oldest());
  std::uint32_t count = written - r.first_record;
  if (r.max_records != 0) count = std::min(count, r.max_records);
  // Following, the stream's end moves with the log (NextStreamReport).
  StartLogStream(h.token, r.first_record, r.first_record + count,
                 r.max_records == wire::kLogReadFollow);
  (void)NextStreamReport();
  return Status::kOk;
}

Status Core::HandleDobControl(const Header& h, std::span<const std::uint8_t> payload) {
  wire::DobControlRequest r;
  if (wire::Decode(payload, r) != Status::kOk)
    return Refuse(Status::kInvalidArgument, wire::Reason::kPayloadLength);
  if (r.run == 1 && !dob_.loaded())
    return Refuse(Status::kFailedPrecondition, wire::Reason::kNoObserver);
  sampler_.SetDobRunning(r.run == 1);
  Respond(h, Status::kOk);
  return Status::kOk;
}

Status Core::PackLogRecords(std::span<std::uint8_t, wire::kMaxStreamPayload> payload,
                            std::size_t& length) {
  // One report: the first record's tick, then records whose ticks follow by the decimation (a
  // gap, where the sampler dropped records, ends the report).
  const wire::LogLayout layout = sampler_.layout();
  const std::size_t rb = layout.RecordBytes();
  const std::uint32_t step = sampler_.config().decimation;
  const std::uint32_t n_max =
      std::min(static_cast<std::uint32_t>(layout.RecordsPerReport()), stream_end_ - stream_next_);
  std::uint32_t first_tick = 0;
  std::uint32_t n = 0;
  for (; n < n_max; ++n) {
    std::span<const std::uint8_t> stored;
    const Status s = ring_.Read(stream_next_ + n, stored);
    if (s != Status::kOk) return s;
    const std::uint32_t tick = wire::LoadU32(stored, 0);
    if (n == 0) {
      first_tick = tick;
    } else if (tick != first_tick + n * step) {
      break;
    }
    const auto body = stored.subspan(wire::kLogIndexBytes, rb);
    std::copy(body.begin(), body.end(),
              payload.begin() + static_cast<std::ptrdiff_t>(wire::kLogIndexBytes + n * rb));
  }
  // A released record can be overwritten while it is copied: if the oldest one of the report
  // is still intact now, so are the others, and the copies (ticks included) are whole.
  if (!ring_.Intact(stream_next_)) return Status::kOutOfRange;
  wire::StoreU32(payload, 0, first_tick);
  length = wire::kLogIndexBytes + n * rb;
  stream_next_ += n;
  return Status::kOk;
}

bool Core::NextStreamReport() {
  if (stream_ == StreamKind::kLog && stream_follows_) {
    // Following the acquisition: everything written so far is due; the stream ends once
    // sampling stopped and every record went out. Sent records are released at once, so the
    // link drains the log as fast as it can; they stay readable until overwritten (a host that
    // lost a report asks for them again with log-read).
    // Sampling is read before written(): a record pushed in between is still sent.
    const bool sampling = Sampling();
    stream_end_ = ring_.written();
    if (stream_next_ == stream_end_ && sampling) return false;
  }
  // Data goes out in stream data reports (58-byte payload); the trailer in a full report.
  std::array<std::uint8_t, wire::kMaxStreamPayload> payload{};
  std::size_t length = 0;
  Status s = Status::kOk;
  if (stream_next_ < stream_end_) {
    if (stream_ == StreamKind::kCalibration) {
      length = std::min<std::size_t>(wire::kMaxStreamPayload, stream_end_ - stream_next_);
      const auto bytes = store_.record_bytes().subspan(stream_next_, length);
      std::copy(bytes.begin(), bytes.end(), payload.begin());
      stream_next_ += static_cast<std::uint32_t>(length);
    } else {
      s = PackLogRecords(payload, length);
    }
    if (s == Status::kOk)
      s = encoder_.Data(std::span<const std::uint8_t>(payload).first(length), pending_);
    if (s == Status::kOk) {
      if (stream_ == StreamKind::kLog && stream_follows_) (void)ring_.Release(stream_next_);
      has_pending_ = true;
      return true;
    }
    // The stream cannot deliver what it promised. Out-of-range: the sampler overwrote released
    // records before they went out (ask again from a newer record); anything else is a broken
    // invariant. End with a refusal either way.
    Header h;
    h.command = static_cast<std::uint8_t>(stream_ == StreamKind::kLog ? Command::kLogRead
                                                                      : Command::kCalGet);
    h.token = stream_token_;  // the host's stream decoder takes only its own token
    stream_ = StreamKind::kNone;
    Respond(h, s == Status::kOutOfRange
                   ? Refuse(Status::kOutOfRange, wire::Reason::kLogOverwritten, ring_.oldest())
                   : Refuse(Status::kInternal, wire::Reason::kUnspecified));
    return true;
  }
  payload.fill(0);
  if (stream_ == StreamKind::kCalibration) {
    wire::CalGetTrailer t;
    t.slot = store_.slot();
    t.sequence = store_.sequence();
    wire::Encode(t, payload);
    (void)encoder_.End(std::span<std::uint8_t>(payload).first(wire::CalGetTrailer::kBytes),
                       pending_);
  } else {
    const wire::LogLayout layout = sampler_.layout();
    wire::LogTrailer t;
    t.first_record = stream_first_;
    t.record_count = stream_end_ - stream_first_;
    t.record_bytes = static_cast<std::uint16_t>(layout.RecordBytes());
    t.channel_mask = layout.channel_mask;
    t.acq_flags = sampler_.config().flags;
    t.sample_period_us = sampler_.config().sample_period_us;
    t.decimation = sampler_.config().decimation;
    t.acq_state = sampler_.state();
    t.trigger_record = ring_.triggered() ? ring_.trigger_index() : wire::kNoRecord;
    t.dropped_records = sampler_.dropped();
    t.overrun_count = sampler_.overruns();
    t.records_written = ring_.written();
    wire::Encode(t, payload);
    (void)encoder_.End(std::span<std::uint8_t>(payload).first(wire::LogTrailer::kBytes), pending_);
  }
  has_pending_ = true;
  stream_ = StreamKind::kNone;
  return true;
}

}  // namespace vibid::fw
