#include "vibid/bench/live_hub.hpp"

#include <algorithm>

namespace vibid::bench {

LiveHub::LiveHub(std::size_t history_bytes, std::size_t queue_bytes)
    : history_limit_(history_bytes), queue_limit_(queue_bytes) {}

std::string LiveHub::Format(const std::string& type, const std::string& json_text) {
  return "event: " + type + "\ndata: " + json_text + "\n\n";
}

void LiveHub::Push(Subscription& s, const std::string& frame, std::size_t limit) {
  std::lock_guard lock(s.mutex);
  // A page that does not keep up loses its oldest display events, never the hub its memory.
  while (!s.queue.empty() && s.queued_bytes + frame.size() > limit) {
    s.queued_bytes -= s.queue.front().size();
    s.queue.pop_front();
  }
  s.queue.push_back(frame);
  s.queued_bytes += frame.size();
  s.ready.notify_one();
}

void LiveHub::Publish(const std::string& type, const std::string& json_text, bool history) {
  const std::string frame = Format(type, json_text);
  std::lock_guard lock(mutex_);
  if (type == "state") state_ = frame;
  if (history) {
    history_.push_back(frame);
    history_bytes_ += frame.size();
    while (history_bytes_ > history_limit_ && !history_.empty()) {
      history_bytes_ -= history_.front().size();
      history_.pop_front();
    }
  }
  for (const auto& s : subs_) Push(*s, frame, queue_limit_);
}

void LiveHub::ResetHistory() {
  std::lock_guard lock(mutex_);
  history_.clear();
  history_bytes_ = 0;
}

std::shared_ptr<LiveHub::Subscription> LiveHub::Subscribe() {
  auto s = std::make_shared<Subscription>();
  std::lock_guard lock(mutex_);
  s->closed = closed_;
  if (!state_.empty()) Push(*s, state_, queue_limit_);
  for (const std::string& f : history_) Push(*s, f, queue_limit_);
  subs_.push_back(s);
  return s;
}

void LiveHub::Unsubscribe(const std::shared_ptr<Subscription>& s) {
  std::lock_guard lock(mutex_);
  subs_.erase(std::remove(subs_.begin(), subs_.end(), s), subs_.end());
}

void LiveHub::Close() {
  std::lock_guard lock(mutex_);
  closed_ = true;
  for (const auto& s : subs_) {
    std::lock_guard sl(s->mutex);
    s->closed = true;
    s->ready.notify_all();
  }
}

std::size_t LiveHub::subscribers() const {
  std::lock_guard lock(mutex_);
  return subs_.size();
}

std::string LiveHub::Subscription::Next(std::chrono::milliseconds wait, bool& is_closed) {
  std::unique_lock lock(mutex);
  ready.wait_for(lock, wait, [&] { return !queue.empty() || closed; });
  is_closed = closed;
  std::string out;
  while (!queue.empty()) {
    out += queue.front();
    queue.pop_front();
  }
  queued_bytes = 0;
  return out;
}

}  // namespace vibid::bench
