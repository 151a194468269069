// self-test: one numbered check per request. The port measures what needs its hardware
// (SystemControl::MeasureSelfTest); the core answers the checks it owns (calibration slots,
// brown-out, reset cause) and judges the numeric ones against the limits below, so every port
// is judged alike.
#include "vibid/fw/self_test_limits.hpp"

#include <cstdint>

#include "vibid/fw/core.hpp"
#include "vibid/shared/board_profile.hpp"

namespace vibid::fw {

namespace {

using wire::SelfTestCheck;
using wire::SelfTestReference;
using wire::SelfTestUnit;
using wire::SelfTestVerdict;

SelfTestUnit UnitOf(SelfTestCheck check) {
  switch (check) {
    case SelfTestCheck::kHsePpm:
    case SelfTestCheck::kHsePpmLse: return SelfTestUnit::kPpm;
    case SelfTestCheck::kVdda: return SelfTestUnit::kVolt;
    case SelfTestCheck::kNoiseForce1:
    case SelfTestCheck::kNoiseForce2:
    case SelfTestCheck::kNoiseAccel1:
    case SelfTestCheck::kNoiseAccel2: return SelfTestUnit::kLsbRms;
    case SelfTestCheck::kOffsetForce1:
    case SelfTestCheck::kOffsetForce2:
    case SelfTestCheck::kOffsetAccel1:
    case SelfTestCheck::kOffsetAccel2: return SelfTestUnit::kLsb;
    case SelfTestCheck::kEncoder1:
    case SelfTestCheck::kEncoder2: return SelfTestUnit::kCount;
    case SelfTestCheck::kImageCrc: return SelfTestUnit::kCrc32;
    case SelfTestCheck::kCalSlotA:
    case SelfTestCheck::kCalSlotB: return SelfTestUnit::kSlot;
    case SelfTestCheck::kBrownOut: return SelfTestUnit::kBrownOut;
    case SelfTestCheck::kResetCause: return SelfTestUnit::kResetCause;
  }
  return SelfTestUnit::kNone;
}

}  // namespace

bool SelfTestWithinLimit(SelfTestCheck check, std::int64_t mantissa, std::int8_t exp10) {
  // Compare in micro-units (value x 10^6 = mantissa x 10^(exp10 + 6)): every limit is a whole
  // number of them. A value too large to scale is beyond every limit.
  std::int64_t micro = mantissa;
  const int shift = exp10 + 6;
  constexpr std::int64_t kScalable = INT64_MAX / 10;
  for (int e = 0; e < shift; ++e) {
    if (micro > kScalable || micro < -kScalable) return false;
    micro *= 10;
  }
  for (int e = 0; e > shift; --e) micro /= 10;
  if (micro == INT64_MIN) return false;  // no magnitude in int64, and beyond every limit
  const std::int64_t magnitude = micro < 0 ? -micro : micro;
  switch (check) {
    case SelfTestCheck::kHsePpm: return magnitude <= kHseToleranceMicroPpm;
    case SelfTestCheck::kHsePpmLse: return magnitude <= kHseLseToleranceMicroPpm;
    case SelfTestCheck::kVdda: return micro >= kVddaMinMicroV && micro <= kVddaMaxMicroV;
    case SelfTestCheck::kNoiseForce1:
    case SelfTestCheck::kNoiseForce2:
    case SelfTestCheck::kNoiseAccel1:
    case SelfTestCheck::kNoiseAccel2: return micro >= 0 && micro <= kNoiseMaxMicroLsbRms;
    case SelfTestCheck::kOffsetForce1:
    case SelfTestCheck::kOffsetForce2:
    case SelfTestCheck::kOffsetAccel1:
    case SelfTestCheck::kOffsetAccel2: return magnitude <= kOffsetMaxMicroLsb;
    default: return false;
  }
}

wire::SelfTestResponse Core::SelfTest(std::uint8_t check_index) {
  const auto check = static_cast<SelfTestCheck>(check_index);
  wire::SelfTestResponse r;
  r.check = check_index;
  r.unit = UnitOf(check);
  const auto judge = [&r](bool pass) {
    r.verdict = pass ? SelfTestVerdict::kPass : SelfTestVerdict::kFail;
  };
  switch (check) {
    case SelfTestCheck::kCalSlotA:
    case SelfTestCheck::kCalSlotB: {
      const wire::SelfTestSlot slot =
          store_.CheckSlot(check == SelfTestCheck::kCalSlotA ? CalibrationFlash::Slot::kA
                                                             : CalibrationFlash::Slot::kB);
      r.mantissa = static_cast<std::int64_t>(slot);
      judge(slot != wire::SelfTestSlot::kDamaged);
      return r;
    }
    case SelfTestCheck::kBrownOut: {
      const wire::BrownOut level = port_.system.BrownOutLevel();
      r.mantissa = static_cast<std::int64_t>(level);
      // 2.7 V is the least supply x32 flash programming takes (RM0090 §3.6.2; docs/board.md,
      // "Brown-out level").
      if (level == wire::BrownOut::kUnknown) {
        r.verdict = SelfTestVerdict::kUnavailable;
      } else {
        judge(level == wire::BrownOut::kLevel3);
      }
      return r;
    }
    case SelfTestCheck::kResetCause: {
      const wire::ResetCause cause = port_.system.LastResetCause();
      r.mantissa = static_cast<std::int64_t>(cause);
      // Informational, except a crash: the board reset itself out of a fault (get-info page
      // kInfoPageFault says where), which no check of a healthy board shows.
      judge(cause != wire::ResetCause::kFault);
      return r;
    }
    default: break;
  }
  const std::uint32_t period_us = configured_ ? config_.sample_period_us : kDefaultSamplePeriodUs;
  const SystemControl::SelfTestMeasurement m = port_.system.MeasureSelfTest(check, period_us);
  if (!m.available) {
    r.verdict = SelfTestVerdict::kUnavailable;
    return r;
  }
  r.mantissa = m.mantissa;
  r.exp10 = m.exp10;
  r.reference = m.reference;
  if (check >= SelfTestCheck::kOffsetForce1 && check <= SelfTestCheck::kOffsetAccel2) {
    // The port measures the idle mean against the mid code; a channel with a calibrated zero
    // (a load cell amplifier idling near 0 V, say) is judged against that zero instead.
    const auto channel =
        static_cast<unsigned>(check) - static_cast<unsigned>(SelfTestCheck::kOffsetForce1);
    r.reference = SelfTestReference::kMidCode;
    const wire::ChannelScaling& scaling = store_.record().channels[channel];
    if (store_.calibrated() && scaling.unit != wire::Unit::kCounts && m.exp10 <= 0 &&
        m.exp10 >= -6) {
      // Scaling and overflow: offset_counts and the mid code are within +-2^31, so their
      // difference times at most 10^6 stays below 2^53. A port's mantissa is a milli-LSB mean
      // (|x| < 2^32), but any int64 may come: a difference that does not fit saturates, a value
      // beyond every limit either way.
      constexpr std::int64_t kMidCode = std::int64_t{1} << (kBoardProfile.adc_bits - 1);
      std::int64_t unit = 1;
      for (int e = 0; e > m.exp10; --e) unit *= 10;
      const std::int64_t shift = (std::int64_t{scaling.offset_counts} - kMidCode) * unit;
      if (__builtin_sub_overflow(m.mantissa, shift, &r.mantissa))
        r.mantissa = shift > 0 ? INT64_MIN : INT64_MAX;
      r.reference = SelfTestReference::kCalibration;
    }
  }
  const bool port_judges = check == SelfTestCheck::kEncoder1 || check == SelfTestCheck::kEncoder2 ||
                           check == SelfTestCheck::kImageCrc;
  judge(port_judges ? m.ok : SelfTestWithinLimit(check, r.mantissa, r.exp10));
  return r;
}

}  // namespace vibid::fw
