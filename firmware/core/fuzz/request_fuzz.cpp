// Fuzzes the board's command server. Random reports almost never get past the header and CRC
// checks, so the input is read as a script (FuzzedDataProvider): each step sends a well-formed
// request for a command the fuzzer picks (payloads built from their fields, calibration uploads
// cut into chunks with a correct CRC most of the time), a request with one header field broken,
// a raw report, frames from the ADCs, a power cut during a commit, a reboot or back-pressure on
// the IN endpoint. The harness checks what a host relies on:
//   - every request is answered, with its own token, the response flag and a known status; a
//     refusal carries a Refusal naming a known reason (protocol 2.1), an answer to get-clips
//     counts no more clipped samples per channel than ticks;
//   - a header that breaks the rules is refused, never dispatched;
//   - log-read and cal-get answer with a stream the host decoder accepts (data, then a trailer
//     whose byte count and CRC match) or with one refusal; a cal-get stream holds one record;
//   - the log stream that follows an acquisition never breaks sequence or CRC, and its records
//     decode with the layout its trailer names.
// An input whose first byte has the top bit set is the previous raw format instead (64-byte
// reports sent as they are), so the regression inputs found with it keep their meaning.
#include <fuzzer/FuzzedDataProvider.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <optional>
#include <span>
#include <type_traits>
#include <vector>

#include "fake_port.hpp"
#include "golden_vectors.hpp"
#include "vibid/fw/core.hpp"
#include "vibid/shared/wire/byte_order.hpp"
#include "vibid/shared/wire/refusal.hpp"
#include "vibid/shared/wire/calibration_record.hpp"
#include "vibid/shared/wire/commands.hpp"
#include "vibid/shared/wire/crc32.hpp"
#include "vibid/shared/wire/log_record.hpp"
#include "vibid/shared/wire/stream.hpp"

namespace {

using namespace vibid;
using fw::testing::FakeLink;
using fw::testing::FakePort;
using wire::Command;
using Event = wire::StreamDecoder::Event;

void Require(bool condition) {
  if (!condition) __builtin_trap();
}

const std::array<std::uint8_t, wire::kCalRecordBytes>& GoldenRecord(bool with_filter) {
  static const auto load = [](const char* name) {
    std::array<std::uint8_t, wire::kCalRecordBytes> r{};
    Require(wire::testing::GoldenVector(name, r) == r.size());
    return r;
  };
  static const auto plain = load("calibration_record");
  static const auto dob = load("calibration_record_dob");
  return with_filter ? dob : plain;
}

// Every id the core dispatches, the port range included, and a few it does not know.
constexpr std::array<std::uint8_t, 22> kCommandIds = {
    0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x10, 0x11, 0x12, 0x13, 0x20,
    0x21, 0x22, 0x23, 0x24, 0x25, 0x30, 0x70, 0x71, 0x7F, 0x00, 0xFF};

// A port that knows two commands, so the core's port dispatch sees answers and refusals.
class FuzzPortCommands final : public fw::PortCommandHandler {
 public:
  Status HandlePortCommand(std::uint8_t command, std::span<const std::uint8_t> request,
                           std::span<std::uint8_t, wire::kMaxPayload> response,
                           std::size_t& response_length) override {
    if (command == 0x70) {
      if (request.size() != wire::ScenarioRequest::kBytes) return Status::kInvalidArgument;
      std::copy(request.begin(), request.begin() + 4, response.begin());
      response_length = 4;
      return Status::kOk;
    }
    if (command == 0x71) {
      wire::InjectFramesRequest inject;
      return wire::Decode(request, inject);
    }
    return Status::kUnimplemented;
  }
};

class Board {
 public:
  Board() {
    // Port measurements for the self-test's judging, the extremes among them: each check is
    // judged without overflow whatever the port reports.
    auto& m = fake.system.self_test;
    m[0] = {.available = true, .mantissa = INT64_MIN, .exp10 = 127};
    m[1] = {.available = true, .mantissa = 3300, .exp10 = -3};
    m[2] = {.available = true, .mantissa = INT64_MAX, .exp10 = -128};
    m[6] = {.available = true, .mantissa = -40, .exp10 = 0};
    m[8] = {.available = true, .mantissa = INT64_MIN, .exp10 = -6};
    m[10] = {.available = true, .mantissa = 17, .exp10 = 0, .ok = true};
    fake.system.brown_out = wire::BrownOut::kLevel2;
    Reboot();
  }

