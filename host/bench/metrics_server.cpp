#include "vibid/bench/metrics_server.hpp"

#include <chrono>

// Before the HTTP library: its <resolv.h> defines _res, a name Eigen's headers use.
#include "vibid/bench/server.hpp"
#include "vibid/common/error.hpp"
// clang-format off
#include "bench_http.hpp"
// clang-format on

namespace vibid::bench {
namespace {

std::string WithoutBrackets(const std::string& a) {
  return a.size() > 2 && a.front() == '[' && a.back() == ']' ? a.substr(1, a.size() - 2) : a;
}

}  // namespace

MetricsServer::MetricsServer(MetricsServerOptions options, std::function<std::string()> text)
    : options_(std::move(options)), text_(std::move(text)), http_(new BenchHttp) {
  options_.bind = WithoutBrackets(options_.bind);
  if (options_.token.empty()) options_.token = NewToken();
}

MetricsServer::~MetricsServer() { Stop(); }

std::string MetricsServer::Url() const {
  return "http://" + UrlHost(options_.bind) + ":" + std::to_string(port_) + kMetricsPath;
}

void MetricsServer::Start() {
  // The figures of a rig and the token's reach stay on this machine: a scraper elsewhere reads
  // them through a Prometheus on this host (federation) or a tunnel, never from this port.
  Require(IsLoopback(options_.bind),
          "--metrics-bind " + options_.bind +
              ": the metrics are served on a loopback address only (127.0.0.1 or ::1); scrape "
              "them from a Prometheus on this host");
  const int port = http_->Bind(options_.bind, options_.port);
  Require(port > 0, "cannot listen on " + UrlHost(options_.bind) + ":" +
                        std::to_string(options_.port) + ": choose a free port (0: any)");
  port_ = port;
  const std::string p = ":" + std::to_string(port_);
  std::vector<std::string> hosts{UrlHost(options_.bind) + p};
  if (options_.bind.find(':') == std::string::npos) hosts.push_back("127.0.0.1" + p);
  hosts.push_back("localhost" + p);
  gate_ = std::make_unique<Gate>(options_.token, hosts);

  httplib::Server& s = *http_;
  s.set_payload_max_length(kMaxBodyBytes);
  httplib::Headers headers;
  for (const auto& [name, value] : SecurityHeaders()) headers.emplace(name, value);
  s.set_default_headers(headers);
  s.set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
    return GateRequest(*gate_, req, res);
  });
  s.set_error_handler([](const httplib::Request&, httplib::Response& res) {
    if (!res.body.empty()) return;
    res.set_content(res.status == 404 ? "only /metrics is served here\n"
                                      : "refused (HTTP " + std::to_string(res.status) + ")\n",
                    "text/plain");
  });
  s.Get(kMetricsPath, [this](const httplib::Request&, httplib::Response& res) {
    res.set_content(text_(), kMetricsType);
  });

  front_ = http_->RunBehindFront(options_.front, thread_);
}

void MetricsServer::Stop() {
  if (http_) http_->stop();
  if (thread_.joinable()) thread_.join();
  if (front_) front_->Stop();
}

}  // namespace vibid::bench
