// The metrics of one process (`vibid watch --metrics-port`) on a loopback port, for a Prometheus
// scraper: GET /metrics only, served by the bench's own connection front (whole requests within
// fixed sizes and a deadline, a few worker threads) behind the bench's gate (the Host header
// naming this server, no foreign Origin, the token as a bearer token or X-Vibid-Token).
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <thread>

#include "vibid/bench/gate.hpp"
#include "vibid/bench/http_front.hpp"

namespace vibid::bench {

class BenchHttp;

struct MetricsServerOptions {
  std::string bind = "127.0.0.1";  ///< A loopback address (another is refused).
  int port = 0;                    ///< 0: a free port.
  std::string token;               ///< Empty: NewToken().
  FrontOptions front;
};

class MetricsServer {
 public:
  /// `text`: the exposition, called on the server's threads at each scrape.
  MetricsServer(MetricsServerOptions options, std::function<std::string()> text);
  ~MetricsServer();
  MetricsServer(const MetricsServer&) = delete;
  MetricsServer& operator=(const MetricsServer&) = delete;

  /// Binds (InputError naming the address when it cannot, or when it is not loopback) and
  /// serves in a thread.
  void Start();
  void Stop();

  int port() const { return port_; }
  /// http://HOST:PORT/metrics
  std::string Url() const;
  const std::string& token() const { return options_.token; }

 private:
  MetricsServerOptions options_;
  std::function<std::string()> text_;
  std::unique_ptr<BenchHttp> http_;
  std::unique_ptr<HttpFront> front_;
  std::unique_ptr<Gate> gate_;
  std::thread thread_;
  int port_ = 0;
};

}  // namespace vibid::bench
