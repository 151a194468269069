// vibid devices | info | monitor
#include <chrono>
#include <cstdio>
#include <iostream>
#include <optional>
#include <sstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "cli_support.hpp"
#include "common/command.hpp"
#include "device_commands.hpp"
#include "session.hpp"
#include "vibid/common/enum_names.hpp"
#include "vibid/common/error.hpp"
#include "vibid/device/board_report.hpp"
#include "vibid/device/acquire_plan.hpp"
#include "vibid/device/error.hpp"
#include "vibid/device/health_report.hpp"
#include "vibid/device/info_json.hpp"
#include "vibid/device/log_table.hpp"
#include "vibid/device/select.hpp"
#include "vibid/device/watch_report.hpp"
#include "vibid/shared/wire/log_record.hpp"

namespace vibid::cli {
namespace {

using device::InfoJson;

constexpr const char* kDevicesHelp =
    "List the vibid boards and emulators this host can reach; with --device or VIBID_DEVICE, "
    "probe the one it names";

struct DevicesArgs {
  const GlobalOptions* globals = nullptr;
};

/// One line for the board `choice` names: what answers there, or a DeviceError saying nothing does.
void Probe(const GlobalOptions& globals, const device::DeviceChoice& choice) {
  try {
    WithDevice(globals, [&](device::Connection& c) {
      const nlohmann::json j = InfoJson(c, c.info(), std::nullopt, std::nullopt, std::nullopt);
      std::cout << choice.text << "\t" << j["board"].get<std::string>() << ", firmware "
                << j["firmware"].get<std::string>() << ", protocol "
                << j["protocol"].get<std::string>() << ", "
                << (j["calibrated"].get<bool>() ? "calibrated" : "not calibrated") << " ("
                << c.Describe() << ")\n";
    });
  } catch (const device::Interrupted&) {
    throw;
  } catch (const device::DeviceError& e) {
    throw device::DeviceError("no vibid board answers at " + choice.text + " (from " +
                              choice.origin + "): " + e.what());
  }
}

void Run(const DevicesArgs& a) {
  const device::DeviceChoice choice = device::ChooseDevice(a.globals->device);
  if (!choice.text.empty()) return Probe(*a.globals, choice);
  const auto all = device::ListDevices();
  if (all.empty()) {
    std::cout << "no vibid device found (no board on USB HID, no vibid-emu on 127.0.0.1:3240)\n";
    return;
  }
  for (const device::Listing& l : all) std::cout << l.spec << "\t" << l.description << "\n";
}

constexpr const char* kInfoHelp =
    "Identity, versions, capabilities and calibration state of the board";

struct InfoArgs {
  const GlobalOptions* globals = nullptr;
  bool json = false;
};

std::string InfoText(const device::Connection& c, const nlohmann::json& j) {
  std::ostringstream o;
  o << "device        " << c.Describe() << "\n"
    << "board         " << j["board"].get<std::string>() << ", firmware "
    << j["firmware"].get<std::string>() << " (build " << j["build_id"].get<std::string>()
    << "), protocol " << j["protocol"].get<std::string>() << "\n"
    << "capabilities  ";
  for (const auto& cap : j["capabilities"]) o << cap.get<std::string>() << " ";
  const wire::InfoResponse& i = c.info();
  o << "\nsampling      " << 1e6 / i.sample_period_us << " Hz (fastest "
    << 1e6 / i.min_sample_period_us << " Hz), log " << i.log_capacity_bytes << " bytes\n"
    << "link          " << std::uint32_t{i.link_reports_per_s} * wire::kReportBytes << " B/s ("
    << i.link_reports_per_s << " reports/s of " << wire::kReportBytes << " B; "
    << std::uint32_t{i.link_reports_per_s} * wire::kLogRecordPayload << " B/s of log records)\n"
    << "channels      ";
  for (const auto& ch : j["channels"]) o << ch.get<std::string>() << " ";
  o << "\ninstants      ";
  if (j["sample_instants_us"].is_null()) {
    o << "not stated (protocol 2.0 board)";
  } else {
    for (const auto& ch : j["channels"]) {
      o << ch.get<std::string>() << " "
        << j["sample_instants_us"][ch.get<std::string>()].get<double>() << " ";
    }
    o << "(us after the sample clock's edge)";
  }
  o << "\ncalibration   ";
  if (i.cal_state == wire::CalState::kCalibrated) {
    o << "slot " << static_cast<int>(i.cal_slot) << ", crc " << j["cal_crc"].get<std::string>();
  } else {
    o << "none (raw counts, no observer)";
  }
  o << "\nmodel         " << j["model_text"].get<std::string>();
  o << "\nreset cause   " << j["reset_cause"].get<std::string>() << "\n";
  if (!j["fault"].is_null()) o << "fault         " << j["fault"]["text"].get<std::string>() << "\n";
  o << "brown-out     " << j["brown_out_level"].get<std::string>() << "\n";
  if (!j["clock_text"].is_null())
    o << "clock         " << j["clock_text"].get<std::string>() << "\n";
  o << "errors        " << i.overrun_count << " overruns, " << i.dropped_records
    << " dropped records";
  if (!j["sampler_recoveries"].is_null())
    o << ", " << j["sampler_recoveries"].get<std::uint32_t>() << " converter recoveries";
  o << "\nclipped       ";
  const nlohmann::json& clips = j["clipped"];
  if (clips.is_null()) {
    o << "not counted per channel by this firmware (protocol " << j["protocol"].get<std::string>()
      << ")\n";
    return o.str();
  }
  const std::uint32_t samples = clips["samples"].get<std::uint32_t>();
  if (samples == 0) {
    o << "none (nothing sampled since the board started)\n";
    return o.str();
  }
  std::string counts;
  for (const auto& ch : j["channels"]) {  // in channel order
    const auto n = clips["channels"][ch.get<std::string>()].get<std::uint32_t>();
    if (n != 0)
      counts += (counts.empty() ? "" : ", ") + ch.get<std::string>() + " " + std::to_string(n);
  }
  o << (counts.empty() ? "none" : counts) << " of " << samples
    << " samples in the last acquisition\n";
  return o.str();
}

void Run(const InfoArgs& a) {
  WithDevice(*a.globals, [&](device::Connection& c) {
    const std::optional<wire::HealthInfoResponse> health = c.GetHealthInfo();
    const std::optional<wire::WatchInfoResponse> watch = c.GetWatchInfo();
    // The fault page only after a fault reset: older firmware never reports one.
    const bool faulted = c.info().reset_cause == wire::ResetCause::kFault ||
                         (health && health->reset_cause == wire::ResetCause::kFault);
    const std::optional<wire::FaultInfoResponse> fault =
        faulted ? c.GetFaultInfo() : std::optional<wire::FaultInfoResponse>{};
    nlohmann::json j =
        InfoJson(c, c.info(), c.GetClips(), c.GetSamplingInfo(), health, watch, fault);
    if (!a.json) {
      j["model_text"] =
          device::WatchText(watch, c.info().sample_period_us, c.GetStatus().dob_running != 0);
    }
    std::cout << (a.json ? j.dump(2) + "\n" : InfoText(c, j));
    if (const auto w =
            device::BrownOutWarning(health ? health->brown_out : wire::BrownOut::kUnknown))
      std::cerr << "vibid: warning: " << *w << "\n";
  });
}

constexpr const char* kMonitorHelp =
    "Print the board's live calibrated values until Ctrl-C (the board samples only while an "
    "acquisition runs)";

/// Each line costs two exchanges (read-latest, get-status), each one report out and one back;
/// the link moves one report each way per 1 ms frame, so a line takes 2 ms at the least (3 ms
/// with a residual test in the calibration: get-info's watch page too).
constexpr double kMinMonitorIntervalS = 0.002;

struct MonitorArgs {
  const GlobalOptions* globals = nullptr;
  double interval_s = 0.2;
  int count = 0;
};

void PrintMonitorHeader(const wire::CalibrationRecord& rec, bool has_record) {
  std::cout << "tick";
  for (std::size_t k = 0; k < wire::kChannelCount; ++k) {
    const wire::Unit u = has_record ? rec.channels[k].unit : wire::Unit::kCounts;
    std::cout << "\t" << device::ChannelStem(static_cast<wire::Channel>(k)) << "_"
              << device::UnitSuffix(u);
  }
  std::cout << "\td_hat_q31\tstate";
  // The residual test's column only where the calibration carries one.
  if (has_record && (rec.flags & wire::kCalFlagHasWatch) != 0) std::cout << "\tmodel";
  std::cout << std::endl;
}

// "ok g/h" in control, "STALE@tick" once the flag is up, "-" while the observer does not run.
std::string MonitorModel(const std::optional<wire::WatchInfoResponse>& w) {
  if (!w || w->state != wire::WatchState::kWatching) return "-";
  std::ostringstream o;
  o.precision(3);
  if (w->stale != 0) {
    o << "STALE@" << w->trip_tick;
  } else {
    o << "ok " << w->statistic / 65536.0 << "/" << w->threshold / 65536.0;
  }
  return o.str();
}

void PrintMonitorLine(const wire::LatestResponse& l, const wire::StatusResponse& st,
                      const wire::CalibrationRecord& rec, bool has_record,
                      const std::optional<std::string>& model) {
  const device::LatestKind kind = device::ClassifyLatest(l, st);
  if (kind == device::LatestKind::kNoFrame) {
    // Zeros here would read as a measurement; there is none.
    std::cout << "-\tidle: no samples (the board samples only while an acquisition runs)"
              << std::endl;
    return;
  }
  std::cout << l.tick;
  for (std::size_t k = 0; k < wire::kChannelCount; ++k) {
    const wire::ChannelScaling s = has_record ? rec.channels[k] : wire::DefaultScaling();
    const double v = s.unit == wire::Unit::kCounts
                         ? l.calibrated[k]
                         : l.calibrated[k] * (static_cast<double>(s.full_scale) / 2147483648.0);
    std::cout << "\t" << v;
  }
  std::cout << "\t" << l.d_hat << "\t";
  if (kind == device::LatestKind::kStopped) {
    std::cout << "stopped: the last frame of the acquisition that "
              << (l.acq_state == wire::AcqState::kDone ? "ended" : "was stopped");
    if (model) std::cout << "\t" << *model;
    std::cout << std::endl;
    return;
  }
  std::cout << (l.acq_state == wire::AcqState::kArmed ? "armed" : "sampling")
            << (l.dob_running != 0 ? "+dob" : "");
  if (model) std::cout << "\t" << *model;
  std::cout << std::endl;
}

void Run(const MonitorArgs& a) {
  std::ostringstream interval;
  interval << a.interval_s;
  Require(a.interval_s >= kMinMonitorIntervalS,
          "--interval-s " + interval.str() +
              ": a line takes two exchanges (read-latest, get-status) of one 64-byte report each "
              "way, and the link moves one report each way per 1 ms frame; use 0.002 or more");
  WithDevice(*a.globals, [&](device::Connection& c) {
    bool has_record = false;
    const wire::CalibrationRecord rec = device::ActiveRecord(c, has_record);
    PrintMonitorHeader(rec, has_record);
    for (int n = 0; a.count == 0 || n < a.count; ++n) {
      if (InterruptFlag().load()) break;
      const wire::LatestResponse latest = c.ReadLatest();
      const wire::StatusResponse status = c.GetStatus();
      std::optional<std::string> model;
      if (has_record && (rec.flags & wire::kCalFlagHasWatch) != 0)
        model = MonitorModel(c.GetWatchInfo());
      PrintMonitorLine(latest, status, rec, has_record, model);
      std::this_thread::sleep_for(std::chrono::duration<double>(a.interval_s));
    }
  });
}

}  // namespace

void RegisterInfoCommands(CLI::App& app, const GlobalOptions& globals) {
  const auto [devices, devices_args] = AddCommand<DevicesArgs>(app, "devices", kDevicesHelp, Run);
  devices_args->globals = &globals;
  TakesDeviceOption(devices);

  const auto [info, info_args] = AddCommand<InfoArgs>(app, "info", kInfoHelp, Run);
  info_args->globals = &globals;
  TakesDeviceOption(info);
  info->add_flag("--json", info_args->json, "Print JSON");

  const auto [monitor, mo] = AddCommand<MonitorArgs>(app, "monitor", kMonitorHelp, Run);
  mo->globals = &globals;
  TakesDeviceOption(monitor);
  monitor
      ->add_option("--interval-s", mo->interval_s,
                   "Seconds between lines (at least 0.002: two exchanges of one 1 ms frame each)")
      ->check(PositiveNumber());
  monitor->add_option("--count", mo->count, "Stop after this many lines (default: until Ctrl-C)")
      ->check(CLI::NonNegativeNumber);
}

}  // namespace vibid::cli
