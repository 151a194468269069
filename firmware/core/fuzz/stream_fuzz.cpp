// Fuzzes the host-side stream decoder. Random reports stop at its first check (the tag, the
// token, the sequence), so the input is read as a script (FuzzedDataProvider): the board's own
// StreamEncoder builds log-read streams (records in a layout the fuzzer picks, packed as the board
// packs them) and cal-get streams, then the link damages them: reports lost, repeated or swapped,
// one byte changed, a stale report of another request or a refusal slipped in, the trailer cut
// short. A broken pull resumes from the first record not received intact, as the host does, for
// up to eight attempts. Invariants:
//   - the decoder accepts a stream (kEnd) only if every payload byte it handed out is the
//     encoder's, in order, and its trailer count and CRC are the encoder's;
//   - nothing is handed out after the end, a refusal or an error;
//   - records of an accepted log stream decode with the layout its trailer names;
//   - the resumed pull ends with every record exactly once, in order, when the link is clean.
// An input whose first byte has the top bit clear is the previous raw format (a command id, a
// token, then 64-byte reports), so its regression inputs keep their meaning.
#include <fuzzer/FuzzedDataProvider.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <vector>

#include "vibid/shared/wire/byte_order.hpp"
#include "vibid/shared/wire/calibration_record.hpp"
#include "vibid/shared/wire/crc32.hpp"
#include "vibid/shared/wire/log_record.hpp"
#include "vibid/shared/wire/refusal.hpp"
#include "vibid/shared/wire/stream.hpp"

