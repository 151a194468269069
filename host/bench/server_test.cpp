// The bench's server in-process against the firmware core (hil CoreLoopback): what the gate
// refuses never reaches the board, bad bodies get 400 with a message, and an acquisition's data
// reach the live channel and the disk.
#include "vibid/bench/server.hpp"

#include "vibid/bench/calibration_routes.hpp"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <thread>

#include <gtest/gtest.h>
#include <httplib.h>

#include "core_loopback.hpp"
#include "vibid/device/calibration_upload.hpp"
#include "vibid/shared/fixed/filter_description.hpp"

namespace vibid::bench {
namespace {

namespace fs = std::filesystem;

/// What the board shows of its state: it must not move under a refused request.
struct BoardFacts {
  wire::AcqState acq_state;
  std::uint8_t dob_running;
  std::uint32_t ticks;
  std::uint32_t records_written;
  std::uint32_t cal_sequence;
  wire::CalState cal_state;
  std::uint32_t cal_crc;
  bool operator==(const BoardFacts&) const = default;
};

class BenchServerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("vibid-bench-test-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    connection_ = std::make_unique<device::Connection>(core_.Connect());
    probe_ = std::make_unique<device::Connection>(core_.Connect());
    board_ = std::make_unique<BenchBoard>(*connection_, dir_.string(), hub_, &interrupt_);
    server_ = std::make_unique<BenchServer>(*board_, hub_, ServerOptions{});
    AddCalibrationRoutes(*server_, *board_, dir_.string(), "0.1.0");
    server_->Start();
    host_ = "127.0.0.1:" + std::to_string(server_->port());
  }
  void TearDown() override {
    server_.reset();
    board_.reset();
    fs::remove_all(dir_);
  }

  BoardFacts Facts() {
    const wire::StatusResponse st = probe_->GetStatus();
    const wire::InfoResponse info = probe_->GetInfo();
    return {st.acq_state,    st.dob_running, st.ticks,    st.records_written,
            st.cal_sequence, info.cal_state, info.cal_crc};
  }

  httplib::Client Client() {
    httplib::Client c("127.0.0.1", server_->port());
    c.set_read_timeout(5, 0);
    return c;
  }
  httplib::Headers Authorized(httplib::Headers h = {}) {
    h.emplace(kTokenHeader, server_->token());
    return h;
  }
  static std::string AcquireBody() {
    return R"({"sample_period_us":1000,"channels":["force1","acc1"],"seconds":0.3})";
  }

