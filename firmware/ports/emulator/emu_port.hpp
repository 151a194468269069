// The emulator's implementation of the core's port interface: a simulated clock, the simulated
// rig as the frame source, calibration slots in the emulated flash, and the system control that
// asks the emulator loop to reset or to switch to the DFU bootloader.
//
// The port holds only what a board port holds. The rig simulation and the flash file are host
// code (host/emulator) and reach the port through the two interfaces below, as a board's
// converters and flash controller reach its port through registers.
#pragma once

#include <array>
#include <cstdint>
#include <span>

#include "vibid/fw/port.hpp"
#include "vibid/fw/port_commands.hpp"
#include "vibid/shared/wire/commands.hpp"
#include "vibid/shared/wire/refusal.hpp"

namespace vibid::emu {

/// The rig behind the converters: started at a sampling period, stepped once per sample tick.
class SimulatedRig {
 public:
  virtual double MaxSampleRateHz() const = 0;
  virtual void Start(double sample_period_s) = 0;
  /// Advances one sample period and writes the converters' codes.
  virtual void Step(std::array<std::int32_t, wire::kChannelCount>& raw) = 0;
  /// select-scenario: kInvalidArgument for a scenario this rig cannot run, `why` naming the cause.
  virtual Status SelectScenario(const wire::ScenarioRequest& request, wire::Refusal& why) = 0;

 protected:
  ~SimulatedRig() = default;
};

/// The emulated flash array: the board's sector map, NOR programming (bits only clear).
class FlashArray {
 public:
  virtual bool EraseSector(int sector) = 0;
  virtual bool Program(std::uint32_t address, std::span<const std::uint8_t> data) = 0;
  virtual bool Read(std::uint32_t address, std::span<std::uint8_t> out) const = 0;

 protected:
  ~FlashArray() = default;
};

/// Simulated time in microseconds; only the emulator loop moves it.
class SimClock final : public fw::Clock {
 public:
  std::uint64_t NowUs() const override { return now_us_; }
  void Advance(std::uint64_t us) { now_us_ += us; }
  /// Moves the clock to `us` (never back).
  void Set(std::uint64_t us) { now_us_ = us > now_us_ ? us : now_us_; }

 private:
  std::uint64_t now_us_ = 0;
};

/// The rig behind the board's converters: Start/Stop come from the core, Tick from the loop.
class RigFrameSource final : public fw::FrameSource {
 public:
  explicit RigFrameSource(SimulatedRig& rig) : rig_(rig) {}

  /// @returns kInvalidArgument for a period faster than the rig's max_sample_rate_hz.
  Status Start(std::uint32_t sample_period_us, fw::FrameSink& sink) override;
  void Stop() override { sink_ = nullptr; }

  bool Running() const { return sink_ != nullptr; }
  std::uint32_t period_us() const { return period_us_; }
  /// Delivers one frame (Running() only).
  void Tick();

 private:
  SimulatedRig& rig_;
  fw::FrameSink* sink_ = nullptr;
  std::uint32_t period_us_ = 0;
  fw::SampleFrame frame_{};
};

/// Calibration slots A and B: sectors 2 and 3 of the emulated flash, as on the board.
class FlashCalibrationSlots final : public fw::CalibrationFlash {
 public:
  explicit FlashCalibrationSlots(FlashArray& flash) : flash_(flash) {}
  static constexpr int kSlotSector[2] = {2, 3};
  /// The STM32F405's sectors 2 and 3 (16 KiB each after sectors 0 and 1).
  static constexpr std::uint32_t kSlotAddress[2] = {0x0800'8000, 0x0800'C000};

  std::size_t SlotBytes() const override { return 16 * 1024; }
  Status Erase(Slot slot) override;
  Status Program(Slot slot, std::size_t offset, std::span<const std::uint8_t> data) override;
  Status Read(Slot slot, std::size_t offset, std::span<std::uint8_t> out) const override;

 private:
  static std::uint32_t Address(Slot slot, std::size_t offset);
  FlashArray& flash_;
};

/// What the firmware asked the emulator to do once the current main-loop step is over.
enum class Request : std::uint8_t { kNone, kReset, kEnterDfu };

class EmuSystemControl final : public fw::SystemControl {
 public:
  /// The emulated board's analog supply: the 3.3 V its converters' codes are scaled to.
  static constexpr std::int64_t kVddaMv = 3300;

  EmuSystemControl(wire::ResetCause cause, SimulatedRig& rig,
                   wire::BrownOut brown_out = wire::BrownOut::kLevel3)
      : cause_(cause), rig_(rig), brown_out_(brown_out) {}
  wire::BoardId Board() const override { return wire::BoardId::kEmulator; }
  std::uint32_t PortCapabilities() const override {
    return wire::kCapDfu | wire::kCapScenarioSelect;
  }
  wire::ResetCause LastResetCause() const override { return cause_; }
  /// The emulated option bytes: BOR level 3, as docs/board.md asks of a board, unless the rig
  /// file says otherwise.
  wire::BrownOut BrownOutLevel() const override { return brown_out_; }
  /// Measures on the simulated parts: the rig's converters sampled as they are (the noise and
  /// offset of its sensor model), its encoders; the crystal is the simulated clock, which also
  /// times the USB frames, so its error is 0 ppm. There is no firmware image to check.
  SelfTestMeasurement MeasureSelfTest(wire::SelfTestCheck check,
                                      std::uint32_t sample_period_us) override;
  void Reset() override { request_ = Request::kReset; }
  void EnterDfu() override { request_ = Request::kEnterDfu; }

  Request TakeRequest() {
    const Request r = request_;
    request_ = Request::kNone;
    return r;
  }

 private:
  wire::ResetCause cause_;
  SimulatedRig& rig_;
  wire::BrownOut brown_out_;
  Request request_ = Request::kNone;
};

/// select-scenario (0x70): the one command only the emulator knows. Refused (failed-precondition)
/// while sampling: the next acquisition starts the new scenario from rest.
class ScenarioCommands final : public fw::PortCommandHandler {
 public:
  ScenarioCommands(SimulatedRig& rig, const RigFrameSource& frames) : rig_(rig), frames_(frames) {}
  Status HandlePortCommand(std::uint8_t command, std::span<const std::uint8_t> request,
                           std::span<std::uint8_t, wire::kMaxPayload> response,
                           std::size_t& response_length) override;

 private:
  SimulatedRig& rig_;
  const RigFrameSource& frames_;
};

}  // namespace vibid::emu
