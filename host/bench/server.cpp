#include "vibid/bench/server.hpp"

#include <arpa/inet.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstring>
#include <stdexcept>

#include <httplib.h>

#include "bench_http.hpp"
#include "vibid/bench/assets.hpp"
#include "vibid/common/error.hpp"
#include "vibid/common/json_file.hpp"
#include "vibid/device/error.hpp"

namespace vibid::bench {

namespace {

void SendJson(httplib::Response& res, int status, const nlohmann::json& j) {
  res.status = status;
  res.set_content(j.dump(), "application/json");
}

void SendError(httplib::Response& res, int status, const std::string& message) {
  SendJson(res, status, {{"error", message}});
}

/// A request that is already in memory, and its answer collected (Exchange).
class MemoryStream : public httplib::Stream {
 public:
  explicit MemoryStream(std::string_view in) : in_(in) {}
  std::string out;
  bool is_readable() const override { return pos_ < in_.size(); }
  bool is_writable() const override { return true; }
  ssize_t read(char* ptr, size_t size) override {
    const std::size_t n = std::min(size, in_.size() - pos_);
    std::memcpy(ptr, in_.data() + pos_, n);
    pos_ += n;
    return static_cast<ssize_t>(n);
  }
  ssize_t write(const char* ptr, size_t size) override {
    out.append(ptr, size);
    return static_cast<ssize_t>(size);
  }
  void get_remote_ip_and_port(std::string& ip, int& port) const override {
    ip = "127.0.0.1";
    port = 1;
  }
  void get_local_ip_and_port(std::string& ip, int& port) const override {
    ip = "127.0.0.1";
    port = 2;
  }
  socket_t socket() const override { return 0; }

