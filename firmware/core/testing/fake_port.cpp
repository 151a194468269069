#include "fake_port.hpp"

#include <algorithm>

namespace vibid::fw::testing {

Status FakeFrameSource::Start(std::uint32_t sample_period_us, FrameSink& sink) {
  if (sink_ != nullptr) return Status::kFailedPrecondition;
  if (start_status != Status::kOk) return start_status;
  period_us = sample_period_us;
  sink_ = &sink;
  next_tick_ = 0;
  ++starts;
  return Status::kOk;
}

bool FakeFrameSource::Emit(const std::array<std::int32_t, wire::kChannelCount>& raw) {
  if (sink_ == nullptr) return false;
  SampleFrame frame;
  frame.tick = next_tick_++;
  frame.raw = raw;
  sink_->OnFrame(frame);
  return true;
}

FakeFlash::FakeFlash() {
  for (auto& slot : data_) slot.fill(kErasedByte);
}

FakeFlash::StepResult FakeFlash::Step() {
  if (!powered_) return StepResult::kOff;
  if (steps_ >= steps_before_cut) {
    powered_ = false;
    return StepResult::kCutNow;
  }
  ++steps_;
  return StepResult::kDone;
}

Status FakeFlash::Erase(Slot slot) {
  auto& bytes = data_[static_cast<std::size_t>(slot)];
  const StepResult step = Step();
  if (step == StepResult::kCutNow) {
    std::fill(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(slot_bytes / 2),
              kErasedByte);
  }
  if (step != StepResult::kDone) return Status::kInternal;
  std::fill(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(slot_bytes), kErasedByte);
  return Status::kOk;
}

Status FakeFlash::Program(Slot slot, std::size_t offset, std::span<const std::uint8_t> data) {
  if (offset + data.size() > slot_bytes) return Status::kOutOfRange;
  if (fail_program) return Status::kInternal;
  auto& bytes = data_[static_cast<std::size_t>(slot)];
  for (std::size_t i = 0; i < data.size(); i += 4) {
    const StepResult step = Step();
    const std::size_t end = std::min(step == StepResult::kDone ? i + 4 : i + 2, data.size());
    if (step != StepResult::kOff) {
      for (std::size_t j = i; j < end; ++j) bytes[offset + j] &= data[j];
    }
    if (step != StepResult::kDone) return Status::kInternal;
  }
  return Status::kOk;
}

Status FakeFlash::Read(Slot slot, std::size_t offset, std::span<std::uint8_t> out) const {
  if (offset + out.size() > slot_bytes) return Status::kOutOfRange;
  const auto& bytes = data_[static_cast<std::size_t>(slot)];
  std::copy_n(bytes.begin() + static_cast<std::ptrdiff_t>(offset), out.size(), out.begin());
  return Status::kOk;
}

Status FakeLink::Receive(wire::Report& out) {
  if (in_count_ == 0) return Status::kUnavailable;
  out = in_[in_head_];
  in_head_ = (in_head_ + 1) % kCapacity;
  --in_count_;
  return Status::kOk;
}

Status FakeLink::Send(const wire::Report& report) {
  if (in_busy || out_count_ == kCapacity) return Status::kUnavailable;
  out_[(out_head_ + out_count_) % kCapacity] = report;
  ++out_count_;
  return Status::kOk;
}

bool FakeLink::Push(const wire::Report& report) {
  if (in_count_ == kCapacity) return false;
  in_[(in_head_ + in_count_) % kCapacity] = report;
  ++in_count_;
  return true;
}

bool FakeLink::Pop(wire::Report& out) {
  if (out_count_ == 0) return false;
  out = out_[out_head_];
  out_head_ = (out_head_ + 1) % kCapacity;
  --out_count_;
  return true;
}

}  // namespace vibid::fw::testing
