#include "vibid/shared/wire/report.hpp"

#include <algorithm>

#include "vibid/shared/wire/byte_order.hpp"

namespace vibid::wire {

bool IsKnownStatus(std::uint8_t value) {
  return value <= static_cast<std::uint8_t>(Status::kUnstable);
}

Status EncodeReport(const Header& header, std::span<const std::uint8_t> payload, Report& out) {
  out.fill(0);
  if (payload.size() > kMaxPayload) return Status::kOutOfRange;
  StoreU16(out, kOffMagic, kMagic);
  StoreU8(out, kOffProtocolMajor, header.protocol_major);
  StoreU8(out, kOffCommand, header.command);
  StoreU8(out, kOffStatus, static_cast<std::uint8_t>(header.status));
  StoreU8(out, kOffFlags, header.flags);
  StoreU16(out, kOffToken, header.token);
  StoreU16(out, kOffSequence, header.sequence);
  StoreU8(out, kOffPayloadLength, static_cast<std::uint8_t>(payload.size()));
  std::copy(payload.begin(), payload.end(), out.begin() + kOffPayload);
  return Status::kOk;
}

Status DecodeHeader(const Report& report, Header& header) {
  if (LoadU16(report, kOffMagic) != kMagic) return Status::kDataLoss;
  header.protocol_major = LoadU8(report, kOffProtocolMajor);
  header.command = LoadU8(report, kOffCommand);
  const std::uint8_t status = LoadU8(report, kOffStatus);
  header.status = IsKnownStatus(status) ? static_cast<Status>(status) : Status::kInternal;
  header.flags = LoadU8(report, kOffFlags);
  header.token = LoadU16(report, kOffToken);
  header.sequence = LoadU16(report, kOffSequence);
  header.payload_length = LoadU8(report, kOffPayloadLength);
  if (header.protocol_major != kProtocolMajor) return Status::kVersionMismatch;
  if (header.payload_length > kMaxPayload || (header.flags & ~kKnownFlags) != 0 ||
      LoadU8(report, kOffReserved) != 0 || !IsKnownStatus(status)) {
    return Status::kInvalidArgument;
  }
  return Status::kOk;
}

std::span<const std::uint8_t> PayloadOf(const Report& report) {
  if (IsStreamData(report)) {
    const std::size_t length = std::min<std::size_t>(report[1], kMaxStreamPayload);
    return std::span<const std::uint8_t>(report).subspan(kStreamHeaderBytes, length);
  }
  const std::size_t length = std::min<std::size_t>(report[kOffPayloadLength], kMaxPayload);
  return std::span<const std::uint8_t>(report).subspan(kOffPayload, length);
}

Status EncodeStreamData(std::uint16_t token, std::uint16_t sequence,
                        std::span<const std::uint8_t> payload, Report& out) {
  out.fill(0);
  if (payload.empty() || payload.size() > kMaxStreamPayload) return Status::kOutOfRange;
  StoreU8(out, 0, kStreamDataTag);
  StoreU8(out, 1, static_cast<std::uint8_t>(payload.size()));
  StoreU16(out, 2, token);
  StoreU16(out, 4, sequence);
  std::copy(payload.begin(), payload.end(), out.begin() + kStreamHeaderBytes);
  return Status::kOk;
}

Status DecodeStreamData(const Report& report, StreamDataHeader& header) {
  if (!IsStreamData(report)) return Status::kDataLoss;
  header.payload_length = LoadU8(report, 1);
  header.token = LoadU16(report, 2);
  header.sequence = LoadU16(report, 4);
  if (header.payload_length == 0 || header.payload_length > kMaxStreamPayload)
    return Status::kInvalidArgument;
  return Status::kOk;
}

}  // namespace vibid::wire
