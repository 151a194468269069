// Log records: what the board keeps of a sample, and how a log-read data report carries them.
//
// A record holds the selected channels in ascending wire::Channel order, each in its log format
// (LogValueBytes: converter channels u16 "12.4" codes, encoders i32 counts), then d_hat (i32, Q31
// of the observer's full scale) if kAcqFlagLogDob, then the residual test's word (u32: g in Q16
// in bits 0..30, the model-stale flag in bit 31) if kAcqFlagLogWatch. All little-endian. A record
// carries no time:
//
// Log-read data report payload:
//   0       u32  sample_index   tick (since acq-start) of the report's first record
//   4 + k r      record k       r = RecordBytes(); record k was sampled at tick
//                               sample_index + k * decimation
// A report holds only records whose ticks follow each other by the decimation; a gap (records
// the board dropped) starts a new report. So the time stamp costs 4 bytes per report, not per
// record. In its RAM the board keeps each record with its full tick (StoredRecordBytes()), which
// is what lets it cut reports at gaps.
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

inline constexpr std::size_t kLogIndexBytes = 4;
/// Payload bytes of a log data report (a stream data report) that carry records.
inline constexpr std::size_t kLogRecordPayload = kMaxStreamPayload - kLogIndexBytes;
/// All channels, d_hat and the residual test's word.
inline constexpr std::size_t kMaxLogRecordBytes = 4 * 2 + 2 * 4 + 4 + 4;
static_assert(kMaxLogRecordBytes == 24 && kMaxLogRecordBytes <= kLogRecordPayload);
/// The residual test's word: the flag bit, and the statistic below it.
inline constexpr std::uint32_t kLogWatchStaleBit = 0x80000000u;
inline constexpr std::uint32_t kLogWatchStatisticMask = 0x7FFFFFFFu;
inline constexpr std::size_t kMinLogRecordBytes = 2;
inline constexpr std::size_t kMaxRecordsPerReport = kLogRecordPayload / kMinLogRecordBytes;
static_assert(kMaxRecordsPerReport == 27);

struct LogLayout {
  std::uint8_t channel_mask = kAllChannelsMask;
  std::uint8_t flags = 0;  ///< acquisition flags; kAcqFlagLogDob and kAcqFlagLogWatch add columns

  /// Nonzero mask within the six channels, known flags, the test's word only beside d_hat.
  constexpr bool Valid() const {
    return channel_mask != 0 && (channel_mask & ~kAllChannelsMask) == 0 &&
           (flags & ~kAcqKnownFlags) == 0 && (!HasWatch() || HasDob());
  }
  constexpr std::size_t ChannelCount() const {
    return static_cast<std::size_t>(std::popcount(static_cast<unsigned>(channel_mask)));
  }
  constexpr bool HasDob() const { return (flags & kAcqFlagLogDob) != 0; }
  constexpr bool HasWatch() const { return (flags & kAcqFlagLogWatch) != 0; }
  /// Bytes of one record on the wire.
  constexpr std::size_t RecordBytes() const {
    std::size_t n = (HasDob() ? 4u : 0u) + (HasWatch() ? 4u : 0u);
    for (std::size_t c = 0; c < kChannelCount; ++c) {
      if ((channel_mask & (1u << c)) != 0) n += LogValueBytes(static_cast<Channel>(c));
    }
    return n;
  }
  /// Bytes of one record in the board's log RAM: its tick, then the wire bytes.
  constexpr std::size_t StoredRecordBytes() const { return kLogIndexBytes + RecordBytes(); }
  /// Records one full log data report carries.
  constexpr std::size_t RecordsPerReport() const { return kLogRecordPayload / RecordBytes(); }
};

struct LogRecord {
  std::uint32_t sample_index = 0;
  /// Indexed by channel, in the log format; entries of channels outside the mask are 0 after
  /// decoding.
  std::array<std::int32_t, kChannelCount> raw{};
  std::int32_t d_hat = 0;   ///< 0 after decoding a layout without d_hat.
  std::uint32_t watch = 0;  ///< The residual test's word; 0 after decoding a layout without it.
};

/// Writes layout.RecordBytes() bytes (the record without its tick). `out` must hold that many.
/// Converter values are clamped to 0..kLogAdcMax.
void EncodeLogRecord(const LogLayout& layout, const LogRecord& record, std::span<std::uint8_t> out);

/// Reads one record's channels and d_hat (sample_index is left as it is).
/// @returns kOk; kInvalidArgument if the layout is not Valid() or in.size() != RecordBytes().
Status DecodeLogRecord(const LogLayout& layout, std::span<const std::uint8_t> in,
                       LogRecord& record);

/// Decodes a log data report payload: the first record's tick, then whole records.
/// @returns kOk with `count` records in out[0..count); kInvalidArgument for an invalid layout,
///          a zero decimation, a payload that is not 4 bytes plus whole records, or more records
///          than `out` holds.
Status DecodeLogPayload(const LogLayout& layout, std::uint32_t decimation,
                        std::span<const std::uint8_t> payload, std::span<LogRecord> out,
                        std::size_t& count);

}  // namespace vibid::wire
