#include "vibid/device/acquire_plan.hpp"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "vibid/common/option_text.hpp"
#include "vibid/common/error.hpp"
#include "vibid/device/log_table.hpp"
#include "vibid/device/refusal_text.hpp"
#include "vibid/shared/fixed/decimator.hpp"
#include "vibid/shared/fixed/filter_description.hpp"
#include "vibid/shared/wire/byte_order.hpp"

namespace vibid::device {
namespace {

/// The whole of `text` as a finite double (strtod's reading).
bool ParseFinite(const std::string& text, double& value) {
  char* end = nullptr;
  errno = 0;
  value = std::strtod(text.c_str(), &end);
  return end != text.c_str() && errno != ERANGE && end == text.c_str() + text.size() &&
         std::isfinite(value);
}

}  // namespace

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
  if (!ChannelFromStem(stem, t.channel) || !wire::IsLoadCell(static_cast<std::uint8_t>(t.channel)))
    bad();
  t.mode = text[op] == '>' ? wire::TriggerMode::kRising : wire::TriggerMode::kFalling;
  if (!ParseFinite(text.substr(op + 1), t.threshold)) bad();
  return t;
}

int DecimationFor(double rate_hz, double log_rate_hz, int decimation) {
  if (decimation == 0) {
    if (log_rate_hz == 0.0) return 1;
    const double d = rate_hz / log_rate_hz;
    decimation = static_cast<int>(std::lround(d));
    Require(std::abs(d - decimation) < 1e-9 * d && decimation >= 1,
            "--log-rate-hz " + OptionNumber(log_rate_hz) + ": the sample rate " +
                OptionNumber(rate_hz) + " Hz must be a whole multiple of it");
  }
  if (!fixed::IsSupportedDecimation(static_cast<std::uint32_t>(decimation))) {
    std::string near;
    for (std::uint32_t d = 1; d <= fixed::kDecimatorMaxFactor; ++d) {
      if (fixed::IsSupportedDecimation(d) &&
          std::abs(static_cast<int>(d) - decimation) <= decimation / 2) {
        near += (near.empty() ? "" : ", ") + OptionNumber(rate_hz / d);
      }
    }
    throw InputError("log rate " + OptionNumber(rate_hz / decimation) +
                     " Hz: the board decimates by 2^a 5^b up to " +
                     std::to_string(fixed::kDecimatorMaxFactor) + " only (decimation " +
                     std::to_string(decimation) + "); log rates near it: " + near + " Hz");
  }
  return decimation;
}

