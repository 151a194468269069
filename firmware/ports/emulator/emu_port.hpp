// The emulator's implementation of the core's port interface: a simulated clock, the simulated
// rig as the frame source, calibration slots in the emulated flash, and the system control that
// asks the emulator loop to reset or to switch to the DFU bootloader.
#pragma once

#include <cstdint>
#include <span>

#include "flash_image.hpp"
#include "rig.hpp"
#include "vibid/fw/port.hpp"
#include "vibid/fw/port_commands.hpp"

namespace vibid::emu {

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
  explicit RigFrameSource(RigSimulator& rig) : rig_(rig) {}

  /// @returns kInvalidArgument for a period faster than the rig's max_sample_rate_hz.
  Status Start(std::uint32_t sample_period_us, fw::FrameSink& sink) override;
  void Stop() override { sink_ = nullptr; }

  bool Running() const { return sink_ != nullptr; }
  std::uint32_t PeriodUs() const { return period_us_; }
  /// Delivers one frame (Running() only).
  void Tick();

 private:
  RigSimulator& rig_;
  fw::FrameSink* sink_ = nullptr;
  std::uint32_t period_us_ = 0;
  fw::SampleFrame frame_{};
};

/// Calibration slots A and B: sectors 2 and 3 of the emulated flash, as on the board.
class FlashCalibrationSlots final : public fw::CalibrationFlash {
 public:
  explicit FlashCalibrationSlots(FlashImage& flash) : flash_(flash) {}
  static constexpr int kSlotSector[2] = {2, 3};

  std::size_t SlotBytes() const override { return 16 * 1024; }
  Status Erase(Slot slot) override;
  Status Program(Slot slot, std::size_t offset, std::span<const std::uint8_t> data) override;
  Status Read(Slot slot, std::size_t offset, std::span<std::uint8_t> out) const override;

 private:
  std::uint32_t Address(Slot slot, std::size_t offset) const;
  FlashImage& flash_;
};

/// What the firmware asked the emulator to do once the current main-loop step is over.
enum class Request : std::uint8_t { kNone, kReset, kEnterDfu };

class EmuSystemControl final : public fw::SystemControl {
 public:
  explicit EmuSystemControl(wire::ResetCause cause) : cause_(cause) {}
  wire::BoardId Board() const override { return wire::BoardId::kEmulator; }
  std::uint32_t PortCapabilities() const override { return wire::kCapDfu | wire::kCapScenarioSelect; }
  wire::ResetCause LastResetCause() const override { return cause_; }
  void Reset() override { request_ = Request::kReset; }
  void EnterDfu() override { request_ = Request::kEnterDfu; }

  Request TakeRequest() {
    const Request r = request_;
    request_ = Request::kNone;
    return r;
  }

 private:
  wire::ResetCause cause_;
  Request request_ = Request::kNone;
};

/// select-scenario (0x70): the one command only the emulator knows. Refused (failed-precondition)
/// while sampling: the next acquisition starts the new scenario from rest.
class ScenarioCommands final : public fw::PortCommandHandler {
 public:
  ScenarioCommands(RigSimulator& rig, const RigFrameSource& frames) : rig_(rig), frames_(frames) {}
  Status HandlePortCommand(std::uint8_t command, std::span<const std::uint8_t> request,
                           std::span<std::uint8_t, wire::kMaxPayload> response,
                           std::size_t& response_length) override;

 private:
  RigSimulator& rig_;
  const RigFrameSource& frames_;
};

}  // namespace vibid::emu
