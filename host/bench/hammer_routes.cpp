#include "vibid/bench/bench_files.hpp"
#include "vibid/bench/hammer_routes.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <ctime>
#include <filesystem>
#include <mutex>
#include <span>

#include "vibid/bench/acquisition_ask.hpp"
#include "vibid/bench/assets.hpp"
#include "vibid/common/error.hpp"
#include "vibid/common/json_keys.hpp"
#include "vibid/device/log_table.hpp"
#include "vibid/ident/impact.hpp"
#include "vibid/workflow/hammer_session.hpp"
#include "vibid/workflow/result_json.hpp"

namespace vibid::bench {
namespace {

/// At most this many progress events a second (samples so far); a judged hit goes out at once.
constexpr double kProgressIntervalMs = 100.0;

/// Wall-clock milliseconds since the epoch: the page compares them with its own clock (the same
/// machine's) to measure how long a hit takes to reach the screen.
double NowMs() {
  return std::chrono::duration<double, std::milli>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

double NumberOr(const nlohmann::json& body, const char* key, double fallback) {
  if (!body.contains(key)) return fallback;
  Require(body[key].is_number(), std::string("'") + key + "' must be a number");
  return body[key].get<double>();
}

/// The hammer test as the page asks for it, read strictly. What is left out takes the library's
/// default, as `vibid frf-estimate` takes it (record_s 0: the shortest hit spacing).
struct Settings {
  nlohmann::json ask;  // the acquisition, as POST /api/acquire takes it
  std::string force;   // channel stems
  std::vector<std::string> responses;
  std::string hammer_point;
  ident::ImpactOptions impact;
};

Settings ParseSettings(const nlohmann::json& body) {
  Require(body.is_object(), "the hammer test's settings must be a JSON object");
  RequireKnownKeys(
      body,
      {"channels", "sample_period_us", "seconds", "record_s", "hammer_point", "trigger",
       "pretrigger_s", "force_window_s", "exp_window", "scenario", "scenario_params"},
      "the hammer test's settings");
  Settings s;
  s.ask = nlohmann::json::object();
  for (const char* k : {"channels", "sample_period_us", "seconds", "scenario", "scenario_params"})
    if (body.contains(k)) s.ask[k] = body[k];
  (void)ParseAcquisitionAsk(s.ask);  // the acquisition's own checks first
  const nlohmann::json& ch = body["channels"];
  Require(ch.size() >= 2, "'channels': the hammer's load cell first, then at least one response");
  s.force = ch[0].get<std::string>();
  Require(s.force.rfind("force", 0) == 0,
          "'channels': the first channel must be the hammer's load cell (force1 or force2), not '" +
              s.force + "'");
  for (std::size_t i = 1; i < ch.size(); ++i) {
    const std::string r = ch[i].get<std::string>();
    Require(r.rfind("force", 0) != 0,
            "'channels': '" + r + "' is a load cell; the responses are accelerometers or encoders");
    s.responses.push_back(r);
  }
  s.impact.record_s = NumberOr(body, "record_s", s.impact.record_s);
  Require(s.impact.record_s >= 0.0,
          "'record_s' must be >= 0 (left out or 0: the shortest spacing between hits)");
  Require(body.contains("hammer_point") && body["hammer_point"].is_string(),
          "'hammer_point' (the response channel at the hammer's point) is missing");
  s.hammer_point = body["hammer_point"].get<std::string>();
  Require(std::find(s.responses.begin(), s.responses.end(), s.hammer_point) != s.responses.end(),
          "'hammer_point': '" + s.hammer_point + "' is not one of the response channels");
  s.impact.trigger_fraction = NumberOr(body, "trigger", s.impact.trigger_fraction);
  s.impact.pretrigger_s = NumberOr(body, "pretrigger_s", s.impact.pretrigger_s);
  s.impact.force_window_s = NumberOr(body, "force_window_s", s.impact.force_window_s);
  s.impact.exp_window_end = NumberOr(body, "exp_window", s.impact.exp_window_end);
  return s;
}

/// The recording's column of channel `stem` under the board's calibration.
std::string Column(const std::string& stem, const wire::CalibrationRecord& cal) {
  wire::Channel c{};
  Require(device::ChannelFromStem(stem, c), "'channels': unknown channel '" + stem + "'");
  return stem + "_" + device::UnitSuffix(cal.channels[static_cast<std::size_t>(c)].unit);
}

}  // namespace

class HammerTests {
 public:
  HammerTests(BenchBoard& board, LiveHub& hub, std::string directory)
      : board_(board), hub_(hub), directory_(std::move(directory)) {}

