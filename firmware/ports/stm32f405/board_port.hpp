// The STM32F405 board's port objects that are not a peripheral driver of their own: the clock
// and the system control (identity, capabilities, reset cause, reset, DFU).
#pragma once

#include "vibid/fw/port.hpp"

namespace vibid::fw::stm32 {

class SysTickClock final : public Clock {
 public:
  std::uint64_t NowUs() const override;
};

class BoardSystemControl final : public SystemControl {
 public:
  /// Reads the reset flags; call once at boot, before anything could reset the chip.
  void Init();
  wire::BoardId Board() const override { return wire::BoardId::kStm32f405; }
  std::uint32_t PortCapabilities() const override { return wire::kCapDfu; }
  wire::ResetCause LastResetCause() const override { return reset_cause_; }
  void Reset() override;
  /// Reboots into the ROM's USB DFU bootloader (system memory, AN2606).
  void EnterDfu() override;

 private:
  wire::ResetCause reset_cause_ = wire::ResetCause::kUnknown;
};

}  // namespace vibid::fw::stm32
