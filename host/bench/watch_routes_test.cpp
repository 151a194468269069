// The Watch view's routes in-process against the firmware core: settings the library refuses are
// answered 400 with its message naming the option, nothing is created and the board does not
// move; a watch holds the board (another start, the hammer view's too, is 409) until Stop, which
// ends it with its journal kept; before a watch the snapshot is empty and the journal refused.
#include "vibid/bench/watch_routes.hpp"

#include <chrono>
#include <filesystem>
#include <fstream>
#include <thread>

#include <gtest/gtest.h>
#include <httplib.h>

#include "bench_on_core.hpp"
#include "vibid/bench/hammer_routes.hpp"

namespace vibid::bench {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

class WatchRoutesTest : public testing::BenchOnCore {
 protected:
  void SetUp() override {
    StartBench("watch-routes-test", [this] {
      hammer_ = AddHammerRoutes(*server_, *board_, hub_, dir_.string());
      runs_ = AddWatchRoutes(*server_, *board_, hub_, dir_.string());
    });
  }

  nlohmann::json Snapshot() {
    const auto r = Post("watch/snapshot", "{}");
    EXPECT_TRUE(r && r->status == 200);
    return r ? nlohmann::json::parse(r->body) : nlohmann::json();
  }

  std::shared_ptr<HammerTests> hammer_;
  std::shared_ptr<WatchRuns> runs_;
};

TEST_F(WatchRoutesTest, RefusedSettingsGet400WithTheLibrarysMessageAndChangeNothing) {
  const wire::StatusResponse before = probe_->GetStatus();
  const std::size_t entries = Entries();
  const std::vector<std::pair<std::string, std::string>> bad = {
      // The library's checks (WatchOptions::Validate, the plan), in vibid watch's words.
      {R"({"rate_hz":200,"block_s":1})", "--block-s 1 is too short for the band"},
      {R"({"rate_hz":200,"reference_s":60})", "--reference-s 60 is too short"},
      {R"({"rate_hz":200,"seconds":100})", "--seconds 100 ends before the first block"},
      {R"({"rate_hz":200,"scenario_params":[1,2,3,4,5]})", "--scenario-param takes at most 4"},
      // The view's reading of its settings.
      {R"({"rate_hz":"fast"})", "'rate_hz' must be a number"},
      {R"({"window_blocks":0})", "'window_blocks' must lie in 1 … 100000, not 0"},
      // Integers beyond an int are refused as given, never wrapped (2^32 + 6 is not 6).
      {R"({"window_blocks":4294967302})", "'window_blocks' must lie in 1 … 100000, not 4294967302"},
      {R"({"order":4294967300})", "'order' must lie in 0 … 40, not 4294967300"},
      {R"({"order":-4294967292})", "'order' must lie in 0 … 40, not -4294967292"},
      {R"({"window_blocks":18446744073709551615})", "not 18446744073709551615"},
      // Every field checked before the board is taken or the journal made.
      {R"({"rate_hz":200,"reference":"missing.csv"})", "missing.csv' cannot be read"},
      {R"({"rate_hz":200,"responses":["<img src=x>"]})", "is not a column of the log"},
      {R"({"rate_hz":200,"responses":["acc3_m_s2"]})", "'acc3_m_s2' is not a column of the log"},
      {R"({"rate_hz":200,"scenario_params":[1e300]})", "beyond a float"},
      {R"({"rate_hz":200,"false_alarm_per_hour":1e-320})", "must be at least 1e-06"},
      {R"({"rate_hz":200,"modes_s":1e12})", "--modes-s 1e+12 is longer than 3600 s"},
      {R"({"window_blocks":2.5})", "'window_blocks' must be a whole number"},
      {R"({"modes_s":-1})", "'modes_s' must be >= 0"},
      {R"({"blocks":6})", "unknown key 'blocks'"},
      {R"({"channels":"acc1"})", "'channels' must be a list of names"},
      {R"({"no_dob":1})", "'no_dob' must be true or false"},
      {R"({"reference":"ref.csv","reference_s":300})", "exclude each other"},
      {R"({"reference":"../ref.csv"})", "reference"},
      // The firmware core is no emulator: no scenario to select.
      {R"({"rate_hz":200,"scenario":"operate"})", "this board is not the emulator"},
  };
  for (const auto& [body, expected] : bad) {
    const auto r = Post("watch/start", body);
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 400) << body;
    EXPECT_NE(r->body.find(expected), std::string::npos) << body << " -> " << r->body;
  }
  EXPECT_EQ(Entries(), entries);
  const wire::StatusResponse after = probe_->GetStatus();
  EXPECT_EQ(after.acq_state, wire::AcqState::kIdle);
  EXPECT_EQ(after.records_written, before.records_written);
  EXPECT_EQ(Snapshot(), nlohmann::json({{"watch", nullptr}, {"blocks", nlohmann::json::array()}}));
  const auto journal = Post("watch/journal", "{}");
  ASSERT_TRUE(journal);
  EXPECT_EQ(journal->status, 400);
  EXPECT_NE(journal->body.find("nothing watched yet"), std::string::npos) << journal->body;
}

