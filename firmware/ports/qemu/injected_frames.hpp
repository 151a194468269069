// The QEMU image's sample source: frames the host injects over the link (inject-frames command)
// wait in a queue; a timer interrupt at the sample period hands one to the core per tick. QEMU
// models no ADC conversions worth sampling, so the analog front end is replaced by the queue
// while the timing path (timer interrupt -> sampler -> DOB -> log) is the board's.
//
// The timer is the core's SysTick. QEMU 7.2's model of TIM2..TIM5 fires its update interrupt
// irregularly once a period has passed (its alarm is computed from a count offset that is never
// advanced), while SysTick is modelled exactly and, under -icount, deterministically.
//
// A tick that finds the queue empty delivers nothing and is counted as starved; the frame tick
// advances only with real frames, so the sequence the core sees (and its DOB output) depends on
// the injected data alone, not on how fast the host could feed QEMU.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <span>

#include "vibid/fw/port.hpp"

namespace vibid::fw::qemu {

class InjectedFrameSource final : public FrameSource {
 public:
  static constexpr std::size_t kQueueFrames = 512;  // Power of two.
  using Raw = std::array<std::int32_t, wire::kChannelCount>;

  Status Start(std::uint32_t sample_period_us, FrameSink& sink) override;
  void Stop() override;

  /// Queues frames (main loop).
  /// @returns kOk; kUnavailable when they do not all fit (none queued; the host retries).
  Status Inject(std::span<const Raw> frames);
  std::size_t Free() const;

  std::uint32_t starved_ticks() const { return starved_; }
  std::uint32_t delivered_frames() const { return tick_; }
  /// Core cycles (SysTick counts, 168 MHz in QEMU) spent in the tick handler over all delivered
  /// frames, from its first instruction to its last: the per-sample interrupt cost.
  std::uint64_t handler_cycles() const { return handler_cycles_; }

  /// `core_clock_hz` clocks SysTick; `idle_tick_hz` is its rate while no acquisition runs.
  void Init(std::uint32_t core_clock_hz, std::uint32_t idle_tick_hz);
  /// The SysTick handler body; returns true when the tick belonged to a running acquisition.
  bool HandleTick();

 private:
  // Static so it lands in .bss: a polymorphic object is initialized from .data as a whole, and
  // 12 KiB of zeros would cost as much flash.
  static std::array<Raw, kQueueFrames> queue_;
  std::atomic<std::uint32_t> head_{0};  ///< Written by Inject.
  std::atomic<std::uint32_t> tail_{0};  ///< Written by the interrupt.
  void ProgramTick(std::uint32_t cycles);

  std::uint32_t core_clock_hz_ = 0;
  std::uint32_t idle_tick_hz_ = 1000;
  FrameSink* sink_ = nullptr;
  volatile bool running_ = false;
  std::uint32_t tick_ = 0;
  std::uint32_t starved_ = 0;
  std::uint64_t handler_cycles_ = 0;
};

}  // namespace vibid::fw::qemu
