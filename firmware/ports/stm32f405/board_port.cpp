#include "board_port.hpp"

#include "clock_plan.hpp"
#include "crystal_check.hpp"
#include "image_crc_self_test.hpp"
#include "otg_fs_dcd.hpp"
#include "regs/peripherals.hpp"
#include "self_test.hpp"
#include "system.hpp"
#include "vibid/shared/board_profile.hpp"

namespace vibid::fw::stm32 {

std::uint64_t SysTickClock::NowUs() const { return MicrosecondsSinceBoot(); }

void BoardSystemControl::Init() { reset_cause_ = ReadAndClearResetCause(&fault_); }

void BoardSystemControl::DrainReplies() const {
  if (dcd_ == nullptr) return;
  // The core calls Reset/EnterDfu from the main loop right after queueing the reply; the OTG
  // interrupt keeps running and the core clears EPENA once the host has taken the packet.
  const std::uint64_t start = MicrosecondsSinceBoot();
  while (dcd_->InTransfersPending() && MicrosecondsSinceBoot() - start < kReplyDrainUs) {
    KickWatchdog();
  }
}

SystemControl::ClockReport BoardSystemControl::ClockHealth() const {
  wire::ClockState state = wire::ClockState::kCrystal;
  if (clocks_.source != ClockSource::kPllFromHse) {
    switch (clocks_.hsi_reason) {
      case HsiReason::kHseWrongFrequency: state = wire::ClockState::kCrystalWrongFrequency; break;
      case HsiReason::kPllDidNotLock: state = wire::ClockState::kPllDidNotLock; break;
      case HsiReason::kHseDidNotStart:
      case HsiReason::kNone: state = wire::ClockState::kCrystalDidNotStart; break;
    }
  }
  return {.state = state, .hse_measured_hz = clocks_.hse_measured_hz};
}

wire::BrownOut BoardSystemControl::BrownOutLevel() const {
  switch (stm32::BrownOutLevel()) {
    case BrownOut::kLevel3: return wire::BrownOut::kLevel3;
    case BrownOut::kLevel2: return wire::BrownOut::kLevel2;
    case BrownOut::kLevel1: return wire::BrownOut::kLevel1;
    case BrownOut::kOff: return wire::BrownOut::kOff;
  }
  return wire::BrownOut::kUnknown;
}

SystemControl::SelfTestMeasurement BoardSystemControl::MeasureSelfTest(
    wire::SelfTestCheck check, std::uint32_t sample_period_us) {
  using wire::SelfTestCheck;
  const auto index = static_cast<unsigned>(check);
  if (index >= static_cast<unsigned>(SelfTestCheck::kNoiseForce1) &&
      index <= static_cast<unsigned>(SelfTestCheck::kOffsetAccel2)) {
    // Noise 2..5 and offset 6..9 take the same channels in wire::Channel order.
    const bool noise = index <= static_cast<unsigned>(SelfTestCheck::kNoiseAccel2);
    const unsigned channel = index - static_cast<unsigned>(noise ? SelfTestCheck::kNoiseForce1
                                                                 : SelfTestCheck::kOffsetForce1);
    CodeSums sums;
    if (sampler_ == nullptr || SampleIdleChannel(*sampler_, sample_period_us, channel,
                                                 wire::kSelfTestSamples, sums) != IdleSampling::kOk)
      return {};
    constexpr std::uint32_t kMidCode = 1u << (kBoardProfile.adc_bits - 1);  // 2048
    std::int64_t milli_lsb = 0;
    const bool measured =
        noise ? RmsMilliLsb(sums, milli_lsb) : OffsetMilliLsb(sums, kMidCode, milli_lsb);
    if (!measured) return {};
    return {.available = true, .mantissa = milli_lsb, .exp10 = -3};
  }
  switch (check) {
    case wire::SelfTestCheck::kHsePpm: {
      // Only a core on the crystal's PLL (168 MHz) times the crystal; on the HSI fallback the
      // count would be the HSI's.
      if (clocks_.source != ClockSource::kPllFromHse) return {};
      std::uint32_t cycles = 0;
      if (!CountCyclesOverFrames(kCrystalCheckFrames, kSysclkTargetHz, cycles)) return {};
      return {.available = true,
              .mantissa = CrystalErrorMilliPpm(cycles, kCrystalCheckFrames, kSysclkTargetHz),
              .exp10 = -3,
              .reference = wire::SelfTestReference::kUsbFrames};
    }
    case wire::SelfTestCheck::kHsePpmLse: {
      std::int64_t milli_ppm = 0;
      if (!has_lse_ || clocks_.source != ClockSource::kPllFromHse || !LseReady() ||
          !MeasureHseAgainstLse(clocks_.apb1_timer_hz, milli_ppm))
        return {};
      return {.available = true,
              .mantissa = milli_ppm,
              .exp10 = -3,
              .reference = wire::SelfTestReference::kLse};
    }
    case wire::SelfTestCheck::kVdda: {
      // Erased or absent calibration (0xFFFF, 0) leaves nothing to scale by.
      const std::uint16_t cal = VrefintCal();
      std::uint32_t code = 0;
      if (cal == 0 || cal == 0xFFFF || !ConvertVrefint(kSysclkTargetHz, code) || code == 0)
        return {};
      return {.available = true, .mantissa = VddaMillivolts(cal, code), .exp10 = -3};
    }
    case wire::SelfTestCheck::kEncoder1:
    case wire::SelfTestCheck::kEncoder2: {
      const EncoderState e =
          ReadEncoder(check == wire::SelfTestCheck::kEncoder1 ? tim::kTim3 : tim::kTim4);
      // The count is the 16-bit timer's: the core extends it to 32 bits only in frames.
      return {.available = true, .mantissa = e.count, .exp10 = 0, .ok = e.running};
    }
    case wire::SelfTestCheck::kImageCrc: return ImageCrcMeasurement(image_);
    default: return {};
  }
}

void BoardSystemControl::Reset() {
  DrainReplies();
  SystemReset();
}

void BoardSystemControl::EnterDfu() {
  DrainReplies();
  RebootToBootloader();
}

}  // namespace vibid::fw::stm32
