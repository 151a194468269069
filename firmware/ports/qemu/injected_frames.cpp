#include "injected_frames.hpp"

#include <algorithm>

#include "regs/core_m4.hpp"

namespace vibid::fw::qemu {

using namespace vibid::fw::stm32;

std::array<InjectedFrameSource::Raw, InjectedFrameSource::kQueueFrames>
    InjectedFrameSource::queue_{};

void InjectedFrameSource::Init(std::uint32_t core_clock_hz, std::uint32_t idle_tick_hz) {
  core_clock_hz_ = core_clock_hz;
  idle_tick_hz_ = idle_tick_hz;
  ProgramTick(core_clock_hz_ / idle_tick_hz_);
}

void InjectedFrameSource::ProgramTick(std::uint32_t cycles) {
  Reg(systick::kCtrl) = 0;
  Reg(systick::kLoad) = cycles - 1;
  Reg(systick::kVal) = 0;
  Reg(systick::kCtrl) = systick::kCtrlEnable | systick::kCtrlTickInt | systick::kCtrlClkSourceCpu;
}

Status InjectedFrameSource::Start(std::uint32_t sample_period_us, FrameSink& sink) {
  if (running_) return Status::kFailedPrecondition;
  const std::uint64_t cycles = std::uint64_t{core_clock_hz_} / 1000000 * sample_period_us;
  // SysTick's reload register holds 24 bits.
  if (sample_period_us == 0 || cycles > (1U << 24)) return Status::kInvalidArgument;
  sink_ = &sink;
  tick_ = 0;
  starved_ = 0;
  handler_cycles_ = 0;
  running_ = true;
  ProgramTick(static_cast<std::uint32_t>(cycles));
  return Status::kOk;
}

void InjectedFrameSource::Stop() {
  running_ = false;
  ProgramTick(core_clock_hz_ / idle_tick_hz_);
}

std::size_t InjectedFrameSource::Free() const {
  return kQueueFrames -
         (head_.load(std::memory_order_relaxed) - tail_.load(std::memory_order_acquire));
}

Status InjectedFrameSource::Inject(std::span<const Raw> frames) {
  if (frames.size() > Free()) return Status::kUnavailable;
  std::uint32_t head = head_.load(std::memory_order_relaxed);
  for (const Raw& f : frames) queue_[head++ % kQueueFrames] = f;
  head_.store(head, std::memory_order_release);
  return Status::kOk;
}

bool InjectedFrameSource::HandleTick() {
  // SysTick counts down at the core clock; the difference over the handler is its cost.
  const std::uint32_t before = Reg(systick::kVal);
  if (!running_) return false;
  const std::uint32_t tail = tail_.load(std::memory_order_relaxed);
  if (tail == head_.load(std::memory_order_acquire)) {
    ++starved_;
    return true;
  }
  SampleFrame frame;
  frame.tick = tick_++;
  frame.raw = queue_[tail % kQueueFrames];
  tail_.store(tail + 1, std::memory_order_release);
  sink_->OnFrame(frame);
  const std::uint32_t after = Reg(systick::kVal);
  const std::uint32_t reload = Reg(systick::kLoad) + 1;
  handler_cycles_ += before >= after ? before - after : before + reload - after;
  return true;
}

}  // namespace vibid::fw::qemu
