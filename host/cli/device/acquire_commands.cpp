// vibid acquire | log pull
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <optional>

#include <unistd.h>

#include "cli_support.hpp"
#include "common/command.hpp"
#include "vibid/common/option_text.hpp"
#include "device_commands.hpp"
#include "session.hpp"
#include "vibid/common/error.hpp"
#include "vibid/device/board_report.hpp"
#include "vibid/device/error.hpp"
#include "vibid/device/link_budget.hpp"
#include "vibid/device/log_table.hpp"
#include "vibid/shared/fixed/decimator.hpp"

namespace vibid::cli {
namespace {

constexpr const char* kAcquireHelp =
    "Record from the board: configure, start, pull the log into a CSV. Ctrl-C stops the "
    "acquisition and keeps what it recorded (exit 130); a second Ctrl-C aborts";

struct AcquireArgs {
  const GlobalOptions* globals = nullptr;
  double seconds = 0.0;
  double rate_hz = 5000.0;
  double log_rate_hz = 0.0;  // 0: the sampling rate
  int decimation = 0;        // 0: from log_rate_hz
  bool allow_drops = false;
  std::vector<std::string> channels;
  std::string trigger;
  double trigger_timeout_s = 0.0;  // 0: wait until Ctrl-C
  double pretrigger_s = 0.0;
  std::string scenario;
  std::vector<float> scenario_params;
  bool no_dob = false;
  std::string output;
};

struct Trigger {
  wire::TriggerMode mode = wire::TriggerMode::kImmediate;
  wire::Channel channel = wire::Channel::kForce1;
  double threshold = 0.0;
  double full_scale_n = 0.0;  ///< The load cell's, from the board's calibration.
};

/// "force>F", "force2<F" ("force" is force1): the load cell, the direction and F in newtons.
Trigger ParseTrigger(const std::string& text) {
  Trigger t;
  if (text.empty()) return t;
  const std::size_t op = text.find_first_of("<>");
  const auto bad = [&] {
    throw InputError("--trigger '" + text + "': expected force>F, force1>F or force2<F (F in N)");
  };
  if (op == std::string::npos) bad();
  std::string stem = text.substr(0, op);
  if (stem == "force") stem = "force1";
  if (!device::ChannelFromStem(stem, t.channel) ||
      !wire::IsLoadCell(static_cast<std::uint8_t>(t.channel)))
    bad();
  t.mode = text[op] == '>' ? wire::TriggerMode::kRising : wire::TriggerMode::kFalling;
  if (ParseNumber(text.substr(op + 1), t.threshold) != NumberText::kOk) bad();
  return t;
}

std::string FormatNumber(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", v);
  return b;
}

/// The decimation for a log rate (or the one given), checked against what the board's
/// decimator supports.
int DecimationFor(double rate_hz, double log_rate_hz, int decimation) {
  if (decimation == 0) {
    if (log_rate_hz == 0.0) return 1;
    const double d = rate_hz / log_rate_hz;
    decimation = static_cast<int>(std::lround(d));
    Require(std::abs(d - decimation) < 1e-9 * d && decimation >= 1,
            "--log-rate-hz " + FormatNumber(log_rate_hz) + ": the sample rate " +
                FormatNumber(rate_hz) + " Hz must be a whole multiple of it");
  }
  if (!fixed::IsSupportedDecimation(static_cast<std::uint32_t>(decimation))) {
    std::string near;
    for (std::uint32_t d = 1; d <= fixed::kDecimatorMaxFactor; ++d) {
      if (fixed::IsSupportedDecimation(d) &&
          std::abs(static_cast<int>(d) - decimation) <= decimation / 2) {
        near += (near.empty() ? "" : ", ") + FormatNumber(rate_hz / d);
      }
    }
    throw InputError("log rate " + FormatNumber(rate_hz / decimation) +
                     " Hz: the board decimates by 2^a 5^b up to " +
                     std::to_string(fixed::kDecimatorMaxFactor) + " only (decimation " +
                     std::to_string(decimation) + "); log rates near it: " + near + " Hz");
  }
  return decimation;
}

void WriteLog(device::Connection& c, const device::LogPull& pull, ClaimedOutput& output) {
  bool has_record = false;
  const wire::CalibrationRecord rec = ActiveRecord(c, has_record);
  output.Write(device::FormatLogCsv(pull, rec, has_record, c.GetSamplingInfo()));
  std::cerr << "vibid: " << pull.records.size() << " records";
  if (pull.trailer.dropped_records != 0 || pull.trailer.overrun_count != 0) {
    std::cerr << " (the board dropped " << pull.trailer.dropped_records << " records and missed "
              << pull.trailer.overrun_count << " ticks)";
  }
  std::cerr << (output.to_stdout() ? "" : " written to " + output.Name()) << "\n";
  // Clipped samples are in the file as the board saw them; say which, and how many.
  if (const std::optional<wire::ClipResponse> clips = c.GetClips()) {
    const std::string text = device::DescribeClips(*clips, has_record ? &rec : nullptr);
    if (!text.empty()) std::cerr << "vibid: warning: " << text << "\n";
  }
}

/// A pull that lost records the board overwrote: what it holds is written all the same, and the
/// error names what is missing.
[[noreturn]] void WriteIncomplete(device::Connection& c, const device::IncompleteLog& e,
                                  ClaimedOutput& output) {
  WriteLog(c, e.pull(), output);
  throw device::DeviceError(std::string(e.what()) + "; the records kept are written" +
                            (output.to_stdout() ? "" : " to " + output.Name()));
}

/// The acquisition the options ask for, checked as far as it can be without the board; `trig` gets
/// the parsed --trigger (read in the order the options are checked, so the first bad one is named).
wire::AcqConfigureRequest AcquireConfig(const AcquireArgs& a, Trigger& trig) {
  wire::AcqConfigureRequest cfg;
  const double period_us = 1e6 / a.rate_hz;
  const std::string rate = "--rate-hz " + FormatNumber(a.rate_hz);
  Require(period_us >= wire::kMinSamplePeriodUs,
          rate + ": the board samples at " + FormatNumber(1e6 / wire::kMinSamplePeriodUs) +
              " Hz at most (a " + std::to_string(wire::kMinSamplePeriodUs) +
              " us period); choose --rate-hz " + FormatNumber(1e6 / wire::kMinSamplePeriodUs) +
              " or less");
  Require(period_us <= wire::kMaxSamplePeriodUs, rate + ": the board samples at " +
                                                     FormatNumber(1e6 / wire::kMaxSamplePeriodUs) +
                                                     " Hz at least; choose --rate-hz 1 or more");
  Require(std::abs(period_us - std::round(period_us)) < 1e-6,
          rate + ": the board's sample period is a whole number of microseconds, and 1000000 / " +
              FormatNumber(a.rate_hz) + " = " + FormatNumber(period_us) +
              " is not; choose a rate that divides 1000000 (10000, 5000, 2500, 2000, 1000, ...)");
  cfg.sample_period_us = static_cast<std::uint32_t>(std::lround(period_us));
  cfg.decimation =
      static_cast<std::uint16_t>(DecimationFor(a.rate_hz, a.log_rate_hz, a.decimation));
  cfg.channel_mask = 0;
  for (const std::string& name : a.channels) {
    wire::Channel ch{};
    Require(device::ChannelFromStem(name, ch),
            "--channels: unknown channel '" + name + "' (force1, force2, acc1, acc2, x1, x2)");
    cfg.channel_mask =
        static_cast<std::uint8_t>(cfg.channel_mask | (1u << static_cast<unsigned>(ch)));
  }
  if (cfg.channel_mask == 0) cfg.channel_mask = wire::kAllChannelsMask;
  trig = ParseTrigger(a.trigger);
  Require(a.pretrigger_s == 0.0 || trig.mode != wire::TriggerMode::kImmediate,
          "--pretrigger-s needs a --trigger");
  Require(a.trigger_timeout_s == 0.0 || trig.mode != wire::TriggerMode::kImmediate,
          "--trigger-timeout-s needs a --trigger");
  const double log_rate_hz = a.rate_hz / cfg.decimation;
  cfg.record_limit = static_cast<std::uint32_t>(std::lround(a.seconds * log_rate_hz));
  cfg.pretrigger_records = static_cast<std::uint32_t>(std::lround(a.pretrigger_s * log_rate_hz));
  Require(cfg.record_limit > 0, "--seconds is shorter than one logged sample");
  Require(a.scenario_params.size() <= 4, "--scenario-param takes at most 4 values");
  return cfg;
}

/// What the board's calibration adds: the observer output, the trigger threshold in ADC units
/// (and the load cell's full scale in `trig`).
void ApplyCalibration(device::Connection& c, const AcquireArgs& a, Trigger& trig,
                      wire::AcqConfigureRequest& cfg) {
  bool has_record = false;
  const wire::CalibrationRecord rec = ActiveRecord(c, has_record);
  if (!a.no_dob && has_record && (rec.flags & wire::kCalFlagHasDob) != 0)
    cfg.flags = wire::kAcqFlagLogDob;
  if (trig.mode == wire::TriggerMode::kImmediate) return;
  const wire::ChannelScaling& s = rec.channels[static_cast<std::size_t>(trig.channel)];
  if (!has_record || s.unit != wire::Unit::kNewton) {
    throw device::DeviceError(
        "a force trigger needs a calibrated load cell: upload a calibration first (vibid cal "
        "upload)");
  }
  const double q = trig.threshold / static_cast<double>(s.full_scale) * 2147483648.0;
  Require(std::abs(q) < 2147483647.0, "--trigger threshold is beyond the load cell's full scale");
  trig.full_scale_n = static_cast<double>(s.full_scale);
  cfg.trigger_mode = trig.mode;
  cfg.trigger_channel = static_cast<std::uint8_t>(trig.channel);
  cfg.trigger_threshold = static_cast<std::int32_t>(std::lround(q));
}

/// Why an acquisition ended before its --seconds.
enum class StopCause { kNone, kCtrlC, kTriggerTimeout };

/// Decides, while the acquisition runs, whether to stop it: on the first Ctrl-C, or when the
/// trigger has not fired within --trigger-timeout-s. While the board waits for the trigger it says
/// so on stderr once a second, with the load cell's present value.
class StopWatch {
 public:
  StopWatch(device::Connection& c, const AcquireArgs& a, const Trigger& trig)
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
  const AcquireArgs& a_;
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
void KeepStopped(device::Connection& c, const device::LogPull& pull, const AcquireArgs& a,
                 const wire::AcqConfigureRequest& cfg, StopCause cause, ClaimedOutput& output) {
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
  WriteLog(c, pull, output);
  char line[300];
  std::snprintf(line, sizeof line, "vibid: %s: kept %zu records (%.3f s at %g Hz) in %s\n",
                why.c_str(), pull.records.size(),
                static_cast<double>(pull.records.size()) / log_rate_hz, log_rate_hz,
                output.Name().c_str());
  std::cerr << line;
  if (cause == StopCause::kCtrlC) throw StoppedByInterrupt();
  throw device::DeviceError(why + ": acquisition stopped, the records before it kept");
}

void Run(const AcquireArgs& a) {
  Trigger trig;
  wire::AcqConfigureRequest cfg = AcquireConfig(a, trig);
  // Claimed before the board starts: a path that cannot be written is refused now, not after.
  ClaimedOutput output(a.output);
  WithDevice(
      *a.globals,
      [&](device::Connection& c) {
        ApplyCalibration(c, a, trig, cfg);
        // Preflight: records the link cannot carry pile up in the log; refuse before the board
        // starts if it would overflow.
        const device::LinkBudget budget = device::ComputeLinkBudget(c.info(), cfg);
        if (budget.overflow_after_s < a.seconds + a.pretrigger_s && !a.allow_drops) {
          throw InputError(device::DescribeOverflow(budget, a.seconds));
        }
        cfg.flags = static_cast<std::uint8_t>(cfg.flags | wire::kAcqFlagStream);
        if (!a.scenario.empty()) c.SelectScenario(a.scenario, a.scenario_params);
        c.Configure(cfg);
        StopWatch stop(c, a, trig);
        device::LogPull pull;
        try {
          pull = Acquire(c, cfg, budget, stop);
        } catch (const device::IncompleteLog& e) {
          WriteIncomplete(c, e, output);
        }
        if (pull.stopped) KeepStopped(c, pull, a, cfg, stop.cause(), output);
        WriteLog(c, pull, output);
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
      WriteIncomplete(c, e, output);
    } catch (const device::Interrupted&) {
      throw device::Interrupted("interrupted: nothing written");
    }
    WriteLog(c, pull, output);
  });
}

void RegisterAcquire(CLI::App& app, const GlobalOptions& globals) {
  const auto [acq, o] = AddCommand<AcquireArgs>(app, "acquire", kAcquireHelp, Run);
  o->globals = &globals;
  TakesDeviceOption(acq);
  acq->add_option("--seconds", o->seconds, "Seconds to record after the trigger")
      ->required()
      ->check(PositiveNumber());
  acq->add_option("--rate-hz", o->rate_hz, "Sample rate (Hz)")->check(PositiveNumber());
  auto* log_rate =
      acq->add_option(
             "--log-rate-hz", o->log_rate_hz,
             "Log rate (Hz): the board low-pass filters and decimates every logged channel "
             "(default: the sample rate)")
          ->check(PositiveNumber());
  acq->add_option("--decimation", o->decimation,
                  "Log one filtered sample in N (2^a 5^b, up to 1000)")
      ->check(CLI::Range(1, 1000))
      ->excludes(log_rate);
  acq->add_flag(
      "--allow-drops", o->allow_drops,
      "Start even if the log rate exceeds what the link carries and the log would overflow");
  acq->add_option("--channels", o->channels,
                  "Channels to log: force1,force2,acc1,acc2,x1,x2 (default all)")
      ->delimiter(',');
  acq->add_option("--trigger", o->trigger, "Start on a load cell threshold: force>F (N), force2<F");
  acq->add_option("--trigger-timeout-s", o->trigger_timeout_s,
                  "Give up when the trigger has not fired after this many seconds (default: "
                  "wait until Ctrl-C)")
      ->check(PositiveNumber());
  acq->add_option("--pretrigger-s", o->pretrigger_s, "Seconds kept before the trigger")
      ->check(NonNegativeNumber());
  acq->add_option("--scenario", o->scenario,
                  "Emulator only: the rig excitation to run (hammer, shaker, push, ...)");
  acq->add_option("--scenario-param", o->scenario_params,
                  "Emulator only: up to 4 scenario parameters (SI)")
      ->delimiter(',');
  acq->add_flag("--no-dob", o->no_dob, "Do not log the observer output");
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
