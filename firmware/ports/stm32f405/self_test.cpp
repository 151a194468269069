#include "self_test.hpp"

#include "regs/core_m4.hpp"
#include "regs/otg_fs.hpp"
#include "regs/peripherals.hpp"
#include "system.hpp"

namespace vibid::fw::stm32 {

EncoderState ReadEncoder(Address timer) {
  constexpr std::uint32_t kSmsMask = 0x7;  // SMCR SMS, bits 2:0
  const bool enabled = (Reg(timer + tim::kCr1) & tim::kCr1Cen) != 0;
  const bool encoder = (Reg(timer + tim::kSmcr) & kSmsMask) == tim::kSmcrEncoderMode3;
  return {.running = enabled && encoder, .count = Reg(timer + tim::kCnt)};
}

namespace {

// Waits for the next SOF flag and clears it; false after `timeout` cycles without one.
bool AwaitStartOfFrame(std::uint32_t timeout, std::uint32_t& at) {
  const std::uint32_t start = Reg(dwt::kCyccnt);
  for (;;) {
    const std::uint32_t now = Reg(dwt::kCyccnt);
    if ((Reg(otg::kGintsts) & otg::kIntSof) != 0) {
      at = now;
      Reg(otg::kGintsts) = otg::kIntSof;  // rc_w1: clears SOF only
      return true;
    }
    // Unsigned differences survive the counter's wrap (25.6 s at 168 MHz).
    if (now - start > timeout) return false;
  }
}

}  // namespace

bool CountCyclesOverFrames(std::uint32_t frames, std::uint32_t sysclk_hz, std::uint32_t& cycles) {
  // TRCENA powers the DWT (ARMv7-M ARM C1.6.5), CYCCNTENA starts the counter (C1.8.7).
  Reg(scb::kDemcr) |= scb::kDemcrTrcena;
  Reg(dwt::kCtrl) |= dwt::kCtrlCyccntEna;
  const std::uint32_t timeout = sysclk_hz / 500;  // 2 ms
  std::uint32_t first = 0;
  // The flag may be left from long ago: clear it and start at the next frame's.
  Reg(otg::kGintsts) = otg::kIntSof;
  if (!AwaitStartOfFrame(timeout, first)) return false;
  std::uint32_t last = first;
  for (std::uint32_t k = 0; k < frames; ++k) {
    if (!AwaitStartOfFrame(timeout, last)) return false;
    if (k % 100 == 0) KickWatchdog();
  }
  cycles = last - first;
  return true;
}

}  // namespace vibid::fw::stm32
