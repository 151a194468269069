#include "core_loopback.hpp"

#include <chrono>
#include <cmath>
#include <condition_variable>
#include <numbers>

#include "vibid/device/error.hpp"

namespace vibid::hil {

class CoreLoopback::Link final : public device::Transport {
 public:
  explicit Link(CoreLoopback& owner) : owner_(owner) {}
  ~Link() override {
    std::lock_guard lock(owner_.mutex_);
    std::erase(owner_.links_, this);
  }

  void Send(const wire::Report& report) override {
    if (owner_.dead_) throw device::DeviceError("device gone");
    std::lock_guard lock(owner_.mutex_);
    owner_.to_device_.push_back(report);
  }

  std::size_t Receive(std::span<std::uint8_t, wire::kReportBytes> out,
                      std::chrono::milliseconds timeout) override {
    std::unique_lock lock(mutex_);
    arrived_.wait_for(lock, timeout, [&] { return !queue_.empty() || owner_.dead_; });
    if (owner_.dead_) throw device::DeviceError("device gone");
    if (queue_.empty()) return 0;
    const auto [report, length] = queue_.front();
    queue_.pop_front();
    std::copy(report.begin(), report.end(), out.begin());
    return length;
  }

  std::string Describe() const override { return "in-process firmware core"; }

  void Push(const wire::Report& r, std::size_t length) {
    std::lock_guard lock(mutex_);
    queue_.emplace_back(r, length);
    arrived_.notify_all();
  }
  void Wake() { arrived_.notify_all(); }

 private:
  CoreLoopback& owner_;
  std::mutex mutex_;
  std::condition_variable arrived_;
  std::deque<std::pair<wire::Report, std::size_t>> queue_;
};

CoreLoopback::CoreLoopback() : log_(std::make_unique<std::array<std::uint8_t, kLogBytes>>()) {
  core_.emplace(port_.port(), link_, *log_);
  static_cast<void>(core_->Boot());
  thread_ = std::thread([this] { Loop(); });
}

CoreLoopback::~CoreLoopback() {
  stop_ = true;
  thread_.join();
}

std::unique_ptr<device::Transport> CoreLoopback::Connect() {
  auto link = std::make_unique<Link>(*this);
  std::lock_guard lock(mutex_);
  links_.push_back(link.get());
  return link;
}

void CoreLoopback::Restart() {
  std::lock_guard lock(mutex_);
  port_.frames.Stop();
  core_.reset();
  link_.ClearOut();
  wire::Report drain{};
  while (link_.Receive(drain) == Status::kOk) {
  }
  to_device_.clear();
  port_.system.reset_cause = wire::ResetCause::kSoftware;
  core_.emplace(port_.port(), link_, *log_);
  static_cast<void>(core_->Boot());
}

void CoreLoopback::Kill() {
  dead_ = true;
  std::lock_guard lock(mutex_);
  for (Link* l : links_) l->Wake();
}

std::array<std::int32_t, wire::kChannelCount> CoreLoopback::FrameAt(std::uint32_t tick) {
  std::array<std::int32_t, wire::kChannelCount> raw{};
  // A 20-tick half-sine pulse of 1500 counts above the load cell's 2048 zero, starting at tick
  // 200 and every 500 ticks after (so a trigger has pre-trigger history).
  const std::uint32_t phase = (tick + 300) % 500;
  raw[0] = 2048 + (phase < 20 ? static_cast<std::int32_t>(
                                    std::lround(1500.0 * std::sin(std::numbers::pi * phase / 20.0)))
                              : 0);
  raw[1] = 2048 + static_cast<std::int32_t>((tick / 8) % 256);
  raw[2] = 2048 + static_cast<std::int32_t>(tick % 64);
  raw[3] = 2048 - static_cast<std::int32_t>(tick % 32);
  raw[4] = static_cast<std::int32_t>(tick);
  raw[5] = -static_cast<std::int32_t>(tick / 2);
  return raw;
}

void CoreLoopback::Deliver(const wire::Report& r) {
  wire::Report out = r;
  std::size_t length = wire::kReportBytes;
  if (drop_ > 0) {
    --drop_;
    return;
  }
  const int seq = drop_sequence_.load();
  wire::StreamDataHeader data;
  if (seq >= 0 && wire::DecodeStreamData(r, data) == Status::kOk) {
    // The drops belong to one stream: a stream of another token (the host gave up and asked
    // again) ends them.
    if (drop_token_ >= 0 && data.token != drop_token_) {
      drop_sequence_ = -1;
    } else if (data.sequence >= seq && data.sequence < seq + drop_count_) {
      drop_token_ = data.token;
      if (data.sequence + 1 == seq + drop_count_) drop_sequence_ = -1;
      return;
    }
  }
  if (corrupt_ > 0) {
    --corrupt_;
    out[wire::kOffMagic] ^= 0xFF;
  } else if (truncate_ > 0) {
    --truncate_;
    length = 40;
  }
  if (!wire::IsStreamData(out)) out[wire::kOffProtocolMajor] = major_;  // stream data has no major
  for (Link* l : links_) l->Push(out, length);
}

void CoreLoopback::Loop() {
  while (!stop_) {
    {
      std::lock_guard lock(mutex_);
      if (!dead_) {
        while (!to_device_.empty() && link_.Push(to_device_.front())) to_device_.pop_front();
        core_->Poll();
        wire::Report r{};
        while (link_.Pop(r)) Deliver(r);
        const int frames = frames_per_step_;
        for (int i = 0; i < frames && port_.frames.running(); ++i) {
          port_.frames.Emit(FrameAt(tick_++));
        }
        if (!port_.frames.running()) tick_ = 0;
      }
    }
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
}

}  // namespace vibid::hil
