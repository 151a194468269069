#include "vibid/bench/gate.hpp"

#include <array>
#include <cstdint>
#include <random>

namespace vibid::bench {

std::string NewToken() {
  std::random_device rd;  // /dev/urandom (getrandom) with libstdc++ on Linux
  static constexpr char kHex[] = "0123456789abcdef";
  std::string token;
  for (int word = 0; word < 4; ++word) {  // 4 x 32 bits
    std::uint32_t v = rd();
    for (int nibble = 0; nibble < 8; ++nibble) {
      token += kHex[v & 0xFu];
      v >>= 4;
    }
  }
  return token;
}

std::string CookieValue(const std::string& header, const std::string& name) {
  std::size_t pos = 0;
  while (pos < header.size()) {
    std::size_t end = header.find(';', pos);
    if (end == std::string::npos) end = header.size();
    std::size_t start = header.find_first_not_of(' ', pos);
    if (start < end) {
      const std::string pair = header.substr(start, end - start);
      const std::size_t eq = pair.find('=');
      if (eq != std::string::npos && pair.substr(0, eq) == name) return pair.substr(eq + 1);
    }
    pos = end + 1;
  }
  return {};
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
  const std::string cookie = CookieValue(r.cookie, kTokenCookie);
  if (TokenMatches(r.query_token) || TokenMatches(r.header_token) || TokenMatches(cookie))
    return std::nullopt;
  return Refusal{403, "no valid token: open the URL vibid bench printed (it carries ?token=)"};
}

}  // namespace vibid::bench
