#include "vibid/bench/gate.hpp"

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

TEST(Gate, AcceptsTheTokenFromQueryHeaderOrCookie) {
  const Gate g = MakeGate();
  EXPECT_FALSE(g.Check(Good()));
  RequestFacts q = Good();
  q.header_token.clear();
  q.query_token = kToken;
  EXPECT_FALSE(g.Check(q));
  RequestFacts c = Good();
  c.header_token.clear();
  c.cookie = "other=1; vibid_bench_token=" + kToken + "; x=y";
  EXPECT_FALSE(g.Check(c));
  RequestFacts l = Good();
  l.host = "localhost:8080";
  l.origin = "http://localhost:8080";
  EXPECT_FALSE(g.Check(l));
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
  RequestFacts cookie_name = Good();
  cookie_name.header_token.clear();
  cookie_name.cookie = "xvibid_bench_token=" + kToken;
  EXPECT_TRUE(g.Check(cookie_name));
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

TEST(Gate, CookieValueParsesPairs) {
  EXPECT_EQ(CookieValue("a=1; b=2", "b"), "2");
  EXPECT_EQ(CookieValue("a=1;b=2", "a"), "1");
  EXPECT_EQ(CookieValue("ab=1", "a"), "");
  EXPECT_EQ(CookieValue("", "a"), "");
}

}  // namespace
}  // namespace vibid::bench