  hil::CoreLoopback core_;
  LiveHub hub_;
  std::atomic<bool> interrupt_{false};  // Ctrl-C, as the CLI's SIGINT handler sets it
  fs::path dir_;
  std::unique_ptr<device::Connection> connection_;
  std::unique_ptr<device::Connection> probe_;
  std::unique_ptr<BenchBoard> board_;
  std::unique_ptr<BenchServer> server_;
  std::string host_;
};

TEST_F(BenchServerTest, ListensOnLoopbackAndPrintsItsTokenInTheUrl) {
  EXPECT_EQ(server_->Url(), "http://" + host_ + "/?token=" + server_->token());
  EXPECT_EQ(server_->token().size(), 32u);
}

TEST_F(BenchServerTest, RefusedRequestsLeaveTheBoardUntouched) {
  const BoardFacts before = Facts();
  httplib::Client c = Client();
  struct Case {
    const char* what;
    httplib::Headers headers;
  };
  const std::vector<Case> cases = {
      {"no token", {}},
      {"wrong token", {{kTokenHeader, std::string(32, '0')}}},
      {"the token in a cookie",
       {{"Cookie", std::string(kOldTokenCookie) + "=" + server_->token()}}},
      {"foreign Origin", Authorized({{"Origin", "http://evil.example"}})},
      {"non-local Host", Authorized({{"Host", "evil.example:" + std::to_string(server_->port())}})},
  };
  for (const Case& k : cases) {
    for (const char* path : {"/api/acquire", "/api/observer"}) {
      const std::string body =
          std::string(path) == "/api/acquire" ? AcquireBody() : R"({"run":true})";
      const auto r = c.Post(path, k.headers, body, "application/json");
      ASSERT_TRUE(r) << k.what;
      EXPECT_EQ(r->status, 403) << k.what << " " << path;
      EXPECT_FALSE(r->body.empty()) << k.what;
      EXPECT_FALSE(r->has_header("Access-Control-Allow-Origin"));
    }
    const auto g = c.Get("/api/board", k.headers);
    ASSERT_TRUE(g);
    EXPECT_EQ(g->status, 403) << k.what;
    const auto live = c.Get("/api/live", k.headers);
    ASSERT_TRUE(live);
    EXPECT_EQ(live->status, 403) << k.what << " (live channel)";
  }
  // The query token of the printed URL with a foreign Origin is refused too.
  const auto q = c.Get("/?token=" + server_->token(), {{"Origin", "http://evil.example"}});
  ASSERT_TRUE(q);
  EXPECT_EQ(q->status, 403);
  EXPECT_EQ(Facts(), before);
  EXPECT_EQ(board_->State()["running"], false);
}

TEST_F(BenchServerTest, ThePageLoadsWithoutACookieAndItsRequestsCarryTheToken) {
  httplib::Client c = Client();
  const auto page = c.Get("/?token=" + server_->token());
  ASSERT_TRUE(page);
  ASSERT_EQ(page->status, 200);
  EXPECT_NE(page->body.find("vibid bench"), std::string::npos);
  EXPECT_FALSE(page->has_header("Set-Cookie"));  // cookies go to every port of the host
  // The page's own files are the same in every bench: no token needed (a reload has none).
  const auto js = c.Get("/assets/uPlot.iife.min.js");
  ASSERT_TRUE(js);
  EXPECT_EQ(js->status, 200);
  EXPECT_GT(js->body.size(), 10000u);  // the embedded plotting library
  // Same-origin requests from the page carry their Origin: accepted.
  const auto board = c.Get("/api/board", Authorized({{"Origin", "http://" + host_}}));
  ASSERT_TRUE(board);
  EXPECT_EQ(board->status, 200);
  const nlohmann::json j = nlohmann::json::parse(board->body);
  EXPECT_EQ(j["calibration"]["state"], "uncalibrated");
  EXPECT_EQ(j["channels"][0]["unit"], "counts");
}

TEST_F(BenchServerTest, OversizedAndMalformedBodiesGetAMessageAndChangeNothing) {
  const BoardFacts before = Facts();
  httplib::Client c = Client();
  const std::string big(kMaxBodyBytes + 1, ' ');
  const auto over = c.Post("/api/acquire", Authorized(), big, "application/json");
  ASSERT_TRUE(over);
  EXPECT_EQ(over->status, 413);
  EXPECT_NE(over->body.find("65536 bytes"), std::string::npos) << over->body;
  const std::vector<std::pair<std::string, std::string>> bad = {
      {R"({"sample_period_us":1000,)", "malformed JSON"},
      {R"({"sample_period_us":1000,"channels":["force1"],"seconds":1,"colour":1})",
       "unknown key 'colour'"},
      {R"({"sample_period_us":50,"channels":["force1"],"seconds":1})", "outside 100..1000000"},
      {R"({"sample_period_us":1000,"channels":["force1"],"seconds":1e9})", "'seconds'"},
      {R"({"sample_period_us":1000,"channels":["force1"],"seconds":1,"log_dob":true})",
       "no observer"},
      {R"([1,2])", "JSON object"},
  };
  for (const auto& [body, expected] : bad) {
    const auto r = c.Post("/api/acquire", Authorized(), body, "application/json");
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 400) << body;
    EXPECT_NE(r->body.find(expected), std::string::npos) << body << " -> " << r->body;
  }
  const auto form =
      c.Post("/api/acquire", Authorized(), AcquireBody(), "application/x-www-form-urlencoded");
  ASSERT_TRUE(form);
  EXPECT_EQ(form->status, 400);
  const auto obs = c.Post("/api/observer", Authorized(), R"({"run":"yes"})", "application/json");
  ASSERT_TRUE(obs);
  EXPECT_EQ(obs->status, 400);
  EXPECT_EQ(Facts(), before);
}

