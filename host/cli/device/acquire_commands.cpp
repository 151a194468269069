// vibid acquire | log pull
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <optional>

#include <unistd.h>

#include "cli_support.hpp"
#include "common/command.hpp"
#include "vibid/common/q31_decimal.hpp"
#include "vibid/common/option_text.hpp"
#include "device_commands.hpp"
#include "session.hpp"
#include "vibid/common/error.hpp"
#include "vibid/device/acquire_plan.hpp"
#include "vibid/device/board_report.hpp"
#include "vibid/device/error.hpp"
#include "vibid/device/link_budget.hpp"
#include "vibid/device/log_facts.hpp"
#include "vibid/device/log_table.hpp"
#include "vibid/ident/recording_facts.hpp"

namespace vibid::cli {
namespace {

constexpr const char* kAcquireHelp =
    "Record from the board: configure, start, pull the log into a CSV. Ctrl-C stops the "
    "acquisition and keeps what it recorded (exit 130); a second Ctrl-C aborts";

struct AcquireArgs {
  const GlobalOptions* globals = nullptr;
  device::AcquireSettings settings;
  std::string scenario;
  std::vector<float> scenario_params;
  std::string output;
};

using device::Trigger;

std::string FormatNumber(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", v);
  return b;
}

/// What the recording's sidecar states of how it was asked for (log_facts.hpp): the options as
/// given and when the host started it (UTC: the board has no clock).
struct Asked {
  ident::AcquisitionFacts facts;
  std::string start_timestamp;
};

Asked AskedOf(const device::AcquireSettings& a, const std::string& scenario,
              const std::vector<float>& params) {
  Asked out;
  out.facts.seconds = a.seconds;
  out.facts.trigger = a.trigger;
  out.facts.pretrigger_s = a.pretrigger_s;
  out.facts.scenario = scenario;
  for (float p : params) out.facts.scenario_params.push_back(ShortestFloat32Decimal(p));
  out.start_timestamp = ident::UtcTimestampNow();
  return out;
}

void WriteLog(device::Connection& c, const device::LogPull& pull, ClaimedOutput& output,
              const Asked& asked) {
  bool has_record = false;
  const wire::CalibrationRecord rec = device::ActiveRecord(c, has_record);
  const device::BoardContext board = device::ContextOf(c);
  // The sidecar (the recording's facts) first: a CSV is never left beside a sidecar of another.
  if (!output.to_stdout()) {
    ident::WriteRecordingFacts(output.Name(),
                               device::LogFacts(pull, pull.records.size(), rec, has_record, board,
                                                asked.facts, asked.start_timestamp));
  }
  output.Write(device::FormatLogCsv(pull, rec, has_record));
  std::cerr << "vibid: " << pull.records.size() << " records";
  if (pull.trailer.dropped_records != 0 || pull.trailer.overrun_count != 0) {
    std::cerr << " (the board dropped " << pull.trailer.dropped_records << " records and missed "
              << pull.trailer.overrun_count << " ticks)";
  }
  std::cerr << (output.to_stdout() ? "" : " written to " + output.Name()) << "\n";
  // Clipped samples are in the file as the board saw them; say which, and how many.
  if (board.clips) {
    const std::string text = device::DescribeClips(*board.clips, has_record ? &rec : nullptr);
    if (!text.empty()) std::cerr << "vibid: warning: " << text << "\n";
  }
}

/// A pull that lost records the board overwrote: what it holds is written all the same, and the
/// error names what is missing.
[[noreturn]] void WriteIncomplete(device::Connection& c, const device::IncompleteLog& e,
                                  ClaimedOutput& output, const Asked& asked) {
  WriteLog(c, e.pull(), output, asked);
  throw device::DeviceError(std::string(e.what()) + "; the records kept are written" +
                            (output.to_stdout() ? "" : " to " + output.Name()));
}

/// Why an acquisition ended before its --seconds.
enum class StopCause { kNone, kCtrlC, kTriggerTimeout };

/// Decides, while the acquisition runs, whether to stop it: on the first Ctrl-C, or when the
/// trigger has not fired within --trigger-timeout-s. While the board waits for the trigger it says
/// so on stderr once a second, with the load cell's present value.
class StopWatch {
 public:
  StopWatch(device::Connection& c, const device::AcquireSettings& a, const Trigger& trig)
      : c_(c), a_(a), trig_(trig), started_(Clock::now()), last_status_(started_) {}

