// The STM32F405 board's port objects that are not a peripheral driver of their own: the clock
// and the system control (identity, capabilities, reset cause, reset, DFU).
#pragma once

#include "vibid/fw/port.hpp"

namespace vibid::fw::stm32 {

class OtgFsDcd;

class SysTickClock final : public Clock {
 public:
  std::uint64_t NowUs() const override;
};

class BoardSystemControl final : public SystemControl {
 public:
  /// How long Reset/EnterDfu wait for the host to take the reply before resetting anyway: the
  /// host polls the HID IN endpoint every 1 ms, so 100 ms is ample and still short for a user.
  static constexpr std::uint64_t kReplyDrainUs = 100000;

  /// Reads the reset flags; call once at boot, before anything could reset the chip.
  void Init();
  /// The USB device whose IN transfers (the reply to "reset" / "enter DFU") must be taken by
  /// the host before the chip resets.
  void AttachUsb(const OtgFsDcd& dcd) { dcd_ = &dcd; }
  wire::BoardId Board() const override { return wire::BoardId::kStm32f405; }
  std::uint32_t PortCapabilities() const override { return wire::kCapDfu; }
  wire::ResetCause LastResetCause() const override { return reset_cause_; }
  /// The option bytes' brown-out level (FLASH_OPTCR BOR_LEV).
  wire::BrownOut BrownOutLevel() const override;
  /// Measures the crystal against the host's USB frames (DWT cycles over OTG_FS SOF flags), VDDA
  /// from VREFINT and reads the encoder timers; the converter noise and offsets and the image CRC
  /// are not measured on this port yet (unavailable).
  SelfTestMeasurement MeasureSelfTest(wire::SelfTestCheck check,
                                      std::uint32_t sample_period_us) override;
  void Reset() override;
  /// Reboots into the ROM's USB DFU bootloader (system memory, AN2606).
  void EnterDfu() override;

 private:
  /// Waits (bounded by kReplyDrainUs, feeding the watchdog) until no IN transfer is pending.
  void DrainReplies() const;

  wire::ResetCause reset_cause_ = wire::ResetCause::kUnknown;
  const OtgFsDcd* dcd_ = nullptr;
};

}  // namespace vibid::fw::stm32
