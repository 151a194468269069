#include "vibid/bench/http_front.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include <httplib.h>

namespace vibid::bench {
namespace {

using Clock = std::chrono::steady_clock;

thread_local bool t_on_live_lane = false;

/// After a refusal: how long, and how many bytes, of what the client still sends are discarded.
constexpr std::chrono::milliseconds kLinger{1000};
constexpr std::size_t kMaxLingerBytes = 256 * 1024;

bool IsLiveRequest(const RequestHead& h) { return h.method == "GET" && h.path == "/api/live"; }

/// Writes all of `data` to the non-blocking socket, waiting for it to drain until `deadline`.
bool SendAll(int fd, const char* data, std::size_t size, Clock::time_point deadline) {
  while (size > 0) {
    const ssize_t n = ::send(fd, data, size, MSG_NOSIGNAL);
    if (n > 0) {
      data += n;
      size -= static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK) return false;
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
    if (left.count() <= 0) return false;
    pollfd p{fd, POLLOUT, 0};
    if (::poll(&p, 1, static_cast<int>(left.count())) <= 0) return false;
  }
  return true;
}

void AddressOf(const sockaddr_storage& a, std::string& ip, int& port) {
  char b[INET6_ADDRSTRLEN] = {};
  if (a.ss_family == AF_INET) {
    const auto& v4 = reinterpret_cast<const sockaddr_in&>(a);
    ::inet_ntop(AF_INET, &v4.sin_addr, b, sizeof b);
    port = ntohs(v4.sin_port);
  } else if (a.ss_family == AF_INET6) {
    const auto& v6 = reinterpret_cast<const sockaddr_in6&>(a);
    ::inet_ntop(AF_INET6, &v6.sin6_addr, b, sizeof b);
    port = ntohs(v6.sin6_port);
  }
  ip = b;
}

}  // namespace

struct HttpFront::Connection {
  int fd = -1;
  std::string in;  // bytes read and not yet served
  Clock::time_point deadline;
  // An answer a worker wrote into memory, sent by the poller as the client reads it: a client
  // that never reads holds this buffer (one answer at most) until the write timeout, never a
  // thread. Its next request is not read before the answer has gone.
  std::string out;
  std::size_t sent = 0;
  bool close_after_send = false;
  // Refused and answered: what the client still sends is discarded (never kept) for a moment, so
  // that closing does not reset the connection before the client has read the answer.
  bool lingering = false;
  std::size_t discarded = 0;
};

namespace {

/// One whole request (already in memory) for the library, and the socket for its answer.
class FrontStream : public httplib::Stream {
 public:
  /// `out` null: the answer is written to the socket as it comes (the live lane, whose thread is
  /// its own); else it is collected there for the poller to send.
  FrontStream(int fd, std::string& in, std::size_t request_bytes,
              std::chrono::milliseconds write_timeout, std::string* out)
      : fd_(fd), in_(in), end_(request_bytes), write_timeout_(write_timeout), out_(out) {}

  std::size_t consumed() const { return pos_; }

  bool is_readable() const override { return pos_ < end_; }
  bool is_writable() const override {
    if (out_ != nullptr) return true;
    pollfd p{fd_, POLLOUT, 0};
    return ::poll(&p, 1, static_cast<int>(write_timeout_.count())) > 0 &&
           (p.revents & (POLLERR | POLLHUP)) == 0;
  }
  // The library reads the request it was handed and nothing beyond it: a pipelined request that
  // arrived in the same read stays for the poller.
  ssize_t read(char* ptr, size_t size) override {
    const std::size_t n = std::min(size, end_ - pos_);
    std::memcpy(ptr, in_.data() + pos_, n);
    pos_ += n;
    return static_cast<ssize_t>(n);
  }
  ssize_t write(const char* ptr, size_t size) override {
    if (out_ != nullptr) {
      out_->append(ptr, size);
      return static_cast<ssize_t>(size);
    }
    return SendAll(fd_, ptr, size, Clock::now() + write_timeout_) ? static_cast<ssize_t>(size) : -1;
  }
  void get_remote_ip_and_port(std::string& ip, int& port) const override {
    sockaddr_storage a{};
    socklen_t len = sizeof a;
    if (::getpeername(fd_, reinterpret_cast<sockaddr*>(&a), &len) == 0) AddressOf(a, ip, port);
  }
  void get_local_ip_and_port(std::string& ip, int& port) const override {
    sockaddr_storage a{};
    socklen_t len = sizeof a;
    if (::getsockname(fd_, reinterpret_cast<sockaddr*>(&a), &len) == 0) AddressOf(a, ip, port);
  }
  socket_t socket() const override { return fd_; }