  void Reboot() {
    core_.reset();
    link.ClearOut();
    core_.emplace(fake.port(), link, log_storage, &port_commands);
    (void)core_->Boot();
    follow_.reset();
  }

  fw::Core& core() { return *core_; }

  // Polls until the core has nothing more to say, taking every report it sends.
  std::vector<wire::Report> Drain() {
    std::vector<wire::Report> out;
    for (int idle = 0, polls = 0; idle < 2 && polls < 4000; ++polls) {
      core_->Poll();
      wire::Report r{};
      bool any = false;
      while (link.Pop(r)) {
        any = true;
        if (follow_ && IsFollowed(r)) {
          Follow(r);
        } else {
          out.push_back(r);
        }
      }
      idle = any ? 0 : idle + 1;
    }
    return out;
  }

  void StartFollowing(std::uint16_t token) {
    follow_.emplace(Command::kLogRead, token);
    follow_token_ = token;
    follow_payloads_.clear();
  }
  bool following(std::uint16_t token) const { return follow_ && follow_token_ == token; }

  FakePort fake;
  FakeLink link;
  std::array<std::uint8_t, 2048> log_storage{};
  FuzzPortCommands port_commands;

  bool IsFollowed(const wire::Report& r) const {
    if (wire::IsStreamData(r)) return wire::LoadU16(r, 2) == follow_token_;
    wire::Header h;
    return wire::DecodeHeader(r, h) == Status::kOk && h.token == follow_token_ &&
           h.command == static_cast<std::uint8_t>(Command::kLogRead);
  }

  void Follow(const wire::Report& r) {
    Require(follow_.has_value() && IsFollowed(r));
    const wire::StreamDecoder::Step step = follow_->Feed(r);
    Require(step.event == Event::kData || step.event == Event::kEnd ||
            step.event == Event::kRefused);
    if (step.event == Event::kData) {
      follow_payloads_.emplace_back(step.payload.begin(), step.payload.end());
      return;
    }
    if (step.event == Event::kEnd) {
      wire::LogTrailer trailer;
      Require(wire::Decode(step.payload, trailer) == Status::kOk);
      CheckLogPayloads(trailer, follow_payloads_);
    }
    follow_.reset();
  }

 public:
  static void CheckLogPayloads(const wire::LogTrailer& trailer,
                               const std::vector<std::vector<std::uint8_t>>& payloads) {
    const wire::LogLayout layout{trailer.channel_mask, trailer.acq_flags};
    std::uint32_t records = 0;
    for (const auto& p : payloads) {
      std::array<wire::LogRecord, wire::kMaxRecordsPerReport> batch{};
      std::size_t n = 0;
      Require(wire::DecodeLogPayload(layout, trailer.decimation, p, batch, n) == Status::kOk);
      records += static_cast<std::uint32_t>(n);
    }
    Require(records == trailer.record_count);
  }

