// The metrics port of `vibid watch`: the exposition behind the bench's gate, on loopback only.
#include "vibid/bench/metrics_server.hpp"

#include <gtest/gtest.h>

#include "vibid/common/error.hpp"
// clang-format off
#include <httplib.h>
// clang-format on

namespace vibid::bench {
namespace {

const std::string kToken = "00112233445566778899aabbccddeeff";
const std::string kText = "# HELP x A figure\n# TYPE x gauge\nx{rig=\"a\"} 1\n";

TEST(MetricsServer, ServesTheExpositionToABearerOfItsTokenOnly) {
  MetricsServer server({.bind = "127.0.0.1", .port = 0, .token = kToken, .front = {}},
                       [] { return kText; });
  server.Start();
  ASSERT_GT(server.port(), 0);
  EXPECT_EQ(server.Url(), "http://127.0.0.1:" + std::to_string(server.port()) + "/metrics");
  httplib::Client c("127.0.0.1", server.port());
  const auto ok = c.Get("/metrics", {{"Authorization", "Bearer " + kToken}});
  ASSERT_TRUE(ok);
  EXPECT_EQ(ok->status, 200);
  EXPECT_EQ(ok->body, kText);
  // The format's content type, version 0.0.4 (Prometheus's exposition formats).
  EXPECT_EQ(ok->get_header_value("Content-Type"), "text/plain; version=0.0.4; charset=utf-8");
  EXPECT_EQ(ok->get_header_value("Cache-Control"), "no-store");  // the bench's headers

  const auto none = c.Get("/metrics");
  ASSERT_TRUE(none);
  EXPECT_EQ(none->status, 403);
  const auto wrong = c.Get("/metrics", {{"Authorization", "Bearer " + std::string(32, '0')}});
  ASSERT_TRUE(wrong);
  EXPECT_EQ(wrong->status, 403);
  // A page of another site reaching the port through its own name (DNS rebinding).
  const auto rebound =
      c.Get("/metrics", {{"Authorization", "Bearer " + kToken}, {"Host", "evil.example"}});
  ASSERT_TRUE(rebound);
  EXPECT_EQ(rebound->status, 403);
  // Nothing else is served, and the bearer token opens nothing else.
  const auto other = c.Get("/api/state", {{"Authorization", "Bearer " + kToken}});
  ASSERT_TRUE(other);
  EXPECT_EQ(other->status, 403);
  const auto page = c.Get("/api/state", {{"X-Vibid-Token", kToken}});
  ASSERT_TRUE(page);
  EXPECT_EQ(page->status, 404);
  server.Stop();
}

TEST(MetricsServer, RefusesAnAddressBeyondLoopback) {
  MetricsServer server({.bind = "0.0.0.0", .port = 0, .token = kToken, .front = {}},
                       [] { return kText; });
  try {
    server.Start();
    FAIL() << "0.0.0.0 was served";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("loopback"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace vibid::bench