 private:
  int fd_;
  std::string& in_;
  std::size_t end_;
  std::size_t pos_ = 0;
  std::chrono::milliseconds write_timeout_;
  std::string* out_;
};

}  // namespace

const std::vector<std::pair<std::string, std::string>>& SecurityHeaders() {
  // No caching of anything the bench answers, no framing by other sites, scripts and styles
  // from the bench itself only, no <base> and no form posts anywhere. No Access-Control-* header
  // is ever sent.
  static const std::vector<std::pair<std::string, std::string>> h = {
      {"Cache-Control", "no-store"},
      {"X-Content-Type-Options", "nosniff"},
      {"X-Frame-Options", "DENY"},
      {"Referrer-Policy", "no-referrer"},
      {"Content-Security-Policy",
       "default-src 'self'; style-src 'self' 'unsafe-inline'; img-src 'self' data:; "
       "frame-ancestors 'none'; base-uri 'none'; form-action 'none'"}};
  return h;
}

std::string RefusalAnswer(int status, const std::string& message, std::string_view request) {
  const std::string body = message + "\n";
  std::string a = "HTTP/1.1 " + std::to_string(status) + " " + ReasonPhrase(status) + "\r\n";
  for (const auto& [name, value] : SecurityHeaders()) a += name + ": " + value + "\r\n";
  a += "Content-Type: text/plain\r\nContent-Length: " + std::to_string(body.size()) +
       "\r\nConnection: close\r\n\r\n";
  // The request line starts with its method: a HEAD's answer is the head alone.
  if (request.substr(0, 5) != "HEAD ") a += body;
  return a;
}

HttpFront::HttpFront(FrontOptions options, ServeRequest serve)
    : options_(options), serve_(std::move(serve)) {
  wake_fd_ = ::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  if (wake_fd_ < 0) throw std::runtime_error("eventfd: " + std::string(std::strerror(errno)));
  poller_ = std::thread([this] { Poll(); });
  for (std::size_t i = 0; i < options_.workers; ++i) workers_.emplace_back([this] { Work(); });
}

HttpFront::~HttpFront() {
  Stop();
  ::close(wake_fd_);
}

bool HttpFront::OnLiveLane() { return t_on_live_lane; }

std::size_t HttpFront::live_channels() const {
  std::lock_guard l(mutex_);
  return live_;
}

void HttpFront::Wake() {
  const std::uint64_t one = 1;
  (void)!::write(wake_fd_, &one, sizeof one);
}

void HttpFront::Adopt(int fd) {
  const int flags = ::fcntl(fd, F_GETFL);
  ::fcntl(fd, F_SETFL, flags | O_NONBLOCK);
  auto c = std::make_shared<Connection>();
  c->fd = fd;
  c->deadline = Clock::now() + options_.head_deadline;
  {
    std::lock_guard l(mutex_);
    if (stopping_) {
      ::close(fd);
      return;
    }
    incoming_.push_back(std::move(c));
  }
  Wake();
}

void HttpFront::Close(const std::shared_ptr<Connection>& c) {
  if (c->fd >= 0) ::close(c->fd);
  c->fd = -1;
}

void HttpFront::Poll() {
  std::vector<pollfd> fds;
  for (;;) {
    std::deque<std::shared_ptr<Connection>> arrived;
    {
      std::lock_guard l(mutex_);
      if (stopping_) break;
      arrived.swap(incoming_);
    }
    for (std::shared_ptr<Connection>& c : arrived) {
      // Past the bound the oldest waiting connection goes: a flood of idle connections costs the
      // flood's own oldest ones, and a new request is still read.
      if (pending_.size() >= options_.max_pending) {
        Close(pending_.front());
        pending_.erase(pending_.begin());
      }
      pending_.push_back(c);
      // A returned connection sends its answer first (most fit the socket's buffer at once),
      // then may hold its next request.
      if (!c->out.empty()) Flush(c);
      if (c->fd >= 0 && !c->in.empty()) Progress(c);
    }
    std::erase_if(pending_, [](const auto& c) { return c->fd < 0; });
    fds.assign(1, pollfd{wake_fd_, POLLIN, 0});
    Clock::time_point next = Clock::now() + std::chrono::seconds(1);
    for (const auto& c : pending_) {
      fds.push_back(pollfd{c->fd, static_cast<short>(c->out.empty() ? POLLIN : POLLOUT), 0});
      next = std::min(next, c->deadline);
    }
    const auto wait = std::chrono::duration_cast<std::chrono::milliseconds>(next - Clock::now());
    ::poll(fds.data(), fds.size(), static_cast<int>(std::max<long>(0, wait.count() + 1)));
    if (fds[0].revents & POLLIN) {
      std::uint64_t v;
      (void)!::read(wake_fd_, &v, sizeof v);
    }
    const Clock::time_point now = Clock::now();
    for (std::size_t i = 0; i < pending_.size(); ++i) {
      const std::shared_ptr<Connection>& c = pending_[i];
      if (!c->out.empty()) {
        if (fds[i + 1].revents & (POLLOUT | POLLHUP | POLLERR)) Flush(c);
        if (c->fd >= 0 && !c->out.empty() && now >= c->deadline) Close(c);  // never read
        if (c->fd >= 0 && c->out.empty() && !c->in.empty()) Progress(c);
        continue;
      }
      if (c->lingering && (fds[i + 1].revents & (POLLIN | POLLHUP | POLLERR))) {
        char sink[16384];
        const ssize_t n = ::recv(c->fd, sink, sizeof sink, 0);
        if (n > 0) c->discarded += static_cast<std::size_t>(n);
        if (n == 0 || (n < 0 && errno != EAGAIN && errno != EINTR) ||
            c->discarded > kMaxLingerBytes)
          Close(c);
      } else if (fds[i + 1].revents & (POLLIN | POLLHUP | POLLERR)) {
        // The head and the body, never more than both may hold.
        const std::size_t room = kMaxHeadBytes + kMaxBodyBytes - c->in.size();
        char buf[16384];
        const ssize_t n = ::recv(c->fd, buf, std::min(room, sizeof buf), 0);
        if (n == 0 || (n < 0 && errno != EAGAIN && errno != EINTR)) {
          Close(c);
          continue;
        }
        if (n > 0) c->in.append(buf, static_cast<std::size_t>(n));
        Progress(c);
      }
      if (c->fd >= 0 && now >= c->deadline) {
        if (!c->in.empty() && !c->lingering) {
          const std::string a =
              RefusalAnswer(408,
                            "the request did not arrive whole within " +
                                std::to_string(options_.head_deadline.count()) + " ms",
                            c->in);
          (void)!::send(c->fd, a.data(), a.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
          // A lingering close, as for a refused head: bytes the client still sends are read and
          // dropped, so its kernel never answers them with a reset that throws the 408 away.
          ::shutdown(c->fd, SHUT_WR);
          c->in.clear();
          c->lingering = true;
          c->deadline = now + kLinger;
          continue;
        }
        Close(c);
      }
    }
    std::erase_if(pending_, [](const auto& c) { return c->fd < 0; });
  }
  for (const auto& c : pending_) Close(c);
  pending_.clear();
}

// Sends what the client's socket takes now of the answer a worker wrote; once all of it has
// gone, the connection waits for its next request (or closes, as its answer said).
void HttpFront::Flush(const std::shared_ptr<Connection>& c) {
  while (c->sent < c->out.size()) {
    const ssize_t n = ::send(c->fd, c->out.data() + c->sent, c->out.size() - c->sent,
                             MSG_NOSIGNAL | MSG_DONTWAIT);
    if (n > 0) {
      c->sent += static_cast<std::size_t>(n);
      // The timeout counts from the last byte the client took, so a slow reader of a large
      // answer is served while one that stopped reading is dropped.
      c->deadline = Clock::now() + options_.write_timeout;
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) return;
    Close(c);
    return;
  }
  c->out.clear();
  c->out.shrink_to_fit();
  c->sent = 0;
  if (c->close_after_send) {
    // A lingering close: what the client still sends is dropped, so its kernel does not answer
    // it with a reset that throws the answer away.
    ::shutdown(c->fd, SHUT_WR);
    c->in.clear();
    c->lingering = true;
    c->deadline = Clock::now() + kLinger;
    return;
  }
  c->deadline = Clock::now() + options_.head_deadline;
}

// Reads what arrived: a refused head is answered and closed, a whole request is handed on.
void HttpFront::Progress(const std::shared_ptr<Connection>& c) {
  if (c->lingering || !c->out.empty()) return;
  const RequestHead head = ParseRequestHead(c->in);
  if (head.status == 0) return;
  if (head.status != 200) {
    const std::string a = RefusalAnswer(head.status, head.message, c->in);
    // Small enough for any socket buffer: sent at once, the rest of the request never read.
    (void)!::send(c->fd, a.data(), a.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
    ::shutdown(c->fd, SHUT_WR);
    c->in.clear();
    c->lingering = true;
    c->deadline = std::min(c->deadline, Clock::now() + kLinger);
    return;
  }
  if (c->in.size() < head.head_bytes + head.body_bytes) return;  // the body is on its way
  Dispatch(c, head);
}

void HttpFront::Dispatch(const std::shared_ptr<Connection>& c, const RequestHead& head) {
  // From here a worker or a live thread owns the connection; the poller forgets it (fd -1).
  auto owned = std::make_shared<Connection>();
  owned->fd = c->fd;
  owned->in = std::move(c->in);
  c->fd = -1;
  c->in.clear();
  std::lock_guard lock(mutex_);
  active_.push_back(owned);
  if (IsLiveRequest(head) && live_ < options_.max_live) {
    ++live_;
    // Threads of channels that ended are joined here (they only return after marking).
    for (auto it = live_threads_.begin(); it != live_threads_.end();) {
      if (*it->done) {
        it->thread.join();
        it = live_threads_.erase(it);
      } else {
        ++it;
      }
    }
    auto done = std::make_shared<bool>(false);
    live_threads_.push_back({std::thread([this, owned, head, done] {
                               t_on_live_lane = true;
                               Serve(owned, head);
                               std::lock_guard ended(mutex_);
                               --live_;
                               *done = true;
                             }),
                             done});
    return;
  }
  // The API before the page's files: a browser loading assets, or a process flooding them,
  // never queues the state or a Stop behind them.
  (head.path.rfind("/api/", 0) == 0 ? api_work_ : work_).emplace_back(owned, head);
  work_ready_.notify_one();
}

void HttpFront::Work() {
  for (;;) {
    std::pair<std::shared_ptr<Connection>, RequestHead> job;
    {
      std::unique_lock l(mutex_);
      work_ready_.wait(l, [&] { return stopping_ || !work_.empty() || !api_work_.empty(); });
      auto& queue = api_work_.empty() ? work_ : api_work_;
      if (queue.empty()) return;
      job = std::move(queue.front());
      queue.pop_front();
    }
    Serve(job.first, job.second);
  }
}

void HttpFront::Serve(const std::shared_ptr<Connection>& c, const RequestHead& head) {
  bool closed = head.close;
  bool ok = false;
  {
    // A worker writes the answer into memory and never waits on the client; a live thread
    // streams to its own socket.
    FrontStream stream(c->fd, c->in, head.head_bytes + head.body_bytes, options_.write_timeout,
                       OnLiveLane() ? nullptr : &c->out);
    bool stopping;
    {
      std::lock_guard l(mutex_);
      stopping = stopping_;
    }
    bool client_closed = false;
    ok = serve_(stream, closed || stopping || OnLiveLane(), client_closed);
    closed = closed || client_closed || stopping;
  }
  c->in.erase(0, head.head_bytes + head.body_bytes);
  std::lock_guard l(mutex_);
  active_.erase(std::remove(active_.begin(), active_.end(), c), active_.end());
  if (stopping_ || OnLiveLane() || c->out.empty()) {
    Close(c);
    return;
  }
  // The poller sends the answer; then, on keep-alive, waits for the next request (no thread
  // does either).
  c->close_after_send = !ok || closed;
  c->deadline = Clock::now() + options_.write_timeout;
  incoming_.push_back(c);
  Wake();
}

void HttpFront::Stop() {
  {
    std::lock_guard l(mutex_);
    if (stopped_) return;
    stopped_ = true;
    stopping_ = true;
    // Unblocks a worker or a live thread in a read or a write: the connection is over.
    for (const auto& c : active_) ::shutdown(c->fd, SHUT_RDWR);
    work_ready_.notify_all();
  }
  Wake();
  if (poller_.joinable()) poller_.join();
  for (std::thread& t : workers_) t.join();
  std::list<LiveThread> live;
  {
    std::lock_guard l(mutex_);
    live.swap(live_threads_);
  }
  for (LiveThread& t : live) t.thread.join();
  std::lock_guard l(mutex_);
  for (const auto& c : incoming_) Close(c);
  incoming_.clear();
  for (auto* queue : {&work_, &api_work_}) {
    for (auto& [c, head] : *queue) Close(c);
    queue->clear();
  }
}

}  // namespace vibid::bench
