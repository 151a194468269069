#include "vibid/bench/watch_routes.hpp"

#include <chrono>
#include <cmath>
#include <cstdint>
#include <memory>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <mutex>
#include <utility>
#include <unistd.h>

#include "vibid/bench/assets.hpp"
#include "vibid/bench/bench_files.hpp"
#include "vibid/common/error.hpp"
#include "vibid/common/json_keys.hpp"
#include "vibid/workflow/watch_board_run.hpp"

namespace vibid::bench {
namespace {

/// The reference's progress goes out at most this often (a block goes out at once).
constexpr double kProgressIntervalMs = 500.0;
/// The blocks a page gets again when it opens: 12 hours of 10 s blocks (the journal holds every
/// block of a run of any length).
constexpr std::size_t kKeptBlocks = 4320;
/// The view's name in the board's state: its Stop ends only a run so named.
constexpr const char* kView = "watch";

double NowMs() {
  return std::chrono::duration<double, std::milli>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

double Number(const nlohmann::json& body, const char* key) {
  Require(body[key].is_number(), std::string("'") + key + "' must be a number");
  return body[key].get<double>();
}

/// A whole number within [lo, hi], read as JSON gives it: one beyond an int is refused, never
/// taken modulo 2^32 (4294967302 is not 6).
int Integer(const nlohmann::json& body, const char* key, int lo, int hi) {
  const nlohmann::json& v = body[key];
  const std::string range = std::to_string(lo) + " … " + std::to_string(hi);
  Require(v.is_number_integer(),
          std::string("'") + key + "' must be a whole number (" + range + ")");
  // An unsigned beyond int64 (up to 2^64 - 1) is compared as unsigned: never converted first.
  const bool inside = v.is_number_unsigned()
                          ? v.get<std::uint64_t>() <= static_cast<std::uint64_t>(hi) &&
                                static_cast<std::int64_t>(v.get<std::uint64_t>()) >= lo
                          : v.get<std::int64_t>() >= lo && v.get<std::int64_t>() <= hi;
  Require(inside, std::string("'") + key + "' must lie in " + range + ", not " + v.dump());
  return static_cast<int>(v.get<std::int64_t>());
}

std::vector<std::string> Strings(const nlohmann::json& body, const char* key) {
  Require(body[key].is_array(), std::string("'") + key + "' must be a list of names");
  std::vector<std::string> out;
  for (const nlohmann::json& v : body[key]) {
    Require(v.is_string(), std::string("'") + key + "' must be a list of names");
    out.push_back(v.get<std::string>());
  }
  return out;
}

/// The page's settings, read strictly, as `vibid watch --device` takes its options: what is left
/// out keeps the library's default.
workflow::WatchBoardSettings ParseSettings(const nlohmann::json& body, const std::string& dir,
                                           bool emulator) {
  Require(body.is_object(), "the watch's settings must be a JSON object");
  RequireKnownKeys(body,
                   {"rate_hz", "log_rate_hz", "channels", "seconds", "responses", "reference",
                    "reference_s", "block_s", "window_blocks", "false_alarm_per_hour", "fmax_hz",
                    "modes_s", "order", "scenario", "scenario_params", "no_dob"},
                   "the watch's settings");
  workflow::WatchBoardSettings s;
  s.acquire.rate_hz = 1000.0;  // vibid watch's default
  const auto positive = [&](const char* key, double& into) {
    if (!body.contains(key)) return;
    into = Number(body, key);
    Require(into > 0.0, std::string("'") + key + "' must be > 0");
  };
  positive("rate_hz", s.acquire.rate_hz);
  positive("log_rate_hz", s.acquire.log_rate_hz);
  positive("seconds", s.acquire.seconds);
  positive("reference_s", s.watch.reference_s);
  positive("block_s", s.watch.block_s);
  positive("false_alarm_per_hour", s.watch.false_alarm_per_hour);
  positive("fmax_hz", s.watch.fmax_hz);
  if (body.contains("modes_s")) {
    s.watch.modes_s = Number(body, "modes_s");
    Require(s.watch.modes_s >= 0.0, "'modes_s' must be >= 0 (0: no modes)");
  }
  if (body.contains("window_blocks")) {
    // The library's own bounds (WatchOptions::Validate) are checked on the value as given.
    s.watch.window_blocks = Integer(body, "window_blocks", 1, 100000);
  }
  if (body.contains("order")) s.watch.order = Integer(body, "order", 0, 40);
  if (body.contains("no_dob")) {
    Require(body["no_dob"].is_boolean(), "'no_dob' must be true or false");
    s.acquire.no_dob = body["no_dob"].get<bool>();
  }
  if (body.contains("channels")) s.acquire.channels = Strings(body, "channels");
  if (body.contains("responses")) s.responses = Strings(body, "responses");
  if (body.contains("reference")) {
    Require(!body.contains("reference_s"),
            "'reference' (a recording of the rig as it should be) and 'reference_s' (a reference "
            "phase) exclude each other: give one");
    s.reference = FileIn(dir, body["reference"], "reference");
  }
  if (body.contains("scenario")) {
    Require(body["scenario"].is_string(), "'scenario' must be a name (operate)");
    s.scenario = body["scenario"].get<std::string>();
    Require(s.scenario.empty() || emulator,
            "'scenario': this board is not the emulator (scenarios select its simulated rig)");
  }
  if (body.contains("scenario_params")) {
    Require(body["scenario_params"].is_array(), "'scenario_params' must be a list of numbers");
    for (const nlohmann::json& v : body["scenario_params"]) {
      Require(v.is_number(), "'scenario_params' must be a list of numbers");
      const double x = v.get<double>();
      // Beyond a float it would become infinity on the way to the board: refused as given.
      Require(std::abs(x) <= 3.4e38,
              "'scenario_params' holds " + v.dump() + ", beyond a float (3.4e38)");
      s.scenario_params.push_back(static_cast<float>(x));
    }
  }
  return s;
}

}  // namespace

class WatchRuns : public std::enable_shared_from_this<WatchRuns> {
 public:
  WatchRuns(BenchBoard& board, LiveHub& hub, std::string directory,
            std::shared_ptr<workflow::WatchMetrics> metrics)
      : board_(board), hub_(hub), directory_(std::move(directory)), metrics_(std::move(metrics)) {}

