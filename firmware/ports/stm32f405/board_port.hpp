// The STM32F405 board's port objects that are not a peripheral driver of their own: the clock
// and the system control (identity, capabilities, reset cause, reset, DFU).
#pragma once

#include "clock.hpp"
#include "image_crc.hpp"
#include "sampler.hpp"
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
  /// The acquisitions' sampler, which the noise and offset checks run while idle.
  void AttachSampler(FrameSource& sampler) { sampler_ = &sampler; }
  /// The image whose CRC the image-crc check computes (OwnImage() on the chip).
  void AttachImage(const ImageView& image) { image_ = image; }
  /// The clocks ConfigureClocks set up (get-info's clock state, and the crystal checks run only
  /// on the crystal), and whether the board has a 32.768 kHz LSE crystal (started by StartLse).
  void AttachClock(const ClockConfig& clocks, bool has_lse) {
    clocks_ = clocks;
    has_lse_ = has_lse;
  }
  /// The sampler's counters, whose recoveries get-info's health page reports.
  void AttachSamplerCounters(const SamplerCounters& counters) { sampler_counters_ = &counters; }
  ClockReport ClockHealth() const override;
  std::uint32_t SamplerRecoveries() const override {
    return sampler_counters_ != nullptr ? sampler_counters_->recoveries : 0;
  }
  wire::BoardId Board() const override { return wire::BoardId::kStm32f405; }
  std::uint32_t PortCapabilities() const override { return wire::kCapDfu; }
  wire::ResetCause LastResetCause() const override { return reset_cause_; }
  /// The fault handler's record when the last reset was a fault (system.hpp).
  wire::FaultInfoResponse LastFault() const override { return fault_; }
  /// The option bytes' brown-out level (FLASH_OPTCR BOR_LEV).
  wire::BrownOut BrownOutLevel() const override;
  /// Measures the crystal against the host's USB frames (DWT cycles over OTG_FS SOF flags) and
  /// against the LSE where the board has one (TIM5 channel 4), both only on the crystal; VDDA
  /// from VREFINT, each analog channel's idle noise and offset over wire::kSelfTestSamples frames
  /// of the sampler (unavailable above 1 s of sampling or without frames), reads the encoder
  /// timers, and computes the image's CRC against its trailer's. The core asks only while idle.
  SelfTestMeasurement MeasureSelfTest(wire::SelfTestCheck check,
                                      std::uint32_t sample_period_us) override;
  void Reset() override;
  /// Reboots into the ROM's USB DFU bootloader (system memory, AN2606).
  void EnterDfu() override;

 private:
  /// Waits (bounded by kReplyDrainUs, feeding the watchdog) until no IN transfer is pending.
  void DrainReplies() const;

  wire::ResetCause reset_cause_ = wire::ResetCause::kUnknown;
  wire::FaultInfoResponse fault_{};
  const OtgFsDcd* dcd_ = nullptr;
  FrameSource* sampler_ = nullptr;
  ImageView image_{};
  ClockConfig clocks_{ClockSource::kPllFromHse, 168000000, 84000000, 84000000};
  bool has_lse_ = false;
  const SamplerCounters* sampler_counters_ = nullptr;
};

}  // namespace vibid::fw::stm32