 private:
  std::optional<fw::Core> core_;
  std::optional<wire::StreamDecoder> follow_;
  std::uint16_t follow_token_ = 0;
  std::vector<std::vector<std::uint8_t>> follow_payloads_;
};

std::vector<std::uint8_t> Payload(FuzzedDataProvider& in, std::uint8_t id) {
  std::vector<std::uint8_t> p;
  const auto encode = [&p](const auto& v) {
    p.resize(std::remove_cvref_t<decltype(v)>::kBytes);
    wire::Encode(v, p);
  };
  // One time in eight the payload is arbitrary bytes of any length the header allows.
  if (in.ConsumeIntegralInRange<int>(0, 7) == 0) {
    return in.ConsumeBytes<std::uint8_t>(
        in.ConsumeIntegralInRange<std::size_t>(0, wire::kMaxPayload));
  }
  switch (static_cast<Command>(id)) {
    case Command::kPing:
      return in.ConsumeBytes<std::uint8_t>(
          in.ConsumeIntegralInRange<std::size_t>(0, wire::kMaxPayload));
    case Command::kAcqConfigure: {
      constexpr std::array<std::uint32_t, 7> kPeriods = {200, 100, 1000, 250, 99, 1000001, 500};
      constexpr std::array<std::uint16_t, 9> kDecimations = {1, 2, 5, 10, 1000, 0, 3, 1024, 8};
      wire::AcqConfigureRequest c;
      c.sample_period_us =
          in.ConsumeBool() ? in.PickValueInArray(kPeriods) : in.ConsumeIntegral<std::uint32_t>();
      c.channel_mask = static_cast<std::uint8_t>(in.ConsumeIntegralInRange<unsigned>(0, 0x40));
      c.flags = static_cast<std::uint8_t>(in.ConsumeIntegralInRange<unsigned>(0, 4));
      c.decimation = in.PickValueInArray(kDecimations);
      c.trigger_mode = static_cast<wire::TriggerMode>(in.ConsumeIntegralInRange<unsigned>(0, 3));
      // Trigger fields are set for an immediate start too, now and then: the board must refuse
      // them.
      if (c.trigger_mode != wire::TriggerMode::kImmediate ||
          in.ConsumeIntegralInRange<int>(0, 7) == 7) {
        c.trigger_channel = static_cast<std::uint8_t>(in.ConsumeIntegralInRange<unsigned>(0, 6));
        c.trigger_threshold = in.ConsumeIntegralInRange<std::int32_t>(-(1 << 30), 1 << 30);
        c.pretrigger_records = in.ConsumeIntegralInRange<std::uint32_t>(0, 200);
      }
      c.record_limit = in.ConsumeIntegralInRange<std::uint32_t>(0, 300);
      encode(c);
      return p;
    }
    case Command::kLogRead: {
      wire::LogReadRequest r;
      r.first_record = in.ConsumeIntegralInRange<std::uint32_t>(0, 400);
      r.max_records = in.ConsumeIntegralInRange<std::uint32_t>(0, 100);
      encode(r);
      return p;
    }
    case Command::kDobControl:
      encode(wire::DobControlRequest{
          .run = static_cast<std::uint8_t>(in.ConsumeIntegralInRange<unsigned>(0, 2))});
      return p;
    case Command::kCalPutBegin: {
      wire::CalPutBeginRequest b;
      b.record_bytes = in.ConsumeBool() ? static_cast<std::uint32_t>(wire::kCalRecordBytes)
                                        : in.ConsumeIntegral<std::uint32_t>();
      b.crc32 = in.ConsumeIntegral<std::uint32_t>();
      encode(b);
      return p;
    }
    case Command::kGetInfo:
      // No payload (the info), or a page: 1 and 2 exist, 0 and 3 are refused.
      if (in.ConsumeBool())
        p.push_back(static_cast<std::uint8_t>(in.ConsumeIntegralInRange<unsigned>(0, 3)));
      return p;
    case Command::kSelfTest:
      // The checks and one past them (refused, unknown-check).
      encode(wire::SelfTestRequest{
          .check = static_cast<std::uint8_t>(
              in.ConsumeIntegralInRange<unsigned>(0, wire::kSelfTestCheckCount))});
      return p;
    case Command::kSelectScenario: p.resize(wire::ScenarioRequest::kBytes); return p;
    case Command::kInjectFrames: {
      wire::InjectFramesRequest f;
      f.frame_count = static_cast<std::uint8_t>(in.ConsumeIntegralInRange<unsigned>(0, 3));
      p = in.ConsumeBytes<std::uint8_t>(4 + 24 * std::min<std::size_t>(f.frame_count, 2));
      if (!p.empty()) p[0] = f.frame_count;
      return p;
    }
    default: return p;  // commands without a request payload
  }
}

class Script {
 public:
  explicit Script(FuzzedDataProvider& in) : in_(in) {}

  void Run() {
    for (int step = 0; step < 64 && in_.remaining_bytes() > 0; ++step) {
      switch (in_.ConsumeIntegralInRange<int>(0, 11)) {
        case 0:
        case 1:
        case 2:
        case 3: WellFormed(in_.PickValueInArray(kCommandIds)); break;
        case 4: Broken(); break;
        case 5: Upload(); break;
        case 6: Frames(); break;
        case 7: RawReport(); break;
        case 8: PowerCutCommit(); break;
        case 9: board_.fake.clock.now_us += in_.ConsumeIntegral<std::uint16_t>(); break;
        case 10:  // the host does not poll the IN endpoint for a while
          board_.link.in_busy = true;
          for (int i = in_.ConsumeIntegralInRange<int>(1, 4); i > 0; --i) board_.core().Poll();
          board_.link.in_busy = false;
          Require(board_.Drain().empty());
          break;
        case 11:
          if (in_.ConsumeBool()) {
            board_.Reboot();
          } else {
            board_.core().OnLinkReset();
          }
          break;
      }
    }
  }