  nlohmann::json Start(const nlohmann::json& body) {
    const bool emulator = (board_.BoardInfo().capabilities & wire::kCapScenarioSelect) != 0;
    auto run = std::make_shared<workflow::WatchBoardRun>(ParseSettings(body, directory_, emulator));
    // Checked: now the journal, a name no file has (two runs in one second get two).
    const NewFile file = CreateNewFile(directory_, "watch-" + TimeStamp(), ".jsonl");
    std::FILE* f = ::fdopen(file.fd, "w");
    if (f == nullptr) {
      ::close(file.fd);
      ::unlink(file.path.c_str());
      throw InputError("cannot write the journal " + file.path);
    }
    auto journal = std::make_shared<workflow::WatchJournal>(f, file.path, "journal");
    nlohmann::json state = {{"name", file.stem},
                            {"journal", file.path},
                            {"settings", body},
                            {"running", true},
                            {"options", OptionsJson(run->options())},
                            {"until_stopped", run->until_stopped()},
                            {"reference_left_s", run->settings().reference.empty()
                                                     ? nlohmann::json(run->options().reference_s)
                                                     : nlohmann::json(0.0)},
                            {"reference", nullptr},
                            {"start", nullptr},
                            {"end", nullptr},
                            {"blocks", 0},
                            {"error", ""},
                            {"warning", ""}};
    nlohmann::json previous_state;
    nlohmann::json previous_blocks;
    {
      std::lock_guard l(mutex_);
      if (!state_.is_null() && state_.value("running", false)) {
        ::unlink(file.path.c_str());
        throw Busy("a watch is running: stop it first");
      }
      previous_state = std::exchange(state_, state);
      previous_blocks = std::exchange(blocks_, nlohmann::json::array());
    }
    try {
      board_.StartTask({{"name", file.stem}, {"view", kView}, {"journal", file.path}},
                       // The run holds its view: it outlives the routes if the bench ends first.
                       [self = shared_from_this(), run, journal](
                           device::Connection& c, const std::function<bool()>& stop) {
                         return self->Execute(*run, *journal, c, stop);
                       });
    } catch (...) {
      {
        std::lock_guard l(mutex_);
        state_ = std::move(previous_state);
        blocks_ = std::move(previous_blocks);
      }
      ::unlink(file.path.c_str());
      throw;
    }
    if (metrics_) metrics_->Start(run->options());
    Publish();
    return {{"name", file.stem}, {"journal", file.path}};
  }

  nlohmann::json Snapshot(const nlohmann::json& body) {
    Require(body.is_object() && body.empty(), "snapshot takes an empty object");
    std::lock_guard l(mutex_);
    return {{"watch", state_}, {"blocks", blocks_}};
  }

  nlohmann::json Journal(const nlohmann::json& body) {
    Require(body.is_object() && body.empty(), "journal takes an empty object");
    std::lock_guard l(mutex_);
    Require(!state_.is_null(), "nothing watched yet: start the watch");
    // The file itself (every block, each appended and flushed as it came), up to its last whole
    // line: one being appended is left for the next download.
    const std::string path = state_["journal"].get<std::string>();
    std::ifstream in(path, std::ios::binary);
    Require(in.good(), "the journal " + path + " cannot be read");
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    text.erase(text.find_last_of('\n') == std::string::npos ? 0 : text.find_last_of('\n') + 1);
    return {{"name", state_["name"]}, {"path", path}, {"text", text}};
  }