  bool operator()(const wire::LogTrailer* state) {
    if (InterruptFlag().load()) {
      // On a terminal the line starts below the progress bar and the ^C the terminal echoed.
      if (cause_ == StopCause::kNone)
        std::cerr << (isatty(STDERR_FILENO) == 1 ? "\n" : "")
                  << "vibid: Ctrl-C: stopping the acquisition, keeping what it recorded (Ctrl-C "
                     "again to abort)\n";
      cause_ = StopCause::kCtrlC;
      return true;
    }
    if (state == nullptr || state->acq_state != wire::AcqState::kArmed) return false;
    const Clock::time_point now = Clock::now();
    const double waited_s = std::chrono::duration<double>(now - started_).count();
    if (a_.trigger_timeout_s > 0.0 && waited_s >= a_.trigger_timeout_s) {
      cause_ = StopCause::kTriggerTimeout;
      return true;
    }
    if (now - last_status_ >= std::chrono::seconds(1)) {
      last_status_ = now;
      PrintStatus(waited_s);
    }
    return false;
  }

  StopCause cause() const { return cause_; }

 private:
  using Clock = std::chrono::steady_clock;

  void PrintStatus(double waited_s) {
    // Between log reads no stream is open: one read-latest fits in.
    const wire::LatestResponse latest = c_.ReadLatest();
    const double now_n = latest.calibrated[static_cast<std::size_t>(trig_.channel)] *
                         (trig_.full_scale_n / 2147483648.0);
    char line[200];
    std::snprintf(
        line, sizeof line,
        "vibid: waiting for the trigger on load cell %d: %s %s %g N, now %.4g N (%.0f s%s)\n",
        trig_.channel == wire::Channel::kForce1 ? 1 : 2, device::ChannelStem(trig_.channel),
        trig_.mode == wire::TriggerMode::kRising ? ">" : "<", trig_.threshold, now_n, waited_s,
        a_.trigger_timeout_s > 0.0 ? "" : "; Ctrl-C stops");
    std::cerr << line;
  }

