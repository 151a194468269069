// vibid cal upload | build | show | commit
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <iterator>
#include <optional>
#include <sstream>

#include <nlohmann/json.hpp>

#include "cli_support.hpp"
#include "common/command.hpp"
#include "vibid/device/acquire_plan.hpp"
#include "vibid/device/error.hpp"
#include "device_commands.hpp"
#include "session.hpp"
#include "vibid/common/atomic_file.hpp"
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
  o << "record    '" << j["label"].get<std::string>() << "', ";
  if (j["slot"].is_null())
    o << "not on a board";  // a record file of `cal build`
  else
    o << "slot " << j["slot"].get<int>() << ", sequence " << j["sequence"].get<std::uint32_t>();
  o << ", crc " << j["crc32"].get<std::string>() << ", built by host "
    << j["host_version"].get<std::string>() << "\n";
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

// The record's inputs read, the model's verdict said, the calibration day read: all before a
// board is asked anything, so that a bad file costs nothing.
device::RecordInputs ReadInputs(const UploadArgs& a, std::optional<Recording>& day) {
  Verdict verdict;
  device::RecordInputs in = device::ReadRecordInputs(Files(a), VIBID_VERSION, &verdict);
  if (verdict.Flagged())
    std::cerr << "vibid: warning: " << a.model
              << " is flagged and taken (--accept-flagged): " << FormatVerdict(verdict) << "\n";
  else if (verdict.level == VerdictLevel::kCaution)
    std::cerr << "vibid: note: " << a.model << ": " << FormatVerdict(verdict) << "\n";
  if (!a.watch_day.empty()) day = LoadRecording(a.watch_day);
  return in;
}

// The record from its inputs, with the model test when a calibration day is given (its design
// line printed): one path for the board's staging and the offline build, so both give the same
// kernel parameters from the same day.
std::array<std::uint8_t, wire::kCalRecordBytes> EncodedRecord(const UploadArgs& a,
                                                              const device::RecordInputs& in,
                                                              const std::optional<Recording>& day,
                                                              wire::CalibrationRecord& rec) {
  rec = device::BuildCalibrationRecord(in);
  if (day) {
    const dob::WatchDesign design = device::AttachWatchTest(rec, *day, a.watch, a.watch_day);
    std::cout << device::WatchDesignText(design) << "\n";
  }
  std::array<std::uint8_t, wire::kCalRecordBytes> bytes{};
  wire::EncodeCalibrationRecord(rec, bytes);
  return bytes;
}

std::string CrcText(std::uint32_t crc) {
  char text[11];
  std::snprintf(text, sizeof(text), "0x%08x", crc);
  return text;
}

void Run(const UploadArgs& a) {
  std::optional<Recording> day;
  device::RecordInputs in = ReadInputs(a, day);
  WithDevice(*a.globals, [&](device::Connection& c) {
    if (a.sensors.empty()) {
      bool has_record = false;
      const wire::CalibrationRecord old = device::ActiveRecord(c, has_record);
      device::KeepBoardSensors(in, has_record ? &old : nullptr);
    }
    wire::CalibrationRecord rec;
    const auto bytes = EncodedRecord(a, in, day, rec);
    {
      ProgressBar bar("cal upload");
      c.CalPut(bytes, bar.Callback());
    }
    std::cout << "staged calibration '" << in.label << "' (" << bytes.size() << " bytes, crc "
              << CrcText(wire::StoredRecordCrc(bytes))
              << "); `vibid cal commit` writes it to flash\n";
  });
}

constexpr const char* kBuildHelp =
    "Build a calibration record into a file, without a board (what upload would stage)";

struct BuildArgs {
  UploadArgs upload;
  std::string out;
};