wire::AcqConfigureRequest PlanAcquisition(const AcquireSettings& a, Trigger& trig) {
  // Every number checked as the CLI's own option checks do, whichever front end set it: a
  // negative or infinite length would otherwise wrap to an endless acquisition.
  const auto positive = [](double v, const char* option) {
    Require(std::isfinite(v) && v > 0.0,
            std::string(option) + " " + OptionNumber(v) + ": must be a number > 0");
  };
  const auto non_negative = [](double v, const char* option) {
    Require(std::isfinite(v) && v >= 0.0,
            std::string(option) + " " + OptionNumber(v) + ": must be a number >= 0");
  };
  positive(a.seconds, "--seconds");
  positive(a.rate_hz, "--rate-hz");
  if (a.log_rate_hz != 0.0) positive(a.log_rate_hz, "--log-rate-hz");
  Require(a.decimation >= 0 && a.decimation <= static_cast<int>(fixed::kDecimatorMaxFactor),
          "--decimation " + std::to_string(a.decimation) + ": must be in 1.." +
              std::to_string(fixed::kDecimatorMaxFactor));
  Require(a.decimation == 0 || a.log_rate_hz == 0.0,
          "--decimation and --log-rate-hz: give one of them, not both");
  non_negative(a.pretrigger_s, "--pretrigger-s");
  non_negative(a.trigger_timeout_s, "--trigger-timeout-s");
  wire::AcqConfigureRequest cfg;
  const double period_us = 1e6 / a.rate_hz;
  const std::string rate = "--rate-hz " + OptionNumber(a.rate_hz);
  Require(period_us >= wire::kMinSamplePeriodUs,
          rate + ": the board samples at " + OptionNumber(1e6 / wire::kMinSamplePeriodUs) +
              " Hz at most (a " + std::to_string(wire::kMinSamplePeriodUs) +
              " us period); choose --rate-hz " + OptionNumber(1e6 / wire::kMinSamplePeriodUs) +
              " or less");
  Require(period_us <= wire::kMaxSamplePeriodUs, rate + ": the board samples at " +
                                                     OptionNumber(1e6 / wire::kMaxSamplePeriodUs) +
                                                     " Hz at least; choose --rate-hz 1 or more");
  Require(std::abs(period_us - std::round(period_us)) < 1e-6,
          rate + ": the board's sample period is a whole number of microseconds, and 1000000 / " +
              OptionNumber(a.rate_hz) + " = " + OptionNumber(period_us) +
              " is not; choose a rate that divides 1000000 (10000, 5000, 2500, 2000, 1000, ...)");
  cfg.sample_period_us = static_cast<std::uint32_t>(std::lround(period_us));
  cfg.decimation =
      static_cast<std::uint16_t>(DecimationFor(a.rate_hz, a.log_rate_hz, a.decimation));
  cfg.channel_mask = 0;
  for (const std::string& name : a.channels) {
    wire::Channel ch{};
    Require(ChannelFromStem(name, ch),
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
  // The board counts records in 32 bits, and the host holds every record it is asked for: a
  // length beyond that count is refused, never wrapped.
  const double records = std::round(a.seconds * log_rate_hz);
  const double pretrigger = std::round(a.pretrigger_s * log_rate_hz);
  constexpr double kMaxRecords = 4294967295.0;
  Require(records + pretrigger <= kMaxRecords,
          "--seconds " + OptionNumber(a.seconds) + ": more records than the board counts (" +
              OptionNumber(kMaxRecords) + " at " + OptionNumber(log_rate_hz) + " Hz, " +
              OptionNumber(kMaxRecords / log_rate_hz) + " s)");
  cfg.record_limit = static_cast<std::uint32_t>(records);
  cfg.pretrigger_records = static_cast<std::uint32_t>(pretrigger);
  Require(cfg.record_limit > 0, "--seconds is shorter than one logged sample");
  return cfg;
}

wire::CalibrationRecord ActiveRecord(Connection& c, bool& has_record) {
  wire::CalibrationRecord r;
  has_record = false;
  // Asked now, not taken from the connection's opening get-info: a commit since then (through
  // this connection or another) changes it.
  if (c.GetInfo().cal_state != wire::CalState::kCalibrated) return r;
  r = DecodeBoardRecord(c.CalGet());
  has_record = true;
  return r;
}

wire::CalibrationRecord DecodeBoardRecord(std::span<const std::uint8_t> bytes) {
  wire::CalibrationRecord r;
  const Status st = wire::DecodeCalibrationRecord(bytes, r);
  if (st == Status::kOk) return r;
  if (st == Status::kVersionMismatch && bytes.size() >= wire::kCalOffDofCount &&
      wire::LoadU32(bytes, wire::kCalOffMagic) == wire::kCalMagic) {
    throw DeviceError(
        "the board's calibration record is version " +
        std::to_string(wire::LoadU16(bytes, wire::kCalOffVersion)) + " (" +
        std::to_string(bytes.size()) + " bytes); this host reads version " +
        std::to_string(wire::kCalRecordVersion) + " (" + std::to_string(wire::kCalRecordBytes) +
        " bytes, chains of up to " + std::to_string(wire::kMaxDof) +
        " masses): flash the firmware of this host's release (vibid flash), then upload and "
        "commit the calibration again (vibid cal upload, vibid cal commit)");
  }
  throw DeviceError(std::string("the board's active calibration record does not decode (") +
                    StatusName(st) +
                    "); upload and commit the calibration again (vibid cal upload, vibid cal "
                    "commit)");
}

void ApplyCalibration(const wire::CalibrationRecord& rec, bool has_record, bool dob_running,
                      bool no_dob, Trigger& trig, wire::AcqConfigureRequest& cfg) {
  // d_hat is logged by default only while the observer runs: a stored observer that is stopped
  // estimates nothing, and its column would take link budget for a constant.
  // The residual test's state goes with it when the calibration carries one: the model-stale
  // flag and its statistic logged with the data they judge.
  if (!no_dob && dob_running && has_record && (rec.flags & wire::kCalFlagHasDob) != 0) {
    cfg.flags = wire::kAcqFlagLogDob;
    if ((rec.flags & wire::kCalFlagHasWatch) != 0)
      cfg.flags = static_cast<std::uint8_t>(cfg.flags | wire::kAcqFlagLogWatch);
    // The board's own rule, checked here first: the observer runs only at the rate it was
    // discretized for. Refused before the link budget, whose advice (a log rate) would
    // otherwise lead straight into the board's refusal of the sample rate.
    fixed::FilterDescription observer;
    static_cast<void>(
        fixed::DecodeDescription(std::span<const std::uint8_t, fixed::kDescriptionBytes>(
                                     rec.dob.data(), fixed::kDescriptionBytes),
                                 observer));
    if (observer.sample_rate_hz != 0 &&
        static_cast<std::uint64_t>(cfg.sample_period_us) * observer.sample_rate_hz != 1000000u) {
      throw InputError(
          "--rate-hz " + OptionNumber(1e6 / cfg.sample_period_us) + ": " +
          ReasonText(Status::kInvalidArgument,
                     wire::Refusal{wire::Reason::kObserverRate, observer.sample_rate_hz}));
    }
  }
  if (trig.mode == wire::TriggerMode::kImmediate) return;
  const wire::ChannelScaling& s = rec.channels[static_cast<std::size_t>(trig.channel)];
  if (!has_record || s.unit != wire::Unit::kNewton) {
    throw DeviceError(
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

LinkBudget Preflight(const wire::InfoResponse& info, const wire::AcqConfigureRequest& cfg,
                     const AcquireSettings& settings) {
  // Records the link cannot carry pile up in the log; refuse before the board starts if it would
  // overflow.
  const LinkBudget budget = ComputeLinkBudget(info, cfg);
  if (budget.overflow_after_s < settings.seconds + settings.pretrigger_s && !settings.allow_drops) {
    throw InputError(DescribeOverflow(budget, settings.seconds));
  }
  return budget;
}

}  // namespace vibid::device
