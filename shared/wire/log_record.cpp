#include "vibid/shared/wire/log_record.hpp"

#include <algorithm>

#include "vibid/shared/wire/byte_order.hpp"

namespace vibid::wire {

void EncodeLogRecord(const LogLayout& layout, const LogRecord& record,
                     std::span<std::uint8_t> out) {
  std::size_t offset = 0;
  for (std::size_t c = 0; c < kChannelCount; ++c) {
    if ((layout.channel_mask & (1u << c)) == 0) continue;
    if (LogValueBytes(static_cast<Channel>(c)) == 2) {
      StoreU16(out, offset,
               static_cast<std::uint16_t>(std::clamp<std::int32_t>(record.raw[c], 0, kLogAdcMax)));
      offset += 2;
    } else {
      StoreI32(out, offset, record.raw[c]);
      offset += 4;
    }
  }
  if (layout.HasDob()) {
    StoreI32(out, offset, record.d_hat);
    offset += 4;
  }
  if (layout.HasWatch()) StoreU32(out, offset, record.watch);
}

Status DecodeLogRecord(const LogLayout& layout, std::span<const std::uint8_t> in,
                       LogRecord& record) {
  if (!layout.Valid() || in.size() != layout.RecordBytes()) return Status::kInvalidArgument;
  record.raw.fill(0);
  record.d_hat = 0;
  record.watch = 0;
  std::size_t offset = 0;
  for (std::size_t c = 0; c < kChannelCount; ++c) {
    if ((layout.channel_mask & (1u << c)) == 0) continue;
    if (LogValueBytes(static_cast<Channel>(c)) == 2) {
      record.raw[c] = LoadU16(in, offset);
      offset += 2;
    } else {
      record.raw[c] = LoadI32(in, offset);
      offset += 4;
    }
  }
  if (layout.HasDob()) {
    record.d_hat = LoadI32(in, offset);
    offset += 4;
  }
  if (layout.HasWatch()) record.watch = LoadU32(in, offset);
  return Status::kOk;
}

Status DecodeLogPayload(const LogLayout& layout, std::uint32_t decimation,
                        std::span<const std::uint8_t> payload, std::span<LogRecord> out,
                        std::size_t& count) {
  count = 0;
  if (!layout.Valid() || decimation == 0 || payload.size() < kLogIndexBytes) {
    return Status::kInvalidArgument;
  }
  const std::size_t rb = layout.RecordBytes();
  const std::size_t body = payload.size() - kLogIndexBytes;
  if (body == 0 || body % rb != 0 || body / rb > out.size()) return Status::kInvalidArgument;
  const std::uint32_t first = LoadU32(payload, 0);
  const std::size_t n = body / rb;
  for (std::size_t k = 0; k < n; ++k) {
    out[k].sample_index = first + static_cast<std::uint32_t>(k) * decimation;
    const Status s = DecodeLogRecord(layout, payload.subspan(kLogIndexBytes + k * rb, rb), out[k]);
    if (s != Status::kOk) return s;
  }
  count = n;
  return Status::kOk;
}

}  // namespace vibid::wire