 private:
  std::string_view in_;
  std::size_t pos_ = 0;
};

/// application/json exactly (any case), with or without parameters (`; charset=utf-8`): not a
/// longer type that begins the same (application/jsonx).
bool IsJsonType(const std::string& value) {
  std::string type = value.substr(0, value.find(';'));
  while (!type.empty() && (type.back() == ' ' || type.back() == '\t')) type.pop_back();
  std::transform(type.begin(), type.end(), type.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return type == "application/json";
}

std::string WithoutBrackets(const std::string& a) {
  return a.size() > 2 && a.front() == '[' && a.back() == ']' ? a.substr(1, a.size() - 2) : a;
}

}  // namespace

bool IsLoopback(const std::string& address) {
  const std::string a = WithoutBrackets(address);
  if (a == "localhost") return true;
  in_addr v4{};
  if (inet_pton(AF_INET, a.c_str(), &v4) == 1) return (ntohl(v4.s_addr) >> 24) == 127;
  in6_addr v6{};
  if (inet_pton(AF_INET6, a.c_str(), &v6) != 1) return false;
  if (IN6_IS_ADDR_LOOPBACK(&v6)) return true;
  return IN6_IS_ADDR_V4MAPPED(&v6) && v6.s6_addr[12] == 127;
}

BenchServer::BenchServer(BenchBoard& board, LiveHub& hub, ServerOptions options)
    : board_(board), hub_(hub), options_(std::move(options)), http_(new BenchHttp) {
  options_.bind = WithoutBrackets(options_.bind);
  if (options_.token.empty()) options_.token = NewToken();
}

BenchServer::~BenchServer() { Stop(); }

std::string BenchServer::Url() const {
  return "http://" + UrlHost(options_.bind) + ":" + std::to_string(port_) +
         "/?token=" + options_.token;
}

void BenchServer::AddMetrics(std::function<std::string()> text) { metrics_ = std::move(text); }

void BenchServer::AddView(View view) { views_.push_back(std::move(view)); }

void BenchServer::AddJsonRoute(const std::string& name, JsonHandler handler) {
  http_->Post("/api/" + name, [handler](const httplib::Request& req, httplib::Response& res) {
    // Only JSON is read: a form a foreign page could post without a preflight is not.
    if (!IsJsonType(req.get_header_value("Content-Type"))) {
      SendError(res, 400, "the body must be JSON (Content-Type: application/json)");
      return;
    }
    // Every request states its body, {} when it has nothing to say: an empty or lost body is
    // never taken for one.
    if (req.body.empty()) {
      SendError(res, 400, "the request has no body: send a JSON object ({} when it has no keys)");
      return;
    }
    try {
      SendJson(res, 200, handler(ParseJsonText(req.body, "the request")));
    } catch (const InputError& e) {
      SendError(res, 400, e.what());
    } catch (const NumericalError& e) {
      SendError(res, 400, e.what());
    } catch (const nlohmann::json::exception& e) {
      SendError(res, 400, std::string("the request: ") + e.what());
    } catch (const Busy& e) {
      SendError(res, 409, e.what());
    } catch (const device::DeviceError& e) {
      SendError(res, 502, std::string("the board: ") + e.what());
    }
  });
}

void BenchServer::Routes() {
  httplib::Server& s = *http_;
  s.set_payload_max_length(kMaxBodyBytes);
  // Each security header once, on every answer the library writes (the front writes its own
  // refusals with the same ones).
  httplib::Headers headers;
  for (const auto& [name, value] : SecurityHeaders()) headers.emplace(name, value);
  s.set_default_headers(headers);
  s.set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
    return GateRequest(*gate_, req, res);
  });
  s.set_exception_handler(
      [](const httplib::Request&, httplib::Response& res, std::exception_ptr e) {
        // A failure no route expected: its message in the JSON body, never in a header.
        std::string what = "unknown";
        try {
          std::rethrow_exception(e);
        } catch (const std::exception& x) {
          what = x.what();
        } catch (...) {
        }
        SendError(res, 500, "the bench failed on this request: " + what);
      });
  s.set_error_handler([](const httplib::Request&, httplib::Response& res) {
    if (!res.body.empty()) return;
    if (res.status == 413) {
      res.set_content("request body beyond " + std::to_string(kMaxBodyBytes) + " bytes\n",
                      "text/plain");
    } else if (res.status == 404) {
      res.set_content("no such page or API\n", "text/plain");
    } else {
      res.set_content("refused (HTTP " + std::to_string(res.status) + ")\n", "text/plain");
    }
  });
  s.Get("/", [](const httplib::Request& req, httplib::Response& res) {
    const Asset* page = FindAsset("/index.html");
    // An older bench kept the token in a cookie every server on this host receives: dropped.
    if (req.get_header_value("Cookie").find(kOldTokenCookie) != std::string::npos) {
      res.set_header("Set-Cookie", std::string(kOldTokenCookie) +
                                       "=; Path=/; Max-Age=0; HttpOnly; SameSite=Strict");
    }
    res.set_content(std::string(page->bytes), std::string(page->content_type));
  });
  s.Get(R"(/assets/([A-Za-z0-9._-]+))", [](const httplib::Request& req, httplib::Response& res) {
    const Asset* a = FindAsset("/assets/" + req.matches[1].str());
    if (a == nullptr) {
      res.status = 404;
      return;
    }
    res.set_content(std::string(a->bytes), std::string(a->content_type));
  });
  s.Get(R"(/views/([a-z0-9-]+)\.js)", [this](const httplib::Request& req, httplib::Response& res) {
    for (const View& v : views_) {
      if (v.id == req.matches[1].str()) {
        res.set_content(v.script, "application/javascript");
        return;
      }
    }
    res.status = 404;
  });
  if (metrics_) {
    s.Get(kMetricsPath, [this](const httplib::Request&, httplib::Response& res) {
      res.set_content(metrics_(), kMetricsType);
    });
  }
  s.Get("/api/views", [this](const httplib::Request&, httplib::Response& res) {
    nlohmann::json j = nlohmann::json::array();
    for (const View& v : views_) j.push_back({{"id", v.id}, {"title", v.title}, {"html", v.html}});
    SendJson(res, 200, j);
  });
  s.Get("/api/board", [this](const httplib::Request&, httplib::Response& res) {
    try {
      SendJson(res, 200, board_.Describe());
    } catch (const device::DeviceError& e) {
      SendError(res, 502, std::string("the board: ") + e.what());
    }
  });
  s.Get("/api/state", [this](const httplib::Request&, httplib::Response& res) {
    SendJson(res, 200, board_.State());
  });
  s.Get("/api/live", [this](const httplib::Request&, httplib::Response& res) {
    // Only on a thread of its own (the front's live lane): past its bound, a refusal the page
    // shows, and it tries again later.
    if (!HttpFront::OnLiveLane()) {
      SendError(res, 503,
                "the bench serves at most " + std::to_string(options_.front.max_live) +
                    " live channels at once and all are open: close other pages of this bench");
      return;
    }
    std::shared_ptr<LiveHub::Subscription> sub = hub_.Subscribe();
    res.set_chunked_content_provider(
        "text/event-stream",
        [sub](std::size_t, httplib::DataSink& sink) {
          bool closed = false;
          std::string frames = sub->Next(std::chrono::milliseconds(500), closed);
          if (closed) {
            sink.done();
            return true;
          }
          // A comment line now and then tells a dead page from a quiet board.
          if (frames.empty()) frames = ": idle\n\n";
          return sink.write(frames.data(), frames.size());
        },
        [this, sub](bool) { hub_.Unsubscribe(sub); });
  });
  AddJsonRoute("budget", [this](const nlohmann::json& b) { return board_.Budget(b); });
  AddJsonRoute("acquire", [this](const nlohmann::json& b) { return board_.Start(b); });
  AddJsonRoute("stop", [this](const nlohmann::json& b) {
    Require(b.is_object() && b.empty(), "stop takes an empty object");
    return board_.Stop();
  });
  AddJsonRoute("observer", [this](const nlohmann::json& b) { return board_.SetObserver(b); });
}

