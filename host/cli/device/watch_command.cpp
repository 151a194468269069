// vibid watch: the rig's modes and the subspace change test, block by block, on the board's live
// responses or on a recording (workflow::WatchSession decides, workflow::WatchBoardRun runs the
// board; this file reads the options and prints).
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>

#include "cli_support.hpp"
#include "common/command.hpp"
#include "device_commands.hpp"
#include "session.hpp"
#include "vibid/common/option_text.hpp"
#include "vibid/common/csv.hpp"
#include "vibid/common/error.hpp"
#include "vibid/bench/gate.hpp"
#include "vibid/bench/metrics_server.hpp"
#include "vibid/workflow/watch_board_run.hpp"
#include "vibid/workflow/watch_columns.hpp"
#include "vibid/workflow/watch_metrics.hpp"
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
  // Prometheus's scrapes (opt-in): port (-1: none), address, token file, rig label, and whether
  // the last figures stay served after the watch ends (until Ctrl-C).
  int metrics_port = -1;
  std::string metrics_bind = "127.0.0.1";
  std::string token_file;
  std::string metrics_rig;
  bool metrics_keep = false;
};

/// A rate to two significant digits.
std::string Rate(double per_hour) {
  char b[32];
  std::snprintf(b, sizeof b, "%.2g", per_hour);
  return b;
}

/// The metrics port, when asked for: serves the watch's figures from now until it goes.
class MetricsPort {
 public:
  MetricsPort(const WatchArgs& a, const std::string& default_rig)
      : figures_(a.metrics_rig.empty() ? default_rig : a.metrics_rig) {
    if (a.metrics_port < 0) return;
    bench::MetricsServerOptions o;
    o.bind = a.metrics_bind;
    o.port = a.metrics_port;
    if (!a.token_file.empty()) o.token = bench::TokenFromFile(a.token_file);
    server_ = std::make_unique<bench::MetricsServer>(o, [this] { return figures_.Text(); });
    server_->Start();
    std::cerr << "vibid: metrics on " << server_->Url() << " (rig \"" << figures_.Figures().rig
              << "\"; the token "
              << (a.token_file.empty() ? server_->token() : "in " + a.token_file)
              << " as a bearer token)\n";
  }
  workflow::WatchMetrics& figures() { return figures_; }
  bool serving() const { return server_ != nullptr; }

 private:
  workflow::WatchMetrics figures_;
  std::unique_ptr<bench::MetricsServer> server_;
};

/// After the watch: with --metrics-keep, its last figures stay served until Ctrl-C.
void KeepServing(const WatchArgs& a, MetricsPort& metrics) {
  metrics.figures().End();
  if (!a.metrics_keep || !metrics.serving()) return;
  std::cerr << "vibid: the watch ended; its last figures are served until Ctrl-C\n";
  UntilCtrlC();
  throw StoppedByInterrupt();
}

/// The reference's summary on stderr, once it is built.
void SayReference(const WatchArgs& a, const workflow::WatchSession& s) {
  const workflow::WatchReference& r = s.reference();
  std::string modes;
  for (const workflow::WatchMode& m : r.modes) {
    char b[80];
    std::snprintf(b, sizeof b, "%s%.3f Hz (ζ %.2f %%)", modes.empty() ? "" : ", ",
                  m.omega_rad_s / (2.0 * std::numbers::pi), 100.0 * m.zeta);
    modes += b;
  }
  std::cerr << "vibid: reference of " << OptionNumber(r.seconds) << " s: modes " << modes
            << "; test order " << r.order << ", " << r.dof << " residuals over "
            << r.reference_blocks << " blocks; window of " << a.watch.window_blocks
            << " blocks alarms over " << OptionNumber(r.window_threshold) << " ("
            << OptionNumber(a.watch.false_alarm_per_hour)
            << " false alarms per hour asked); this reference gives between "
            << Rate(r.false_alarms_per_hour_low) << " and " << Rate(r.false_alarms_per_hour_high)
            << " false alarms per hour (95 %)";
  if (r.advised_reference_s == 0.0) {
    std::cerr << "; even a reference 8 times as long would leave the band's low end under a "
                 "fifth of the rate asked";
  } else if (r.advised_reference_s > r.seconds) {
    std::cerr << "; a reference of " << OptionNumber(r.advised_reference_s)
              << " s would give at least " << Rate(r.advised_false_alarms_per_hour_low);
  }
  std::cerr << "; the sequential test (onsets up to " << a.watch.sequential_blocks
            << " blocks back) alarms over " << OptionNumber(r.sequential_threshold)
            << " (an exact reference's: " << OptionNumber(r.sequential_exact_threshold)
            << "); this reference gives it between " << Rate(r.sequential_false_alarms_per_hour_low)
            << " and " << Rate(r.sequential_false_alarms_per_hour_high)
            << " false alarms per hour (95 %)";
  std::cerr << "\n";
}

