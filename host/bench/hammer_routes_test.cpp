// The hammer view's routes in-process against the firmware core: settings the session or the
// acquisition refuses are answered 400 with the refusal's message, nothing is created and the
// board does not move; before a test, the choices and traces are refused and the snapshot is empty.
#include "vibid/bench/hammer_routes.hpp"

#include <filesystem>

#include <gtest/gtest.h>
#include <httplib.h>

#include "bench_on_core.hpp"

namespace vibid::bench {
namespace {

namespace fs = std::filesystem;

class HammerRoutesTest : public testing::BenchOnCore {
 protected:
  void SetUp() override {
    StartBench("hammer-routes-test",
               [this] { tests_ = AddHammerRoutes(*server_, *board_, hub_, dir_.string()); });
  }

  /// POST /api/hammer/`route`.
  httplib::Result Hammer(const std::string& route, const std::string& body) {
    return Post("hammer/" + route, body);
  }

  std::shared_ptr<HammerTests> tests_;
};

constexpr const char* kGood =
    R"("channels":["force1","acc1","acc2"],"sample_period_us":200,"seconds":10,"record_s":1,)"
    R"("hammer_point":"acc2")";

TEST_F(HammerRoutesTest, RefusedSettingsGet400WithTheirMessageAndChangeNothing) {
  const wire::StatusResponse before = probe_->GetStatus();
  const std::size_t entries = Entries();
  const std::string good = kGood;
  const std::vector<std::pair<std::string, std::string>> bad = {
      // The session's own checks (HammerSessionOptions::Validate).
      {"{" + good + R"(,"pretrigger_s":0.6})",
       "--pretrigger-s must be shorter than half of --record-s"},
      {"{" + good + R"(,"exp_window":-1})", "exp"},
      // The view's settings.
      {R"({"channels":["force1","acc1"],"sample_period_us":200,"seconds":10,"record_s":-1,)"
       R"("hammer_point":"acc1"})",
       "'record_s' must be >= 0"},
      {"{" + good + R"(,"hammer_point":"acc3"})", "'hammer_point'"},
      {R"({"channels":["acc1","force1"],"sample_period_us":200,"seconds":10,"record_s":1,)"
       R"("hammer_point":"force1"})",
       "the first channel must be the hammer's load cell"},
      {"{" + good + R"(,"windoe":1})", "unknown key 'windoe'"},
      // The acquisition's (the same checks as POST /api/acquire).
      {R"({"channels":["force1","acc1"],"sample_period_us":200,"seconds":-1,"record_s":1,)"
       R"("hammer_point":"acc1"})",
       "'seconds'"},
      // Good settings on an uncalibrated board: the force would be in counts.
      {"{" + good + "}", "the board is uncalibrated"},
  };
  for (const auto& [body, expected] : bad) {
    const auto r = Hammer("start", body);
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 400) << body;
    EXPECT_NE(r->body.find(expected), std::string::npos) << body << " -> " << r->body;
  }
  EXPECT_EQ(Entries(), entries);
  const wire::StatusResponse after = probe_->GetStatus();
  EXPECT_EQ(after.acq_state, wire::AcqState::kIdle);
  EXPECT_EQ(after.records_written, before.records_written);
}

TEST_F(HammerRoutesTest, BeforeATestChoicesAndTracesAreRefusedAndTheSnapshotIsEmpty) {
  for (const auto& [route, body] :
       std::vector<std::pair<std::string, std::string>>{{"choose", R"({"index":1,"accept":true})"},
                                                        {"traces", R"({"index":1})"},
                                                        {"save", "{}"}}) {
    const auto r = Hammer(route, body);
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 400) << route;
    EXPECT_NE(r->body.find("no hammer test yet"), std::string::npos) << r->body;
  }
  const auto s = Hammer("snapshot", "{}");
  ASSERT_TRUE(s);
  ASSERT_EQ(s->status, 200);
  EXPECT_EQ(nlohmann::json::parse(s->body),
            nlohmann::json({{"test", nullptr}, {"snapshot", nullptr}}));
  const auto choose = Hammer("choose", R"({"index":0,"accept":"yes"})");
  ASSERT_TRUE(choose);
  EXPECT_EQ(choose->status, 400);
}

TEST_F(HammerRoutesTest, ThePreflightIsTheLinkBudgetAcquireChecks) {
  // 5 kHz, force1 + acc1 + acc2: 6-byte records (3 x 16 bit), well within the link.
  const auto r = Hammer("preflight", std::string("{") + kGood + "}");
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200) << r->body;
  const nlohmann::json b = nlohmann::json::parse(r->body);
  EXPECT_EQ(b["record_bytes"], 6);
  EXPECT_EQ(b["log_rate_hz"], 5000);
  EXPECT_EQ(b["keeps_up"], true);
  EXPECT_FALSE(b.contains("refusal"));
}

}  // namespace
}  // namespace vibid::bench
