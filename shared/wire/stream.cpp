#include "vibid/shared/wire/stream.hpp"

#include <algorithm>

namespace vibid::wire {

void StreamEncoder::Begin(Command command, std::uint16_t token) {
  command_ = command;
  token_ = token;
  data_reports_ = 0;
  total_bytes_ = 0;
  crc_ = Crc32{};
}

Status StreamEncoder::Data(std::span<const std::uint8_t> payload, Report& out) {
  const Status s =
      EncodeStreamData(token_, static_cast<std::uint16_t>(data_reports_), payload, out);
  if (s != Status::kOk) return s;
  crc_.Update(payload);
  total_bytes_ += static_cast<std::uint32_t>(payload.size());
  ++data_reports_;
  return Status::kOk;
}

Status StreamEncoder::End(std::span<std::uint8_t> trailer_payload, Report& out) {
  if (trailer_payload.size() < StreamTrailer::kBytes || trailer_payload.size() > kMaxPayload) {
    return Status::kOutOfRange;
  }
  Encode(StreamTrailer{.total_bytes = total_bytes_, .crc32 = crc_.value()}, trailer_payload);
  return BuildReport(command_, token_, static_cast<std::uint16_t>(data_reports_),
                     kFlagResponse | kFlagStreamEnd, Status::kOk, trailer_payload, out);
}

StreamDecoder::Step StreamDecoder::Feed(const Report& report) {
  Step step;
  if (finished_) {
    step.status = Status::kFailedPrecondition;
    return step;
  }
  if (IsStreamData(report)) {
    StreamDataHeader h;
    const Status decoded = DecodeStreamData(report, h);
    if (decoded == Status::kOk && h.token != token_) {
      step.event = Event::kStale;
      return step;
    }
    if (decoded != Status::kOk || h.sequence != static_cast<std::uint16_t>(data_reports_)) {
      finished_ = true;
      step.status = decoded != Status::kOk ? decoded : Status::kDataLoss;
      return step;
    }
    step.event = Event::kData;
    step.payload = PayloadOf(report);
    crc_.Update(step.payload);
    total_bytes_ += static_cast<std::uint32_t>(step.payload.size());
    ++data_reports_;
    return step;
  }
  Header h;
  const Status decoded = DecodeHeader(report, h);
  if (decoded == Status::kOk && ((h.flags & kFlagResponse) == 0 || h.token != token_ ||
                                 h.command != static_cast<std::uint8_t>(command_))) {
    step.event = Event::kStale;
    return step;
  }
  finished_ = true;
  if (decoded != Status::kOk) {
    step.status = decoded;
    return step;
  }
  if (h.status != Status::kOk) {
    step.event = Event::kRefused;
    step.status = h.status;
    step.payload = PayloadOf(report);  // the Refusal (refusal.hpp), empty from a 2.0 device
    return step;
  }
  if (h.sequence != static_cast<std::uint16_t>(data_reports_)) {
    step.status = Status::kDataLoss;
    return step;
  }
  // A full report answering the stream is its trailer (data comes in stream data reports).
  step.payload = PayloadOf(report);
  StreamTrailer trailer;
  if ((h.flags & kFlagStreamEnd) == 0 || Decode(step.payload, trailer) != Status::kOk) {
    step.status = Status::kInvalidArgument;
    return step;
  }
  if (trailer.total_bytes != total_bytes_ || trailer.crc32 != crc_.value()) {
    step.status = Status::kDataLoss;
    return step;
  }
  step.event = Event::kEnd;
  return step;
}

Status BuildCalPutBegin(std::span<const std::uint8_t> record, std::uint16_t token, Report& out) {
  if (record.empty() || record.size() > 0xFFFFu) return Status::kOutOfRange;
  const CalPutBeginRequest begin{.record_bytes = static_cast<std::uint32_t>(record.size()),
                                 .crc32 = ComputeCrc32(record)};
  return BuildReport(Command::kCalPutBegin, token, 0, 0, Status::kOk, begin, out);
}

Status BuildCalPutData(std::span<const std::uint8_t> record, std::size_t chunk, std::uint16_t token,
                       Report& out) {
  if (chunk >= CalPutChunkCount(record.size()) || chunk > 0xFFFFu) return Status::kOutOfRange;
  const std::size_t offset = chunk * kMaxPayload;
  const std::size_t length = std::min(kMaxPayload, record.size() - offset);
  return BuildReport(Command::kCalPutData, token, static_cast<std::uint16_t>(chunk), 0, Status::kOk,
                     record.subspan(offset, length), out);
}

}  // namespace vibid::wire