  device::Connection& c_;
  const device::AcquireSettings& a_;
  const Trigger& trig_;
  Clock::time_point started_;
  Clock::time_point last_status_;
  StopCause cause_ = StopCause::kNone;
};

/// Runs the configured acquisition, streaming the log as it fills. `stop` may end it early; what
/// was recorded until then is returned (marked stopped). The board is left idle on any failure.
device::LogPull Acquire(device::Connection& c, const wire::AcqConfigureRequest& cfg,
                        const device::LinkBudget& budget, StopWatch& stop) {
  try {
    ProgressBar bar("acquire");
    const std::uint64_t total = std::uint64_t{cfg.record_limit} + cfg.pretrigger_records;
    // Progress in records from the bytes received (the 4-byte ticks make it slightly ahead).
    return c.AcquireStreamed(
        [&](std::uint64_t bytes, std::uint64_t) {
          bar.Update(std::min<std::uint64_t>(total, bytes / budget.record_bytes), total);
        },
        [&](const wire::LogTrailer* state) { return stop(state); });
  } catch (const device::Interrupted&) {
    c.StopAcquisition();
    throw device::Interrupted("interrupted again: acquisition stopped, nothing written");
  } catch (...) {
    // The board is left idle whenever it can still be reached.
    try {
      c.StopAcquisition();
    } catch (const device::DeviceError&) {
    }
    throw;
  }
}

/// Writes what a stopped acquisition kept and says how much and where; then ends the command
/// with the exit code of its cause.
void KeepStopped(device::Connection& c, const device::LogPull& pull,
                 const device::AcquireSettings& a, const wire::AcqConfigureRequest& cfg,
                 StopCause cause, ClaimedOutput& output, const Asked& asked) {
  const double log_rate_hz = 1e6 / cfg.sample_period_us / cfg.decimation;
  const std::string why = cause == StopCause::kCtrlC
                              ? "stopped by Ctrl-C"
                              : "the trigger did not fire within " +
                                    FormatNumber(a.trigger_timeout_s) + " s (--trigger-timeout-s)";
  if (pull.records.empty()) {
    const std::string what =
        why + ": acquisition stopped before anything was recorded" +
        (cause == StopCause::kCtrlC && cfg.trigger_mode != wire::TriggerMode::kImmediate
             ? " (the trigger had not fired)"
             : "") +
        ", nothing written";
    if (cause == StopCause::kCtrlC) throw device::Interrupted(what);
    throw device::DeviceError(what);
  }
  WriteLog(c, pull, output, asked);
  char line[300];
  std::snprintf(line, sizeof line, "vibid: %s: kept %zu records (%.3f s at %g Hz) in %s\n",
                why.c_str(), pull.records.size(),
                static_cast<double>(pull.records.size()) / log_rate_hz, log_rate_hz,
                output.Name().c_str());
  std::cerr << line;
  if (cause == StopCause::kCtrlC) throw StoppedByInterrupt();
  throw device::DeviceError(why + ": acquisition stopped, the records before it kept");
}

void Run(const AcquireArgs& args) {
  const device::AcquireSettings& a = args.settings;
  Trigger trig;
  wire::AcqConfigureRequest cfg = device::PlanAcquisition(a, trig);
  Require(args.scenario_params.size() <= 4, "--scenario-param takes at most 4 values");
  // Claimed before the board starts: a path that cannot be written is refused now, not after.
  ClaimedOutput output(args.output);
  WithDevice(
      *args.globals,
      [&](device::Connection& c) {
        bool has_record = false;
        const wire::CalibrationRecord rec = device::ActiveRecord(c, has_record);
        device::ApplyCalibration(rec, has_record, c.GetStatus().dob_running != 0, a.no_dob, trig,
                                 cfg);
        const device::LinkBudget budget = device::Preflight(c.info(), cfg, a);
        cfg.flags = static_cast<std::uint8_t>(cfg.flags | wire::kAcqFlagStream);
        if (!args.scenario.empty()) c.SelectScenario(args.scenario, args.scenario_params);
        c.Configure(cfg);
        StopWatch stop(c, a, trig);
        const Asked asked = AskedOf(a, args.scenario, args.scenario_params);
        device::LogPull pull;
        try {
          pull = Acquire(c, cfg, budget, stop);
        } catch (const device::IncompleteLog& e) {
          WriteIncomplete(c, e, output, asked);
        }
        if (pull.stopped) KeepStopped(c, pull, a, cfg, stop.cause(), output, asked);
        WriteLog(c, pull, output, asked);
      },
      CtrlC::kStopsAcquisition);
}

constexpr const char* kPullHelp = "Pull the log of the last acquisition into a CSV";

struct PullArgs {
  const GlobalOptions* globals = nullptr;
  std::string output;
  std::uint32_t first = 0;
  bool first_given = false;
};

void Run(const PullArgs& a) {
  // Claimed before the pull: a path that cannot be written is refused now, not after.
  ClaimedOutput output(a.output);
  WithDevice(*a.globals, [&](device::Connection& c) {
    device::LogPull pull;
    try {
      ProgressBar bar("log pull");
      // By default everything the board still holds: records pulled before (by acquire, while
      // sampling) stay readable until the log wraps over them.
      const wire::StatusResponse st = c.GetStatus();
      const std::uint32_t first = a.first_given ? a.first : st.oldest_record;
      if (first < st.oldest_record) {
        throw device::DeviceError("--from " + std::to_string(first) +
                                  ": the board's log has been overwritten up to record " +
                                  std::to_string(st.oldest_record) + ", the oldest it still holds");
      }
      if (first > st.records_written) {
        throw device::DeviceError("--from " + std::to_string(first) + ": the log holds only " +
                                  std::to_string(st.records_written) + " records");
      }
      pull = c.PullLog(first, bar.Callback());
    } catch (const device::IncompleteLog& e) {
      WriteIncomplete(c, e, output, {});
    } catch (const device::Interrupted&) {
      throw device::Interrupted("interrupted: nothing written");
    }
    // A pull states no options: the acquisition was asked for elsewhere.
    WriteLog(c, pull, output, {});
  });
}

void RegisterAcquire(CLI::App& app, const GlobalOptions& globals) {
  const auto [acq, o] = AddCommand<AcquireArgs>(app, "acquire", kAcquireHelp, Run);
  o->globals = &globals;
  TakesDeviceOption(acq);
  acq->add_option("--seconds", o->settings.seconds, "Seconds to record after the trigger")
      ->required()
      ->check(PositiveNumber());
  acq->add_option("--rate-hz", o->settings.rate_hz, "Sample rate (Hz)")
      ->check(PositiveNumber())
      ->capture_default_str();
  auto* log_rate =
      acq->add_option(
             "--log-rate-hz", o->settings.log_rate_hz,
             "Log rate (Hz): the board low-pass filters and decimates every logged channel "
             "(default: the sample rate)")
          ->check(PositiveNumber());
  acq->add_option("--decimation", o->settings.decimation,
                  "Log one filtered sample in N (2^a 5^b, up to 1000)")
      ->check(CLI::Range(1, 1000))
      ->excludes(log_rate);
  acq->add_flag(
      "--allow-drops", o->settings.allow_drops,
      "Start even if the log rate exceeds what the link carries and the log would overflow");
  acq->add_option("--channels", o->settings.channels,
                  "Channels to log: force1,force2,acc1,acc2,x1,x2 (default all)")
      ->delimiter(',');
  acq->add_option("--trigger", o->settings.trigger,
                  "Start on a load cell threshold: force>F (N), force2<F");
  acq->add_option("--trigger-timeout-s", o->settings.trigger_timeout_s,
                  "Give up when the trigger has not fired after this many seconds (default: "
                  "wait until Ctrl-C)")
      ->check(PositiveNumber());
  acq->add_option("--pretrigger-s", o->settings.pretrigger_s, "Seconds kept before the trigger")
      ->check(NonNegativeNumber());
  acq->add_option(
      "--scenario", o->scenario,
      "Emulator only: the rig excitation to run (hammer, shaker, push, step, tone, operate, "
      "idle)");
  acq->add_option("--scenario-param", o->scenario_params,
                  "Emulator only: up to 4 scenario parameters (SI)")
      ->delimiter(',');
  acq->add_flag("--no-dob", o->settings.no_dob,
                "Do not log the observer output (logged by default while the board's observer "
                "runs: vibid dob start)");
  acq->add_option("-o,--output", o->output, "Output CSV")->required();
}

void RegisterLogPull(CLI::App& app, const GlobalOptions& globals) {
  CLI::App* log = app.add_subcommand("log", "The board's acquisition log");
  log->require_subcommand(1);
  const auto added = AddCommand<PullArgs>(*log, "pull", kPullHelp, Run);
  CLI::App* pull_cmd = added.first;
  PullArgs* po = added.second;
  po->globals = &globals;
  TakesDeviceOption(pull_cmd);
  pull_cmd->add_option("-o,--output", po->output, "Output CSV")->required();
  pull_cmd
      ->add_option("--from", po->first,
                   "First log record to pull (default: the oldest the board still holds)")
      ->each([po](const std::string&) { po->first_given = true; });
}

}  // namespace

void RegisterAcquireCommands(CLI::App& app, const GlobalOptions& globals) {
  RegisterAcquire(app, globals);
  RegisterLogPull(app, globals);
}

}  // namespace vibid::cli
