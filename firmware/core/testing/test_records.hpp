// Calibration records for the core's tests.
#pragma once

#include <array>
#include <cstdint>

#include "vibid/shared/wire/calibration_record.hpp"

namespace vibid::fw::testing {

/// A valid two-mass record; `tag` goes into the label ("rig 7") and created_unix_s so records
/// can be told apart after a reboot.
inline wire::CalibrationRecord TestRecord(std::uint32_t tag) {
  wire::CalibrationRecord r;
  r.dof_count = 2;
  r.created_unix_s = 1700000000 + tag;
  r.host_minor = 1;
  const char prefix[] = "rig ";
  std::size_t n = 0;
  for (; prefix[n] != '\0'; ++n) r.label[n] = prefix[n];
  char digits[10] = {};
  std::size_t d = 0;
  std::uint32_t v = tag;
  do {
    digits[d++] = static_cast<char>('0' + v % 10);
    v /= 10;
  } while (v != 0);
  while (d > 0) r.label[n++] = digits[--d];
  // 2 x 2 in the record's kMaxDof x kMaxDof row-major blocks (entries beyond are 0).
  constexpr std::size_t w = wire::kMaxDof;
  r.mass_kg[0] = 0.57f;
  r.mass_kg[w + 1] = 0.56f;
  r.damping_ns_per_m[0] = 1.0f;
  r.damping_ns_per_m[1] = r.damping_ns_per_m[w] = -0.5f;
  r.damping_ns_per_m[w + 1] = 0.5f;
  r.stiffness_n_per_m[0] = 30.0f;
  r.stiffness_n_per_m[1] = r.stiffness_n_per_m[w] = -15.0f;
  r.stiffness_n_per_m[w + 1] = 15.0f;
  // Load cells: 12-bit ADC centred at 2048, 2048 counts = full scale.
  r.channels[0] = {2048, 1 << 20, 0, wire::Unit::kNewton, 1, 100.0f};
  r.channels[1] = {2048, 1 << 20, 0, wire::Unit::kNewton, 1, 50.0f};
  r.channels[2] = {2048, 1 << 20, 0, wire::Unit::kMeterPerSecond2, 0, 490.0f};
  r.channels[3] = {2048, 1 << 20, 0, wire::Unit::kMeterPerSecond2, 1, 490.0f};
  r.channels[4] = {0, 1 << 16, 0, wire::Unit::kMeter, 0, 0.5f};
  r.channels[5] = {0, 1 << 16, 0, wire::Unit::kMeter, 1, 0.5f};
  return r;
}

inline std::array<std::uint8_t, wire::kCalRecordBytes> Encoded(const wire::CalibrationRecord& r) {
  std::array<std::uint8_t, wire::kCalRecordBytes> bytes{};
  wire::EncodeCalibrationRecord(r, bytes);
  return bytes;
}

}  // namespace vibid::fw::testing