  nlohmann::json Preflight(const nlohmann::json& body) {
    return board_.Budget(ParseSettings(body).ask);
  }

  nlohmann::json Start(const nlohmann::json& body) {
    const Settings s = ParseSettings(body);
    // Uncalibrated: the columns in counts, so that the settings are checked all the same before
    // the calibration is asked for.
    const wire::CalibrationRecord* active = board_.ActiveCalibration();
    wire::CalibrationRecord counts{};
    for (wire::ChannelScaling& c : counts.channels) c = wire::DefaultScaling();
    const wire::CalibrationRecord* cal = active != nullptr ? active : &counts;
    const AcquisitionAsk ask = ParseAcquisitionAsk(s.ask);
    const wire::AcqConfigureRequest cfg = ConfigFor(ask, board_.BoardInfo());
    workflow::HammerSessionOptions o;
    o.layout = wire::LogLayout{cfg.channel_mask, cfg.flags};
    o.sample_period_us = cfg.sample_period_us;
    o.decimation = cfg.decimation;
    o.calibration = *cal;
    o.has_calibration = active != nullptr;
    o.estimation.force = Column(s.force, *cal);
    // Accelerometers and encoders may be mixed: each response is what its channel measures.
    std::string responses, sensor;
    for (const std::string& r : s.responses) {
      responses += (responses.empty() ? "" : ",") + Column(r, *cal);
      sensor += std::string(sensor.empty() ? "" : ",") + (r.rfind("acc", 0) == 0 ? "acc" : "disp");
    }
    o.estimation.responses = responses;
    o.estimation.impact = true;
    o.estimation.sensor = sensor;
    o.estimation.impact_options.record_s = s.impact.record_s;
    o.estimation.impact_options.trigger_fraction = s.impact.trigger_fraction;
    o.estimation.impact_options.pretrigger_s = s.impact.pretrigger_s;
    o.estimation.impact_options.force_window_s = s.impact.force_window_s;
    o.estimation.impact_options.exp_window_end = s.impact.exp_window_end;
    o.modes.driving_point = Column(s.hammer_point, *cal);
    auto test = std::make_shared<Test>();
    test->name = "hammer-" + TimeStamp();
    // Two tests in the same second: the second gets its own folder, never the first one's.
    for (int k = 2; std::filesystem::exists(directory_ + "/" + test->name); ++k)
      test->name = "hammer-" + TimeStamp() + "-" + std::to_string(k);
    test->dir = directory_ + "/" + test->name;
    test->settings = body;
    test->ask = s.ask;
    o.live_csv_path = test->dir + "/live.csv";
    // The test kept whole as it goes: every choice journaled, the files written at any end.
    o.test_dir = test->dir;
    o.Validate();  // before anything is created: a refusal changes nothing
    Require(active != nullptr,
            "the board is uncalibrated: a hammer test needs the force in N (vibid cal upload "
            "MODEL.json --design DESIGN.json --sensors SENSORS.json, then vibid cal commit)");
    board_.WithIdleBoard([&](device::Connection& c) { o.instants = c.GetSamplingInfo(); });
    // Created, not checked then created: a folder (or link) that appeared since gives a new name.
    test->dir = CreateNewDirectory(directory_, test->name);
    test->name = test->dir.substr(directory_.size() + 1);
    o.live_csv_path = test->dir + "/live.csv";
    o.test_dir = test->dir;
    try {
      test->session = std::make_unique<workflow::HammerSession>(o);
      {
        std::lock_guard l(mutex_);
        pending_ = test;
      }
      test->running = true;
      board_.Start(s.ask, "hammer test");
    } catch (...) {
      {
        std::lock_guard l(mutex_);
        pending_.reset();
      }
      test->session.reset();
      std::filesystem::remove_all(test->dir);
      throw;
    }
    // The new test is the one on every page from now (no hit yet, its own settings): the last
    // test's hits and modes never stand beside the new settings until its first hit.
    {
      std::lock_guard l(mutex_);
      current_ = test;
    }
    nlohmann::json shown = Publish(*test, nullptr);
    shown["name"] = test->name;
    shown["dir"] = test->dir;
    return shown;
  }

