#include "vibid/device/watch_day.hpp"

#include <cmath>
#include <cstdio>
#include <vector>

#include <Eigen/Core>

#include "vibid/common/option_text.hpp"
#include "vibid/common/error.hpp"
#include "vibid/device/log_table.hpp"
#include "vibid/dob/quantize.hpp"
#include "vibid/shared/fixed/filter_description.hpp"

namespace vibid::device {

namespace {

// The recording's column of a board channel, as the log names it under the record's scaling.
const Eigen::VectorXd& ChannelColumn(const Recording& day, const wire::CalibrationRecord& record,
                                     std::size_t channel, const std::string& source,
                                     const std::string& why) {
  const std::string name = std::string(ChannelStem(static_cast<wire::Channel>(channel))) + "_" +
                           UnitSuffix(record.channels[channel].unit);
  Require(day.table.Has(name), source + " has no column '" + name + "' (" + why +
                                   "): record the calibration day with that channel (vibid "
                                   "acquire --channels ...)");
  return day.table.Column(name);
}

}  // namespace

dob::WatchDesign AttachWatchTest(wire::CalibrationRecord& record, const Recording& day,
                                 const WatchDayOptions& options, const std::string& source) {
  Require((record.flags & wire::kCalFlagHasDob) != 0,
          "--watch-day: the test watches the observer's residual, and this calibration has no "
          "observer; give one (--design)");
  fixed::FilterDescription d;
  Require(fixed::DecodeDescription(record.dob, d) == Status::kOk,
          "--watch-day: the observer's description does not decode");
  const double fs_hz = d.sample_rate_hz;
  Require(std::abs(day.fs_hz - fs_hz) <= 1e-6 * fs_hz,
          source + " is sampled at " + OptionNumber(day.fs_hz) + " Hz, but the observer steps at " +
              OptionNumber(fs_hz) +
              " Hz: record the calibration day at the observer's rate (vibid " +
              "acquire --rate-hz " + OptionNumber(fs_hz) + ", no --log-rate-hz)");

  // The observer's inputs in the description's order, from the channels the record routes them
  // to, replayed as the board runs them (the SI values the log wrote are its Q31 integers
  // exactly, so the replay is bit for bit).
  std::vector<Eigen::VectorXd> inputs;
  for (std::size_t i = 0; i < d.input_count; ++i) {
    const std::uint8_t ch = record.dob_input_channel[i];
    Require(ch < wire::kChannelCount, "--watch-day: the observer's input " + std::to_string(i + 1) +
                                          " has no channel in the record");
    inputs.push_back(ChannelColumn(day, record, ch, source, "an input of the observer"));
    Require(inputs.back().allFinite(), source + ": an observer input holds a non-finite value");
  }
  const dob::FixedRun run = dob::RunFixed(d, inputs);
  if (day.table.Has("d_hat_q31")) {
    const Eigen::VectorXd& board = day.table.Column("d_hat_q31");
    for (Eigen::Index n = 0; n < board.size(); ++n) {
      if (board(n) == static_cast<double>(run.d_hat_q31[static_cast<std::size_t>(n)])) continue;
      throw InputError(source +
                       ": the board's d_hat differs from this observer's replay from "
                       "sample " +
                       std::to_string(n) +
                       " on: the calibration day was recorded with another observer; record it "
                       "again with the observer being uploaded running (vibid cal upload and "
                       "commit it first, then vibid acquire)");
    }
  }

  std::vector<std::int32_t> reference_q31;
  double reference_ratio = 0.0;
  std::uint8_t reference_channel = wire::kNoChannel;
  if (!options.reference.empty()) {
    wire::Channel c{};
    Require(ChannelFromStem(options.reference, c) && wire::IsLoadCell(static_cast<std::uint8_t>(c)),
            "--watch-reference '" + options.reference + "' is not a load cell (force1 or force2)");
    const auto ch = static_cast<std::size_t>(c);
    Require(record.channels[ch].unit == wire::Unit::kNewton,
            "--watch-reference " + options.reference +
                " is not calibrated in newtons; give its scaling in the sensors file");
    const Eigen::VectorXd& f = ChannelColumn(day, record, ch, source, "the reference load cell");
    const double full_scale = static_cast<double>(record.channels[ch].full_scale);
    reference_q31.resize(static_cast<std::size_t>(f.size()));
    for (Eigen::Index n = 0; n < f.size(); ++n) {
      reference_q31[static_cast<std::size_t>(n)] =
          static_cast<std::int32_t>(std::lround(f(n) / full_scale * 2147483648.0));
    }
    reference_ratio =
        full_scale / static_cast<double>(fixed::FullScaleValue(d.output_full_scale_bits));
    reference_channel = static_cast<std::uint8_t>(ch);
  }
  dob::WatchOptions o;
  o.false_alarms_per_hour = options.false_alarms_per_hour;
  o.shift_spreads = options.shift_spreads;
  o.window_samples = options.window_samples;
  o.observer_pole_radius = dob::SlowestPoleRadius(d);  // the hold-off after the observer's start
  const dob::WatchDesign design =
      dob::DesignWatch(run.d_hat_q31, reference_q31, reference_ratio, fs_hz, o);
  record.flags = static_cast<std::uint8_t>(record.flags | wire::kCalFlagHasWatch);
  record.watch = design.params;
  record.watch_reference_channel = reference_channel;
  record.watch_in_control_arl_windows = static_cast<float>(design.arl0_windows);
  return design;
}

std::string WatchDesignText(const dob::WatchDesign& d) {
  char line[640];
  std::snprintf(line, sizeof line,
                "model test: windows of %u samples (%.3g s) from %zu on the calibration day; "
                "k %.2f, h %.2f for at most %.3g false alarms per hour: this calibration gives "
                "between %.3g and %.3g false alarms per hour (95 %%; one in %.3g windows at its "
                "own estimates); the window mean shifted by %.3g spread%s is caught in about "
                "%.1f windows; the first %u window%s (%.3g s) after the observer's start held "
                "off (its slowest pole, radius %.6g, settles in %.0f samples)",
                d.params.window_samples, d.window_s, d.calibration_windows, d.k, d.h,
                d.false_alarms_per_hour, d.false_alarms_low, d.false_alarms_high, d.arl0_windows,
                2.0 * d.k, 2.0 * d.k == 1.0 ? "" : "s", d.detection_windows,
                static_cast<unsigned>(d.params.holdoff_windows),
                d.params.holdoff_windows == 1 ? "" : "s", d.params.holdoff_windows * d.window_s,
                d.observer_pole_radius, std::ceil(d.holdoff_samples));
  return line;
}

}  // namespace vibid::device