TEST_F(BenchServerTest, CalibrationRequestsNameFilesInTheBenchDirectoryOnly) {
  const BoardFacts before = Facts();
  httplib::Client c = Client();
  const std::vector<std::pair<std::string, std::string>> bad = {
      {R"({"model":"../../etc/passwd","design":"d.json"})",
       "is not a file in the bench's directory"},
      {R"({"model":"/etc/passwd","design":"d.json"})", "is not a file in the bench's directory"},
      {R"({"model":".hidden","design":"d.json"})", "is not a file in the bench's directory"},
      {R"({"model":"saved/../../x.json","design":"d.json"})",
       "is not a file in the bench's directory"},
      {R"({"model":"saved//x.json","design":"d.json"})", "is not a file in the bench's directory"},
      {R"({"model":"m.json"})", "'design' is missing"},
      {R"({"model":"m.json","design":"d.json","sensor":"s.json"})", "unknown key 'sensor'"},
      {R"({"model":"missing.json","design":"d.json"})", "missing.json"},
  };
  for (const char* route : {"/api/cal/preview", "/api/cal/upload"}) {
    for (const auto& [body, expected] : bad) {
      const auto r = c.Post(route, Authorized(), body, "application/json");
      ASSERT_TRUE(r);
      EXPECT_EQ(r->status, 400) << route << " " << body;
      EXPECT_NE(r->body.find(expected), std::string::npos) << body << " -> " << r->body;
    }
  }
  const auto commit = c.Post("/api/cal/commit", Authorized(), R"({"now":1})", "application/json");
  ASSERT_TRUE(commit);
  EXPECT_EQ(commit->status, 400);
  const auto foreign =
      c.Post("/api/cal/commit", {{"Origin", "http://evil.example"}}, "{}", "application/json");
  ASSERT_TRUE(foreign);
  EXPECT_EQ(foreign->status, 403);
  EXPECT_EQ(Facts(), before);
}

TEST_F(BenchServerTest, CtrlCStopsTheAcquisitionAndKeepsWhatItRecorded) {
  board_->AddAcquisitionListener({.records = [&](std::span<const wire::LogRecord>) {
    interrupt_ = true;  // as soon as the first records are in
  }});
  httplib::Client c = Client();
  const auto r = c.Post("/api/acquire", Authorized(),
                        R"({"sample_period_us":1000,"channels":["force1"],"seconds":3600})",
                        "application/json");
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200) << r->body;
  board_->Shutdown();  // waits for the recording
  const nlohmann::json st = board_->State();
  ASSERT_TRUE(st.contains("file")) << st.dump();
  EXPECT_EQ(st["stopped"], true);
  EXPECT_GT(st["records"].get<int>(), 0);
  EXPECT_LT(st["records"].get<int>(), 3600000);
  EXPECT_TRUE(fs::exists(st["file"].get<std::string>()));
  EXPECT_EQ(Facts().acq_state, wire::AcqState::kIdle);  // the board left idle
}

TEST(RecordChanges, ListsTheFieldsThatDifferAndNotTheTimeOfBuilding) {
  const nlohmann::json now = {{"label", "rig"},          {"M", {{2.0}}},
                              {"K", {{4000.0}}},         {"created_unix_s", 1},
                              {"host_version", "0.1.0"}, {"observer", nullptr}};
  nlohmann::json next = now;
  next["M"] = {{1.8}};
  next["created_unix_s"] = 2;
  next["host_version"] = "0.2.0";
  next["observer"] = {{"sample_rate_hz", 5000}};
  const nlohmann::json changes = RecordChanges(now, next);
  ASSERT_EQ(changes.size(), 2u);
  EXPECT_EQ(changes[0]["field"], "M");
  EXPECT_EQ(changes[0]["from"], nlohmann::json({{2.0}}));
  EXPECT_EQ(changes[0]["to"], nlohmann::json({{1.8}}));
  EXPECT_EQ(changes[1]["field"], "observer");
  EXPECT_TRUE(changes[1]["from"].is_null());
  // An uncalibrated board: every field of the new record is a change.
  EXPECT_EQ(RecordChanges(nullptr, next).size(), 4u);
}