bool EndsWith(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

// A record no board has taken (a file of `cal build`): as `cal show --json` prints a board's, the
// CRC its stored bytes carry and no slot or sequence.
nlohmann::json OffBoardRecordJson(const wire::CalibrationRecord& rec,
                                  std::span<const std::uint8_t, wire::kCalRecordBytes> bytes) {
  nlohmann::json j = device::RecordJson(rec);
  j["slot"] = nullptr;
  j["sequence"] = nullptr;
  j["crc32"] = CrcText(wire::StoredRecordCrc(bytes));
  return j;
}

// The record file: that JSON when the name ends in .json, the record's bytes otherwise. The file
// is claimed before the design runs (a bad path costs nothing) and renamed into place whole.
void Run(const BuildArgs& a) {
  std::optional<Recording> day;
  const device::RecordInputs in = ReadInputs(a.upload, day);
  AtomicOutputFile out(a.out);
  wire::CalibrationRecord rec;
  const auto bytes = EncodedRecord(a.upload, in, day, rec);
  if (EndsWith(a.out, ".json"))
    out.Commit(OffBoardRecordJson(rec, bytes).dump(2) + "\n");
  else
    out.Commit(std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
  std::cout << "built calibration '" << in.label << "' (" << bytes.size() << " bytes, crc "
            << CrcText(wire::StoredRecordCrc(bytes)) << ") into " << a.out << "\n";
}

constexpr const char* kShowHelp = "Print the board's active calibration record";

struct ShowArgs {
  const GlobalOptions* globals = nullptr;
  bool json = false;
  std::string record;
};

// A record file of `cal build`: decoded as the board decodes its own, shown without slot or
// sequence (no board has taken it).
void ShowFile(const ShowArgs& a) {
  std::ifstream f(a.record, std::ios::binary);
  if (!f) throw InputError(a.record + ": cannot read the record file");
  const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(f)),
                                        std::istreambuf_iterator<char>());
  wire::CalibrationRecord r;
  const Status st = wire::DecodeCalibrationRecord(bytes, r);
  if (st != Status::kOk || bytes.size() != wire::kCalRecordBytes)
    throw InputError(a.record + ": not a calibration record of this host (" +
                     std::to_string(bytes.size()) + " bytes; `vibid cal build -o FILE.bin` " +
                     "writes one of " + std::to_string(wire::kCalRecordBytes) + ")");
  const nlohmann::json j = OffBoardRecordJson(
      r, std::span<const std::uint8_t, wire::kCalRecordBytes>(bytes.data(), bytes.size()));
  std::cout << (a.json ? j.dump(2) + "\n" : FormatRecord(j));
}

void Run(const ShowArgs& a) {
  if (!a.record.empty()) {
    ShowFile(a);
    return;
  }
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

  const auto [build, bo] = AddCommand<BuildArgs>(*cal, "build", kBuildHelp, Run);
  build->add_option("model", bo->upload.model, "Model file (M, C, K) of the rig")->required();
  build->add_option("--design", bo->upload.design, "Observer design file from `vibid dob design`")
      ->required();
  build->add_option("--sensors", bo->upload.sensors, "Sensors file")->required();
  build->add_option("--label", bo->upload.label,
                    "Rig name stored in the record (default: the model file's name)");
  build->add_flag("--accept-flagged", bo->upload.accept_flagged,
                  "Build from a model whose verdict is flagged (refused otherwise, exit 6)");
  CLI::Option* build_day = build->add_option(
      "--watch-day", bo->upload.watch_day,
      "Calibration-day recording (as for cal upload): builds the board's model test into the "
      "record");
  build
      ->add_option("--watch-false-alarms-per-hour", bo->upload.watch.false_alarms_per_hour,
                   "The model test's false alarms per hour of in-control running (default 0.001)")
      ->needs(build_day);
  build
      ->add_option("--watch-reference", bo->upload.watch.reference,
                   "Load cell measuring the force where the observer estimates it (force1 or "
                   "force2)")
      ->needs(build_day);
  build
      ->add_option("-o,--output", bo->out,
                   "Record file: NAME.json as `cal show --json` prints it, else the record's bytes "
                   "(read back by `cal show --record`)")
      ->required();

  const auto [show, show_args] = AddCommand<ShowArgs>(*cal, "show", kShowHelp, Run);
  show_args->globals = &globals;
  TakesDeviceOption(show);
  show->add_flag("--json", show_args->json, "Print JSON");
  show->add_option("--record", show_args->record,
                   "A record file from `vibid cal build -o FILE.bin` instead of the board's");

  const auto [commit, commit_args] = AddCommand<CommitArgs>(*cal, "commit", kCommitHelp, Run);
  commit_args->globals = &globals;
  TakesDeviceOption(commit);
}

}  // namespace vibid::cli