namespace {

using namespace vibid;
using wire::Command;
using Event = wire::StreamDecoder::Event;

void Require(bool condition) {
  if (!condition) __builtin_trap();
}

struct Sent {
  std::vector<wire::Report> reports;
  std::vector<std::uint8_t> data;       // every data payload byte, in order
  std::vector<std::uint32_t> first_of;  // log: the record index each data report starts with
  std::uint32_t end_record = 0;
};

// The board's side: records from `first` packed like Core::PackLogRecords (the first record's
// tick, then records whose ticks follow by the decimation; a gap ends the report).
Sent EncodeLog(FuzzedDataProvider& in, std::uint16_t token, const wire::LogLayout& layout,
               std::uint16_t decimation, const std::vector<std::uint32_t>& ticks,
               const std::vector<wire::LogRecord>& records, std::uint32_t first) {
  Sent s;
  wire::StreamEncoder encoder;
  encoder.Begin(Command::kLogRead, token);
  const std::size_t rb = layout.RecordBytes();
  std::uint32_t next = first;
  const auto end = static_cast<std::uint32_t>(records.size());
  while (next < end) {
    std::array<std::uint8_t, wire::kMaxStreamPayload> payload{};
    const std::uint32_t n_max =
        std::min<std::uint32_t>(static_cast<std::uint32_t>(layout.RecordsPerReport()), end - next);
    std::uint32_t n = 0;
    for (; n < n_max; ++n) {
      if (n > 0 && ticks[next + n] != ticks[next] + n * decimation) break;
      wire::EncodeLogRecord(
          layout, records[next + n],
          std::span<std::uint8_t>(payload).subspan(wire::kLogIndexBytes + n * rb, rb));
    }
    wire::StoreU32(payload, 0, ticks[next]);
    const std::size_t length = wire::kLogIndexBytes + n * rb;
    wire::Report r{};
    Require(encoder.Data(std::span<const std::uint8_t>(payload).first(length), r) == Status::kOk);
    s.reports.push_back(r);
    s.first_of.push_back(next);
    s.data.insert(s.data.end(), payload.begin(),
                  payload.begin() + static_cast<std::ptrdiff_t>(length));
    next += n;
  }
  std::array<std::uint8_t, wire::LogTrailer::kBytes> trailer{};
  wire::LogTrailer t;
  t.first_record = first;
  t.record_count = end - first;
  t.record_bytes = static_cast<std::uint16_t>(rb);
  t.channel_mask = layout.channel_mask;
  t.acq_flags = layout.flags;
  t.sample_period_us = in.ConsumeIntegral<std::uint32_t>();
  t.decimation = decimation;
  t.acq_state = static_cast<wire::AcqState>(in.ConsumeIntegralInRange<unsigned>(0, 3));
  t.records_written = end;
  wire::Encode(t, trailer);
  wire::Report r{};
  Require(encoder.End(trailer, r) == Status::kOk);
  s.reports.push_back(r);
  s.end_record = end;
  return s;
}

Sent EncodeCalibration(FuzzedDataProvider& in, std::uint16_t token) {
  Sent s;
  wire::StreamEncoder encoder;
  encoder.Begin(Command::kCalGet, token);
  std::vector<std::uint8_t> record = in.ConsumeBytes<std::uint8_t>(wire::kCalRecordBytes);
  record.resize(wire::kCalRecordBytes);
  for (std::size_t at = 0; at < record.size(); at += wire::kMaxStreamPayload) {
    const std::size_t n = std::min(wire::kMaxStreamPayload, record.size() - at);
    wire::Report r{};
    Require(encoder.Data(std::span<const std::uint8_t>(record).subspan(at, n), r) == Status::kOk);
    s.reports.push_back(r);
  }
  s.data = record;
  std::array<std::uint8_t, wire::CalGetTrailer::kBytes> trailer{};
  wire::Encode(wire::CalGetTrailer{.slot = in.ConsumeIntegral<std::uint8_t>(),
                                   .sequence = in.ConsumeIntegral<std::uint32_t>()},
               trailer);
  wire::Report r{};
  Require(encoder.End(trailer, r) == Status::kOk);
  s.reports.push_back(r);
  return s;
}

// The link between board and host. Returns true if it delivered the stream untouched.
bool Damage(FuzzedDataProvider& in, std::vector<wire::Report>& reports, std::uint16_t token,
            Command command) {
  bool clean = true;
  bool byte_changed = false;
  const int rounds = in.ConsumeIntegralInRange<int>(0, 3);
  for (int k = 0; k < rounds && !reports.empty(); ++k) {
    const std::size_t at = in.ConsumeIntegralInRange<std::size_t>(0, reports.size() - 1);
    switch (in.ConsumeIntegralInRange<int>(0, 7)) {
      case 0:  // lost
        reports.erase(reports.begin() + static_cast<std::ptrdiff_t>(at));
        clean = false;
        break;
      case 1:  // repeated
        reports.insert(reports.begin() + static_cast<std::ptrdiff_t>(at), reports[at]);
        clean = false;
        break;
      case 2:  // swapped with the next
        if (at + 1 < reports.size()) {
          std::swap(reports[at], reports[at + 1]);
          clean = false;
        }
        break;
      case 3:  // one byte changed (once per stream: CRC-32 finds every such change)
        if (!byte_changed) {
          reports[at][in.ConsumeIntegralInRange<std::size_t>(0, wire::kReportBytes - 1)] ^=
              in.ConsumeIntegralInRange<std::uint8_t>(1, 255);
          byte_changed = true;
          clean = false;
        }
        break;
      case 4: {  // a stale data report or answer of another request: ignored
        wire::Report stale{};
        const auto other =
            static_cast<std::uint16_t>(token ^ in.ConsumeIntegralInRange<std::uint16_t>(1, 0xFFFF));
        if (in.ConsumeBool()) {
          const auto bytes = in.ConsumeBytes<std::uint8_t>(
              in.ConsumeIntegralInRange<std::size_t>(1, wire::kMaxStreamPayload));
          if (bytes.empty()) break;  // the input ran out: no report to slip in
          Require(wire::EncodeStreamData(other, in.ConsumeIntegral<std::uint16_t>(), bytes,
                                         stale) == Status::kOk);
        } else {
          const auto id =
              in.ConsumeBool() ? command : static_cast<Command>(in.ConsumeIntegral<std::uint8_t>());
          const std::uint16_t to = in.ConsumeBool() ? other : token;
          const std::uint8_t flags = in.ConsumeBool() ? wire::kFlagResponse : 0;
          Require(wire::BuildReport(id, to, in.ConsumeIntegral<std::uint16_t>(), flags, Status::kOk,
                                    {}, stale) == Status::kOk);
          // An answer to this very request is no stale report: it ends the stream.
          if (id == command && to == token && flags != 0) clean = false;
        }
        reports.insert(reports.begin() + static_cast<std::ptrdiff_t>(at), stale);
        break;
      }
      case 5: {  // the board gave up: a refusal in place of the rest, with its reason (2.1) or not
        wire::Report refusal{};
        const auto status = in.PickValueInArray(
            {Status::kOutOfRange, Status::kInternal, Status::kFailedPrecondition});
        std::array<std::uint8_t, wire::Refusal::kBytes> why{};
        wire::Encode(
            wire::Refusal{.reason = static_cast<wire::Reason>(in.ConsumeIntegral<std::uint16_t>()),
                          .detail = in.ConsumeIntegral<std::uint32_t>()},
            why);
        const std::span<const std::uint8_t> payload =
            in.ConsumeBool() ? std::span<const std::uint8_t>(why) : std::span<const std::uint8_t>();
        Require(wire::BuildReport(command, token, 0, wire::kFlagResponse, status, payload,
                                  refusal) == Status::kOk);
        reports.resize(at);
        reports.push_back(refusal);
        clean = false;
        break;
      }
      case 6:  // cut off
        reports.resize(at);
        clean = false;
        break;
      default:  // an arbitrary report
        if (!byte_changed) {
          const auto bytes = in.ConsumeBytes<std::uint8_t>(wire::kReportBytes);
          std::copy(bytes.begin(), bytes.end(), reports[at].begin());
          byte_changed = true;
          clean = false;
        }
        break;
    }
  }
  return clean;
}

struct Received {
  Event last = Event::kError;
  std::vector<std::uint8_t> data;
  std::vector<std::vector<std::uint8_t>> payloads;
  std::vector<std::uint8_t> trailer;
};

Received Decode(Command command, std::uint16_t token, const std::vector<wire::Report>& reports) {
  Received r;
  wire::StreamDecoder decoder(command, token);
  bool finished = false;
  for (const wire::Report& report : reports) {
    const wire::StreamDecoder::Step step = decoder.Feed(report);
    if (finished) {
      Require(step.event == Event::kError && step.payload.empty());
      continue;
    }
    Require(step.payload.size() <= wire::kMaxStreamPayload);
    if (step.event == Event::kRefused) {
      // The refusal's payload is handed over whole: whatever it holds decodes as a Refusal, or
      // is refused as too short (a damaged length), never read past.
      wire::Refusal why;
      Require(wire::Decode(step.payload, why) == Status::kOk ||
              step.payload.size() < wire::Refusal::kBytes);
    }
    switch (step.event) {
      case Event::kData:
        r.data.insert(r.data.end(), step.payload.begin(), step.payload.end());
        r.payloads.emplace_back(step.payload.begin(), step.payload.end());
        break;
      case Event::kStale: break;
      case Event::kEnd: r.trailer.assign(step.payload.begin(), step.payload.end()); [[fallthrough]];
      case Event::kRefused:
      case Event::kError:
        r.last = step.event;
        finished = true;
        Require(decoder.finished());
        break;
    }
  }
  Require(finished == decoder.finished());
  return r;
}

void RunLog(FuzzedDataProvider& in) {
  wire::LogLayout layout;
  layout.channel_mask =
      static_cast<std::uint8_t>(in.ConsumeIntegralInRange<unsigned>(1, wire::kAllChannelsMask));
  layout.flags =
      static_cast<std::uint8_t>(in.ConsumeIntegralInRange<unsigned>(0, wire::kAcqKnownFlags));
  // The residual test's word travels only beside d_hat (a layout the board configures).
  if (layout.HasWatch())
    layout.flags = static_cast<std::uint8_t>(layout.flags | wire::kAcqFlagLogDob);
  const std::uint16_t decimation = in.PickValueInArray<std::uint16_t>({1, 2, 5, 10, 1000});
  // Records with ticks that follow by the decimation, with gaps where the sampler dropped some.
  const std::size_t count = in.ConsumeIntegralInRange<std::size_t>(0, 200);
  std::vector<std::uint32_t> ticks(count);
  std::vector<wire::LogRecord> records(count);
  std::uint32_t tick = in.ConsumeIntegral<std::uint32_t>() / 2;
  for (std::size_t i = 0; i < count; ++i) {
    ticks[i] = tick;
    records[i].sample_index = tick;
    for (std::size_t c = 0; c < wire::kChannelCount; ++c) {
      if ((layout.channel_mask & (1u << c)) != 0)
        records[i].raw[c] = static_cast<std::int32_t>((tick * 37u + c * 1000u) % 4096u);
    }
    if (layout.HasDob()) records[i].d_hat = static_cast<std::int32_t>(tick * 2654435761u);
    if (layout.HasWatch()) records[i].watch = tick * 40503u;
    tick += decimation * (in.ConsumeIntegralInRange<int>(0, 15) == 0
                              ? in.ConsumeIntegralInRange<std::uint32_t>(2, 9)
                              : 1u);
  }

  // The host's pull: from record 0, resumed from the first record not yet received intact.
  std::uint32_t have = 0;
  std::uint16_t token = in.ConsumeIntegral<std::uint16_t>();
  bool ended = false;
  for (int attempt = 0; attempt < 8 && !ended; ++attempt) {
    ++token;
    Sent sent = EncodeLog(in, token, layout, decimation, ticks, records, have);
    std::vector<wire::Report> link = sent.reports;
    const bool clean = Damage(in, link, token, Command::kLogRead);
    const Received got = Decode(Command::kLogRead, token, link);
    if (got.last == Event::kEnd) {
      Require(got.data == sent.data);
      const std::uint32_t from = have;
      have = sent.end_record;
      ended = true;
      // The CRC covers the data, not the trailer's own fields: those are checked as sent.
      const auto sent_trailer = wire::PayloadOf(sent.reports.back());
      if (!std::equal(got.trailer.begin(), got.trailer.end(), sent_trailer.begin(),
                      sent_trailer.end()))
        continue;
      wire::LogTrailer t;
      Require(wire::Decode(got.trailer, t) == Status::kOk);
      Require(t.first_record == from && t.record_count == sent.end_record - from);
      std::uint32_t decoded = 0;
      for (const auto& p : got.payloads) {
        std::array<wire::LogRecord, wire::kMaxRecordsPerReport> batch{};
        std::size_t n = 0;
        Require(wire::DecodeLogPayload(wire::LogLayout{t.channel_mask, t.acq_flags}, t.decimation,
                                       p, batch, n) == Status::kOk);
        for (std::size_t k = 0; k < n; ++k) {
          const wire::LogRecord& want = records[from + decoded + k];
          Require(batch[k].sample_index == want.sample_index && batch[k].raw == want.raw &&
                  batch[k].d_hat == want.d_hat && batch[k].watch == want.watch);
        }
        decoded += static_cast<std::uint32_t>(n);
      }
      Require(decoded == t.record_count);
    } else {
      // A pull that broke off keeps nothing of it and asks again from the same record.
      Require(!clean);
    }
  }
  if (ended) Require(have == count);
}

void RunCalibration(FuzzedDataProvider& in) {
  const std::uint16_t token = in.ConsumeIntegral<std::uint16_t>();
  Sent sent = EncodeCalibration(in, token);
  std::vector<wire::Report> link = sent.reports;
  const bool clean = Damage(in, link, token, Command::kCalGet);
  const Received got = Decode(Command::kCalGet, token, link);
  if (clean) Require(got.last == Event::kEnd);
  if (got.last == Event::kEnd) {
    Require(got.data == sent.data);
    wire::CalGetTrailer t;
    Require(wire::Decode(got.trailer, t) == Status::kOk);
    wire::CalibrationRecord record;
    (void)wire::DecodeCalibrationRecord(got.data, record);
  }
}

// What a host decodes from an answer must be what the device encoded: a payload that decodes
// as a response encodes back to the same bytes.
template <typename Response>
void CheckResponse(std::span<const std::uint8_t> payload) {
  Response v;
  if (wire::Decode(payload, v) != Status::kOk) return;
  std::array<std::uint8_t, Response::kBytes> again{};
  wire::Encode(v, again);
  Require(payload.size() >= again.size() &&
          std::equal(again.begin(), again.end(), payload.begin()));
}

void CheckResponses(const wire::Report& report) {
  const auto payload = wire::PayloadOf(report);
  CheckResponse<wire::InfoResponse>(payload);
  CheckResponse<wire::SamplingInfoResponse>(payload);
  CheckResponse<wire::HealthInfoResponse>(payload);
  CheckResponse<wire::SelfTestResponse>(payload);
  CheckResponse<wire::StatusResponse>(payload);
  CheckResponse<wire::AcqConfigureResponse>(payload);
  CheckResponse<wire::AcqStopResponse>(payload);
  CheckResponse<wire::LatestResponse>(payload);
  CheckResponse<wire::CalCommitResponse>(payload);
  CheckResponse<wire::LogTrailer>(payload);
  CheckResponse<wire::CalGetTrailer>(payload);
}

// The raw format: command id, token, then 64-byte reports fed as they are; each report's payload
// is also read as every response the host decodes.
void RunRaw(const std::uint8_t* data, std::size_t size) {
  if (size < 3) return;
  const auto command = static_cast<Command>(data[0]);
  const auto token = static_cast<std::uint16_t>(data[1] | data[2] << 8);
  wire::StreamDecoder decoder(command, token);
  wire::Crc32 crc;
  std::uint32_t bytes = 0;
  for (std::size_t offset = 3; offset < size; offset += wire::kReportBytes) {
    wire::Report report{};
    std::memcpy(report.data(), data + offset, std::min(wire::kReportBytes, size - offset));
    CheckResponses(report);
    const wire::StreamDecoder::Step step = decoder.Feed(report);
    Require(step.payload.size() <= wire::kMaxStreamPayload);
    if (step.event == Event::kData) {
      crc.Update(step.payload);
      bytes += static_cast<std::uint32_t>(step.payload.size());
    } else if (step.event == Event::kEnd) {
      wire::StreamTrailer t;
      Require(wire::Decode(step.payload, t) == Status::kOk);
      Require(t.crc32 == crc.value() && t.total_bytes == bytes);
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  if ((data[0] & 0x80u) == 0) {
    RunRaw(data, size);
    return 0;
  }
  FuzzedDataProvider in(data + 1, size - 1);
  if ((data[0] & 1u) == 0) {
    RunLog(in);
  } else {
    RunCalibration(in);
  }
  return 0;
}