// Two observers alike in rate, mass and sensors, their coefficients apart: "Show the changes"
// lists the observer, with each one's checksum (the CRC the description carries).
TEST(RecordChanges, AnObserverWhoseCoefficientsAloneChangedIsAChange) {
  const auto record = [](std::int32_t gain) {
    fixed::FilterDescription d;
    d.input_count = 1;
    d.output_dof = 1;
    d.sample_rate_hz = 1000;
    d.paths[0].section_count = 1;
    d.paths[0].output_gain = gain;
    d.checksum = fixed::ComputeChecksum(d);
    wire::CalibrationRecord r{};
    r.dof_count = 2;
    r.flags = wire::kCalFlagHasDob;
    fixed::EncodeDescription(d, std::span<std::uint8_t, fixed::kDescriptionBytes>(
                                    r.dob.data(), fixed::kDescriptionBytes));
    return std::pair{device::RecordJson(r), d.checksum};
  };
  const auto [now, crc_now] = record(1000);
  const auto [next, crc_next] = record(1001);
  ASSERT_NE(crc_now, crc_next);
  char hex[11];
  std::snprintf(hex, sizeof hex, "0x%08x", crc_next);
  EXPECT_EQ(next["observer"]["checksum"], hex);
  const nlohmann::json changes = RecordChanges(now, next);
  ASSERT_EQ(changes.size(), 1u) << changes.dump();
  EXPECT_EQ(changes[0]["field"], "observer");
  EXPECT_EQ(RecordChanges(now, now).size(), 0u);
}

TEST_F(BenchServerTest, AnAcquisitionReachesTheLiveChannelAndTheDisk) {
  // A view's listener (the hammer session's way in) sees the same records, each once, in order.
  std::uint32_t started_period_us = 0;
  std::vector<std::uint32_t> indices;
  nlohmann::json ended;
  board_->AddAcquisitionListener(
      {.started =
           [&](const AcquisitionAsk&, const wire::AcqConfigureRequest& cfg) {
             started_period_us = cfg.sample_period_us;
           },
       .records =
           [&](std::span<const wire::LogRecord> r) {
             for (const wire::LogRecord& x : r) indices.push_back(x.sample_index);
           },
       .ended = [&](const nlohmann::json& st) { ended = st; }});
  // The live channel first: the blocks it carries are the acquisition's, in SI columns.
  std::string received;
  std::atomic<bool> saw_block{false};
  std::thread reader([&] {
    httplib::Client c = Client();
    // Until the state event that says the acquisition ended (a bound only against a hang).
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    c.Get("/api/live", Authorized(), [&](const char* data, std::size_t n) {
      received.append(data, n);
      const std::size_t block = received.find("event: block");
      if (block != std::string::npos && received.find("\"file\":", block) != std::string::npos) {
        saw_block = true;
        return false;
      }
      return std::chrono::steady_clock::now() < give_up;
    });
  });
  httplib::Client c = Client();
  const auto r = c.Post("/api/acquire", Authorized(), AcquireBody(), "application/json");
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200) << r->body;
  // A second start while it runs is refused as busy.
  const auto again = c.Post("/api/acquire", Authorized(), AcquireBody(), "application/json");
  ASSERT_TRUE(again);
  EXPECT_TRUE(again->status == 409 || again->status == 200) << again->body;
  reader.join();
  board_->Shutdown();
  EXPECT_TRUE(saw_block.load());
  EXPECT_NE(received.find("\"names\":[\"t_s\",\"force1_counts\",\"acc1_counts\"]"),
            std::string::npos);
  const nlohmann::json st = board_->State();
  ASSERT_TRUE(st.contains("file")) << st.dump();
  EXPECT_EQ(st["records"], 300);  // 0.3 s at 1 kHz
  std::ifstream csv(st["file"].get<std::string>());
  std::string line;
  int lines = 0;
  while (std::getline(csv, line))
    if (!line.empty() && line[0] != '#') ++lines;
  EXPECT_EQ(lines, 301);  // header + 300 records
  EXPECT_EQ(started_period_us, 1000u);
  ASSERT_EQ(indices.size(), 300u);
  for (std::size_t i = 0; i < indices.size(); ++i) ASSERT_EQ(indices[i], i);  // decimation 1
  EXPECT_EQ(ended["file"], st["file"]);
  // The journal was replaced by the checked recording.
  EXPECT_FALSE(fs::exists(dir_ / (st["name"].get<std::string>() + ".partial.csv")));
}

}  // namespace
}  // namespace vibid::bench