/// One block printed: its JSON line (as journaled) or its line of text.
void PrintBlock(const WatchArgs& a, const workflow::WatchBlock& b, const std::string& line) {
  if (a.json) {
    std::cout << line << "\n";
  } else {
    std::cout << workflow::WatchBlockText(b) << "\n";
  }
  std::cout.flush();
}

void RunOnRecording(const WatchArgs& a) {
  Require(a.settings.seconds == 0.0 && a.scenario.empty(),
          "watch: --seconds and --scenario are for the board (--device), not a recording");
  const Recording rec = LoadRecording(a.recording);
  const workflow::WatchColumns columns = workflow::ChooseWatchColumns(
      rec.table.names, a.responses.empty() ? std::vector<std::string>{} : SplitList(a.responses),
      a.recording, workflow::OptionSpelling::kCli);
  const std::vector<std::string>& responses = columns.responses;
  workflow::WatchOptions o = a.watch;
  o.fs_hz = rec.fs_hz;
  o.channels = static_cast<int>(responses.size());
  workflow::WatchJournal journal(a.journal, "-o");
  workflow::WatchSession s(o);
  MetricsPort metrics(a, std::filesystem::path(a.recording).stem().string());
  metrics.figures().Start(o);
  if (!a.reference.empty())
    s.SetReference(workflow::LoadWatchReference(a.reference, responses, o.fs_hz));
  Eigen::MatrixXd y(static_cast<Eigen::Index>(rec.samples()),
                    static_cast<Eigen::Index>(responses.size()));
  for (std::size_t j = 0; j < responses.size(); ++j)
    y.col(static_cast<Eigen::Index>(j)) = rec.table.Column(responses[j]);
  // The board's model test, when the log carries it: each block with the board's flag.
  Eigen::MatrixXd board;
  if (columns.board_statistic) {
    board.resize(y.rows(), 2);
    board.col(0) = rec.table.Column(*columns.board_statistic);
    board.col(1) = rec.table.Column(*columns.board_flag);
  }
  bool reference_said = false;
  // Fed as a board would, a block at a time, so that each line is out as soon as it is made.
  const auto step = std::max<Eigen::Index>(1, std::lround(o.block_s * o.fs_hz));
  for (Eigen::Index at = 0; at < y.rows(); at += step) {
    const Eigen::Index n = std::min(step, y.rows() - at);
    const std::vector<workflow::WatchBlock> blocks =
        board.size() > 0 ? s.Feed(y.middleRows(at, n), board.middleRows(at, n), rec.t0_s)
                         : s.Feed(y.middleRows(at, n), rec.t0_s);
    if (s.has_reference() && !reference_said) {
      reference_said = true;
      SayReference(a, s);
      // The journal's first line: the options, the reference and its thresholds.
      nlohmann::json h = workflow::WatchHeaderJson(s);
      if (!a.reference.empty()) h["reference"]["file"] = a.reference;
      const std::string header = h.dump();
      journal.Append(header);
      if (a.json) std::cout << header << "\n" << std::flush;
      metrics.figures().Reference(s.reference());
    }
    for (const workflow::WatchBlock& b : blocks) {
      metrics.figures().Block(b);
      const std::string line = workflow::WatchBlockJson(b).dump();
      journal.Append(line);
      PrintBlock(a, b, line);
    }
  }
  if (!s.has_reference()) {
    throw InputError("watch: " + a.recording + " holds " +
                     OptionNumber(static_cast<double>(y.rows()) / o.fs_hz) +
                     " s, shorter than the reference (--reference-s " +
                     OptionNumber(o.reference_s) +
                     "); give a longer recording, a shorter --reference-s or --reference");
  }
  KeepServing(a, metrics);
}

