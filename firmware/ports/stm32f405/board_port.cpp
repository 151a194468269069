#include "board_port.hpp"

#include "system.hpp"

namespace vibid::fw::stm32 {

std::uint64_t SysTickClock::NowUs() const { return MicrosecondsSinceBoot(); }

void BoardSystemControl::Init() { reset_cause_ = ReadAndClearResetCause(); }
void BoardSystemControl::Reset() { SystemReset(); }
void BoardSystemControl::EnterDfu() { RebootToBootloader(); }

}  // namespace vibid::fw::stm32
