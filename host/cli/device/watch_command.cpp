// vibid watch: the rig's modes and the subspace change test, block by block, on the board's live
// responses or on a recording (workflow::WatchSession decides; this file reads, prints, journals).
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <limits>
#include <numbers>
#include <optional>

#include "cli_support.hpp"
#include "common/command.hpp"
#include "device_commands.hpp"
#include "session.hpp"
#include "vibid/common/csv.hpp"
#include "vibid/common/error.hpp"
#include "vibid/device/acquire_plan.hpp"
#include "vibid/device/error.hpp"
#include "vibid/device/log_table.hpp"
#include "vibid/device/watch_report.hpp"
#include "vibid/workflow/watch_columns.hpp"
#include "vibid/workflow/watch_session.hpp"

namespace vibid::cli {
namespace {

constexpr const char* kWatchHelp =
    "Watch the rig while it runs: its modes and a change test on its responses, one line per "
    "block (the first --reference-s seconds are the reference). On the board (--device) it "
    "starts the acquisition itself and runs until --seconds or Ctrl-C (exit 130, the journal "
    "kept); or on a recording REC.csv";

struct WatchArgs {
  const GlobalOptions* globals = nullptr;
  std::string recording;
  device::AcquireSettings settings;
  std::string scenario;
  std::vector<float> scenario_params;
  std::string reference;
  std::string responses;
  workflow::WatchOptions watch;
  bool json = false;
  std::string journal;
};

std::string Num(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", v);
  return b;
}

/// --response's names ("" names none).
std::vector<std::string> Requested(const std::string& responses) {
  return responses.empty() ? std::vector<std::string>{} : SplitList(responses);
}

/// The watched columns: --response's, or every acceleration and position column (the library's
/// choice, as Python's).
std::vector<std::string> ResponseNames(const std::string& responses,
                                       const std::vector<std::string>& names,
                                       const std::string& source) {
  return workflow::ChooseWatchColumns(names, Requested(responses), source,
                                      workflow::OptionSpelling::kCli)
      .responses;
}

/// The journal: JSON lines appended and flushed as the blocks come, so a crash leaves every
/// whole line. Opened (created or truncated) before the board starts.
class Journal {
 public:
  explicit Journal(const std::string& path) : path_(path) {
    if (path.empty()) return;
    file_ = std::fopen(path.c_str(), "wb");
    if (file_ == nullptr) {
      throw InputError("-o " + path + ": cannot create the journal: " + std::strerror(errno) +
                       "; give a writable path");
    }
  }
  ~Journal() {
    if (file_ != nullptr) std::fclose(file_);
  }
  Journal(const Journal&) = delete;
  Journal& operator=(const Journal&) = delete;

  void Append(const std::string& line) {
    if (file_ == nullptr) return;
    if (std::fputs((line + "\n").c_str(), file_) < 0 || std::fflush(file_) != 0)
      throw InputError("-o " + path_ + ": cannot append to the journal: " + std::strerror(errno));
  }

 private:
  std::string path_;
  std::FILE* file_ = nullptr;
};

/// Prints and journals each block; the reference's summary on stderr once it is built.
class Printer {
 public:
  Printer(const WatchArgs& a, Journal& journal) : a_(a), journal_(journal) {}

  void Blocks(const workflow::WatchSession& s, const std::vector<workflow::WatchBlock>& blocks,
              const nlohmann::json& model_stale = nullptr) {
    if (s.has_reference() && !reference_said_) {
      reference_said_ = true;
      const workflow::WatchReference& r = s.reference();
      std::string modes;
      for (const workflow::WatchMode& m : r.modes) {
        char b[80];
        std::snprintf(b, sizeof b, "%s%.3f Hz (ζ %.2f %%)", modes.empty() ? "" : ", ",
                      m.omega_rad_s / (2.0 * std::numbers::pi), 100.0 * m.zeta);
        modes += b;
      }
      std::cerr << "vibid: reference of " << Num(r.seconds) << " s: modes " << modes
                << "; test order " << r.order << ", " << r.dof << " residuals over "
                << r.reference_blocks << " blocks; window of " << a_.watch.window_blocks
                << " blocks alarms over " << Num(r.window_threshold) << " ("
                << Num(a_.watch.false_alarm_per_hour) << " false alarms per hour)\n";
    }
    for (const workflow::WatchBlock& b : blocks) {
      nlohmann::json j = workflow::WatchBlockJson(b);
      if (!model_stale.is_null()) j["model_stale"] = model_stale;
      const std::string line = j.dump();
      journal_.Append(line);
      if (a_.json) {
        std::cout << line << "\n";
      } else {
        std::cout << workflow::WatchBlockText(b) << "\n";
      }
      std::cout.flush();
    }
  }