  nlohmann::json Choose(const nlohmann::json& body) {
    Require(body.is_object(), "the choice must be a JSON object");
    RequireKnownKeys(body, {"index", "accept"}, "the hit choice");
    Require(body.contains("index") && body["index"].is_number_unsigned(),
            "'index' (the hit's number, from 1) is missing");
    Require(body.contains("accept") && body["accept"].is_boolean(),
            "'accept' must be true or false");
    const std::shared_ptr<Test> t = Current();
    const auto index = body["index"].get<std::size_t>();
    if (body["accept"].get<bool>()) {
      t->session->Accept(index);
    } else {
      t->session->Reject(index);
    }
    return Publish(*t, nullptr);
  }

  nlohmann::json Save(const nlohmann::json& body) {
    Require(body.is_object() && body.empty(), "save takes an empty object");
    const std::shared_ptr<Test> t = Current();
    t->session->Save(t->dir);
    {
      std::lock_guard l(t->mutex);
      t->saved = true;
    }
    Publish(*t, nullptr);
    return {{"dir", t->dir},
            {"files",
             {"recording.csv", "recording.csv.json", "hits.json", "frf.csv", "frf.csv.json",
              "frf.uff"}},
            {"running", t->running.load()}};
  }

  nlohmann::json Snapshot(const nlohmann::json& body) {
    Require(body.is_object() && body.empty(), "snapshot takes an empty object");
    std::shared_ptr<Test> t;
    {
      std::lock_guard l(mutex_);
      t = current_;
    }
    if (!t) return {{"test", nullptr}, {"snapshot", nullptr}};
    return Full(*t, t->session->Snapshot(), nullptr);
  }

  nlohmann::json Traces(const nlohmann::json& body) {
    Require(body.is_object(), "the request must be a JSON object");
    RequireKnownKeys(body, {"index"}, "the traces request");
    Require(body.contains("index") && body["index"].is_number_unsigned(),
            "'index' (the hit's number, from 1) is missing");
    return workflow::HitTracesJson(Current()->session->Traces(body["index"].get<std::size_t>()));
  }

  // The acquisition thread's side.
  void OnStarted() {
    // Only the acquisition this test asked for: another view's (started in between) is not fed.
    const nlohmann::json running = board_.State().value("ask", nlohmann::json());
    std::lock_guard l(mutex_);
    feeding_.reset();
    if (pending_ && pending_->ask == running) feeding_.swap(pending_);
    if (feeding_) {
      current_ = feeding_;
      current_->running = true;
      last_version_ = 0;
      last_key_.clear();
      last_progress_ms_ = 0.0;
    }
  }

  void OnRecords(std::span<const wire::LogRecord> records) {
    if (!feeding_) return;
    Test& t = *feeding_;
    const double arrived_ms = NowMs();
    try {
      t.session->Feed(records);
    } catch (const std::exception& e) {
      // The recording so far stays on disk; the test stops taking records.
      t.SetError(std::string("the hammer test stopped taking records: ") + e.what());
      Publish(t, nullptr);
      feeding_.reset();
      return;
    }
    const std::uint64_t v = t.session->Version();
    if (v == last_version_) return;
    last_version_ = v;
    const workflow::HammerSnapshot snap = t.session->Snapshot();
    const std::string key = std::to_string(snap.hits.size()) + "/" + std::to_string(snap.accepted) +
                            "/" + std::to_string(snap.frf.averages) + "/" + snap.modes_error;
    if (key != last_key_) {
      last_key_ = key;
      hub_.Publish("hammer", Full(t, snap, arrived_ms).dump());
    } else if (arrived_ms - last_progress_ms_ >= kProgressIntervalMs) {
      last_progress_ms_ = arrived_ms;
      hub_.Publish("hammer-progress", nlohmann::json{{"version", snap.version},
                                                     {"samples", snap.samples},
                                                     {"fs_hz", snap.fs_hz},
                                                     {"pending_hits", snap.pending_hits}}
                                          .dump());
    }
  }

