// The bench's HTTP server: the embedded page, a JSON API over the board, and the live channel
// (Server-Sent Events at /api/live). Connections are read by the HttpFront (whole requests within
// fixed sizes and a deadline, no thread held by a slow client, a bounded number of live
// channels); every request then passes the Gate; a request the API cannot read is answered 400
// with a message and changes nothing.
//
// Views plug in with AddView (a tab of the page: its section's HTML and its script, served
// embedded or as given) and AddJsonRoute (POST /api/<name>: JSON in, JSON out, behind the gate,
// InputError and NumericalError -> 400, Busy -> 409, device::DeviceError -> 502, anything else
// 500; always a JSON {"error": message}, never a message in a header).
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <thread>

#include <nlohmann/json.hpp>

#include "vibid/bench/bench_board.hpp"
#include "vibid/bench/gate.hpp"
#include "vibid/bench/http_front.hpp"
#include "vibid/bench/live_hub.hpp"
#include "vibid/bench/request_head.hpp"

namespace vibid::bench {

class BenchHttp;

struct ServerOptions {
  std::string bind = "127.0.0.1";  ///< An IPv6 address with or without its brackets.
  int port = 0;                    ///< 0: a free port.
  std::string token;               ///< Empty: NewToken().
  FrontOptions front;
};

/// A tab of the page beyond the built-in ones.
struct View {
  std::string id;      ///< "hammer": the tab, the section id "view-hammer".
  std::string title;   ///< The tab's label.
  std::string html;    ///< The section's content.
  std::string script;  ///< JavaScript run once the page has loaded (it may use window.bench).
};

using JsonHandler = std::function<nlohmann::json(const nlohmann::json& body)>;

class BenchServer {
 public:
  BenchServer(BenchBoard& board, LiveHub& hub, ServerOptions options);
  ~BenchServer();
  BenchServer(const BenchServer&) = delete;
  BenchServer& operator=(const BenchServer&) = delete;

  /// Binds (throws std::runtime_error naming the address when it cannot) and serves in a thread.
  void Start();
  void Stop();

  int port() const { return port_; }
  /// http://HOST:PORT/?token=TOKEN (an IPv6 HOST in brackets)
  std::string Url() const;
  /// Serves the routes without a socket, as if the server listened on `port`: for Exchange.
  void StartWithoutSocket(int port);
  /// One request's bytes through the same checks and routes as a connection's, and the answer's
  /// bytes (the fuzz target's way in).
  std::string Exchange(std::string_view request);
  const std::string& token() const { return options_.token; }

  /// GET /metrics answers `text()` (Prometheus's text format), behind the gate: the token as
  /// X-Vibid-Token or as a bearer token (gate.hpp). Before Start.
  void AddMetrics(std::function<std::string()> text);

  void AddView(View view);
  void AddJsonRoute(const std::string& name, JsonHandler handler);

 private:
  void Routes();
  void Ready(int port);

  BenchBoard& board_;
  LiveHub& hub_;
  ServerOptions options_;
  std::unique_ptr<BenchHttp> http_;
  std::unique_ptr<HttpFront> front_;
  std::unique_ptr<Gate> gate_;
  std::vector<View> views_;
  std::function<std::string()> metrics_;
  std::thread thread_;
  int port_ = 0;
};

/// True for 127.0.0.0/8, ::1 (and ::ffff:127.0.0.0/104) and "localhost".
bool IsLoopback(const std::string& address);

}  // namespace vibid::bench