 private:
  std::vector<wire::Report> Send(const wire::Report& r) {
    Require(board_.link.Push(r));
    return board_.Drain();
  }

  // A request the header checks accept: the answer carries its token and command.
  void WellFormed(std::uint8_t id, std::uint16_t sequence = 0) {
    const std::vector<std::uint8_t> payload = Payload(in_, id);
    Request(id, payload, sequence);
  }

  std::vector<wire::Report> Request(std::uint8_t id, std::span<const std::uint8_t> payload,
                                    std::uint16_t sequence) {
    const std::uint16_t token = ++token_;
    wire::Report r{};
    wire::Header h;
    h.command = id;
    h.token = token;
    h.sequence = sequence;
    h.payload_length = static_cast<std::uint8_t>(payload.size());
    Require(wire::EncodeReport(h, payload, r) == Status::kOk);
    const std::vector<wire::Report> out = Send(r);
    Check(id, token, payload, out);
    return out;
  }

  // What a host relies on in the answer to a request the header checks accept.
  void Check(std::uint8_t id, std::uint16_t token, std::span<const std::uint8_t> payload,
             const std::vector<wire::Report>& out) {
    Require(!out.empty());
    if (id == static_cast<std::uint8_t>(Command::kLogRead) ||
        id == static_cast<std::uint8_t>(Command::kCalGet)) {
      CheckStream(static_cast<Command>(id), token, out);
      return;
    }
    const Header answer = Answer(out[0], token, id);
    if (id == static_cast<std::uint8_t>(Command::kAcqStart) && answer.status == Status::kOk &&
        stream_flag_) {
      // The stream that follows the acquisition may already have begun behind the answer.
      board_.StartFollowing(token);
      for (std::size_t i = 1; i < out.size(); ++i) board_.Follow(out[i]);
    } else {
      Require(out.size() == 1);
    }
    if (id == static_cast<std::uint8_t>(Command::kAcqConfigure) && answer.status == Status::kOk) {
      wire::AcqConfigureRequest c;
      Require(wire::Decode(payload, c) == Status::kOk);
      stream_flag_ = (c.flags & wire::kAcqFlagStream) != 0;
    }
    if (id == static_cast<std::uint8_t>(Command::kCalCommit) && answer.status == Status::kOk) {
      dob_loaded_ = staged_dob_;
    }
    if (id == static_cast<std::uint8_t>(Command::kPing)) {
      Require(answer.status == Status::kOk);
      const auto echoed = wire::PayloadOf(out[0]);
      Require(std::equal(echoed.begin(), echoed.end(), payload.begin(), payload.end()));
    }
  }

  struct Header {
    Status status;
  };

  // A refusal names a reason this build knows, in exactly a Refusal's bytes.
  static void RequireReason(const wire::Report& r) {
    const auto payload = wire::PayloadOf(r);
    wire::Refusal why;
    Require(payload.size() == wire::Refusal::kBytes);
    Require(wire::Decode(payload, why) == Status::kOk);
    Require(static_cast<std::uint16_t>(why.reason) <=
            static_cast<std::uint16_t>(wire::kLastReason));
    Require(wire::LoadU16(payload, 2) == 0);
  }

  static Header Answer(const wire::Report& r, std::uint16_t token, std::uint8_t id) {
    Require(!wire::IsStreamData(r));
    wire::Header h;
    Require(wire::DecodeHeader(r, h) == Status::kOk);
    Require((h.flags & wire::kFlagResponse) != 0 && h.token == token && h.command == id);
    if (h.status != Status::kOk) RequireReason(r);
    if (h.status == Status::kOk && id == static_cast<std::uint8_t>(Command::kGetClips)) {
      wire::ClipResponse clips;
      Require(wire::Decode(wire::PayloadOf(r), clips) == Status::kOk);
      for (const std::uint32_t n : clips.clipped) Require(n <= clips.ticks);
    }
    if (h.status == Status::kOk && id == static_cast<std::uint8_t>(Command::kSelfTest)) {
      wire::SelfTestResponse check;
      Require(wire::Decode(wire::PayloadOf(r), check) == Status::kOk);
      Require(check.check < check.check_count && check.check_count == wire::kSelfTestCheckCount);
    }
    return {h.status};
  }

