// Fuzzes the calibration-record decoder. Each input is tried twice: as it is, and fitted to the
// record length with a correct CRC so the field checks behind the CRC are reached. A record that
// decodes must encode back to exactly the same bytes (no field is read one way and written
// another), and a record that decodes must also pass through the board's upload path.
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "vibid/fw/calibration_upload.hpp"
#include "vibid/shared/wire/byte_order.hpp"
#include "vibid/shared/wire/calibration_record.hpp"
#include "vibid/shared/wire/crc32.hpp"
#include "vibid/shared/wire/stream.hpp"

namespace {

void CheckRoundTrip(std::span<const std::uint8_t> bytes) {
  using namespace vibid;
  wire::CalibrationRecord record;
  if (wire::DecodeCalibrationRecord(bytes, record) != Status::kOk) return;
  std::array<std::uint8_t, wire::kCalRecordBytes> again{};
  wire::EncodeCalibrationRecord(record, again);
  if (!std::equal(again.begin(), again.end(), bytes.begin(), bytes.end())) __builtin_trap();

  fw::CalibrationUpload upload;
  if (upload.Begin({.record_bytes = wire::kCalRecordBytes, .crc32 = wire::ComputeCrc32(bytes)}) !=
      Status::kOk) {
    __builtin_trap();
  }
  bool complete = false;
  for (std::size_t i = 0; i < wire::CalPutChunkCount(bytes.size()); ++i) {
    const std::size_t offset = i * wire::kMaxPayload;
    const auto chunk = bytes.subspan(offset, std::min(wire::kMaxPayload, bytes.size() - offset));
    if (upload.Data(static_cast<std::uint16_t>(i), chunk, complete) != Status::kOk)
      __builtin_trap();
  }
  if (!complete || !upload.staged()) __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace vibid;
  CheckRoundTrip(std::span<const std::uint8_t>(data, size));

  std::array<std::uint8_t, wire::kCalRecordBytes> fitted{};
  std::copy_n(data, std::min(size, fitted.size()), fitted.begin());
  wire::StoreU32(fitted, wire::kCalOffCrc,
                 wire::ComputeCrc32(std::span<const std::uint8_t>(fitted).first(wire::kCalOffCrc)));
  CheckRoundTrip(fitted);
  return 0;
}
