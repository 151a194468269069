#include "vibid/bench/gate.hpp"

#include <fcntl.h>
#include <sys/random.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <stdexcept>

#include "vibid/common/error.hpp"

namespace vibid::bench {

std::string HexOf(const unsigned char* bytes, std::size_t n) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string s;
  s.reserve(2 * n);
  for (std::size_t i = 0; i < n; ++i) {
    s += kHex[bytes[i] >> 4];
    s += kHex[bytes[i] & 0xFu];
  }
  return s;
}

std::string NewToken() {
  // The kernel's generator itself (getrandom, blocking only until it is seeded at boot), not
  // std::random_device, which libstdc++ may serve from the CPU's RDSEED/RDRAND instead.
  unsigned char bytes[16];
  std::size_t got = 0;
  while (got < sizeof bytes) {
    const ssize_t n = ::getrandom(bytes + got, sizeof bytes - got, 0);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0)
      throw std::runtime_error(std::string("no random bytes from the kernel (getrandom): ") +
                               std::strerror(errno));
    got += static_cast<std::size_t>(n);
  }
  return HexOf(bytes, sizeof bytes);
}

std::string TokenFromFile(const std::string& path) {
  std::ifstream in(path);
  if (in.good()) {
    std::string token;
    std::getline(in, token);
    while (!token.empty() && (token.back() == '\r' || token.back() == ' ')) token.pop_back();
    bool ok = token.size() >= 16 && token.size() <= 256;
    for (const char c : token)
      ok = ok && (std::isalnum(static_cast<unsigned char>(c)) || std::strchr("-._~+/", c));
    Require(ok, "the token file " + path +
                    " must hold one line of 16 to 256 letters, digits or -._~+/ (a bearer "
                    "token): remove it and a new token is written there");
    return token;
  }
  // Created here, readable by its owner only: the token opens the board to whoever holds it.
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  Require(fd >= 0, "cannot create the token file " + path + " (" + std::strerror(errno) +
                       "): name a file in a directory you can write");
  const std::string token = NewToken();
  const std::string line = token + "\n";
  const bool written = ::write(fd, line.data(), line.size()) == static_cast<ssize_t>(line.size());
  ::close(fd);
  Require(written, "cannot write the token file " + path);
  return token;
}

std::string BearerToken(const std::string& authorization) {
  // The scheme is case-insensitive (RFC 9110, 11.1); one space before the token.
  static constexpr char kScheme[] = "bearer ";
  if (authorization.size() <= sizeof kScheme - 1) return "";
  for (std::size_t i = 0; i + 1 < sizeof kScheme; ++i) {
    if (std::tolower(static_cast<unsigned char>(authorization[i])) != kScheme[i]) return "";
  }
  return authorization.substr(sizeof kScheme - 1);
}

bool IsStaticFile(const std::string& method, const std::string& path) {
  if (method != "GET" && method != "HEAD") return false;
  if (path == "/") return true;
  if (path.rfind("/assets/", 0) == 0) return true;
  return path.rfind("/views/", 0) == 0 && path.size() > 10 &&
         path.compare(path.size() - 3, 3, ".js") == 0;
}

std::string UrlHost(const std::string& address) {
  return address.find(':') != std::string::npos ? "[" + address + "]" : address;
}

Gate::Gate(std::string token, std::vector<std::string> hosts)
    : token_(std::move(token)), hosts_(std::move(hosts)) {}

bool Gate::TokenMatches(const std::string& given) const {
  // Compared in time independent of where the first difference lies.
  if (given.size() != token_.size()) return false;
  unsigned diff = 0;
  for (std::size_t i = 0; i < given.size(); ++i)
    diff |= static_cast<unsigned>(static_cast<unsigned char>(given[i]) ^
                                  static_cast<unsigned char>(token_[i]));
  return diff == 0;
}

std::optional<Refusal> Gate::Check(const RequestFacts& r) const {
  bool host_ok = false;
  for (const std::string& h : hosts_) host_ok = host_ok || r.host == h;
  if (!host_ok) {
    return Refusal{403, "Host '" + r.host + "' is not this bench (it answers to " + hosts_.front() +
                            "): a page of another site cannot reach it through its own name"};
  }
  if (!r.origin.empty() && r.origin != "http://" + r.host) {
    return Refusal{403, "Origin '" + r.origin +
                            "' is another site: the bench answers its own page only (no CORS)"};
  }
  // The printed URL's token, when one is given, must be this bench's, on the page too.
  if (!r.query_token.empty() && !TokenMatches(r.query_token))
    return Refusal{403, "this is not the token of this bench: open the URL vibid bench printed"};
  if (IsStaticFile(r.method, r.path) || TokenMatches(r.header_token)) return std::nullopt;
  const bool scrape = (r.method == "GET" || r.method == "HEAD") && r.path == kMetricsPath;
  if (scrape && TokenMatches(r.bearer_token)) return std::nullopt;
  if (r.path == kMetricsPath) {
    return Refusal{403,
                   "no valid token: a scraper sends the token file's token as a bearer token "
                   "(authorization: credentials_file in its scrape config)"};
  }
  return Refusal{403, "no valid token: open the URL vibid bench printed (it carries ?token=)"};
}

}  // namespace vibid::bench
