// The bench's HTTP server: the embedded page, a JSON API over the board, and the live channel
// (Server-Sent Events at /api/live). Every request passes the Gate first; bodies are limited to
// kMaxBodyBytes; a request the API cannot read is answered 400 with a message and changes nothing.
//
// Views plug in with AddView (a tab of the page: its section's HTML and its script, served
// embedded or as given) and AddJsonRoute (POST /api/<name>: JSON in, JSON out, behind the gate,
// InputError -> 400, Busy -> 409, device::DeviceError -> 502).
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>

#include "vibid/bench/bench_board.hpp"
#include "vibid/bench/gate.hpp"
#include "vibid/bench/live_hub.hpp"

namespace httplib {
class Server;
}

namespace vibid::bench {

inline constexpr std::size_t kMaxBodyBytes = 64 * 1024;

struct ServerOptions {
  std::string bind = "127.0.0.1";
  int port = 0;       ///< 0: a free port.
  std::string token;  ///< Empty: NewToken().
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
  /// http://HOST:PORT/?token=TOKEN
  std::string Url() const;
  const std::string& token() const { return options_.token; }

  void AddView(View view);
  void AddJsonRoute(const std::string& name, JsonHandler handler);

 private:
  void Routes();

  BenchBoard& board_;
  LiveHub& hub_;
  ServerOptions options_;
  std::unique_ptr<httplib::Server> http_;
  std::unique_ptr<Gate> gate_;
  std::vector<View> views_;
  std::thread thread_;
  int port_ = 0;
};

/// True for 127.0.0.0/8, ::1 and "localhost".
bool IsLoopback(const std::string& address);

}  // namespace vibid::bench