 private:
  static nlohmann::json OptionsJson(const workflow::WatchOptions& o) {
    return {{"fs_hz", o.fs_hz},
            {"reference_s", o.reference_s},
            {"block_s", o.block_s},
            {"window_blocks", o.window_blocks},
            {"false_alarm_per_hour", o.false_alarm_per_hour},
            {"fmax_hz", o.fmax_hz},
            {"modes_s", o.modes_s},
            {"order", o.order}};
  }

  /// In the board's thread: the library's run, its events published as they come.
  nlohmann::json Execute(workflow::WatchBoardRun& run, workflow::WatchJournal& journal,
                         device::Connection& c, const std::function<bool()>& stop) {
    workflow::WatchBoardEvents events;
    double last_progress_ms = 0.0;
    events.starting = [&](const workflow::WatchBoardStart& s) {
      Update({{"start",
               {{"responses", s.responses},
                {"log_rate_hz", s.log_rate_hz},
                {"board_columns", s.board_columns},
                {"model_stale", s.model_stale},
                {"model_text", s.model_text}}}});
    };
    events.fed = [&](const workflow::WatchSession& s, double t_s) {
      const double now = NowMs();
      if (s.has_reference() || now - last_progress_ms < kProgressIntervalMs) return;
      last_progress_ms = now;
      Update({{"reference_left_s", s.reference_left_s()}, {"t_s", t_s}});
    };
    events.reference = [&](const workflow::WatchSession& s) {
      if (metrics_) metrics_->Reference(s.reference());
      Update(
          {{"reference", workflow::WatchReferenceJson(s.reference())}, {"reference_left_s", 0.0}});
    };
    events.header = [&](const std::string& line) {
      Update({{"header", nlohmann::json::parse(line)}});
    };
    events.block = [&](const workflow::WatchBlock& b, const std::string& line) {
      if (metrics_) metrics_->Block(b);
      {
        std::lock_guard l(mutex_);
        blocks_.push_back(nlohmann::json::parse(line));
        if (blocks_.size() > kKeptBlocks) blocks_.erase(blocks_.begin());
        state_["t_s"] = blocks_.back()["t_s"];
        state_["blocks"] = state_.value("blocks", 0) + 1;
      }
      hub_.Publish("watch-block", line);
    };
    nlohmann::json end;
    try {
      const workflow::WatchBoardResult r = run.Run(c, journal, events, stop);
      end = {{"stopped", r.stopped},
             {"warning", r.warning},
             {"model_stale", r.model_stale},
             {"model_text", r.model_text},
             {"reference_built", r.reference_built},
             {"reference_left_s", r.reference_left_s},
             {"blocks", r.blocks}};
      if (metrics_) metrics_->End();
      Update({{"running", false}, {"end", end}, {"warning", r.warning}});
    } catch (const std::exception& e) {
      if (metrics_) metrics_->End();
      Update({{"running", false}, {"error", e.what()}});
      throw;
    }
    return {{"blocks", end["blocks"]}, {"stopped", end["stopped"]}};
  }

  void Update(const nlohmann::json& changes) {
    {
      std::lock_guard l(mutex_);
      if (state_.is_null()) return;
      for (const auto& [k, v] : changes.items()) state_[k] = v;
    }
    Publish();
  }

  void Publish() {
    nlohmann::json s;
    {
      std::lock_guard l(mutex_);
      s = state_;
    }
    hub_.Publish("watch", s.dump());
  }

  BenchBoard& board_;
  LiveHub& hub_;
  std::string directory_;
  std::shared_ptr<workflow::WatchMetrics> metrics_;  // null: no metrics
  std::mutex mutex_;                                 // state_, blocks_
  nlohmann::json state_;
  nlohmann::json blocks_ = nlohmann::json::array();  // the last kKeptBlocks
};

std::shared_ptr<WatchRuns> AddWatchRoutes(BenchServer& server, BenchBoard& board, LiveHub& hub,
                                          const std::string& directory,
                                          std::shared_ptr<workflow::WatchMetrics> metrics) {
  auto runs = std::make_shared<WatchRuns>(board, hub, directory, metrics);
  if (metrics) server.AddMetrics([metrics] { return metrics->Text(); });
  const Asset* html = FindAsset("/assets/watch.html");
  const Asset* script = FindAsset("/assets/watch.js");
  server.AddView({"watch", "Watch", std::string(html->bytes), std::string(script->bytes)});
  server.AddJsonRoute("watch/start", [runs](const nlohmann::json& b) { return runs->Start(b); });
  server.AddJsonRoute("watch/snapshot",
                      [runs](const nlohmann::json& b) { return runs->Snapshot(b); });
  server.AddJsonRoute("watch/journal",
                      [runs](const nlohmann::json& b) { return runs->Journal(b); });
  server.AddJsonRoute("watch/stop", [&board](const nlohmann::json& b) {
    Require(b.is_object() && b.empty(), "stop takes an empty object");
    return board.Stop(kView);
  });
  return runs;
}

}  // namespace vibid::bench
