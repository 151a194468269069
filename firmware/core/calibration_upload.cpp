#include "vibid/fw/calibration_upload.hpp"

#include <algorithm>

namespace vibid::fw {

void CalibrationUpload::Clear() {
  active_ = false;
  staged_ = false;
  received_ = 0;
  next_sequence_ = 0;
}

Status CalibrationUpload::Begin(const wire::CalPutBeginRequest& begin) {
  Clear();
  if (begin.record_bytes != wire::kCalRecordBytes) return Status::kVersionMismatch;
  active_ = true;
  expected_crc_ = begin.crc32;
  return Status::kOk;
}

Status CalibrationUpload::Data(std::uint16_t sequence, std::span<const std::uint8_t> chunk,
                               bool& complete) {
  complete = false;
  if (!active_) return Status::kFailedPrecondition;
  const std::size_t remaining = wire::kCalRecordBytes - received_;
  const std::size_t want = std::min(wire::kMaxPayload, remaining);
  Status verdict = Status::kOk;
  if (sequence != next_sequence_) {
    verdict = Status::kOutOfRange;
  } else if (chunk.size() != want) {
    verdict = Status::kInvalidArgument;
  }
  if (verdict != Status::kOk) {
    Clear();
    return verdict;
  }
  std::copy(chunk.begin(), chunk.end(), bytes_.begin() + received_);
  received_ += static_cast<std::uint32_t>(chunk.size());
  ++next_sequence_;
  if (received_ < wire::kCalRecordBytes) return Status::kOk;

  active_ = false;
  if (wire::ComputeCrc32(bytes_) != expected_crc_) return Status::kDataLoss;
  verdict = wire::DecodeCalibrationRecord(bytes_, record_);
  if (verdict != Status::kOk) return verdict;
  staged_ = true;
  complete = true;
  return Status::kOk;
}

}  // namespace vibid::fw