  void CheckStream(Command command, std::uint16_t token, const std::vector<wire::Report>& out) {
    wire::StreamDecoder decoder(command, token);
    std::vector<std::vector<std::uint8_t>> payloads;
    std::uint32_t bytes = 0;
    for (std::size_t i = 0; i < out.size(); ++i) {
      const wire::StreamDecoder::Step step = decoder.Feed(out[i]);
      if (step.event == Event::kData) {
        payloads.emplace_back(step.payload.begin(), step.payload.end());
        bytes += static_cast<std::uint32_t>(step.payload.size());
        continue;
      }
      // Nothing follows the end of a stream, and the end is a trailer or a refusal.
      Require(i + 1 == out.size());
      Require(step.event == Event::kEnd || step.event == Event::kRefused);
      if (step.event == Event::kEnd) {
        if (command == Command::kCalGet) {
          wire::CalGetTrailer t;
          Require(wire::Decode(step.payload, t) == Status::kOk);
          Require(bytes == wire::kCalRecordBytes);
        } else {
          wire::LogTrailer t;
          Require(wire::Decode(step.payload, t) == Status::kOk);
          Board::CheckLogPayloads(t, payloads);
        }
      }
      return;
    }
    // The stream did not end although the core had nothing more to send.
    Require(false);
  }

  // One header field broken: refused with the request's token, never dispatched.
  void Broken() {
    const std::uint8_t id = in_.PickValueInArray(kCommandIds);
    const std::vector<std::uint8_t> payload = Payload(in_, id);
    const std::uint16_t token = ++token_;
    wire::Report r{};
    wire::Header h;
    h.command = id;
    h.token = token;
    h.payload_length = static_cast<std::uint8_t>(payload.size());
    Require(wire::EncodeReport(h, payload, r) == Status::kOk);
    // One-byte header fields and the lowest broken value written there: above what a request
    // carries (major 2, at most 52 payload bytes, zero flags, reserved byte and status).
    struct BrokenByte {
      std::size_t offset;
      unsigned lowest;
    };
    constexpr BrokenByte kBrokenBytes[] = {{wire::kOffProtocolMajor, 3},
                                           {wire::kOffPayloadLength, 53},
                                           {wire::kOffFlags, 1},
                                           {wire::kOffReserved, 1},
                                           {wire::kOffStatus, 1}};
    switch (const int field = in_.ConsumeIntegralInRange<int>(0, 6)) {
      case 0:
        r[in_.ConsumeIntegralInRange<std::size_t>(0, 1)] ^=
            static_cast<std::uint8_t>(in_.ConsumeIntegralInRange<unsigned>(1, 255));
        break;
      case 6:
        if (id == static_cast<std::uint8_t>(Command::kCalPutData)) return;  // sequences are its own
        wire::StoreU16(r, wire::kOffSequence, in_.ConsumeIntegralInRange<std::uint16_t>(1, 0xFFFF));
        break;
      default: {
        const BrokenByte& b = kBrokenBytes[field - 1];
        r[b.offset] =
            static_cast<std::uint8_t>(in_.ConsumeIntegralInRange<unsigned>(b.lowest, 255));
        break;
      }
    }
    const std::vector<wire::Report> out = Send(r);
    // Two fields a request should leave alone are not checked by the board: a known status
    // byte and the stream-end flag (both only mean something device to host). Such a request is
    // dispatched like a well-formed one.
    const bool vibid = r[0] == 'V' && r[1] == 'B';
    if (vibid && ((r[wire::kOffStatus] != 0 && wire::IsKnownStatus(r[wire::kOffStatus])) ||
                  r[wire::kOffFlags] == wire::kFlagStreamEnd)) {
      Check(id, token, payload, out);
      return;
    }
    // Anything else broken is refused with one report. A stream data report is not a request;
    // it is answered like any other non-vibid report, with the token its bytes hold.
    Require(out.size() == 1 && !wire::IsStreamData(out[0]));
    wire::Header a;
    Require(wire::DecodeHeader(out[0], a) == Status::kOk);
    Require((a.flags & wire::kFlagResponse) != 0 && a.status != Status::kOk);
    Require(r[0] == wire::kStreamDataTag || a.token == token);
    RequireReason(out[0]);
  }

