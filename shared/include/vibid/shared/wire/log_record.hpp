// One log record: a sample the board kept, in the layout chosen at acq-configure.
//
// Byte layout (little-endian):
//   0        u32  sample_index   the frame's tick since acq-start (time = index * sample period)
//   4 + 4 j  i32  raw            the j-th selected channel's raw value, channels in ascending
//                                wire::Channel order (only those set in channel_mask)
//   4 + 4 n  i32  d_hat          the DOB output (Q31 of its full scale), if kAcqFlagLogDob
//
// Records never straddle reports: a log-read data report carries
// RecordsPerReport() whole records.
#pragma once

#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <span>

#include "vibid/shared/status.hpp"
#include "vibid/shared/wire/commands.hpp"
#include "vibid/shared/wire/device.hpp"
#include "vibid/shared/wire/report.hpp"

namespace vibid::wire {

inline constexpr std::size_t kMaxLogRecordBytes = 4 + 4 * kChannelCount + 4;
static_assert(kMaxLogRecordBytes == 32 && kMaxLogRecordBytes <= kMaxPayload);

struct LogLayout {
  std::uint8_t channel_mask = kAllChannelsMask;
  std::uint8_t flags = 0;  ///< kAcqFlagLogDob

  /// Nonzero mask within the six channels, known flags.
  constexpr bool Valid() const {
    return channel_mask != 0 && (channel_mask & ~kAllChannelsMask) == 0 &&
           (flags & ~kAcqKnownFlags) == 0;
  }
  constexpr std::size_t ChannelCount() const {
    return static_cast<std::size_t>(std::popcount(static_cast<unsigned>(channel_mask)));
  }
  constexpr bool HasDob() const { return (flags & kAcqFlagLogDob) != 0; }
  constexpr std::size_t RecordBytes() const { return 4 + 4 * ChannelCount() + (HasDob() ? 4 : 0); }
  constexpr std::size_t RecordsPerReport() const { return kMaxPayload / RecordBytes(); }
};

struct LogRecord {
  std::uint32_t sample_index = 0;
  /// Indexed by channel; entries of channels outside the layout's mask are 0 after decoding.
  std::array<std::int32_t, kChannelCount> raw{};
  std::int32_t d_hat = 0;  ///< 0 after decoding a layout without d_hat.
};

/// Writes layout.RecordBytes() bytes. `out` must hold at least that many.
void EncodeLogRecord(const LogLayout& layout, const LogRecord& record, std::span<std::uint8_t> out);

/// @returns kOk; kInvalidArgument if the layout is not Valid() or in.size() != RecordBytes().
Status DecodeLogRecord(const LogLayout& layout, std::span<const std::uint8_t> in, LogRecord& record);

}  // namespace vibid::wire
