// What an acquisition asks of the board, decided the same way by every front end (`vibid
// acquire`, the Python Board): the configuration from the user's settings, what the board's
// calibration adds (observer logging, the trigger threshold in ADC units), and the preflight
// refusal of an acquisition the link cannot carry. Messages name the CLI's options.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "vibid/device/connection.hpp"
#include "vibid/device/link_budget.hpp"
#include "vibid/shared/wire/calibration_record.hpp"
#include "vibid/shared/wire/commands.hpp"

namespace vibid::device {

/// The acquisition a user asks for, in the CLI's terms and with its defaults.
struct AcquireSettings {
  double seconds = 0.0;               ///< Recorded after the trigger.
  double rate_hz = 5000.0;            ///< Sample rate.
  double log_rate_hz = 0.0;           ///< 0: the sample rate (or `decimation`).
  int decimation = 0;                 ///< 0: from log_rate_hz.
  std::vector<std::string> channels;  ///< Stems (force1, acc2...); empty: all.
  std::string trigger;                ///< "force>F", "force2<F" (N); empty: immediate.
  double trigger_timeout_s = 0.0;     ///< 0: no timeout.
  double pretrigger_s = 0.0;
  bool no_dob = false;       ///< Do not log the observer output.
  bool allow_drops = false;  ///< Start even if the link cannot carry the log rate.
};

struct Trigger {
  wire::TriggerMode mode = wire::TriggerMode::kImmediate;
  wire::Channel channel = wire::Channel::kForce1;
  double threshold = 0.0;
  double full_scale_n = 0.0;  ///< The load cell's, from the board's calibration.
};

/// "force>F", "force2<F" ("force" is force1): the load cell, the direction and F in newtons.
/// InputError otherwise; empty text is the immediate start.
Trigger ParseTrigger(const std::string& text);

/// The decimation for a log rate (or the one given), checked against what the board's decimator
/// supports; InputError naming the rates near it otherwise.
int DecimationFor(double rate_hz, double log_rate_hz, int decimation);

/// The configuration the settings ask for, checked as far as it can be without the board (every
/// number finite and in its option's range, the length within what the board counts); `trig`
/// gets the parsed trigger. InputError naming the first bad setting by its CLI option.
wire::AcqConfigureRequest PlanAcquisition(const AcquireSettings& settings, Trigger& trig);

/// The board's active calibration record; `has_record` false when it is uncalibrated.
wire::CalibrationRecord ActiveRecord(Connection& c, bool& has_record);

/// The record the board sent (cal-get), decoded; DeviceError otherwise, naming the cause and the
/// way out: a record of another version (firmware and host of different releases: flash the
/// firmware that matches this host, then upload and commit the calibration again) or one the
/// board's own checks should have refused.
wire::CalibrationRecord DecodeBoardRecord(std::span<const std::uint8_t> bytes);

/// What the board's state adds to `cfg`: the observer output when the observer runs (`dob_running`,
/// from get-status) unless `no_dob`, the trigger threshold in ADC units (and the load cell's full
/// scale in `trig`). DeviceError when a trigger needs a calibrated load cell the board does not
/// have; InputError (the board's words for it) when the observer's output is logged at a sample
/// rate other than the one the observer was designed for, before Preflight's link budget.
void ApplyCalibration(const wire::CalibrationRecord& record, bool has_record, bool dob_running,
                      bool no_dob, Trigger& trig, wire::AcqConfigureRequest& cfg);

/// Preflight: the link budget of `cfg` on this board; InputError (DescribeOverflow) when the log
/// would overflow within the acquisition and drops are not allowed.
LinkBudget Preflight(const wire::InfoResponse& info, const wire::AcqConfigureRequest& cfg,
                     const AcquireSettings& settings);

}  // namespace vibid::device