  // cal-put-begin and its chunks: the golden record (filter or not), now and then with a bad CRC,
  // a flipped byte, a missing, repeated or out-of-order chunk, or an abandoned upload.
  void Upload() {
    const bool with_filter = in_.ConsumeBool();
    std::vector<std::uint8_t> record(GoldenRecord(with_filter).begin(),
                                     GoldenRecord(with_filter).end());
    const int damage = in_.ConsumeIntegralInRange<int>(0, 15);
    if (damage == 1) {
      record[in_.ConsumeIntegralInRange<std::size_t>(0, record.size() - 1)] ^=
          in_.ConsumeIntegralInRange<std::uint8_t>(1, 255);
    }
    if (damage == 2) {
      // A field changed behind a correct record CRC: the range and filter checks decide.
      record[in_.ConsumeIntegralInRange<std::size_t>(0, wire::kCalOffCrc - 1)] =
          in_.ConsumeIntegral<std::uint8_t>();
      wire::StoreU32(
          record, wire::kCalOffCrc,
          wire::ComputeCrc32(std::span<const std::uint8_t>(record).first(wire::kCalOffCrc)));
    }
    std::uint32_t crc = wire::ComputeCrc32(record);
    if (damage == 3) crc ^= 1u;
    std::array<std::uint8_t, wire::CalPutBeginRequest::kBytes> begin{};
    wire::Encode(wire::CalPutBeginRequest{.record_bytes = static_cast<std::uint32_t>(record.size()),
                                          .crc32 = crc},
                 begin);
    const auto begin_out = Request(static_cast<std::uint8_t>(Command::kCalPutBegin), begin, 0);
    const std::size_t chunks = wire::CalPutChunkCount(record.size());
    const std::size_t stop =
        damage == 4 ? in_.ConsumeIntegralInRange<std::size_t>(0, chunks) : chunks;
    Status last = Status::kOk;
    for (std::size_t i = 0; i < stop; ++i) {
      std::size_t chunk = i;
      if (damage == 5 && in_.ConsumeIntegralInRange<int>(0, 7) == 0)
        chunk = in_.ConsumeIntegralInRange<std::size_t>(0, chunks);
      const std::size_t offset = std::min(chunk * wire::kMaxPayload, record.size());
      const auto data = std::span<const std::uint8_t>(record).subspan(
          offset, std::min(wire::kMaxPayload, record.size() - offset));
      const auto out = Request(static_cast<std::uint8_t>(Command::kCalPutData), data,
                               static_cast<std::uint16_t>(chunk));
      wire::Header h;
      (void)wire::DecodeHeader(out[0], h);
      last = h.status;
      if (last != Status::kOk) break;
    }
    wire::Header begin_h;
    (void)wire::DecodeHeader(begin_out[0], begin_h);
    // An intact record uploaded in order is accepted: its verdict comes with the last chunk.
    if (damage == 0 || damage >= 6) {
      Require(begin_h.status == Status::kOk && last == Status::kOk);
      staged_dob_ = with_filter;
    }
  }

  void Frames() {
    const int n = in_.ConsumeIntegralInRange<int>(1, 64);
    const int shape = in_.ConsumeIntegralInRange<int>(0, 3);
    for (int k = 0; k < n; ++k) {
      std::array<std::int32_t, wire::kChannelCount> raw{};
      for (std::size_t c = 0; c < raw.size(); ++c) {
        switch (shape) {
          case 0: raw[c] = 2048 + static_cast<std::int32_t>((tick_ * (c + 3)) % 512) - 256; break;
          case 1:
            raw[c] = (tick_ / 16) % 2 == 0 ? 0 : 4095;
            break;  // full-scale steps fire triggers
          case 2: raw[c] = in_.ConsumeIntegral<std::int32_t>(); break;
          default: raw[c] = in_.ConsumeIntegralInRange<std::int32_t>(0, 4095); break;
        }
      }
      if (in_.ConsumeIntegralInRange<int>(0, 31) == 0)
        board_.fake.frames.Skip(in_.ConsumeIntegralInRange<std::uint32_t>(1, 50));
      (void)board_.fake.frames.Emit(raw);
      ++tick_;
      if (in_.ConsumeIntegralInRange<int>(0, 3) == 0) {
        Require(board_.Drain().empty());
      } else {
        board_.core().Poll();
      }
    }
    // Between requests the board only speaks in the stream that follows an acquisition.
    Require(board_.Drain().empty());
  }