 private:
  const WatchArgs& a_;
  Journal& journal_;
  bool reference_said_ = false;
};

Eigen::MatrixXd Columns(const Recording& r, const std::vector<std::string>& names) {
  Eigen::MatrixXd y(static_cast<Eigen::Index>(r.samples()),
                    static_cast<Eigen::Index>(names.size()));
  for (std::size_t j = 0; j < names.size(); ++j)
    y.col(static_cast<Eigen::Index>(j)) = r.table.Column(names[j]);
  return y;
}

void SetReference(const WatchArgs& a, workflow::WatchSession& s,
                  const std::vector<std::string>& names) {
  if (a.reference.empty()) return;
  RecordingOptions ro;
  ro.channels = names;
  const Recording ref = LoadRecording(a.reference, ro);
  Require(std::abs(ref.fs_hz / s.options().fs_hz - 1.0) < 1e-6,
          "--reference " + a.reference + ": sampled at " + Num(ref.fs_hz) + " Hz, the watched " +
              "responses at " + Num(s.options().fs_hz) + " Hz; record both at one rate");
  s.SetReference(Columns(ref, names));
}

void RunOnRecording(const WatchArgs& a) {
  Require(a.settings.seconds == 0.0 && a.scenario.empty(),
          "watch: --seconds and --scenario are for the board (--device), not a recording");
  const Recording rec = LoadRecording(a.recording);
  const workflow::WatchColumns columns = workflow::ChooseWatchColumns(
      rec.table.names, Requested(a.responses), a.recording, workflow::OptionSpelling::kCli);
  const std::vector<std::string>& responses = columns.responses;
  workflow::WatchOptions o = a.watch;
  o.fs_hz = rec.fs_hz;
  o.channels = static_cast<int>(responses.size());
  Journal journal(a.journal);
  workflow::WatchSession s(o);
  SetReference(a, s, responses);
  Printer printer(a, journal);
  const Eigen::MatrixXd y = Columns(rec, responses);
  // The board's model test, when the log carries it: each block with the board's flag.
  Eigen::MatrixXd board;
  if (columns.board_statistic)
    board = Columns(rec, {*columns.board_statistic, *columns.board_flag});
  // Fed as a board would, a block at a time, so that each line is out as soon as it is made.
  const auto step = std::max<Eigen::Index>(1, std::lround(o.block_s * o.fs_hz));
  for (Eigen::Index at = 0; at < y.rows(); at += step) {
    const Eigen::Index n = std::min(step, y.rows() - at);
    printer.Blocks(s, board.size() > 0
                          ? s.Feed(y.middleRows(at, n), board.middleRows(at, n), rec.t0_s)
                          : s.Feed(y.middleRows(at, n), rec.t0_s));
  }
  if (!s.has_reference()) {
    throw InputError("watch: " + a.recording + " holds " +
                     Num(static_cast<double>(y.rows()) / o.fs_hz) +
                     " s, shorter than the reference (--reference-s " + Num(o.reference_s) +
                     "); give a longer recording, a shorter --reference-s or --reference");
  }
}

void RunOnDevice(const WatchArgs& a) {
  device::AcquireSettings settings = a.settings;
  const bool until_stopped = settings.seconds == 0.0;
  if (settings.channels.empty()) settings.channels = {"acc1", "acc2"};
  const int decimation =
      device::DecimationFor(settings.rate_hz, settings.log_rate_hz, settings.decimation);
  const double log_rate_hz = settings.rate_hz / decimation;
  // Without --seconds: as long as the board counts records (about 50 days at 1 kHz, capped at
  // 30 days), stopped by Ctrl-C.
  if (until_stopped) settings.seconds = std::min(30.0 * 86400.0, 4.0e9 / log_rate_hz);
  device::Trigger trig;
  wire::AcqConfigureRequest cfg = device::PlanAcquisition(settings, trig);
  Require(a.scenario_params.size() <= 4, "--scenario-param takes at most 4 values");
  // The columns the log will have (as acquire writes them), before the board is asked.
  device::LogPull format;
  format.layout = wire::LogLayout{cfg.channel_mask, cfg.flags};
  format.trailer.sample_period_us = cfg.sample_period_us;
  format.trailer.decimation = cfg.decimation;
  format.trailer.channel_mask = cfg.channel_mask;
  format.trailer.acq_flags = cfg.flags;
  // Units: the calibration is read from the board below; the names do not depend on it being
  // there except for their unit suffix, so the options are checked against the names read then.
  workflow::WatchOptions o = a.watch;
  o.fs_hz = log_rate_hz;
  int responses_count = 0;
  if (!a.responses.empty()) {
    responses_count = static_cast<int>(SplitList(a.responses).size());
  } else {
    for (const std::string& c : settings.channels)
      responses_count += workflow::IsWatchResponse(c) ? 1 : 0;
  }
  o.channels = std::max(1, responses_count);
  o.Validate();  // before the board starts: a bad option costs nothing
  Require(
      until_stopped || settings.seconds > (a.reference.empty() ? o.reference_s : 0.0) + o.block_s,
      "--seconds " + Num(settings.seconds) + " ends before the first block after the reference (" +
          Num(o.reference_s + o.block_s) + " s); watch longer or shorten --reference-s");
  Journal journal(a.journal);  // refused now, not after the board has started
  WithDevice(
      *a.globals,
      [&](device::Connection& c) {
        bool has_record = false;
        const wire::CalibrationRecord rec = device::ActiveRecord(c, has_record);
        const bool dob_running = c.GetStatus().dob_running != 0;
        device::ApplyCalibration(rec, has_record, dob_running, settings.no_dob, trig, cfg);
        (void)device::Preflight(c.info(), cfg, settings);
        cfg.flags = static_cast<std::uint8_t>(cfg.flags | wire::kAcqFlagStream);
        format.layout = wire::LogLayout{cfg.channel_mask, cfg.flags};
        format.trailer.acq_flags = cfg.flags;
        device::LogPull empty = format;
        const std::vector<std::string> names = device::MakeLogTable(empty, rec, has_record).names;
        const std::vector<std::string> responses = ResponseNames(a.responses, names, "the log");
        std::vector<std::size_t> index;
        for (const std::string& n : responses)
          for (std::size_t k = 0; k < names.size(); ++k)
            if (names[k] == n) index.push_back(k);
        o.channels = static_cast<int>(responses.size());
        workflow::WatchSession s(o);
        SetReference(a, s, responses);
        // The board's residual test, when its observer runs: read before and after (a request
        // while the log streams would hold the link).
        nlohmann::json stale = nullptr;
        if (dob_running) {
          stale = device::WatchJson(c.GetWatchInfo(), cfg.sample_period_us);
          std::cerr << "vibid: the board's model test: "
                    << device::WatchText(c.GetWatchInfo(), cfg.sample_period_us) << "\n";
        }
        if (!a.scenario.empty()) c.SelectScenario(a.scenario, a.scenario_params);
        c.Configure(cfg);
        Printer printer(a, journal);
        if (s.has_reference()) {
          printer.Blocks(s, {});
        } else {
          std::cerr << "vibid: reference: the first " << Num(o.reference_s)
                    << " s (the rig as it is now)\n";
        }
        std::uint32_t next = 0;  // the next log index expected
        std::exception_ptr failed;
        const auto live = [&](std::uint32_t first, std::span<const wire::LogRecord> records) {
          if (failed) return;
          try {
            // A resumed stream may hand over again what came before: from `next` on only.
            const std::size_t skip = first < next ? next - first : 0;
            if (skip >= records.size()) return;
            if (first > next) s.Gap(static_cast<long>(first - next));
            device::LogPull block = format;
            block.records.assign(records.begin() + static_cast<std::ptrdiff_t>(skip),
                                 records.end());
            const device::LogTable table = device::MakeLogTable(block, rec, has_record);
            Eigen::MatrixXd y(static_cast<Eigen::Index>(block.records.size()),
                              static_cast<Eigen::Index>(index.size()));
            for (std::size_t j = 0; j < index.size(); ++j)
              y.col(static_cast<Eigen::Index>(j)) = table.columns[index[j]];
            next = first + static_cast<std::uint32_t>(records.size());
            printer.Blocks(s, s.Feed(y, table.columns[0][0]), stale);
          } catch (...) {
            failed = std::current_exception();
          }
        };
        bool interrupted = false;
        device::LogPull pull;
        try {
          pull = c.AcquireStreamed(
              {},
              [&](const wire::LogTrailer*) {
                if (InterruptFlag().load() && !interrupted) {
                  interrupted = true;
                  std::cerr << "vibid: Ctrl-C: stopping the acquisition; the journal is kept "
                               "(Ctrl-C again to abort)\n";
                }
                return interrupted || failed != nullptr;
              },
              live);
        } catch (const device::IncompleteLog& e) {
          std::cerr << "vibid: warning: " << e.what() << "\n";
        } catch (...) {
          try {
            c.StopAcquisition();
          } catch (const device::DeviceError&) {
          }
          throw;
        }
        if (failed) std::rethrow_exception(failed);
        if (dob_running) {
          std::cerr << "vibid: the board's model test at the end: "
                    << device::WatchText(c.GetWatchInfo(), cfg.sample_period_us) << "\n";
        }
        if (!s.has_reference()) {
          std::cerr << "vibid: stopped during the reference (" << Num(s.reference_left_s())
                    << " s of it to go): nothing watched\n";
        }
        if (interrupted) throw StoppedByInterrupt();
      },
      CtrlC::kStopsAcquisition);
}

void Run(const WatchArgs& a) {
  if (!a.recording.empty()) {
    RunOnRecording(a);
  } else {
    RunOnDevice(a);
  }
}

}  // namespace

void RegisterWatchCommand(CLI::App& app, const GlobalOptions& globals) {
  const auto [cmd, o] = AddCommand<WatchArgs>(app, "watch", kWatchHelp, Run);
  o->globals = &globals;
  TakesDeviceOption(cmd);
  o->settings.rate_hz = 1000.0;
  cmd->add_option("recording", o->recording,
                  "A recording to watch (as acquire writes it) instead of the board");
  cmd->add_option("--seconds", o->settings.seconds,
                  "Board: seconds to watch, reference included (default: until Ctrl-C)")
      ->check(PositiveNumber());
  cmd->add_option("--rate-hz", o->settings.rate_hz, "Board: sample rate (Hz)")
      ->check(PositiveNumber())
      ->capture_default_str();
  cmd->add_option("--log-rate-hz", o->settings.log_rate_hz,
                  "Board: log rate (Hz), filtered and decimated on the board (default: the "
                  "sample rate)")
      ->check(PositiveNumber());
  cmd->add_option("--channels", o->settings.channels,
                  "Board: channels to log (default acc1,acc2): force1,force2,acc1,acc2,x1,x2")
      ->delimiter(',');
  cmd->add_option("--scenario", o->scenario,
                  "Emulator only: the rig excitation to run (operate: the rig in operation)");
  cmd->add_option("--scenario-param", o->scenario_params,
                  "Emulator only: up to 4 scenario parameters (SI)")
      ->delimiter(',');
  cmd->add_flag("--no-dob", o->settings.no_dob,
                "Board: do not log the observer output while the observer runs");
  cmd->add_option("--response", o->responses,
                  "Columns watched, as acquire names them (default: every acceleration and "
                  "position column: acc1_m_s2,...)");
  auto* ref = cmd->add_option("--reference", o->reference,
                              "A recording of the rig as it should be (same columns and rate): "
                              "every block is watched, no reference phase");
  cmd->add_option("--reference-s", o->watch.reference_s,
                  "Seconds at the start that are the reference")
      ->check(PositiveNumber())
      ->capture_default_str()
      ->excludes(ref);
  cmd->add_option("--block-s", o->watch.block_s, "Seconds per block (one line each)")
      ->check(PositiveNumber())
      ->capture_default_str();
  cmd->add_option("--window-blocks", o->watch.window_blocks,
                  "Blocks averaged by the accumulated test (its alarm)")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  cmd->add_option("--false-alarm-per-hour", o->watch.false_alarm_per_hour,
                  "Expected false alarms per hour of an unchanged rig")
      ->check(PositiveNumber())
      ->capture_default_str();
  cmd->add_option("--fmax-hz", o->watch.fmax_hz, "Top of the band (above the highest mode)")
      ->check(PositiveNumber())
      ->capture_default_str();
  cmd->add_option("--modes-s", o->watch.modes_s,
                  "Modes over the last this many seconds at each block (0: none)")
      ->check(NonNegativeNumber())
      ->capture_default_str();
  cmd->add_option("--order", o->watch.order,
                  "Model order of the test (2 x modes; 0: from the reference's modes)")
      ->capture_default_str();
  cmd->add_flag("--json", o->json, "One JSON object per block (JSON lines)");
  cmd->add_option("-o,--journal", o->journal,
                  "Append each block's JSON line to this file as it comes (created or truncated)");
}

}  // namespace vibid::cli
