// The request heads the bench accepts, waits for or refuses, each refusal with its status
// (RFC 9110 / 9112: 411 Length Required, 413, 414, 417, 431, 505) before any body is read.
#include "vibid/bench/request_head.hpp"

#include <gtest/gtest.h>

namespace vibid::bench {
namespace {

const std::string kHost = "Host: 127.0.0.1:8080\r\n";

int StatusOf(const std::string& head) { return ParseRequestHead(head).status; }

TEST(RequestHead, WaitsForTheBlankLine) {
  EXPECT_EQ(StatusOf(""), 0);
  EXPECT_EQ(StatusOf("GET /api/state HTTP/1.1\r\n"), 0);
  EXPECT_EQ(StatusOf("GET /api/state HTTP/1.1\r\n" + kHost), 0);
  EXPECT_EQ(StatusOf("GET /api/state HTTP/1.1\r\n" + kHost + "\r"), 0);
}

TEST(RequestHead, ReadsAWholeHead) {
  const std::string get = "GET /api/state?x=1 HTTP/1.1\r\n" + kHost + "\r\nGET / HTTP/1.1";
  const RequestHead g = ParseRequestHead(get);
  EXPECT_EQ(g.status, 200) << g.message;
  EXPECT_EQ(g.method, "GET");
  EXPECT_EQ(g.path, "/api/state");
  EXPECT_EQ(g.head_bytes, get.find("GET /", 5));  // the next (pipelined) request is not part
  EXPECT_EQ(g.body_bytes, 0u);
  EXPECT_FALSE(g.close);
  const RequestHead p = ParseRequestHead("POST /api/stop HTTP/1.1\r\n" + kHost +
                                         "Content-Type: application/json\r\n"
                                         "Content-Length:  2 \r\n\r\n{}");
  EXPECT_EQ(p.status, 200) << p.message;
  EXPECT_EQ(p.body_bytes, 2u);
  EXPECT_TRUE(ParseRequestHead("GET / HTTP/1.0\r\n" + kHost + "\r\n").close);
  EXPECT_TRUE(ParseRequestHead("GET / HTTP/1.1\r\n" + kHost + "Connection: Close\r\n\r\n").close);
}

TEST(RequestHead, RefusesEveryTransferEncodingBeforeTheBody) {
  for (const char* te : {"chunked", "gzip, chunked", "identity"}) {
    for (const char* name : {"Transfer-Encoding", "transfer-encoding", "TRANSFER-ENCODING"}) {
      const RequestHead h = ParseRequestHead("POST /api/acquire HTTP/1.1\r\n" + kHost + name +
                                             ": " + te + "\r\nContent-Length: 2\r\n\r\n");
      EXPECT_EQ(h.status, 411) << name << ": " << te;
      EXPECT_NE(h.message.find("Transfer-Encoding"), std::string::npos) << h.message;
      EXPECT_TRUE(h.close);
    }
  }
}

TEST(RequestHead, RefusesAContentLengthThatIsNotOneByteCountInRange) {
  const std::string post = "POST /api/cal/commit HTTP/1.1\r\n" + kHost;
  for (const char* v : {"abc", "", "1 2", "+2", "-1", "2.0", "0x10", "1%30", "99999999999"})
    EXPECT_EQ(StatusOf(post + "Content-Length: " + v + "\r\n\r\n"), 400) << "'" << v << "'";
  EXPECT_EQ(StatusOf(post + "Content-Length: 2\r\nContent-Length: 2\r\n\r\n"), 400);
  EXPECT_EQ(StatusOf(post + "Content-Length: 65537\r\n\r\n"), 413);
  EXPECT_EQ(StatusOf(post + "Content-Length: 65536\r\n\r\n"), 200);
  EXPECT_EQ(StatusOf(post + "\r\n"), 411);  // a POST states its length
  EXPECT_EQ(StatusOf("GET /api/state HTTP/1.1\r\n" + kHost + "Content-Length: 5\r\n\r\n"), 400);
  EXPECT_EQ(StatusOf("GET /api/state HTTP/1.1\r\n" + kHost + "Content-Length: 0\r\n\r\n"), 200);
}

TEST(RequestHead, CapsTheRequestLineAndTheHeadersBeforeTheyAreWhole) {
  // No line end yet: one byte past the cap is enough to refuse.
  const std::string line = "GET /" + std::string(kMaxRequestLineBytes, 'a');
  EXPECT_EQ(StatusOf(line.substr(0, kMaxRequestLineBytes)), 0);
  EXPECT_EQ(StatusOf(line), 414);
  EXPECT_EQ(StatusOf(line + " HTTP/1.1\r\n" + kHost + "\r\n"), 414);
  const std::string big =
      "GET / HTTP/1.1\r\n" + kHost + "X-Pad: " + std::string(kMaxHeadBytes, 'b');
  EXPECT_EQ(StatusOf(big), 431);
  EXPECT_EQ(StatusOf(big + "\r\n\r\n"), 431);
}

TEST(RequestHead, RefusesMalformedLines) {
  const std::string get = "GET / HTTP/1.1\r\n";
  EXPECT_EQ(StatusOf("GET / HTTP/1.1\n" + kHost + "\r\n\r\n"), 400);  // a bare LF
  EXPECT_EQ(StatusOf(get + "Host: a\nX: b\r\n\r\n"), 400);
  EXPECT_EQ(StatusOf(get + kHost + "X: a\rb\r\n\r\n"), 400);  // a bare CR
  EXPECT_EQ(StatusOf(get + kHost + std::string("X: a\0b\r\n\r\n", 10)), 400);
  EXPECT_EQ(StatusOf(get + kHost + "X: a\r\n b\r\n\r\n"), 400);  // folded
  EXPECT_EQ(StatusOf(get + kHost + "no colon\r\n\r\n"), 400);
  EXPECT_EQ(StatusOf(get + kHost + "Bad Name: x\r\n\r\n"), 400);
  EXPECT_EQ(StatusOf(get + kHost + ": x\r\n\r\n"), 400);
  EXPECT_EQ(StatusOf(get + "\r\n"), 400);  // no Host
  EXPECT_EQ(StatusOf(get + kHost + kHost + "\r\n"), 400);
  EXPECT_EQ(StatusOf(get + kHost + "X-Vibid-Token: a\r\nx-vibid-token: b\r\n\r\n"), 400);
  EXPECT_EQ(StatusOf(get + kHost + "Expect: 100-continue\r\n\r\n"), 417);
  EXPECT_EQ(StatusOf("PUT / HTTP/1.1\r\n" + kHost + "\r\n"), 405);
  EXPECT_EQ(StatusOf("GET / HTTP/2.0\r\n" + kHost + "\r\n"), 505);
  EXPECT_EQ(StatusOf("GET / HTTP/1.1 x\r\n" + kHost + "\r\n"), 400);
  EXPECT_EQ(StatusOf("GET  / HTTP/1.1\r\n" + kHost + "\r\n"), 400);
  EXPECT_EQ(StatusOf("GET api HTTP/1.1\r\n" + kHost + "\r\n"), 400);
  EXPECT_EQ(StatusOf("\r\n" + kHost + "\r\n"), 400);
}

}  // namespace
}  // namespace vibid::bench
