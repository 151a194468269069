// The rest of the port interface for the QEMU netduinoplus2 image: a microsecond clock from
// TIM5, calibration slots in RAM (QEMU models the flash as ROM with no programming interface),
// and system control. Sampling is InjectedFrameSource, the link UsartReportLink.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "image_crc.hpp"
#include "vibid/fw/port.hpp"

namespace vibid::fw::qemu {

/// TIM5 (32 bit) counting microseconds, extended to 64 bits on read. Reads come from the main
/// loop and the sampling interrupt alike, so the extension is done with interrupts masked.
class TimerClock final : public Clock {
 public:
  void Init();
  std::uint64_t NowUs() const override;

 private:
  mutable std::uint32_t last_ = 0;
  mutable std::uint64_t high_ = 0;
};

/// Two 16 KiB slots with NOR-flash semantics (erase to 0xFF, programming only clears bits), the
/// same size as the board's sectors 2 and 3. Contents last until QEMU exits.
class RamCalibrationFlash final : public CalibrationFlash {
 public:
  static constexpr std::size_t kSlotBytes = 16 * 1024;

  RamCalibrationFlash();
  std::size_t SlotBytes() const override { return kSlotBytes; }
  Status Erase(Slot slot) override;
  Status Program(Slot slot, std::size_t offset, std::span<const std::uint8_t> data) override;
  Status Read(Slot slot, std::size_t offset, std::span<std::uint8_t> out) const override;

 private:
  std::array<std::array<std::uint8_t, kSlotBytes>, 2> slots_;
};

class QemuSystemControl final : public SystemControl {
 public:
  /// Reads the reset flags once (QEMU does not model RCC: they read as zero -> kUnknown).
  void Init();
  wire::BoardId Board() const override { return wire::BoardId::kQemuNetduinoPlus2; }
  std::uint32_t PortCapabilities() const override { return wire::kCapSampleInjection; }
  wire::ResetCause LastResetCause() const override { return reset_cause_; }
  /// The image whose CRC the image-crc check computes: the ELF QEMU loaded into its flash.
  void AttachImage(const stm32::ImageView& image) { image_ = image; }
  /// The image CRC against the one the build wrote, as on the board. QEMU 7.2's netduinoplus2
  /// has no crystal, VREFINT calibration, timer-triggered ADC, DMA, encoder timers or option
  /// bytes to measure, so every other check the port measures is unavailable.
  SelfTestMeasurement MeasureSelfTest(wire::SelfTestCheck check,
                                      std::uint32_t sample_period_us) override;
  /// System reset through AIRCR; QEMU started with -no-reboot then exits.
  void Reset() override;
  /// There is no ROM bootloader in QEMU (kCapDfu is not advertised); a request that still
  /// arrives resets the image instead of leaving it in an undefined state.
  void EnterDfu() override;

 private:
  wire::ResetCause reset_cause_ = wire::ResetCause::kUnknown;
  stm32::ImageView image_{};
};

}  // namespace vibid::fw::qemu
