// The board's side of cal-put: collects a record sent as cal-put-begin + cal-put-data reports,
// checks order, lengths and the announced CRC-32, then decodes and validates the record and
// keeps it staged for cal-commit. Any refusal abandons the transfer; the host starts again with
// cal-put-begin. A staged record survives until the next begin or a commit.
#pragma once

#include <array>
#include <cstdint>
#include <span>

#include "vibid/shared/status.hpp"
#include "vibid/shared/wire/calibration_record.hpp"
#include "vibid/shared/wire/commands.hpp"
#include "vibid/shared/wire/crc32.hpp"

namespace vibid::fw {

class CalibrationUpload {
 public:
  /// Starts a transfer; drops any staged record.
  /// @returns kOk; kVersionMismatch if record_bytes is not wire::kCalRecordBytes (a record of
  ///          another version).
  Status Begin(const wire::CalPutBeginRequest& begin);

  /// One chunk; `sequence` must be the next chunk index and the chunk full (52 bytes) except
  /// the last. `complete` is set when this was the last chunk and the record is staged.
  /// @returns kOk; kFailedPrecondition without a transfer in progress; kOutOfRange for a
  ///          sequence other than the next; kInvalidArgument for a wrong chunk length;
  ///          kDataLoss if the assembled bytes do not match the announced CRC-32; otherwise the
  ///          record's own verdict (DecodeCalibrationRecord, the filter included).
  Status Data(std::uint16_t sequence, std::span<const std::uint8_t> chunk, bool& complete);

  bool staged() const { return staged_; }
  bool active() const { return active_; }
  /// The chunk index Data expects next.
  std::uint16_t next_sequence() const { return next_sequence_; }
  /// Every chunk arrived (a refusal of the last chunk is the verdict on the record).
  bool assembled() const { return received_ == wire::kCalRecordBytes; }
  std::span<const std::uint8_t, wire::kCalRecordBytes> bytes() const { return bytes_; }
  const wire::CalibrationRecord& record() const { return record_; }
  void Clear();

 private:
  bool active_ = false;
  bool staged_ = false;
  std::uint32_t expected_crc_ = 0;
  std::uint32_t received_ = 0;
  std::uint16_t next_sequence_ = 0;
  std::array<std::uint8_t, wire::kCalRecordBytes> bytes_{};
  wire::CalibrationRecord record_{};
};

}  // namespace vibid::fw
