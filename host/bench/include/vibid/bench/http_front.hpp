// The bench's connections, in front of the HTTP library. cpp-httplib 0.11 gives each connection
// one thread of a fixed pool (max(8, cores - 1)) for as long as it lives: eight open live
// channels, eight idle keep-alive connections or eight clients that never finish their headers
// and nobody else is answered. Here instead:
//   - one thread (the poller) reads every connection's head and body, without blocking on any:
//     a request reaches the library only whole (ParseRequestHead's checks passed, the body of its
//     Content-Length in memory), so a slow or silent client holds no thread; a head not complete
//     within the deadline is answered 408 and closed; past kMaxPending connections waiting, the
//     oldest is closed;
//   - whole requests are served by a few worker threads that write each answer into memory and
//     hand the connection back to the poller, which sends it as the client reads (a client that
//     stops reading holds its one answer until the write timeout, never a thread; its next
//     request is not read before) and then waits for the next request (keep-alive costs no
//     thread); requests to /api/ go before the page's files;
//   - the live channel (GET /api/live) gets a thread of its own, at most `max_live` of them; past
//     that bound its handler answers 503 on a worker (OnLiveLane() tells it where it runs).
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <list>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "vibid/bench/request_head.hpp"

namespace httplib {
class Stream;
}

namespace vibid::bench {

struct FrontOptions {
  /// A connection's next request must be complete (head and body) this long after the
  /// connection opened or its previous answer was sent.
  std::chrono::milliseconds head_deadline{10000};
  /// A client that takes none of its answer for this long is closed.
  std::chrono::milliseconds write_timeout{5000};
  std::size_t workers = 4;
  std::size_t max_live = 64;
  std::size_t max_pending = 256;
};

/// Serves one whole request read from `stream` and writes its answer (the library's
/// process_request); false when the connection must close.
using ServeRequest =
    std::function<bool(httplib::Stream& stream, bool close_connection, bool& connection_closed)>;

/// The answer the front sends itself to a refused head (status, reason, a one-line message, the
/// bench's security headers, Connection: close). `request` is what arrived: the answer to a HEAD
/// request states the message's Content-Length and carries no body (RFC 9110, 9.3.2).
std::string RefusalAnswer(int status, const std::string& message, std::string_view request = {});

/// The headers every answer of the bench carries, as (name, value) pairs.
const std::vector<std::pair<std::string, std::string>>& SecurityHeaders();

class HttpFront {
 public:
  HttpFront(FrontOptions options, ServeRequest serve);
  ~HttpFront();
  HttpFront(const HttpFront&) = delete;
  HttpFront& operator=(const HttpFront&) = delete;

  /// A connection just accepted: the front owns (and closes) it from now on.
  void Adopt(int fd);
  /// Closes every connection and joins every thread.
  void Stop();

  /// True on a live-channel thread (the only place a live channel may stream from).
  static bool OnLiveLane();

  std::size_t live_channels() const;
  const FrontOptions& options() const { return options_; }

 private:
  struct Connection;
  void Poll();
  void Progress(const std::shared_ptr<Connection>& c);
  void Dispatch(const std::shared_ptr<Connection>& c, const RequestHead& head);
  void Work();
  void Serve(const std::shared_ptr<Connection>& c, const RequestHead& head);
  void Flush(const std::shared_ptr<Connection>& c);
  void Wake();
  void Close(const std::shared_ptr<Connection>& c);

  FrontOptions options_;
  ServeRequest serve_;
  int wake_fd_ = -1;
  bool stopped_ = false;

  mutable std::mutex mutex_;
  std::condition_variable work_ready_;
  std::deque<std::shared_ptr<Connection>> incoming_;  // to the poller (new or returned)
  std::deque<std::pair<std::shared_ptr<Connection>, RequestHead>> work_;
  std::deque<std::pair<std::shared_ptr<Connection>, RequestHead>> api_work_;  // before work_
  std::vector<std::shared_ptr<Connection>> active_;  // handed to a worker or a live thread
  struct LiveThread {
    std::thread thread;
    std::shared_ptr<bool> done;  // under mutex_
  };
  std::list<LiveThread> live_threads_;
  std::size_t live_ = 0;
  bool stopping_ = false;

  std::thread poller_;
  std::vector<std::thread> workers_;
  // The poller's own.
  std::vector<std::shared_ptr<Connection>> pending_;
};

}  // namespace vibid::bench
