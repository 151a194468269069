#include "vibid/bench/server.hpp"

#include <arpa/inet.h>

#include <chrono>
#include <stdexcept>

#include <httplib.h>

#include "vibid/bench/assets.hpp"
#include "vibid/common/error.hpp"
#include "vibid/common/json_file.hpp"
#include "vibid/device/error.hpp"

namespace vibid::bench {
namespace {

// What every answer carries: no caching of the token-bearing page, no framing by other sites,
// scripts and styles from the bench itself only. No Access-Control-* header is ever sent.
void Harden(httplib::Response& res) {
  res.set_header("Cache-Control", "no-store");
  res.set_header("X-Content-Type-Options", "nosniff");
  res.set_header("X-Frame-Options", "DENY");
  res.set_header("Referrer-Policy", "no-referrer");
  res.set_header("Content-Security-Policy",
                 "default-src 'self'; style-src 'self' 'unsafe-inline'; img-src 'self' data:; "
                 "frame-ancestors 'none'");
}

void SendJson(httplib::Response& res, int status, const nlohmann::json& j) {
  res.status = status;
  res.set_content(j.dump(), "application/json");
}

void SendError(httplib::Response& res, int status, const std::string& message) {
  SendJson(res, status, {{"error", message}});
}

}  // namespace

bool IsLoopback(const std::string& address) {
  if (address == "localhost" || address == "::1") return true;
  in_addr a{};
  if (inet_pton(AF_INET, address.c_str(), &a) != 1) return false;
  return (ntohl(a.s_addr) >> 24) == 127;
}

BenchServer::BenchServer(BenchBoard& board, LiveHub& hub, ServerOptions options)
    : board_(board), hub_(hub), options_(std::move(options)), http_(new httplib::Server) {
  if (options_.token.empty()) options_.token = NewToken();
}

BenchServer::~BenchServer() { Stop(); }

std::string BenchServer::Url() const {
  return "http://" + options_.bind + ":" + std::to_string(port_) + "/?token=" + options_.token;
}

void BenchServer::AddView(View view) { views_.push_back(std::move(view)); }

void BenchServer::AddJsonRoute(const std::string& name, JsonHandler handler) {
  http_->Post("/api/" + name, [handler](const httplib::Request& req, httplib::Response& res) {
    // Only JSON is read: a form a foreign page could post without a preflight is not.
    const std::string type = req.get_header_value("Content-Type");
    if (type.rfind("application/json", 0) != 0) {
      SendError(res, 400, "the body must be JSON (Content-Type: application/json)");
      return;
    }
    try {
      const nlohmann::json body =
          req.body.empty() ? nlohmann::json::object() : ParseJsonText(req.body, "the request");
      SendJson(res, 200, handler(body));
    } catch (const InputError& e) {
      SendError(res, 400, e.what());
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
  s.set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
    Harden(res);
    RequestFacts f;
    f.host = req.get_header_value("Host");
    f.origin = req.get_header_value("Origin");
    f.query_token = req.get_param_value("token");
    f.cookie = req.get_header_value("Cookie");
    f.header_token = req.get_header_value(kTokenHeader);
    if (const std::optional<Refusal> r = gate_->Check(f)) {
      res.status = r->status;
      res.set_content(r->message + "\n", "text/plain");
      return httplib::Server::HandlerResponse::Handled;
    }
    return httplib::Server::HandlerResponse::Unhandled;
  });
  s.set_error_handler([](const httplib::Request&, httplib::Response& res) {
    Harden(res);
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
  s.Get("/", [this](const httplib::Request& req, httplib::Response& res) {
    const Asset* page = FindAsset("/index.html");
    if (req.has_param("token")) {
      // The gate has checked it: later requests (scripts, API, live channel) carry the cookie.
      res.set_header("Set-Cookie", std::string(kTokenCookie) + "=" + options_.token +
                                       "; Path=/; HttpOnly; SameSite=Strict");
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

void BenchServer::Start() {
  if (options_.bind == "0.0.0.0" || options_.bind == "::") {
    throw InputError("--bind " + options_.bind +
                     ": name the one address to serve on (the Host check needs it)");
  }
  port_ = options_.port == 0
              ? http_->bind_to_any_port(options_.bind)
              : (http_->bind_to_port(options_.bind, options_.port) ? options_.port : -1);
  if (port_ <= 0) {
    throw InputError("cannot listen on " + options_.bind + ":" + std::to_string(options_.port));
  }
  const std::string p = ":" + std::to_string(port_);
  std::vector<std::string> hosts{options_.bind + p};
  if (IsLoopback(options_.bind)) {
    hosts.push_back("127.0.0.1" + p);
    hosts.push_back("localhost" + p);
  }
  gate_ = std::make_unique<Gate>(options_.token, hosts);
  Routes();
  thread_ = std::thread([this] { http_->listen_after_bind(); });
  // A stop before the loop runs would be lost (httplib sets its running flag as the loop starts).
  while (!http_->is_running()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
}

void BenchServer::Stop() {
  hub_.Close();
  if (http_) http_->stop();
  if (thread_.joinable()) thread_.join();
}

}  // namespace vibid::bench
