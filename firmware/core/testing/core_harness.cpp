#include "core_harness.hpp"

#include "vibid/shared/wire/log_record.hpp"

namespace vibid::fw::testing {

Response CoreHarness::Raw(const wire::Report& report) {
  link.ClearOut();
  link.Push(report);
  core.Poll();
  Response r;
  if (link.Pop(r.report)) {
    r.received = true;
    (void)wire::DecodeHeader(r.report, r.header);
  }
  return r;
}

Response CoreHarness::Request(wire::Command command, std::span<const std::uint8_t> payload,
                              std::uint16_t sequence) {
  last_token = next_token++;
  wire::Report report{};
  (void)wire::BuildReport(command, last_token, sequence, 0, Status::kOk, payload, report);
  return Raw(report);
}

std::size_t CoreHarness::Drain() {
  std::size_t before = link.pending_out();
  for (int i = 0; i < 1000; ++i) {
    core.Poll();
    if (link.pending_out() == before) break;
    before = link.pending_out();
  }
  return link.pending_out();
}

Status CoreHarness::Upload(std::span<const std::uint8_t> record) {
  wire::Report report{};
  last_token = next_token++;
  (void)wire::BuildCalPutBegin(record, last_token, report);
  Response r = Raw(report);
  if (r.status() != Status::kOk) return r.status();
  for (std::size_t chunk = 0; chunk < wire::CalPutChunkCount(record.size()); ++chunk) {
    (void)wire::BuildCalPutData(record, chunk, last_token, report);
    r = Raw(report);
    if (r.status() != Status::kOk) return r.status();
  }
  return Status::kOk;
}

Status CoreHarness::StartAcquisition(const wire::AcqConfigureRequest& config) {
  Response r = Request(wire::Command::kAcqConfigure, config);
  if (r.status() != Status::kOk) return r.status();
  return Request(wire::Command::kAcqStart).status();
}

void CoreHarness::EmitRamp(std::uint32_t n,
                           const std::array<std::int32_t, wire::kChannelCount>& base,
                           std::int32_t step) {
  for (std::uint32_t k = 0; k < n; ++k) {
    std::array<std::int32_t, wire::kChannelCount> raw = base;
    for (auto& v : raw) v += static_cast<std::int32_t>(emitted) * step;
    fake.frames.Emit(raw);
    ++emitted;
  }
}

PulledLog PullLog(CoreHarness& h, std::uint32_t first, std::uint32_t max, int lose_report) {
  PulledLog out;
  h.last_token = h.next_token++;
  std::array<std::uint8_t, wire::LogReadRequest::kBytes> payload{};
  wire::Encode(wire::LogReadRequest{.first_record = first, .max_records = max}, payload);
  wire::Report report{};
  (void)wire::BuildReport(wire::Command::kLogRead, h.last_token, 0, 0, Status::kOk, payload,
                          report);
  h.link.ClearOut();
  h.link.Push(report);

  // Data payloads are kept whole until the trailer brings the layout.
  wire::StreamDecoder decoder(wire::Command::kLogRead, h.last_token);
  std::array<std::array<std::uint8_t, wire::kMaxStreamPayload>, 160> payloads{};
  std::array<std::size_t, 160> lengths{};
  std::size_t payload_count = 0;
  for (int polls = 0; polls < 10000 && !decoder.finished(); ++polls) {
    h.core.Poll();
    wire::Report in{};
    while (!decoder.finished() && h.link.Pop(in)) {
      wire::StreamDataHeader data;
      if (wire::DecodeStreamData(in, data) == Status::kOk && data.sequence == lose_report) continue;
      const wire::StreamDecoder::Step step = decoder.Feed(in);
      out.last_event = step.event;
      out.status = step.status;
      if (step.event == wire::StreamDecoder::Event::kData && payload_count < payloads.size()) {
        std::copy(step.payload.begin(), step.payload.end(), payloads[payload_count].begin());
        lengths[payload_count++] = step.payload.size();
      } else if (step.event == wire::StreamDecoder::Event::kEnd) {
        out.status = wire::Decode(step.payload, out.trailer);
      }
    }
  }
  if (out.last_event != wire::StreamDecoder::Event::kEnd || out.status != Status::kOk) return out;
  const wire::LogLayout layout{out.trailer.channel_mask, out.trailer.acq_flags};
  for (std::size_t p = 0; p < payload_count; ++p) {
    std::array<wire::LogRecord, wire::kMaxRecordsPerReport> batch{};
    std::size_t n = 0;
    if (wire::DecodeLogPayload(layout, out.trailer.decimation,
                               std::span<const std::uint8_t>(payloads[p]).first(lengths[p]), batch,
                               n) != Status::kOk) {
      out.status = Status::kInvalidArgument;
      return out;
    }
    for (std::size_t k = 0; k < n && out.count < out.records.size(); ++k)
      out.records[out.count++] = batch[k];
  }
  return out;
}

}  // namespace vibid::fw::testing
