#include "board_port.hpp"

#include "otg_fs_dcd.hpp"
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

void BoardSystemControl::Reset() {
  DrainReplies();
  SystemReset();
}

void BoardSystemControl::EnterDfu() {
  DrainReplies();
  RebootToBootloader();
}

}  // namespace vibid::fw::stm32