  void OnEnded() {
    if (!feeding_) return;
    Test& t = *feeding_;
    try {
      t.session
          ->Finish();  // and the test kept whole in its folder (HammerSessionOptions::test_dir)
      std::lock_guard l(t.mutex);
      t.saved = true;
    } catch (const std::exception& e) {
      t.SetError(e.what());
    }
    t.running = false;
    Publish(t, nullptr);
    feeding_.reset();
  }

 private:
  struct Test {
    std::string name;
    std::string dir;
    nlohmann::json settings;
    nlohmann::json ask;  // the acquisition it asked the board for
    std::unique_ptr<workflow::HammerSession> session;
    std::atomic<bool> running{false};
    mutable std::mutex mutex;  // saved, error
    bool saved = false;
    std::string error;

    void SetError(const std::string& e) {
      std::lock_guard l(mutex);
      error = e;
    }
  };

  std::shared_ptr<Test> Current() {
    std::lock_guard l(mutex_);
    Require(current_ != nullptr, "no hammer test yet: start one");
    return current_;
  }

  nlohmann::json Full(const Test& t, const workflow::HammerSnapshot& snap,
                      const nlohmann::json& arrived_ms) {
    std::lock_guard l(t.mutex);
    return {{"test",
             {{"name", t.name},
              {"dir", t.dir},
              {"running", t.running.load()},
              {"saved", t.saved},
              {"error", t.error},
              {"settings", t.settings}}},
            {"snapshot", workflow::HammerSnapshotJson(snap)},
            {"arrived_ms", arrived_ms},
            {"sent_ms", NowMs()}};
  }

  nlohmann::json Publish(const Test& t, const nlohmann::json& arrived_ms) {
    nlohmann::json j = Full(t, t.session->Snapshot(), arrived_ms);
    hub_.Publish("hammer", j.dump());
    return j;
  }

  BenchBoard& board_;
  LiveHub& hub_;
  std::string directory_;
  std::mutex mutex_;  // pending_, current_
  std::shared_ptr<Test> pending_;
  std::shared_ptr<Test> current_;
  // The acquisition thread's own.
  std::shared_ptr<Test> feeding_;
  std::uint64_t last_version_ = 0;
  std::string last_key_;
  double last_progress_ms_ = 0.0;
};

std::shared_ptr<HammerTests> AddHammerRoutes(BenchServer& server, BenchBoard& board, LiveHub& hub,
                                             const std::string& directory) {
  auto tests = std::make_shared<HammerTests>(board, hub, directory);
  const Asset* html = FindAsset("/assets/hammer.html");
  const Asset* script = FindAsset("/assets/hammer.js");
  server.AddView({"hammer", "Hammer test", std::string(html->bytes), std::string(script->bytes)});
  board.AddAcquisitionListener(
      {[tests](const AcquisitionAsk&, const wire::AcqConfigureRequest&) { tests->OnStarted(); },
       [tests](std::span<const wire::LogRecord> r) { tests->OnRecords(r); },
       [tests](const nlohmann::json&) { tests->OnEnded(); }});
  const auto route = [&server, tests](const std::string& name,
                                      nlohmann::json (HammerTests::*f)(const nlohmann::json&)) {
    server.AddJsonRoute("hammer/" + name,
                        [tests, f](const nlohmann::json& b) { return ((*tests).*f)(b); });
  };
  route("preflight", &HammerTests::Preflight);
  route("start", &HammerTests::Start);
  route("choose", &HammerTests::Choose);
  route("save", &HammerTests::Save);
  route("snapshot", &HammerTests::Snapshot);
  route("traces", &HammerTests::Traces);
  server.AddJsonRoute("hammer/stop", [&board](const nlohmann::json& b) {
    Require(b.is_object() && b.empty(), "stop takes an empty object");
    return board.Stop("hammer test");
  });
  return tests;
}

}  // namespace vibid::bench
