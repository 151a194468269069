#include "injected_frames.hpp"

#include <algorithm>

#include "regs/core_m4.hpp"
#include "regs/peripherals.hpp"
#include "regs/rcc.hpp"

namespace vibid::fw::qemu {

using namespace vibid::fw::stm32;

namespace {
// QEMU's netduinoplus2 clocks TIM2..TIM5 at 48 MHz; prescaling by 48 gives 1 us per count, so
// every whole-microsecond period is exact.
constexpr std::uint32_t kTimerClockHz = 48000000;
constexpr std::uint32_t kPrescaler = kTimerClockHz / 1000000;
}  // namespace

std::array<InjectedFrameSource::Raw, InjectedFrameSource::kQueueFrames> InjectedFrameSource::queue_{};

Status InjectedFrameSource::Start(std::uint32_t sample_period_us, FrameSink& sink) {
  if (running_) return Status::kFailedPrecondition;
  if (sample_period_us == 0) return Status::kInvalidArgument;
  sink_ = &sink;
  tick_ = 0;
  starved_ = 0;
  handler_cycles_ = 0;
  running_ = true;
  Reg(rcc::kApb1enr) |= rcc::kApb1Tim2;
  Reg(tim::kTim2 + tim::kCr1) = 0;
  Reg(tim::kTim2 + tim::kPsc) = kPrescaler - 1;
  Reg(tim::kTim2 + tim::kArr) = sample_period_us - 1;
  Reg(tim::kTim2 + tim::kCnt) = 0;
  Reg(tim::kTim2 + tim::kSr) = 0;
  Reg(tim::kTim2 + tim::kDier) = tim::kDierUie;
  nvic::SetPriority(irq::kTim2, 2);
  nvic::ClearPending(irq::kTim2);
  nvic::Enable(irq::kTim2);
  Reg(tim::kTim2 + tim::kCr1) = tim::kCr1Cen;
  return Status::kOk;
}

void InjectedFrameSource::Stop() {
  Reg(tim::kTim2 + tim::kCr1) = 0;
  nvic::Disable(irq::kTim2);
  running_ = false;
}

std::size_t InjectedFrameSource::Free() const {
  return kQueueFrames - (head_.load(std::memory_order_relaxed) - tail_.load(std::memory_order_acquire));
}

Status InjectedFrameSource::Inject(std::span<const Raw> frames) {
  if (frames.size() > Free()) return Status::kUnavailable;
  std::uint32_t head = head_.load(std::memory_order_relaxed);
  for (const Raw& f : frames) queue_[head++ % kQueueFrames] = f;
  head_.store(head, std::memory_order_release);
  return Status::kOk;
}

void InjectedFrameSource::HandleTimerInterrupt() {
  // SysTick counts down at the core clock; the difference over the handler is its cost.
  const std::uint32_t before = Reg(systick::kVal);
  Reg(tim::kTim2 + tim::kSr) = 0;
  if (!running_) return;
  const std::uint32_t tail = tail_.load(std::memory_order_relaxed);
  if (tail == head_.load(std::memory_order_acquire)) {
    ++starved_;
    return;
  }
  SampleFrame frame;
  frame.tick = tick_++;
  frame.raw = queue_[tail % kQueueFrames];
  tail_.store(tail + 1, std::memory_order_release);
  sink_->OnFrame(frame);
  const std::uint32_t after = Reg(systick::kVal);
  const std::uint32_t reload = Reg(systick::kLoad) + 1;
  handler_cycles_ += before >= after ? before - after : before + reload - after;
}

}  // namespace vibid::fw::qemu