  // Any 64 bytes but the token, which stays unique so answers can be told apart. Those that pass
  // the header checks are held to what well-formed requests are.
  void RawReport() {
    wire::Report r{};
    const auto bytes = in_.ConsumeBytes<std::uint8_t>(wire::kReportBytes);
    std::copy(bytes.begin(), bytes.end(), r.begin());
    const std::uint16_t token = ++token_;
    wire::StoreU16(r, wire::kOffToken, token);
    const std::vector<wire::Report> out = Send(r);
    wire::Header h;
    if (wire::DecodeHeader(r, h) == Status::kOk && (h.flags & wire::kFlagResponse) == 0 &&
        (h.sequence == 0 || h.command == static_cast<std::uint8_t>(Command::kCalPutData))) {
      Check(h.command, token, wire::PayloadOf(r), out);
      return;
    }
    Require(out.size() == 1);
    wire::Header a;
    Require(wire::DecodeHeader(out[0], a) == Status::kOk && (a.flags & wire::kFlagResponse) != 0 &&
            a.status != Status::kOk && a.token == token);
    RequireReason(out[0]);
  }

  // A commit that loses power part-way (or meets a flash controller that reports errors); the
  // board reboots with what the flash holds.
  void PowerCutCommit() {
    board_.fake.flash.steps_before_cut = in_.ConsumeIntegralInRange<std::uint32_t>(0, 600);
    board_.fake.flash.fail_program = in_.ConsumeIntegralInRange<int>(0, 7) == 7;
    const std::uint16_t token = ++token_;
    wire::Report r{};
    Require(wire::BuildReport(Command::kCalCommit, token, 0, 0, Status::kOk, {}, r) == Status::kOk);
    (void)Send(r);
    board_.fake.flash.steps_before_cut = FakeFlashNoCut();
    board_.fake.flash.fail_program = false;
    board_.fake.flash.PowerOn();
    board_.Reboot();
    dob_loaded_ = false;  // unknown after a cut: the configure refusals cover either case
  }

  static std::uint32_t FakeFlashNoCut() { return vibid::fw::testing::FakeFlash::kNoCut; }

  FuzzedDataProvider& in_;
  Board board_;
  std::uint16_t token_ = 0;
  std::uint32_t tick_ = 0;
  bool stream_flag_ = false;
  bool staged_dob_ = false;
  bool dob_loaded_ = false;
};

// The raw format: a calibration switch byte, then 64-byte reports (the last one zero-padded)
// with a frame delivered between reports.
void RunRaw(const std::uint8_t* data, std::size_t size) {
  Board board;
  if ((data[0] & 1u) != 0) {
    const auto& record = GoldenRecord(true);
    wire::Report r{};
    (void)wire::BuildCalPutBegin(record, 1, r);
    board.link.Push(r);
    for (std::size_t chunk = 0; chunk < wire::CalPutChunkCount(record.size()); ++chunk) {
      (void)wire::BuildCalPutData(record, chunk, 1, r);
      board.link.Push(r);
      (void)board.Drain();
    }
    (void)wire::BuildReport(Command::kCalCommit, 2, 0, 0, Status::kOk, {}, r);
    board.link.Push(r);
    const auto out = board.Drain();
    wire::Header h;
    Require(!out.empty() && wire::DecodeHeader(out.back(), h) == Status::kOk &&
            h.status == Status::kOk);
  }
  ++data;
  --size;
  std::int32_t k = 0;
  for (std::size_t offset = 0; offset < size; offset += wire::kReportBytes) {
    wire::Report report{};
    std::memcpy(report.data(), data + offset, std::min(wire::kReportBytes, size - offset));
    board.link.ClearOut();
    board.link.Push(report);
    const std::vector<wire::Report> out = board.Drain();
    // Answered with a full response, or by a stream whose first report is already data.
    Require(!out.empty());
    if (!wire::IsStreamData(out[0])) {
      wire::Header header;
      Require(wire::DecodeHeader(out[0], header) == Status::kOk);
      Require((header.flags & wire::kFlagResponse) != 0);
    }
    board.fake.frames.Emit({k, 2048 - k, 3 * k, -k, k * k, 7});
    ++k;
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  if ((data[0] & 0x80u) != 0) {
    RunRaw(data, size);
    return 0;
  }
  FuzzedDataProvider in(data + 1, size - 1);
  Script script(in);
  script.Run();
  return 0;
}
