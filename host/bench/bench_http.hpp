// The HTTP library's server as the bench runs it, shared by the bench (server.cpp) and the
// metrics server of `vibid watch` (metrics_server.cpp): connections handed to the HttpFront, and
// every request through the Gate before any handler.
#pragma once

#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <thread>

#include <httplib.h>

#include "vibid/bench/gate.hpp"
#include "vibid/bench/http_front.hpp"

namespace vibid::bench {

/// The Content-Type of Prometheus's text format (0.0.4).
inline constexpr const char* kMetricsType = "text/plain; version=0.0.4; charset=utf-8";

// cpp-httplib's server with its connections handed to the HttpFront: the accept loop gives each
// new socket to the front at once (no pool of its own), and the front hands whole requests back
// to process_request.
class BenchHttp : public httplib::Server {
 public:
  BenchHttp() {
    new_task_queue = [] { return new Inline; };
  }
  HttpFront* front = nullptr;

  bool ServeOne(httplib::Stream& s, bool close_connection, bool& connection_closed) {
    return process_request(s, close_connection, connection_closed, nullptr);
  }

  /// Binds `port` on `bind` (0: any free port); the port bound, or -1.
  int Bind(const std::string& bind, int port) {
    if (port == 0) return bind_to_any_port(bind);
    return bind_to_port(bind, port) ? port : -1;
  }

  /// After Bind: puts a front with `options` before this server and runs the accept loop on
  /// `thread`; returns the front once the loop runs (a stop before it would be lost: the library
  /// sets its running flag as the loop starts).
  std::unique_ptr<HttpFront> RunBehindFront(const FrontOptions& options, std::thread& thread) {
    auto f = std::make_unique<HttpFront>(
        options, [this](httplib::Stream& st, bool close_connection, bool& closed) {
          return ServeOne(st, close_connection, closed);
        });
    front = f.get();
    thread = std::thread([this] { listen_after_bind(); });
    while (!is_running()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    return f;
  }

 private:
  class Inline : public httplib::TaskQueue {
   public:
    void enqueue(std::function<void()> fn) override { fn(); }
    void shutdown() override {}
  };
  bool process_and_close_socket(socket_t sock) override {
    front->Adopt(sock);
    return true;
  }
};

/// The gate's verdict on a request: Handled (answered with the refusal) or Unhandled (it may
/// pass), as the library's pre-routing handler returns it.
inline httplib::Server::HandlerResponse GateRequest(const Gate& gate, const httplib::Request& req,
                                                    httplib::Response& res) {
  RequestFacts f;
  f.host = req.get_header_value("Host");
  f.origin = req.get_header_value("Origin");
  f.query_token = req.get_param_value("token");
  f.header_token = req.get_header_value(kTokenHeader);
  f.bearer_token = BearerToken(req.get_header_value("Authorization"));
  f.method = req.method;
  f.path = req.path;
  if (const std::optional<Refusal> r = gate.Check(f)) {
    res.status = r->status;
    res.set_content(r->message + "\n", "text/plain");
    return httplib::Server::HandlerResponse::Handled;
  }
  return httplib::Server::HandlerResponse::Unhandled;
}

}  // namespace vibid::bench