void RunOnDevice(const WatchArgs& a) {
  workflow::WatchBoardSettings settings;
  settings.acquire = a.settings;
  settings.scenario = a.scenario;
  settings.scenario_params = a.scenario_params;
  if (!a.responses.empty()) settings.responses = SplitList(a.responses);
  settings.reference = a.reference;
  settings.watch = a.watch;
  workflow::WatchBoardRun run(settings);            // every option checked: a bad one costs nothing
  workflow::WatchJournal journal(a.journal, "-o");  // refused now, not after the board started
  MetricsPort metrics(a, "board");
  metrics.figures().Start(run.options());
  WithDevice(
      *a.globals,
      [&](device::Connection& c) {
        workflow::WatchBoardEvents events;
        events.starting = [&](const workflow::WatchBoardStart& start) {
          if (!start.model_text.empty())
            std::cerr << "vibid: the board's model test: " << start.model_text << "\n";
          if (a.reference.empty()) {
            std::cerr << "vibid: reference: the first " << OptionNumber(run.options().reference_s)
                      << " s (the rig as it is now)\n";
          }
        };
        events.reference = [&](const workflow::WatchSession& s) {
          SayReference(a, s);
          metrics.figures().Reference(s.reference());
        };
        events.header = [&](const std::string& line) {
          if (a.json) std::cout << line << "\n" << std::flush;
        };
        events.block = [&](const workflow::WatchBlock& b, const std::string& line) {
          metrics.figures().Block(b);
          PrintBlock(a, b, line);
        };
        bool interrupted = false;
        const workflow::WatchBoardResult r = run.Run(c, journal, events, [&] {
          if (InterruptFlag().load() && !interrupted) {
            interrupted = true;
            std::cerr << "vibid: Ctrl-C: stopping the acquisition; the journal is kept "
                         "(Ctrl-C again to abort)\n";
          }
          return interrupted;
        });
        if (!r.warning.empty()) std::cerr << "vibid: warning: " << r.warning << "\n";
        if (!r.model_text.empty())
          std::cerr << "vibid: the board's model test at the end: " << r.model_text << "\n";
        if (!r.reference_built) {
          std::cerr << "vibid: stopped during the reference (" << OptionNumber(r.reference_left_s)
                    << " s of it to go): nothing watched\n";
        }
        if (interrupted) throw StoppedByInterrupt();
      },
      CtrlC::kStopsAcquisition);
  KeepServing(a, metrics);
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
  cmd->add_option("--sequential-blocks", o->watch.sequential_blocks,
                  "Longest onset of the sequential test, in blocks (it alarms at any block)")
      ->check(CLI::Range(1, 720))
      ->capture_default_str();
  cmd->add_option("--false-alarm-per-hour", o->watch.false_alarm_per_hour,
                  "Expected false alarms per hour of an unchanged rig, asked of each test")
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
  auto* port = cmd->add_option("--metrics-port", o->metrics_port,
                               "Serve the watch's figures to Prometheus on this loopback port "
                               "(GET /metrics; 0: a free one, printed)")
                   ->check(CLI::Range(0, 65535));
  cmd->add_option("--metrics-bind", o->metrics_bind,
                  "Loopback address of the metrics port (127.0.0.1 or ::1)")
      ->capture_default_str()
      ->needs(port);
  cmd->add_option("--token-file", o->token_file,
                  "The metrics' token (a scraper's bearer token) in this file: read, or a new one "
                  "written there readable by you only (default: a new token, printed)")
      ->needs(port);
  cmd->add_option("--metrics-rig", o->metrics_rig,
                  "The rig label of every metric (default: the recording's name, or board)")
      ->needs(port);
  cmd->add_flag("--metrics-keep", o->metrics_keep,
                "After the watch ends, keep serving its last figures until Ctrl-C (exit 130)")
      ->needs(port);
}

}  // namespace vibid::cli
