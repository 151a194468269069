#include "vibid/bench/request_head.hpp"

#include <algorithm>
#include <array>
#include <cctype>

namespace vibid::bench {
namespace {

RequestHead Refuse(int status, std::string message) {
  RequestHead h;
  h.status = status;
  h.message = std::move(message);
  h.close = true;
  return h;
}

bool IsTokenChar(char c) {
  static constexpr std::string_view kExtra = "!#$%&'*+-.^_`|~";
  return std::isalnum(static_cast<unsigned char>(c)) != 0 || kExtra.find(c) != std::string::npos;
}

bool SameName(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) ==
                  std::tolower(static_cast<unsigned char>(y));
         });
}

std::string_view Trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

// The headers the bench (or the library for it) reads: each at most once, so that what the gate
// checks and what the library uses are the same value.
constexpr std::array<std::string_view, 8> kSingle = {
    "Host",          "Origin",     "Content-Length", "Content-Type",
    "X-Vibid-Token", "Connection", "Range",          "Accept-Encoding"};

}  // namespace

RequestHead ParseRequestHead(std::string_view bytes) {
  const std::size_t end = bytes.find("\r\n\r\n");
  const std::size_t first_line = bytes.find('\n');
  if (first_line == std::string_view::npos) {
    if (bytes.size() > kMaxRequestLineBytes)
      return Refuse(414, "the request line is longer than " + std::to_string(kMaxRequestLineBytes) +
                             " bytes");
    return {};
  }
  if (first_line > kMaxRequestLineBytes)
    return Refuse(
        414, "the request line is longer than " + std::to_string(kMaxRequestLineBytes) + " bytes");
  if (end == std::string_view::npos || end + 4 > kMaxHeadBytes) {
    if (bytes.size() >= kMaxHeadBytes || (end != std::string_view::npos))
      return Refuse(
          431, "the request's headers are longer than " + std::to_string(kMaxHeadBytes) + " bytes");
    // Complete lines so far must already be well formed: refuse early what cannot become so.
    if (bytes.find('\0') != std::string_view::npos)
      return Refuse(400, "a NUL byte in the request's head");
    return {};
  }
  const std::string_view head = bytes.substr(0, end + 2);  // every line with its CRLF
  RequestHead h;
  h.head_bytes = end + 4;
  std::size_t pos = 0;
  bool first = true;
  bool has_length = false;
  std::array<int, kSingle.size()> seen{};
  while (pos < head.size()) {
    const std::size_t eol = head.find('\n', pos);
    if (eol == 0 || head[eol - 1] != '\r')
      return Refuse(400, "a line of the request's head does not end in CR LF");
    const std::string_view line = head.substr(pos, eol - 1 - pos);
    pos = eol + 1;
    for (const char c : line) {
      if ((static_cast<unsigned char>(c) < 0x20 && c != '\t') || c == 0x7f)
        return Refuse(400, "a control character in the request's head");
    }
    if (first) {
      first = false;
      const std::size_t a = line.find(' ');
      const std::size_t b = a == std::string_view::npos ? a : line.find(' ', a + 1);
      if (b == std::string_view::npos || line.find(' ', b + 1) != std::string_view::npos ||
          b == a + 1 || a == 0)
        return Refuse(400, "the request line is not METHOD TARGET HTTP/1.1");
      h.method = std::string(line.substr(0, a));
      const std::string_view target = line.substr(a + 1, b - a - 1);
      const std::string_view version = line.substr(b + 1);
      if (version != "HTTP/1.1" && version != "HTTP/1.0")
        return Refuse(version.rfind("HTTP/", 0) == 0 ? 505 : 400,
                      "the bench speaks HTTP/1.1 (and 1.0) only");
      if (h.method != "GET" && h.method != "HEAD" && h.method != "POST")
        return Refuse(405, "the bench answers GET and POST only");
      if (target.empty() || target.front() != '/' || target.find('\t') != std::string_view::npos)
        return Refuse(400, "the request's target is not a path from /");
      h.path = std::string(target.substr(0, target.find('?')));
      h.close = version == "HTTP/1.0";
      continue;
    }
    if (line.front() == ' ' || line.front() == '\t')
      return Refuse(400, "a folded header line (obsolete; the bench reads none)");
    const std::size_t colon = line.find(':');
    if (colon == std::string_view::npos || colon == 0)
      return Refuse(400, "a header line without a name and a colon");
    const std::string_view name = line.substr(0, colon);
    if (!std::all_of(name.begin(), name.end(), IsTokenChar))
      return Refuse(400, "a header name with characters a name cannot hold");
    const std::string_view value = Trim(line.substr(colon + 1));
    for (std::size_t i = 0; i < kSingle.size(); ++i) {
      if (SameName(name, kSingle[i]) && ++seen[i] > 1)
        return Refuse(400, "the header " + std::string(kSingle[i]) + " is given twice");
    }
    if (SameName(name, "Transfer-Encoding"))
      return Refuse(411,
                    "the bench reads a body of a stated Content-Length only (no "
                    "Transfer-Encoding: " +
                        std::string(value) + ")");
    if (SameName(name, "Expect"))
      return Refuse(
          417, "the bench takes a request's body at once (no Expect: " + std::string(value) + ")");
    if (SameName(name, "Content-Length")) {
      if (value.empty() || value.size() > 9 ||
          !std::all_of(value.begin(), value.end(), [](char c) { return c >= '0' && c <= '9'; }))
        return Refuse(400, "Content-Length '" + std::string(value) + "' is not a byte count");
      h.body_bytes = std::stoul(std::string(value));
      if (h.body_bytes > kMaxBodyBytes)
        return Refuse(413, "request body beyond " + std::to_string(kMaxBodyBytes) + " bytes");
      has_length = true;
    }
    if (SameName(name, "Range") && value.find(',') != std::string_view::npos) {
      // Many ranges make one answer many times the file's size (2 044 ranges of a 50 kB script
      // are 100 MB): a single range is all the page or a player asks for.
      return Refuse(416, "the bench answers one byte range at most (Range: " +
                             std::string(value.substr(0, 40)) + (value.size() > 40 ? "...)" : ")"));
    }
    if (SameName(name, "Connection")) {
      std::string v(value);
      std::transform(v.begin(), v.end(), v.begin(),
                     [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
      if (v == "close") h.close = true;
    }
  }
  if (seen[0] == 0) return Refuse(400, "the request has no Host header");
  if (h.method == "POST" && !has_length)
    return Refuse(411, "a POST needs its Content-Length (the API reads a JSON body)");
  if (h.method != "POST" && h.body_bytes > 0)
    return Refuse(400, "a " + h.method + " request carries no body");
  h.status = 200;
  return h;
}

const char* ReasonPhrase(int status) {
  switch (status) {
    case 200: return "OK";
    case 400: return "Bad Request";
    case 403: return "Forbidden";
    case 404: return "Not Found";
    case 405: return "Method Not Allowed";
    case 408: return "Request Timeout";
    case 409: return "Conflict";
    case 411: return "Length Required";
    case 413: return "Payload Too Large";
    case 414: return "URI Too Long";
    case 416: return "Range Not Satisfiable";
    case 417: return "Expectation Failed";
    case 431: return "Request Header Fields Too Large";
    case 500: return "Internal Server Error";
    case 502: return "Bad Gateway";
    case 503: return "Service Unavailable";
    case 505: return "HTTP Version Not Supported";
    default: return "Error";
  }
}

}  // namespace vibid::bench
