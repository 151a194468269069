// A small valid DOB description for tests of records that carry a filter: two inputs (a force
// and an acceleration on mass 1), one stable section each (poles at 0.5 and 0.25).
#pragma once

#include <array>
#include <cstdint>

#include "vibid/shared/fixed/filter_description.hpp"
#include "vibid/shared/wire/calibration_record.hpp"

namespace vibid::wire::testing {

inline constexpr float kForceFullScaleN = 100.0f;
inline constexpr float kAccelFullScaleMs2 = 490.0f;

inline fixed::FilterDescription TestFilter(std::uint32_t sample_rate_hz = 5000) {
  constexpr std::int32_t kOneQ30 = 1 << 30;  // 1.0 with shift 1
  fixed::FilterDescription d;
  d.input_count = 2;
  d.output_dof = 1;
  d.sample_rate_hz = sample_rate_hz;
  d.input_kind = {fixed::InputKind::kForce, fixed::InputKind::kAcceleration,
                  fixed::InputKind::kUnused};
  d.input_dof = {1, 1, 0};
  d.input_full_scale_bits = {fixed::FullScaleBits(kForceFullScaleN),
                             fixed::FullScaleBits(kAccelFullScaleMs2), 0};
  d.output_full_scale_bits = fixed::FullScaleBits(200.0f);
  for (std::size_t i = 0; i < 2; ++i) {
    fixed::Path& p = d.paths[i];
    p.section_count = 1;
    p.output_gain = i == 0 ? -(1 << 30) : (1 << 30);
    p.output_shift = 1;
    p.sections[0] = fixed::Section{.b0 = kOneQ30 / 4,
                                   .b1 = kOneQ30 / 8,
                                   .b2 = 0,
                                   .a1 = -3 * (kOneQ30 / 4),
                                   .a2 = kOneQ30 / 8,
                                   .shift = 1};
  }
  fixed::Seal(d);
  return d;
}

/// Puts `filter` into `record`, fed by force channel `force_channel` and accelerometer
/// `accel_channel` (whose scaling must match the filter's inputs).
inline void AttachFilter(CalibrationRecord& record, const fixed::FilterDescription& filter,
                         std::uint8_t force_channel, std::uint8_t accel_channel) {
  record.flags |= kCalFlagHasDob;
  record.dob_input_channel = {force_channel, accel_channel, kNoChannel};
  fixed::EncodeDescription(filter, record.dob);
}

}  // namespace vibid::wire::testing