void BenchServer::Ready(int port) {
  port_ = port;
  const std::string p = ":" + std::to_string(port_);
  std::vector<std::string> hosts{UrlHost(options_.bind) + p};
  if (IsLoopback(options_.bind)) {
    if (options_.bind.find(':') == std::string::npos) hosts.push_back("127.0.0.1" + p);
    hosts.push_back("localhost" + p);
  }
  gate_ = std::make_unique<Gate>(options_.token, hosts);
  Routes();
}

void BenchServer::StartWithoutSocket(int port) { Ready(port); }

std::string BenchServer::Exchange(std::string_view request) {
  const RequestHead head = ParseRequestHead(request);
  if (head.status == 0 ||
      (head.status == 200 && request.size() < head.head_bytes + head.body_bytes))
    return RefusalAnswer(408, "the request did not arrive whole", request);
  if (head.status != 200) return RefusalAnswer(head.status, head.message, request);
  MemoryStream stream(request.substr(0, head.head_bytes + head.body_bytes));
  bool closed = false;
  http_->ServeOne(stream, true, closed);
  return stream.out;
}

void BenchServer::Start() {
  if (options_.bind == "0.0.0.0" || options_.bind == "::") {
    throw InputError("--bind " + options_.bind +
                     ": name the one address to serve on (the Host check needs it)");
  }
  const int port = http_->Bind(options_.bind, options_.port);
  if (port <= 0) {
    throw InputError("cannot listen on " + UrlHost(options_.bind) + ":" +
                     std::to_string(options_.port));
  }
  Ready(port);
  front_ = http_->RunBehindFront(options_.front, thread_);
}

void BenchServer::Stop() {
  hub_.Close();
  if (http_) http_->stop();
  if (thread_.joinable()) thread_.join();
  if (front_) front_->Stop();
}

}  // namespace vibid::bench
