#include "vibid/bench/gate.hpp"

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>

#include <gtest/gtest.h>

namespace vibid::bench {
namespace {

const std::string kToken = "00112233445566778899aabbccddeeff";

Gate MakeGate() { return Gate(kToken, {"127.0.0.1:8080", "localhost:8080"}); }

RequestFacts Good() {
  RequestFacts f;
  f.host = "127.0.0.1:8080";
  f.header_token = kToken;
  f.method = "POST";
  f.path = "/api/acquire";
  return f;
}

TEST(Gate, TokenIs128BitsOfHexAndDiffersEachTime) {
  std::set<std::string> seen;
  for (int i = 0; i < 16; ++i) {
    const std::string t = NewToken();
    ASSERT_EQ(t.size(), 32u);  // 128 bits, 4 per hex digit
    EXPECT_EQ(t.find_first_not_of("0123456789abcdef"), std::string::npos) << t;
    seen.insert(t);
  }
  EXPECT_EQ(seen.size(), 16u);
}

TEST(Gate, TheTokenIsTheKernelBytesInHexInOrder) {
  // Reference: the bytes 0x00, 0x01, ..., 0x0f, 0xa5, 0xff written two lower-case hex digits each.
  const unsigned char bytes[] = {0x00, 0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07, 0x08,
                                 0x09, 0x0a, 0x0b, 0x0c, 0x0d, 0x0e, 0x0f, 0xa5, 0xff};
  EXPECT_EQ(HexOf(bytes, sizeof bytes), "000102030405060708090a0b0c0d0e0fa5ff");
}

TEST(Gate, AcceptsTheTokenInItsHeaderOnly) {
  const Gate g = MakeGate();
  EXPECT_FALSE(g.Check(Good()));
  RequestFacts l = Good();
  l.host = "localhost:8080";
  l.origin = "http://localhost:8080";
  EXPECT_FALSE(g.Check(l));
  // The printed URL's query token opens the page, not the API: a URL is no credential for it.
  RequestFacts q = Good();
  q.header_token.clear();
  q.query_token = kToken;
  EXPECT_TRUE(g.Check(q));
  q.path = "/";
  q.method = "GET";
  EXPECT_FALSE(g.Check(q));
}

TEST(Gate, ThePageFilesNeedNoTokenButTheirHostAndOrigin) {
  const Gate g = MakeGate();
  for (const char* path : {"/", "/assets/bench.js", "/views/hammer.js"}) {
    RequestFacts f = Good();
    f.header_token.clear();
    f.method = "GET";
    f.path = path;
    EXPECT_FALSE(g.Check(f)) << path;
    f.host = "evil.example:8080";  // DNS rebinding: refused on the page too
    EXPECT_TRUE(g.Check(f)) << path;
    f.host = "127.0.0.1:8080";
    f.query_token = std::string(32, '0');  // a wrong printed token is refused on the page too
    EXPECT_TRUE(g.Check(f)) << path;
  }
  for (const char* path :
       {"/api/state", "/api/live", "/api/views", "/views/hammer.json", "/assets"}) {
    RequestFacts f = Good();
    f.header_token.clear();
    f.method = "GET";
    f.path = path;
    EXPECT_TRUE(g.Check(f)) << path;
  }
  RequestFacts post = Good();
  post.header_token.clear();
  post.method = "POST";
  post.path = "/";
  EXPECT_TRUE(g.Check(post));
}

TEST(Gate, RefusesMissingWrongOrTruncatedTokens) {
  const Gate g = MakeGate();
  RequestFacts none = Good();
  none.header_token.clear();
  ASSERT_TRUE(g.Check(none));
  EXPECT_EQ(g.Check(none)->status, 403);
  RequestFacts wrong = Good();
  wrong.header_token[31] = '0';
  EXPECT_TRUE(g.Check(wrong));
  RequestFacts prefix = Good();
  prefix.header_token = kToken.substr(0, 31);
  EXPECT_TRUE(g.Check(prefix));
}

TEST(Gate, RefusesForeignHostsAndOrigins) {
  const Gate g = MakeGate();
  for (const char* host : {"evil.example:8080", "127.0.0.1:8081", "127.0.0.1", ""}) {
    RequestFacts f = Good();
    f.host = host;
    ASSERT_TRUE(g.Check(f)) << host;
    EXPECT_NE(g.Check(f)->message.find("Host"), std::string::npos);
  }
  for (const char* origin :
       {"http://evil.example", "http://localhost:8080", "null", "https://127.0.0.1:8080"}) {
    RequestFacts f = Good();
    f.origin = origin;  // Host is 127.0.0.1:8080: its own origin is http://127.0.0.1:8080
    ASSERT_TRUE(g.Check(f)) << origin;
    EXPECT_NE(g.Check(f)->message.find("Origin"), std::string::npos);
  }
}

TEST(Gate, AScraperShowsTheTokenAsABearerTokenOnTheMetricsOnly) {
  const Gate g = MakeGate();
  RequestFacts scrape;
  scrape.host = "127.0.0.1:8080";
  scrape.method = "GET";
  scrape.path = "/metrics";
  scrape.bearer_token = BearerToken("Bearer " + kToken);
  EXPECT_FALSE(g.Check(scrape));
  RequestFacts head = scrape;
  head.method = "HEAD";
  EXPECT_FALSE(g.Check(head));
  // The header token works there too (the page's own way).
  RequestFacts header = scrape;
  header.bearer_token.clear();
  header.header_token = kToken;
  EXPECT_FALSE(g.Check(header));
  // Nowhere else: a bearer token does not open the API.
  RequestFacts api = Good();
  api.header_token.clear();
  api.bearer_token = kToken;
  EXPECT_TRUE(g.Check(api));
  RequestFacts post = scrape;
  post.method = "POST";
  EXPECT_TRUE(g.Check(post));
  // The Host rule holds for a scraper as for the page.
  RequestFacts foreign = scrape;
  foreign.host = "evil.example:8080";
  EXPECT_TRUE(g.Check(foreign));
  RequestFacts wrong = scrape;
  wrong.bearer_token = BearerToken("Bearer " + std::string(32, '0'));
  const std::optional<Refusal> r = g.Check(wrong);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 403);
  EXPECT_NE(r->message.find("bearer token"), std::string::npos) << r->message;
}

TEST(Gate, TheBearerSchemeIsReadWithoutRegardToCase) {
  // RFC 9110, 11.1: the scheme is case-insensitive; RFC 6750, 2.1: "Bearer" SP token.
  EXPECT_EQ(BearerToken("Bearer abc"), "abc");
  EXPECT_EQ(BearerToken("bearer abc"), "abc");
  EXPECT_EQ(BearerToken("BEARER abc"), "abc");
  EXPECT_EQ(BearerToken("Basic abc"), "");
  EXPECT_EQ(BearerToken("Bearer"), "");
  EXPECT_EQ(BearerToken("Bearer "), "");
  EXPECT_EQ(BearerToken(""), "");
}

TEST(Gate, ATokenFileIsWrittenForItsOwnerAndReadBackTheSame) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("vibid-token-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "token").string();
  const std::string written = TokenFromFile(path);
  EXPECT_EQ(written.size(), 32u);
  EXPECT_EQ(std::filesystem::status(path).permissions() & std::filesystem::perms::all,
            std::filesystem::perms::owner_read | std::filesystem::perms::owner_write);
  EXPECT_EQ(TokenFromFile(path), written);
  // One a user wrote (a trailing newline or CR is not part of it).
  const std::string own = (dir / "own").string();
  std::ofstream(own) << "Abc-def_123.456~+/xyz\r\n";
  EXPECT_EQ(TokenFromFile(own), "Abc-def_123.456~+/xyz");
  // Too short, or with a character a bearer token cannot hold: refused, naming the file.
  const std::string bad = (dir / "bad").string();
  std::ofstream(bad) << "short\n";
  EXPECT_THROW(TokenFromFile(bad), std::exception);
  std::ofstream(bad) << "spaces are not in tokens at all\n";
  EXPECT_THROW(TokenFromFile(bad), std::exception);
  std::filesystem::remove_all(dir);
}

TEST(Gate, AnIpv6AddressIsBracketedInUrlsAndHosts) {
  EXPECT_EQ(UrlHost("::1"), "[::1]");
  EXPECT_EQ(UrlHost("127.0.0.1"), "127.0.0.1");
  EXPECT_EQ(UrlHost("localhost"), "localhost");
  const Gate g(kToken, {"[::1]:8080", "localhost:8080"});
  RequestFacts f = Good();
  f.host = "[::1]:8080";  // what a browser sends for http://[::1]:8080/
  f.origin = "http://[::1]:8080";
  EXPECT_FALSE(g.Check(f));
  f.host = "::1:8080";
  f.origin.clear();
  EXPECT_TRUE(g.Check(f));
}

}  // namespace
}  // namespace vibid::bench