TEST_F(WatchRoutesTest, AWatchHoldsTheBoardUntilStopWhichKeepsItsJournal) {
  const auto start = Post("watch/start", R"({"rate_hz":200})");
  ASSERT_TRUE(start);
  ASSERT_EQ(start->status, 200) << start->body;
  const nlohmann::json started = nlohmann::json::parse(start->body);
  const std::string journal = started["journal"].get<std::string>();
  EXPECT_TRUE(fs::exists(journal));
  EXPECT_EQ(fs::path(journal).parent_path(), dir_);
  EXPECT_EQ(board_->State()["running"], true);
  EXPECT_EQ(board_->State()["view"], "watch");
  // One board user at a time: another watch, and the other views' acquisitions, wait for Stop.
  const auto again = Post("watch/start", R"({"rate_hz":200})");
  ASSERT_TRUE(again);
  EXPECT_EQ(again->status, 409) << again->body;
  const auto acquire =
      Post("acquire", R"({"sample_period_us":5000,"channels":["acc1"],"seconds":1})");
  ASSERT_TRUE(acquire);
  EXPECT_EQ(acquire->status, 409) << acquire->body;
  // The reference phase under way (the default 30 minutes): the board samples.
  const auto deadline = std::chrono::steady_clock::now() + 10s;
  while (Snapshot()["watch"]["start"].is_null()) {
    ASSERT_LT(std::chrono::steady_clock::now(), deadline) << Snapshot().dump();
    std::this_thread::sleep_for(10ms);
  }
  const nlohmann::json s = Snapshot()["watch"];
  EXPECT_EQ(s["start"]["responses"], nlohmann::json({"acc1_counts", "acc2_counts"}));
  EXPECT_EQ(s["start"]["log_rate_hz"], 200.0);
  EXPECT_EQ(s["start"]["board_columns"], false);
  EXPECT_EQ(s["options"]["reference_s"], 1800.0);  // WatchOptions' default
  ASSERT_TRUE(Post("watch/stop", "{}"));
  while (Snapshot()["watch"]["running"] != false) {
    ASSERT_LT(std::chrono::steady_clock::now(), deadline) << Snapshot().dump();
    std::this_thread::sleep_for(10ms);
  }
  const nlohmann::json end = Snapshot()["watch"];
  EXPECT_EQ(end["end"]["stopped"], true) << end.dump();
  EXPECT_EQ(end["end"]["reference_built"], false);
  EXPECT_GT(end["end"]["reference_left_s"].get<double>(), 0.0);
  EXPECT_EQ(end["error"], "");
  EXPECT_TRUE(fs::exists(journal));  // kept (no block yet: empty)
  EXPECT_EQ(fs::file_size(journal), 0u);
  while (board_->State()["running"] != false) {
    ASSERT_LT(std::chrono::steady_clock::now(), deadline);
    std::this_thread::sleep_for(10ms);
  }
  EXPECT_NE(probe_->GetStatus().acq_state, wire::AcqState::kAcquiring);
  const auto text = Post("watch/journal", "{}");
  ASSERT_TRUE(text);
  ASSERT_EQ(text->status, 200);
  EXPECT_EQ(nlohmann::json::parse(text->body)["text"], "");
}

