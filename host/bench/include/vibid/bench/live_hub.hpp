// The live channel's fan-out: every event the bench publishes (the scope's blocks, the state of
// the acquisition, the observer's running fit) goes to every open page as a Server-Sent Event.
// The hub keeps the recent events so a page that opens (or reloads) mid-acquisition draws the
// running state again: the last `state` event and the blocks of the last `history_s` seconds.
// A page that cannot keep up loses display events beyond its queue; the data on disk do not
// depend on any page.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace vibid::bench {

class LiveHub {
 public:
  /// One page's queue of formatted events.
  class Subscription {
   public:
    /// The next formatted events, waiting up to `wait`; empty on timeout. `closed` is set when the
    /// hub shuts down.
    std::string Next(std::chrono::milliseconds wait, bool& closed);

   private:
    friend class LiveHub;
    std::mutex mutex;
    std::condition_variable ready;
    std::deque<std::string> queue;
    std::size_t queued_bytes = 0;
    bool closed = false;
  };

  explicit LiveHub(std::size_t history_bytes = 8u << 20, std::size_t queue_bytes = 16u << 20);

  /// A `type` event whose data is `json_text` (one line). Blocks go into the history; a `state`
  /// event replaces the kept state; `reset` empties the history (a new acquisition).
  void Publish(const std::string& type, const std::string& json_text, bool history = false);
  void ResetHistory();

  /// A new page: its queue starts with the kept state and history.
  std::shared_ptr<Subscription> Subscribe();
  void Unsubscribe(const std::shared_ptr<Subscription>& s);
  /// Ends every subscription (server shutdown).
  void Close();

  std::size_t subscribers() const;

 private:
  static std::string Format(const std::string& type, const std::string& json_text);
  static void Push(Subscription& s, const std::string& frame, std::size_t limit);

  mutable std::mutex mutex_;
  std::vector<std::shared_ptr<Subscription>> subs_;
  std::deque<std::string> history_;
  std::size_t history_bytes_ = 0;
  std::size_t history_limit_;
  std::size_t queue_limit_;
  std::string state_;  // the last state frame
  bool closed_ = false;
};

}  // namespace vibid::bench
