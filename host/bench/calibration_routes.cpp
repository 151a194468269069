#include "vibid/bench/calibration_routes.hpp"

#include "vibid/bench/bench_files.hpp"

#include <cstdio>
#include <memory>
#include <mutex>
#include <optional>

#include "vibid/common/error.hpp"
#include "vibid/common/json_keys.hpp"
#include "vibid/common/verdict.hpp"
#include "vibid/device/calibration_upload.hpp"

namespace vibid::bench {
namespace {

/// A file of the request inside `directory` (FileIn), or "" for an optional one not given.
std::string FileOf(const std::string& directory, const nlohmann::json& body, const char* key,
                   bool required) {
  if (!body.contains(key)) {
    Require(!required, std::string("'") + key + "' is missing");
    return {};
  }
  return FileIn(directory, body[key], key);
}

/// The page's explicit accept of a flagged model (a box the user ticks): `accept_flagged`.
constexpr const char* kAcceptOption =
    "the page's accept box (\"accept_flagged\": true in the request)";

bool AcceptFlagged(const nlohmann::json& body) {
  if (!body.contains("accept_flagged")) return false;
  Require(body["accept_flagged"].is_boolean(), "'accept_flagged' must be true or false");
  return body["accept_flagged"].get<bool>();
}

device::UploadFiles Files(const std::string& directory, const nlohmann::json& body) {
  Require(body.is_object(), "the request must be a JSON object");
  RequireKnownKeys(body, {"model", "design", "sensors", "label", "accept_flagged"},
                   "the calibration request");
  device::UploadFiles f;
  f.accept_flagged = AcceptFlagged(body);
  f.accept_option = kAcceptOption;
  f.model = FileOf(directory, body, "model", true);
  f.design = FileOf(directory, body, "design", true);
  f.sensors = FileOf(directory, body, "sensors", false);
  if (body.contains("label")) {
    Require(body["label"].is_string(), "'label' must be a string");
    f.label = body["label"].get<std::string>();
  }
  return f;
}

/// The record `cal upload` would stage (the board's sensors kept without a sensors file).
wire::CalibrationRecord Build(BenchBoard& board, const device::UploadFiles& files,
                              const std::string& host_version, Verdict& verdict) {
  device::RecordInputs in = device::ReadRecordInputs(files, host_version, &verdict);
  if (files.sensors.empty()) device::KeepBoardSensors(in, board.ActiveCalibration());
  return device::BuildCalibrationRecord(in);
}

/// The verdict of the model this bench staged last, so that its commit asks the same accept; a
/// record staged elsewhere (the CLI) has none here.
struct Staged {
  std::mutex mutex;
  std::optional<Verdict> verdict;
  std::string model;
};

nlohmann::json VerdictJson(const Verdict& v) {
  nlohmann::json j = VerdictToJson(v);
  j["stated"] = v.stated;
  j["text"] = FormatVerdict(v);
  return j;
}

}  // namespace

nlohmann::json RecordChanges(const nlohmann::json& current, const nlohmann::json& staged) {
  nlohmann::json changes = nlohmann::json::array();
  for (const auto& [field, value] : staged.items()) {
    if (field == "created_unix_s" || field == "host_version") continue;
    const nlohmann::json from =
        current.is_object() && current.contains(field) ? current[field] : nlohmann::json();
    if (from != value) changes.push_back({{"field", field}, {"from", from}, {"to", value}});
  }
  return changes;
}

void AddCalibrationRoutes(BenchServer& server, BenchBoard& board, const std::string& directory,
                          const std::string& host_version) {
  // The preview shows any model with its verdict (nothing reaches the board): the page asks for
  // the accept of a flagged one before it offers the upload.
  server.AddJsonRoute("cal/preview", [&board, directory, host_version](const nlohmann::json& b) {
    device::UploadFiles files = Files(directory, b);
    files.accept_flagged = true;
    Verdict verdict;
    const wire::CalibrationRecord staged = Build(board, files, host_version, verdict);
    const wire::CalibrationRecord* active = board.ActiveCalibration();
    const nlohmann::json current = active ? device::RecordJson(*active) : nlohmann::json();
    const nlohmann::json next = device::RecordJson(staged);
    return nlohmann::json{{"current", current},
                          {"staged", next},
                          {"changes", RecordChanges(current, next)},
                          {"verdict", VerdictJson(verdict)}};
  });
  const auto staged = std::make_shared<Staged>();
  server.AddJsonRoute(
      "cal/upload", [&board, directory, host_version, staged](const nlohmann::json& b) {
        const device::UploadFiles files = Files(directory, b);
        Verdict verdict;
        const wire::CalibrationRecord rec = Build(board, files, host_version, verdict);
        std::array<std::uint8_t, wire::kCalRecordBytes> bytes{};
        wire::EncodeCalibrationRecord(rec, bytes);
        board.WithIdleBoard([&](device::Connection& c) { c.CalPut(bytes); });
        {
          const std::lock_guard lock(staged->mutex);
          staged->verdict = verdict;
          staged->model = files.model.substr(files.model.find_last_of('/') + 1);
        }
        char crc[11];
        std::snprintf(crc, sizeof crc, "0x%08x", wire::StoredRecordCrc(bytes));
        return nlohmann::json{{"staged", device::RecordJson(rec)["label"]},
                              {"crc32", crc},
                              {"verdict", VerdictJson(verdict)}};
      });
  server.AddJsonRoute("cal/commit", [&board, staged](const nlohmann::json& b) {
    Require(b.is_object(), "commit takes an object: {} or {\"accept_flagged\": true}");
    RequireKnownKeys(b, {"accept_flagged"}, "the commit request");
    {
      // A flagged model staged here is committed only with the same explicit accept.
      const std::lock_guard lock(staged->mutex);
      if (staged->verdict)
        RequireUsable(*staged->verdict, AcceptFlagged(b), "the staged model " + staged->model,
                      "commit", kAcceptOption);
    }
    wire::CalCommitResponse r{};
    board.WithIdleBoard([&](device::Connection& c) { r = c.CalCommit(); });
    board.ReadCalibrationAgain();
    nlohmann::json out{{"slot", r.slot}, {"sequence", r.sequence}};
    const std::lock_guard lock(staged->mutex);
    if (staged->verdict) out["verdict"] = VerdictJson(*staged->verdict);
    staged->verdict.reset();
    return out;
  });
}

}  // namespace vibid::bench