// Each view's Stop ends its own run only; the page's Stop ends any. A watch's journal is named by
// its absolute path.
TEST_F(WatchRoutesTest, EachStopRouteStopsOnlyItsOwnRun) {
  const auto deadline = std::chrono::steady_clock::now() + 10s;
  const auto idle = [&] {
    while (board_->State()["running"] != false) {
      ASSERT_LT(std::chrono::steady_clock::now(), deadline);
      std::this_thread::sleep_for(10ms);
    }
  };
  // Nothing runs: every Stop is a no-op.
  for (const char* route : {"stop", "watch/stop", "hammer/stop"}) {
    const auto r = Post(route, "{}");
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 200) << route << " " << r->body;
  }
  const auto start = Post("watch/start", R"({"rate_hz":200})");
  ASSERT_TRUE(start);
  ASSERT_EQ(start->status, 200) << start->body;
  const std::string journal = nlohmann::json::parse(start->body)["journal"];
  EXPECT_TRUE(fs::path(journal).is_absolute()) << journal;
  const auto hammer_stop = Post("hammer/stop", "{}");
  ASSERT_TRUE(hammer_stop);
  EXPECT_EQ(hammer_stop->status, 409);
  EXPECT_NE(hammer_stop->body.find("no hammer test runs: the board runs a watch"),
            std::string::npos)
      << hammer_stop->body;
  std::this_thread::sleep_for(200ms);
  EXPECT_EQ(board_->State()["running"], true) << "the hammer view's Stop ended a watch";
  const auto watch_stop = Post("watch/stop", "{}");
  ASSERT_TRUE(watch_stop);
  EXPECT_EQ(watch_stop->status, 200);
  idle();
  // A plain acquisition: neither view's Stop ends it, the page's does. The core loopback runs
  // faster than the clock (a 60 s record ends within half a second), so the acquisition is long
  // enough to be still running whatever the machine's load, and the page's Stop is seen to end it.
  const auto acquire =
      Post("acquire", R"({"sample_period_us":5000,"channels":["acc1"],"seconds":3600})");
  ASSERT_TRUE(acquire);
  ASSERT_EQ(acquire->status, 200) << acquire->body;
  for (const char* route : {"watch/stop", "hammer/stop"}) {
    const auto r = Post(route, "{}");
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 409) << route;
    EXPECT_NE(r->body.find("the board runs an acquisition"), std::string::npos) << r->body;
  }
  std::this_thread::sleep_for(200ms);
  EXPECT_EQ(board_->State()["running"], true) << board_->State().dump();
  const auto stop = Post("stop", "{}");
  ASSERT_TRUE(stop);
  EXPECT_EQ(stop->status, 200);
  idle();
  const nlohmann::json ended = board_->State();
  EXPECT_EQ(ended.value("stopped", false), true) << ended.dump();
  EXPECT_LT(ended.value("records", 0), 720000) << ended.dump();
}

}  // namespace
}  // namespace vibid::bench

namespace vibid::bench {
namespace {

class WatchMetricsRoutesTest : public testing::BenchOnCore {
 protected:
  void SetUp() override {
    StartBench("watch-metrics-test", [this] {
      runs_ = AddWatchRoutes(*server_, *board_, hub_, dir_.string(),
                             std::make_shared<workflow::WatchMetrics>("bench-a"));
    });
  }

  httplib::Result Scrape(const httplib::Headers& headers) {
    httplib::Client c("127.0.0.1", server_->port());
    return c.Get("/metrics", headers);
  }

  std::shared_ptr<WatchRuns> runs_;
};

TEST_F(WatchMetricsRoutesTest, TheRunningWatchIsScrapedWithTheBenchsTokenAsABearerToken) {
  const auto none = Scrape({});
  ASSERT_TRUE(none);
  EXPECT_EQ(none->status, 403);
  const auto start = Post("watch/start", R"({"rate_hz":200,"false_alarm_per_hour":0.5})");
  ASSERT_TRUE(start);
  ASSERT_EQ(start->status, 200) << start->body;
  const auto r = Scrape({{"Authorization", "Bearer " + server_->token()}});
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200) << r->body;
  EXPECT_EQ(r->get_header_value("Content-Type"), "text/plain; version=0.0.4; charset=utf-8");
  // The run's options as the start asked, its reference still to come.
  EXPECT_NE(r->body.find("\nvibid_watch_running{rig=\"bench-a\"} 1\n"), std::string::npos)
      << r->body;
  EXPECT_NE(r->body.find("\nvibid_watch_false_alarms_per_hour{rig=\"bench-a\"} 0.5\n"),
            std::string::npos);
  EXPECT_NE(r->body.find("\nvibid_watch_reference_ready{rig=\"bench-a\"} 0\n"), std::string::npos);
  // The page's header works too; the bearer token opens no other route.
  const auto header = Scrape({{kTokenHeader, server_->token()}});
  ASSERT_TRUE(header);
  EXPECT_EQ(header->status, 200);
  httplib::Client c("127.0.0.1", server_->port());
  const auto state = c.Get("/api/state", {{"Authorization", "Bearer " + server_->token()}});
  ASSERT_TRUE(state);
  EXPECT_EQ(state->status, 403);
  ASSERT_TRUE(Post("watch/stop", "{}"));
}

TEST_F(WatchRoutesTest, WithoutMetricsTheBenchServesNone) {
  httplib::Client c("127.0.0.1", server_->port());
  const auto r = c.Get("/metrics", {{kTokenHeader, server_->token()}});
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 404);
}

}  // namespace
}  // namespace vibid::bench
