// Multi-report transfers, both directions, both ends.
//
// Device to host (log-read, cal-get): StreamEncoder builds the data reports and the trailer on
// the board; StreamDecoder checks them on the host (sequence gaps, byte count, CRC-32) so the
// host's device layer and the tests share one implementation.
//
// Host to device (cal-put): the Build* helpers cut a record into cal-put-begin and cal-put-data
// reports; the board's side is CalUploadReceiver.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "vibid/shared/status.hpp"
#include "vibid/shared/wire/commands.hpp"
#include "vibid/shared/wire/crc32.hpp"
#include "vibid/shared/wire/report.hpp"

namespace vibid::wire {

/// Device side of a stream: data reports numbered 0, 1, ..., then the trailer.
class StreamEncoder {
 public:
  /// Starts a new stream answering `command` with `token`.
  void Begin(Command command, std::uint16_t token);

  /// The next data report (a stream data report) carrying `payload` (1..kMaxStreamPayload bytes).
  /// Sequence numbers wrap after 65535 (the decoder counts modulo 2^16 too).
  /// @returns kOk; kOutOfRange for an empty or oversize payload.
  Status Data(std::span<const std::uint8_t> payload, Report& out);

  /// The trailer: `trailer_payload` (at least StreamTrailer::kBytes) gets the byte count and
  /// CRC-32 written into its first 8 bytes, then goes out flagged kFlagStreamEnd.
  /// @returns kOk; kOutOfRange if the trailer payload is too short or too long.
  Status End(std::span<std::uint8_t> trailer_payload, Report& out);

  std::uint32_t data_reports() const { return data_reports_; }
  std::uint32_t total_bytes() const { return total_bytes_; }

 private:
  Command command_ = Command::kPing;
  std::uint16_t token_ = 0;
  std::uint32_t data_reports_ = 0;
  std::uint32_t total_bytes_ = 0;
  Crc32 crc_;
};

/// Host side of a stream. Feed it every report that arrives after the request, in order.
class StreamDecoder {
 public:
  enum class Event : std::uint8_t {
    kData,     ///< A data report in sequence; `payload` holds its bytes.
    kEnd,      ///< The trailer matched; `payload` holds the whole trailer payload.
    kStale,    ///< Not an answer to this request (other token or command): ignore it.
    kRefused,  ///< The device refused the request; `status` says so, `payload` is the Refusal.
    kError,    ///< Broken stream; `status` says why (kDataLoss for a gap, count or CRC mismatch).
  };
  struct Step {
    Event event = Event::kError;
    Status status = Status::kOk;
    std::span<const std::uint8_t> payload;  ///< Points into the fed report.
  };

  StreamDecoder(Command command, std::uint16_t token) : command_(command), token_(token) {}

  /// After kEnd, kRefused or kError every further report yields kError (kFailedPrecondition).
  Step Feed(const Report& report);

  bool finished() const { return finished_; }
  std::uint32_t data_reports() const { return data_reports_; }
  std::uint32_t total_bytes() const { return total_bytes_; }

 private:
  Command command_;
  std::uint16_t token_;
  std::uint32_t data_reports_ = 0;
  std::uint32_t total_bytes_ = 0;
  Crc32 crc_;
  bool finished_ = false;
};

/// Number of cal-put-data reports a record of `record_bytes` takes.
constexpr std::size_t CalPutChunkCount(std::size_t record_bytes) {
  return (record_bytes + kMaxPayload - 1) / kMaxPayload;
}

/// cal-put-begin for `record` (its length and CRC-32).
/// @returns kOk; kOutOfRange if the record is empty or longer than 0xFFFF bytes.
Status BuildCalPutBegin(std::span<const std::uint8_t> record, std::uint16_t token, Report& out);

/// cal-put-data report number `chunk` of `record`.
/// @returns kOk; kOutOfRange if chunk >= CalPutChunkCount(record.size()).
Status BuildCalPutData(std::span<const std::uint8_t> record, std::size_t chunk, std::uint16_t token,
                       Report& out);

}  // namespace vibid::wire
