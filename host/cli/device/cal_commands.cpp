// vibid cal upload | show | commit
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <optional>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli_support.hpp"
#include "common/command.hpp"
#include "vibid/device/acquire_plan.hpp"
#include "vibid/device/error.hpp"
#include "device_commands.hpp"
#include "session.hpp"
#include "vibid/common/error.hpp"
#include "vibid/common/json_file.hpp"
#include "vibid/common/verdict.hpp"
#include "vibid/device/calibration_builder.hpp"
#include "vibid/device/calibration_upload.hpp"
#include "vibid/device/log_table.hpp"
#include "vibid/device/watch_day.hpp"
#include "vibid/common/csv.hpp"
#include "vibid/dob/design_json.hpp"
#include "vibid/model/model_json.hpp"

namespace vibid::cli {
namespace {

/// `cal show --json`: the record, with the slot, sequence and CRC the board gave it.
nlohmann::json RecordJson(const wire::CalibrationRecord& r, const wire::CalGetTrailer& t,
                          std::uint32_t crc) {
  char crc_text[11];
  std::snprintf(crc_text, sizeof(crc_text), "0x%08x", crc);
  nlohmann::json j = device::RecordJson(r);
  j["slot"] = t.slot;
  j["sequence"] = t.sequence;
  j["crc32"] = crc_text;
  return j;
}

std::string FormatRecord(const nlohmann::json& j) {
  std::ostringstream o;
  o << "record    '" << j["label"].get<std::string>() << "', slot " << j["slot"].get<int>()
    << ", sequence " << j["sequence"].get<std::uint32_t>() << ", crc "
    << j["crc32"].get<std::string>() << ", built by host " << j["host_version"].get<std::string>()
    << "\n";
  for (const char* m : {"M", "C", "K"}) o << m << "         " << j[m].dump() << "\n";
  for (const auto& [name, c] : j["channels"].items()) {
    o << "sensor    " << name << ": " << c["counts_per_unit"].get<double>() << " counts/"
      << c["unit"].get<std::string>() << ", offset " << c["offset_counts"].get<std::int64_t>()
      << ", full scale " << c["full_scale"].get<double>() << " " << c["unit"].get<std::string>();
    if (c.contains("dof")) o << ", mass " << c["dof"].get<int>();
    o << "\n";
  }
  if (j["observer"].is_null()) {
    o << "observer  none\n";
  } else {
    const auto& d = j["observer"];
    o << "observer  " << d["sample_rate_hz"].get<std::uint32_t>() << " Hz, d_hat on mass "
      << d["output_dof"].get<int>() << " (full scale " << d["output_full_scale_n"].get<double>()
      << " N), inputs";
    for (const auto& in : d["inputs"])
      o << " " << in["channel"].get<std::string>() << "(" << in["sections"].get<int>()
        << " sections)";
    o << "\n";
  }
  return o.str();
}

constexpr const char* kUploadHelp =
    "Build a calibration record and stage it on the board (commit makes it permanent)";

struct UploadArgs {
  const GlobalOptions* globals = nullptr;
  std::string model;
  std::string design;
  std::string sensors;
  std::string label;
  bool accept_flagged = false;
  std::string watch_day;
  device::WatchDayOptions watch;
};

device::UploadFiles Files(const UploadArgs& a) {
  return {.model = a.model,
          .design = a.design,
          .sensors = a.sensors,
          .label = a.label,
          .accept_flagged = a.accept_flagged};
}

void Run(const UploadArgs& a) {
  Verdict verdict;
  device::RecordInputs in = device::ReadRecordInputs(Files(a), VIBID_VERSION, &verdict);
  if (verdict.Flagged())
    std::cerr << "vibid: warning: " << a.model
              << " is flagged and taken (--accept-flagged): " << FormatVerdict(verdict) << "\n";
  else if (verdict.level == VerdictLevel::kCaution)
    std::cerr << "vibid: note: " << a.model << ": " << FormatVerdict(verdict) << "\n";
  // Read before the board is asked anything: a bad recording costs nothing.
  std::optional<Recording> day;
  if (!a.watch_day.empty()) day = LoadRecording(a.watch_day);
  WithDevice(*a.globals, [&](device::Connection& c) {
    if (a.sensors.empty()) {
      bool has_record = false;
      const wire::CalibrationRecord old = device::ActiveRecord(c, has_record);
      device::KeepBoardSensors(in, has_record ? &old : nullptr);
    }
    wire::CalibrationRecord rec = device::BuildCalibrationRecord(in);
    if (day) {
      const dob::WatchDesign design = device::AttachWatchTest(rec, *day, a.watch, a.watch_day);
      std::cout << device::WatchDesignText(design) << "\n";
    }
    std::array<std::uint8_t, wire::kCalRecordBytes> bytes{};
    wire::EncodeCalibrationRecord(rec, bytes);
    {
      ProgressBar bar("cal upload");
      c.CalPut(bytes, bar.Callback());
    }
    char crc[11];
    std::snprintf(crc, sizeof(crc), "0x%08x", wire::StoredRecordCrc(bytes));
    std::cout << "staged calibration '" << in.label << "' (" << bytes.size() << " bytes, crc "
              << crc << "); `vibid cal commit` writes it to flash\n";
  });
}

constexpr const char* kShowHelp = "Print the board's active calibration record";

struct ShowArgs {
  const GlobalOptions* globals = nullptr;
  bool json = false;
};

void Run(const ShowArgs& a) {
  WithDevice(*a.globals, [&](device::Connection& c) {
    if (c.info().cal_state != wire::CalState::kCalibrated) {
      std::cout << (a.json ? "null\n" : "uncalibrated: raw counts, no observer\n");
      return;
    }
    wire::CalGetTrailer t;
    const std::vector<std::uint8_t> bytes = c.CalGet(&t);
    const wire::CalibrationRecord r = device::DecodeBoardRecord(bytes);
    const nlohmann::json j =
        RecordJson(r, t,
                   wire::StoredRecordCrc(std::span<const std::uint8_t, wire::kCalRecordBytes>(
                       bytes.data(), bytes.size())));
    std::cout << (a.json ? j.dump(2) + "\n" : FormatRecord(j));
  });
}

constexpr const char* kCommitHelp = "Write the staged record to flash (refused while acquiring)";

struct CommitArgs {
  const GlobalOptions* globals = nullptr;
};

void Run(const CommitArgs& a) {
  WithDevice(*a.globals, [](device::Connection& c) {
    const wire::CalCommitResponse r = c.CalCommit();
    std::cout << "committed to slot " << static_cast<int>(r.slot) << ", sequence " << r.sequence
              << "\n";
  });
}

}  // namespace

void RegisterCalCommands(CLI::App& app, const GlobalOptions& globals) {
  CLI::App* cal =
      app.add_subcommand("cal", "The board's calibration record: model, sensor scaling, observer");
  cal->require_subcommand(1);

  const auto [upload, uo] = AddCommand<UploadArgs>(*cal, "upload", kUploadHelp, Run);
  uo->globals = &globals;
  TakesDeviceOption(upload);
  upload->add_option("model", uo->model, "Model file (M, C, K) of the rig")->required();
  upload->add_option("--design", uo->design, "Observer design file from `vibid dob design`")
      ->required();
  upload->add_option("--sensors", uo->sensors,
                     "Sensors file (default: the scaling the board already holds)");
  upload->add_option("--label", uo->label,
                     "Rig name stored in the record (default: the model file's name)");
  upload->add_flag("--accept-flagged", uo->accept_flagged,
                   "Upload a model whose verdict is flagged (refused otherwise, exit 6)");
  CLI::Option* day =
      upload->add_option("--watch-day", uo->watch_day,
                         "Calibration-day recording (vibid acquire at the observer's rate, the "
                         "observer running, its inputs logged): builds the board's model test "
                         "into the record (docs/dob.md)");
  upload
      ->add_option("--watch-false-alarms-per-hour", uo->watch.false_alarms_per_hour,
                   "The model test's false alarms per hour of in-control running (default "
                   "0.001: one in 1000 hours)")
      ->needs(day);
  upload
      ->add_option("--watch-reference", uo->watch.reference,
                   "Load cell measuring the force where the observer estimates it (force1 or "
                   "force2): the test watches d_hat minus it (default: d_hat alone)")
      ->needs(day);

  const auto [show, show_args] = AddCommand<ShowArgs>(*cal, "show", kShowHelp, Run);
  show_args->globals = &globals;
  TakesDeviceOption(show);
  show->add_flag("--json", show_args->json, "Print JSON");

  const auto [commit, commit_args] = AddCommand<CommitArgs>(*cal, "commit", kCommitHelp, Run);
  commit_args->globals = &globals;
  TakesDeviceOption(commit);
}

}  // namespace vibid::cli
