#include "vibid/bench/calibration_routes.hpp"

#include "vibid/bench/bench_files.hpp"

#include <cstdio>

#include "vibid/common/error.hpp"
#include "vibid/common/json_keys.hpp"
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

device::UploadFiles Files(const std::string& directory, const nlohmann::json& body) {
  Require(body.is_object(), "the request must be a JSON object");
  RequireKnownKeys(body, {"model", "design", "sensors", "label"}, "the calibration request");
  device::UploadFiles f;
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
                              const std::string& host_version) {
  device::RecordInputs in = device::ReadRecordInputs(files, host_version);
  if (files.sensors.empty()) device::KeepBoardSensors(in, board.ActiveCalibration());
  return device::BuildCalibrationRecord(in);
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
  server.AddJsonRoute("cal/preview", [&board, directory, host_version](const nlohmann::json& b) {
    const wire::CalibrationRecord staged = Build(board, Files(directory, b), host_version);
    const wire::CalibrationRecord* active = board.ActiveCalibration();
    const nlohmann::json current = active ? device::RecordJson(*active) : nlohmann::json();
    const nlohmann::json next = device::RecordJson(staged);
    return nlohmann::json{
        {"current", current}, {"staged", next}, {"changes", RecordChanges(current, next)}};
  });
  server.AddJsonRoute("cal/upload", [&board, directory, host_version](const nlohmann::json& b) {
    const wire::CalibrationRecord rec = Build(board, Files(directory, b), host_version);
    std::array<std::uint8_t, wire::kCalRecordBytes> bytes{};
    wire::EncodeCalibrationRecord(rec, bytes);
    board.WithIdleBoard([&](device::Connection& c) { c.CalPut(bytes); });
    char crc[11];
    std::snprintf(crc, sizeof crc, "0x%08x", wire::StoredRecordCrc(bytes));
    return nlohmann::json{{"staged", device::RecordJson(rec)["label"]}, {"crc32", crc}};
  });
  server.AddJsonRoute("cal/commit", [&board](const nlohmann::json& b) {
    Require(b.is_object() && b.empty(), "commit takes an empty object");
    wire::CalCommitResponse r{};
    board.WithIdleBoard([&](device::Connection& c) { r = c.CalCommit(); });
    board.ReadCalibrationAgain();
    return nlohmann::json{{"slot", r.slot}, {"sequence", r.sequence}};
  });
}

}  // namespace vibid::bench
