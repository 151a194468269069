// What the bench reads of a request before any of it reaches the HTTP library: the request line
// and the headers, whole, within fixed sizes, with a framing the server can trust. The library
// (cpp-httplib 0.11) buffers a request line of any length, reads a chunked body of any size past
// its payload limit and takes `Content-Length: abc` as an empty body; here each of these is
// refused with its status before a byte of the body is read, and the connection is closed.
//
// Accepted: GET, HEAD or POST, HTTP/1.0 or 1.1, every line ending in CRLF, header names of token
// characters, values without control characters, one Host, at most one of each header the bench
// reads, no Transfer-Encoding and no Expect (the page sends neither), a Content-Length of digits
// within kMaxBodyBytes on a POST (required there), none on GET or HEAD, a Range of one range.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace vibid::bench {

inline constexpr std::size_t kMaxBodyBytes = 64 * 1024;
/// The request line (method, target, version): longer is 414.
inline constexpr std::size_t kMaxRequestLineBytes = 8 * 1024;
/// The whole head (request line and headers): longer is 431.
inline constexpr std::size_t kMaxHeadBytes = 16 * 1024;

struct RequestHead {
  /// 0: the head is incomplete (read more); 200: accepted; else the status that refuses it.
  int status = 0;
  std::string message;         ///< Why it is refused (one line).
  std::size_t head_bytes = 0;  ///< Up to and including the blank line.
  std::size_t body_bytes = 0;  ///< The Content-Length.
  std::string method;
  std::string path;    ///< The target before '?', as sent.
  bool close = false;  ///< The client asked to close after this request.
};

/// Reads the head at the start of `bytes` (what arrived so far on the connection).
RequestHead ParseRequestHead(std::string_view bytes);

/// The reason phrase of the statuses the bench answers with.
const char* ReasonPhrase(int status);

}  // namespace vibid::bench
