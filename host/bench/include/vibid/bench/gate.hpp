// Who may talk to the bench. The page can reconfigure the board, so every request passes the gate
// before any handler runs: the random token of the printed URL (query `token` on the first page
// load, then the cookie the server sets, or the X-Vibid-Token header), a Host header naming the
// server itself (a DNS-rebinding page has the attacker's host name there) and, when the browser
// sends one, an Origin equal to the server's own (a cross-site form or fetch has its own origin).
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace vibid::bench {

/// 128 random bits (std::random_device, the kernel's generator on Linux) as 32 hex digits.
std::string NewToken();

/// The cookie that carries the token after the first page load.
inline constexpr const char* kTokenCookie = "vibid_bench_token";
/// The header a script may carry it in instead.
inline constexpr const char* kTokenHeader = "X-Vibid-Token";

/// What a request shows the gate.
struct RequestFacts {
  std::string host;          ///< The Host header ("" when absent).
  std::string origin;        ///< The Origin header ("" when absent).
  std::string query_token;   ///< ?token= ("" when absent).
  std::string cookie;        ///< The Cookie header ("" when absent).
  std::string header_token;  ///< X-Vibid-Token ("" when absent).
};

struct Refusal {
  int status = 403;
  std::string message;
};

class Gate {
 public:
  /// `hosts`: the host:port values this server answers to (127.0.0.1:PORT and localhost:PORT, or
  /// the --bind address with its port).
  Gate(std::string token, std::vector<std::string> hosts);

  /// Why the request is refused (403, a message naming what is wrong), or nothing.
  std::optional<Refusal> Check(const RequestFacts& r) const;

  const std::string& token() const { return token_; }

 private:
  bool TokenMatches(const std::string& given) const;

  std::string token_;
  std::vector<std::string> hosts_;
};

/// The value of cookie `name` in a Cookie header ("" when absent).
std::string CookieValue(const std::string& header, const std::string& name);

}  // namespace vibid::bench
