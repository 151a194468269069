// Who may talk to the bench. The page can reconfigure the board, so every request passes the gate
// before any handler runs: a Host header naming the server itself (a DNS-rebinding page has the
// attacker's host name there), when the browser sends one an Origin equal to the server's own (a
// cross-site form or fetch has its own origin), and on everything but the page's static files
// the random token of the printed URL in the X-Vibid-Token header. The token is never a cookie:
// cookies belong to the host, not the port, so every other server on 127.0.0.1 would receive it
// and a second bench would replace it. The page keeps it in its own memory (and its tab's
// sessionStorage, which is per origin, port included, for a reload).
//
// A Prometheus scraper shows the token as a bearer token (`Authorization: Bearer TOKEN`, its
// scrape config's `authorization: {credentials_file: ...}`), taken on GET /metrics only: the
// Host rule holds for it as for the page, and a foreign page cannot set that header without a
// preflight the bench never grants.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace vibid::bench {

/// 128 random bits from the kernel (getrandom(2)) as 32 hex digits. Throws std::runtime_error
/// when the kernel gives none.
std::string NewToken();
/// `bytes` as lower-case hex, two digits a byte in order.
std::string HexOf(const unsigned char* bytes, std::size_t n);

/// The header the page carries the token in.
inline constexpr const char* kTokenHeader = "X-Vibid-Token";
/// The path of the metrics (Prometheus's text format), where a bearer token is taken.
inline constexpr const char* kMetricsPath = "/metrics";
/// The cookie an older bench set; a request that still carries it is told to drop it.
inline constexpr const char* kOldTokenCookie = "vibid_bench_token";

/// What a request shows the gate.
struct RequestFacts {
  std::string host;          ///< The Host header ("" when absent).
  std::string origin;        ///< The Origin header ("" when absent).
  std::string query_token;   ///< ?token= ("" when absent): the printed URL's, on the page only.
  std::string header_token;  ///< X-Vibid-Token ("" when absent).
  std::string bearer_token;  ///< Authorization: Bearer TOKEN ("" when absent), on /metrics only.
  std::string method;
  std::string path;
};

/// The page's own files (GET or HEAD of "/", "/assets/...", "/views/....js"): the same bytes in
/// every bench, no data of the board; they need no token (a reload finds it in the tab).
bool IsStaticFile(const std::string& method, const std::string& path);

/// The token of `path`: read when the file exists (one line of 16 to 256 characters, letters,
/// digits and -._~+/), else a NewToken() written to a new file only its owner may read, for a
/// scraper's credentials_file and for runs that keep their token. InputError naming the file
/// and the way out when it holds something else or cannot be written.
std::string TokenFromFile(const std::string& path);

/// The token of `Authorization: Bearer TOKEN` ("" for any other value).
std::string BearerToken(const std::string& authorization);

/// The host part of a URL for `address`: an IPv6 literal in brackets ("[::1]").
std::string UrlHost(const std::string& address);

struct Refusal {
  int status = 403;
  std::string message;
};

class Gate {
 public:
  /// `hosts`: the host:port values this server answers to (127.0.0.1:PORT and localhost:PORT, or
  /// the --bind address with its port, an IPv6 one in brackets: [::1]:PORT).
  Gate(std::string token, std::vector<std::string> hosts);

  /// Why the request is refused (403, a message naming what is wrong), or nothing.
  std::optional<Refusal> Check(const RequestFacts& r) const;

  const std::string& token() const { return token_; }

 private:
  bool TokenMatches(const std::string& given) const;

  std::string token_;
  std::vector<std::string> hosts_;
};

}  // namespace vibid::bench
