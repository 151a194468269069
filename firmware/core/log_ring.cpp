#include "vibid/fw/log_ring.hpp"

#include <algorithm>

namespace vibid::fw {

std::uint32_t LogRing::CapacityFor(std::size_t record_bytes) const {
  if (record_bytes == 0) return 0;
  return static_cast<std::uint32_t>(storage_.size() / record_bytes);
}

Status LogRing::Reset(std::size_t record_bytes, std::uint32_t pretrigger_records) {
  if (record_bytes == 0) return Status::kInvalidArgument;
  const std::uint32_t capacity = CapacityFor(record_bytes);
  if (pretrigger_records >= capacity) return Status::kOutOfRange;
  record_bytes_ = record_bytes;
  capacity_ = capacity;
  pretrigger_ = pretrigger_records;
  write_slot_ = 0;
  pre_kept_ = 0;
  start_slot_ = 0;
  trigger_index_ = 0;
  written_.store(0, std::memory_order_relaxed);
  released_.store(0, std::memory_order_relaxed);
  triggered_.store(false, std::memory_order_release);
  return Status::kOk;
}

bool LogRing::Push(std::span<const std::uint8_t> record) {
  if (capacity_ == 0) return false;
  const bool after_trigger = triggered_.load(std::memory_order_relaxed);
  std::uint32_t written = 0;
  if (after_trigger) {
    written = written_.load(std::memory_order_relaxed);
    if (written - released_.load(std::memory_order_acquire) >= capacity_) return false;
  }
  // Keeps the store that published index `written` (end of the previous Push) ahead of the
  // bytes below: a reader that sees any of them then sees `written` in Intact and knows the
  // slot's old record is gone.
  std::atomic_thread_fence(std::memory_order_release);
  std::copy_n(record.begin(), std::min(record.size(), record_bytes_),
              storage_.begin() + static_cast<std::ptrdiff_t>(write_slot_ * record_bytes_));
  write_slot_ = write_slot_ + 1 == capacity_ ? 0 : write_slot_ + 1;
  if (after_trigger) {
    written_.store(written + 1, std::memory_order_release);
  } else if (pre_kept_ < pretrigger_) {
    ++pre_kept_;
  }
  return true;
}

void LogRing::MarkTrigger() {
  if (capacity_ == 0 || triggered_.load(std::memory_order_relaxed)) return;
  start_slot_ = (write_slot_ + capacity_ - pre_kept_) % capacity_;
  trigger_index_ = pre_kept_;
  written_.store(pre_kept_, std::memory_order_relaxed);
  triggered_.store(true, std::memory_order_release);
}

std::uint32_t LogRing::written() const {
  if (!triggered_.load(std::memory_order_acquire)) return 0;
  return written_.load(std::memory_order_acquire);
}

std::uint32_t LogRing::oldest() const {
  const std::uint32_t w = written();
  if (capacity_ == 0 || w < capacity_) return 0;
  // Below w - capacity + 1 a slot has been (or is being) reused once the producer was let in.
  return std::min(released(), w - capacity_ + 1);
}

Status LogRing::Release(std::uint32_t first_kept) {
  if (first_kept > written()) return Status::kOutOfRange;
  if (first_kept > released()) released_.store(first_kept, std::memory_order_release);
  return Status::kOk;
}

bool LogRing::Intact(std::uint32_t index) const {
  // Orders the caller's copy of the record before the load of written_ below.
  std::atomic_thread_fence(std::memory_order_acquire);
  const std::uint32_t w = written();
  if (index >= w) return false;
  return index >= released() || w - index < capacity_;
}

Status LogRing::Read(std::uint32_t index, std::span<const std::uint8_t>& record) const {
  if (!Intact(index)) return Status::kOutOfRange;
  const std::uint32_t slot = (start_slot_ + index % capacity_) % capacity_;
  record = std::span<const std::uint8_t>(storage_).subspan(slot * record_bytes_, record_bytes_);
  return Status::kOk;
}

}  // namespace vibid::fw
