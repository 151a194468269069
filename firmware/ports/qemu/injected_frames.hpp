// The QEMU image's sample source: frames the host injects over the link (inject-frames command)
// wait in a queue; a TIM2 update interrupt at the sample period hands one to the core per tick.
// QEMU models TIM2 (48 MHz kernel clock) but no ADC conversions worth sampling, so the analog
// front end is replaced by the queue while the timing path (timer interrupt -> sampler -> DOB ->
// log) is the board's.
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

  std::uint32_t StarvedTicks() const { return starved_; }
  std::uint32_t DeliveredFrames() const { return tick_; }
  /// SysTick counts (core clock, 168 MHz in QEMU) spent in the timer handler over all delivered
  /// frames, from its first instruction to its last: the per-sample interrupt cost.
  std::uint64_t HandlerCycles() const { return handler_cycles_; }

  /// The TIM2 interrupt handler body.
  void HandleTimerInterrupt();

 private:
  // Static so it lands in .bss: a polymorphic object is initialized from .data as a whole, and
  // 12 KiB of zeros would cost as much flash.
  static std::array<Raw, kQueueFrames> queue_;
  std::atomic<std::uint32_t> head_{0};  ///< Written by Inject.
  std::atomic<std::uint32_t> tail_{0};  ///< Written by the interrupt.
  FrameSink* sink_ = nullptr;
  volatile bool running_ = false;
  std::uint32_t tick_ = 0;
  std::uint32_t starved_ = 0;
  std::uint64_t handler_cycles_ = 0;
};

}  // namespace vibid::fw::qemu
