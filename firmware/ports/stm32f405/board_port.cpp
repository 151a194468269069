#include "board_port.hpp"

#include "clock_plan.hpp"
#include "otg_fs_dcd.hpp"
#include "regs/peripherals.hpp"
#include "self_test.hpp"
#include "system.hpp"

namespace vibid::fw::stm32 {

std::uint64_t SysTickClock::NowUs() const { return MicrosecondsSinceBoot(); }

void BoardSystemControl::Init() { reset_cause_ = ReadAndClearResetCause(); }

void BoardSystemControl::DrainReplies() const {
  if (dcd_ == nullptr) return;
  // The core calls Reset/EnterDfu from the main loop right after queueing the reply; the OTG
  // interrupt keeps running and the core clears EPENA once the host has taken the packet.
  const std::uint64_t start = MicrosecondsSinceBoot();
  while (dcd_->InTransfersPending() && MicrosecondsSinceBoot() - start < kReplyDrainUs) {
    KickWatchdog();
  }
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
  (void)sample_period_us;
  switch (check) {
    case wire::SelfTestCheck::kHsePpm: {
      // USB runs only with the PLL on the HSE at 168 MHz (the HSI fallback keeps it off the
      // bus), so a host that asks is timing a 168 MHz core.
      std::uint32_t cycles = 0;
      if (!CountCyclesOverFrames(kCrystalCheckFrames, kSysclkTargetHz, cycles)) return {};
      return {.available = true,
              .mantissa = CrystalErrorMilliPpm(cycles, kCrystalCheckFrames, kSysclkTargetHz),
              .exp10 = -3};
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
