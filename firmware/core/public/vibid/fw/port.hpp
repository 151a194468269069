// The port interface: everything the portable core needs from a board, and nothing else.
//
// A port (stm32f405, qemu, emulator, the unit tests' fake) implements these four small
// interfaces and hands the core a Port of references to them. The core never touches a register.
//
// Context: FrameSink::OnFrame runs in the sampling interrupt on a board (or in the emulator's
// simulated-time loop); everything else is called from the main loop. No call blocks for long:
// Erase may take the flash's sector-erase time, which is why it is only called while idle.
//
// Interfaces have protected non-virtual destructors: the core never owns or deletes a port, and
// a virtual destructor would pull operator delete into a heap-free image.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "vibid/shared/status.hpp"
#include "vibid/shared/wire/commands.hpp"
#include "vibid/shared/wire/device.hpp"

namespace vibid::fw {

/// Monotonic time since the port started.
class Clock {
 public:
  /// Microseconds since boot; monotonic, does not wrap in the product's lifetime (64 bits).
  virtual std::uint64_t NowUs() const = 0;

 protected:
  ~Clock() = default;
};

/// One sampling tick: all six channels captured at the same instant.
struct SampleFrame {
  /// Tick counter since FrameSource::Start, +1 per sample period. A jump of more than one means
  /// frames were lost before they reached the core; the core counts the missing ticks as overruns.
  std::uint32_t tick = 0;
  /// Raw integers in wire::Channel order: ADC codes for load cells and accelerometers (right
  /// aligned, unsigned range of the converter), signed 32-bit counts for the encoders.
  std::array<std::int32_t, wire::kChannelCount> raw{};
};

/// Receives frames; the core's sampler implements it.
class FrameSink {
 public:
  /// Called once per tick, in tick order, from the sampling context.
  virtual void OnFrame(const SampleFrame& frame) = 0;

 protected:
  ~FrameSink() = default;
};

/// The timer-triggered converter (ADC + DMA + encoder timers on the board, injected samples on the
/// QEMU image, the simulated rig in the emulator).
class FrameSource {
 public:
  /// Starts delivering one frame every sample_period_us to sink.OnFrame, ticks from 0.
  /// @returns kOk; kInvalidArgument if the port cannot produce that period exactly;
  ///          kFailedPrecondition if already running.
  virtual Status Start(std::uint32_t sample_period_us, FrameSink& sink) = 0;

  /// Stops delivery. After it returns, OnFrame is not called again. Idempotent.
  virtual void Stop() = 0;

 protected:
  ~FrameSource() = default;
};

/// Two flash regions of equal size holding the calibration slots. NOR semantics: Erase sets every
/// byte to kErasedByte, Program can only clear bits. A power cut may stop any call part way.
class CalibrationFlash {
 public:
  enum class Slot : std::uint8_t { kA = 0, kB = 1 };
  static constexpr std::uint8_t kErasedByte = 0xFF;

  /// Bytes in each slot (the same for both); at least the calibration record plus its slot header.
  virtual std::size_t SlotBytes() const = 0;

  /// Erases the whole slot.
  /// @returns kOk; kInternal if the controller reported an error (the slot content is undefined).
  virtual Status Erase(Slot slot) = 0;

  /// Programs data at offset within the slot.
  /// @returns kOk; kOutOfRange if offset + data.size() > SlotBytes();
  ///          kInternal if the controller reported an error.
  virtual Status Program(Slot slot, std::size_t offset, std::span<const std::uint8_t> data) = 0;

  /// Reads out.size() bytes from offset within the slot.
  /// @returns kOk; kOutOfRange if offset + out.size() > SlotBytes().
  virtual Status Read(Slot slot, std::size_t offset, std::span<std::uint8_t> out) const = 0;

 protected:
  ~CalibrationFlash() = default;
};

/// Identity of the board and the ways to leave the running firmware.
class SystemControl {
 public:
  virtual wire::BoardId Board() const = 0;

  /// Port-specific wire capability bits (kCapDfu, kCapScenarioSelect, kCapSampleInjection); the
  /// core adds its own (kCapDob, kCapForceTrigger).
  virtual std::uint32_t PortCapabilities() const = 0;

  /// Why this boot happened; read once by the port at startup.
  virtual wire::ResetCause LastResetCause() const = 0;

  /// What the fault handler recorded before the reset this boot came from (get-info page
  /// kInfoPageFault), when LastResetCause() is kFault; otherwise, and on ports that keep no
  /// record, all zero (recorded = 0).
  virtual wire::FaultInfoResponse LastFault() const { return {}; }

  /// The brown-out reset level the hardware is set to; ports without one keep kUnknown.
  virtual wire::BrownOut BrownOutLevel() const { return wire::BrownOut::kUnknown; }

  /// One self-test measurement as the port takes it: value = mantissa x 10^exp10 in the
  /// check's unit (wire::SelfTestCheck). The core answers the calibration slots, brown-out and
  /// reset-cause checks itself and judges the numeric ones against its limits (selftest.hpp).
  struct SelfTestMeasurement {
    bool available = false;  ///< false: this port cannot measure the check.
    std::int64_t mantissa = 0;
    std::int8_t exp10 = 0;
    bool ok = false;  ///< The port's verdict for checks without a limit (encoders, image CRC).
    /// The time reference of a crystal check (the USB frames or the LSE); the core sets the
    /// offset checks' own.
    wire::SelfTestReference reference = wire::SelfTestReference::kNone;
  };

  /// Takes one self-test measurement, only while idle; the noise and offset checks sample
  /// wire::kSelfTestSamples frames at sample_period_us. Ports without it answer unavailable.
  virtual SelfTestMeasurement MeasureSelfTest(wire::SelfTestCheck check,
                                              std::uint32_t sample_period_us) {
    (void)check;
    (void)sample_period_us;
    return {};
  }

  /// Where the system clock comes from and the crystal as measured at start (get-info health
  /// page). A port on its internal oscillator reports why; the core then refuses acquisitions.
  struct ClockReport {
    wire::ClockState state = wire::ClockState::kUnknown;
    std::uint32_t hse_measured_hz = 0;  ///< 0: not measured.
  };
  virtual ClockReport ClockHealth() const { return {}; }

  /// Times the port restarted its converters and DMA after an overrun or a transfer error.
  virtual std::uint32_t SamplerRecoveries() const { return 0; }

  /// Resets the board. Does not return on a board; the emulator restarts its core.
  virtual void Reset() = 0;

  /// Hands over to the DFU bootloader (the ROM's on the STM32, the emulator's DfuSe personality).
  /// Does not return on a board.
  virtual void EnterDfu() = 0;

 protected:
  ~SystemControl() = default;
};

/// What a port hands to the core. References: the port owns the objects and outlives the core.
struct Port {
  Clock& clock;
  FrameSource& frames;
  CalibrationFlash& flash;
  SystemControl& system;
};

}  // namespace vibid::fw
