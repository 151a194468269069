#include "vibid/shared/wire/log_record.hpp"

#include "vibid/shared/wire/byte_order.hpp"

namespace vibid::wire {

void EncodeLogRecord(const LogLayout& layout, const LogRecord& record,
                     std::span<std::uint8_t> out) {
  StoreU32(out, 0, record.sample_index);
  std::size_t offset = 4;
  for (std::size_t c = 0; c < kChannelCount; ++c) {
    if ((layout.channel_mask & (1u << c)) == 0) continue;
    StoreI32(out, offset, record.raw[c]);
    offset += 4;
  }
  if (layout.HasDob()) StoreI32(out, offset, record.d_hat);
}

Status DecodeLogRecord(const LogLayout& layout, std::span<const std::uint8_t> in,
                       LogRecord& record) {
  if (!layout.Valid() || in.size() != layout.RecordBytes()) return Status::kInvalidArgument;
  record = LogRecord{};
  record.sample_index = LoadU32(in, 0);
  std::size_t offset = 4;
  for (std::size_t c = 0; c < kChannelCount; ++c) {
    if ((layout.channel_mask & (1u << c)) == 0) continue;
    record.raw[c] = LoadI32(in, offset);
    offset += 4;
  }
  if (layout.HasDob()) record.d_hat = LoadI32(in, offset);
  return Status::kOk;
}

}  // namespace vibid::wire
