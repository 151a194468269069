// A port for unit tests: a settable clock, frames pushed by the test, NOR flash with power-cut
// injection, a recording system control, and a report link with queues on both sides.
// Fixed-size storage only, so the tests also run on the Cortex-M4 image.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "vibid/fw/port.hpp"
#include "vibid/fw/report_link.hpp"
#include "vibid/shared/wire/report.hpp"

namespace vibid::fw::testing {

class FakeClock final : public Clock {
 public:
  std::uint64_t NowUs() const override { return now_us; }
  std::uint64_t now_us = 0;
};

class FakeFrameSource final : public FrameSource {
 public:
  Status Start(std::uint32_t sample_period_us, FrameSink& sink) override;
  void Stop() override { sink_ = nullptr; }

  bool running() const { return sink_ != nullptr; }
  /// Delivers one frame with the next tick; false if not running.
  bool Emit(const std::array<std::int32_t, wire::kChannelCount>& raw);
  /// Loses `n` ticks before the next frame (an overrun the core must count).
  void Skip(std::uint32_t n) { next_tick_ += n; }

  std::uint32_t period_us = 0;
  std::uint32_t starts = 0;
  Status start_status = Status::kOk;  ///< What Start answers (a port refusing a period).

 private:
  FrameSink* sink_ = nullptr;
  std::uint32_t next_tick_ = 0;
};

/// NOR flash, two slots. Power cut: after `steps_before_cut` steps (one erase, or one 32-bit
/// word programmed) every operation fails and nothing more changes. The step that is cut is left
/// half done: an erase erases the first half of the slot, a word program writes its first two
/// bytes.
class FakeFlash final : public CalibrationFlash {
 public:
  static constexpr std::size_t kSlotBytes = 2048;  // holds a slot header and a record (1052 B)
  static constexpr std::uint32_t kNoCut = 0xFFFFFFFFu;

  FakeFlash();

  std::size_t SlotBytes() const override { return slot_bytes; }
  Status Erase(Slot slot) override;
  Status Program(Slot slot, std::size_t offset, std::span<const std::uint8_t> data) override;
  Status Read(Slot slot, std::size_t offset, std::span<std::uint8_t> out) const override;

  /// Restores power and counts steps from zero again.
  void PowerOn() {
    steps_ = 0;
    powered_ = true;
  }

  std::span<std::uint8_t> bytes(Slot slot) { return data_[static_cast<std::size_t>(slot)]; }

  std::size_t slot_bytes = kSlotBytes;
  std::uint32_t steps_before_cut = kNoCut;
  bool fail_program = false;  ///< The controller reports an error on every program.

  std::uint32_t steps() const { return steps_; }
  bool powered() const { return powered_; }

 private:
  enum class StepResult { kDone, kCutNow, kOff };
  StepResult Step();

  std::array<std::array<std::uint8_t, kSlotBytes>, 2> data_{};
  std::uint32_t steps_ = 0;
  bool powered_ = true;
};

class FakeSystem final : public SystemControl {
 public:
  wire::BoardId Board() const override { return wire::BoardId::kHostTest; }
  std::uint32_t PortCapabilities() const override { return capabilities; }
  wire::ResetCause LastResetCause() const override { return reset_cause; }
  wire::BrownOut BrownOutLevel() const override { return brown_out; }
  wire::FaultInfoResponse LastFault() const override { return fault; }
  /// Answers self_test[check] and records the period it was asked at.
  SelfTestMeasurement MeasureSelfTest(wire::SelfTestCheck check,
                                      std::uint32_t sample_period_us) override {
    self_test_period_us = sample_period_us;
    return self_test[static_cast<std::size_t>(check)];
  }
  ClockReport ClockHealth() const override { return clock; }
  std::uint32_t SamplerRecoveries() const override { return sampler_recoveries; }
  void Reset() override { ++resets; }
  void EnterDfu() override { ++dfu_entries; }

  ClockReport clock{};
  std::uint32_t sampler_recoveries = 0;
  std::uint32_t capabilities = wire::kCapDfu;
  wire::ResetCause reset_cause = wire::ResetCause::kPowerOn;
  wire::BrownOut brown_out = wire::BrownOut::kUnknown;
  wire::FaultInfoResponse fault{};
  std::array<SelfTestMeasurement, wire::kSelfTestCheckCount> self_test{};
  std::uint32_t self_test_period_us = 0;
  int resets = 0;
  int dfu_entries = 0;
};

/// Host-to-device queue and device-to-host capture. `in_busy` makes Send refuse, like an IN
/// endpoint the host has not polled yet.
class FakeLink final : public ReportLink {
 public:
  static constexpr std::size_t kCapacity = 64;

  Status Receive(wire::Report& out) override;
  Status Send(const wire::Report& report) override;

  /// Queues a request; false if the queue is full.
  bool Push(const wire::Report& report);
  /// Takes the oldest captured device report; false if none.
  bool Pop(wire::Report& out);
  std::size_t pending_out() const { return out_count_; }
  void ClearOut() { out_head_ = out_count_ = 0; }

  bool in_busy = false;

 private:
  std::array<wire::Report, kCapacity> in_{};
  std::size_t in_head_ = 0;
  std::size_t in_count_ = 0;
  std::array<wire::Report, kCapacity> out_{};
  std::size_t out_head_ = 0;
  std::size_t out_count_ = 0;
};

/// All of it, as one port.
struct FakePort {
  FakeClock clock;
  FakeFrameSource frames;
  FakeFlash flash;
  FakeSystem system;
  Port port() { return Port{clock, frames, flash, system}; }
};

}  // namespace vibid::fw::testing
