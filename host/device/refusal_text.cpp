#include "vibid/device/refusal_text.hpp"

#include "vibid/device/health_report.hpp"
#include "vibid/shared/wire/commands.hpp"

namespace vibid::device {
namespace {

std::string Hz(std::uint32_t hz) { return std::to_string(hz) + " Hz"; }

// What a status alone says, for a device that gave no reason.
std::string StatusText(Status status) {
  switch (status) {
    case Status::kUnimplemented: return "the device does not know this command";
    case Status::kFailedPrecondition: return "not allowed in the device's current state";
    case Status::kVersionMismatch: return "protocol version";
    default: return StatusName(status);
  }
}

}  // namespace

std::string ReasonText(Status status, const wire::Refusal& r) {
  const std::uint32_t d = r.detail;
  switch (r.reason) {
    case wire::Reason::kUnspecified: return StatusText(status);
    case wire::Reason::kMalformedRequest:
      return "the request's header is malformed; use a host that matches the firmware";
    case wire::Reason::kPayloadLength:
      return "the request's payload has the wrong length for this command; use a host that "
             "matches the firmware (vibid info shows its protocol)";
    case wire::Reason::kUnknownCommand:
      return "the firmware does not know this command; flash firmware that matches this host "
             "(vibid flash)";
    case wire::Reason::kBusySampling:
      return "the board is acquiring; wait for the acquisition to end (or interrupt the vibid "
             "acquire that runs it) and try again";
    case wire::Reason::kSamplePeriod:
      if (d == 0) return "the board's converters cannot sample this fast; choose a lower --rate-hz";
      return "the sample rate is outside the board's 1 Hz .. " + Hz(1000000u / d) +
             "; choose --rate-hz from 1 to " + std::to_string(1000000u / d);
    case wire::Reason::kChannelSelection:
      return "the channel selection is empty or names a channel the board does not have; choose "
             "from force1, force2, acc1, acc2, x1, x2 (--channels)";
    case wire::Reason::kDecimation:
      return "the board decimates by 2^a 5^b up to " + std::to_string(d) +
             " only; choose another --log-rate-hz";
    case wire::Reason::kTrigger:
      return "the trigger's mode, channel or threshold is inconsistent; trigger on a load cell "
             "(--trigger force>F or force2<F)";
    case wire::Reason::kPretriggerTooLong:
      return "the pre-trigger does not fit the board's log of " + std::to_string(d) +
             " records; shorten --pretrigger-s";
    case wire::Reason::kNoObserver:
      return "the board's calibration holds no observer; design one (vibid dob design), upload "
             "it (vibid cal upload MODEL.json --design DESIGN.json --sensors SENSORS.json) and "
             "commit it (vibid cal commit)";
    case wire::Reason::kObserverRate:
      return "the board's observer was designed for " + Hz(d) +
             " and runs at that rate only; acquire at --rate-hz " + std::to_string(d) +
             ", or without the observer (--no-dob), or design and upload an observer for this "
             "rate (vibid dob design --fs-hz)";
    case wire::Reason::kNotConfigured:
      return "no acquisition is configured; vibid acquire configures and starts one";
    case wire::Reason::kNothingStaged:
      return "no calibration record is staged; stage one first (vibid cal upload MODEL.json "
             "--design DESIGN.json --sensors SENSORS.json), then commit";
    case wire::Reason::kNotCalibrated:
      return "the board holds no calibration; upload and commit one (vibid cal upload, vibid cal "
             "commit)";
    case wire::Reason::kNoLog:
      return "the board holds no log (nothing was acquired since it started); record one with "
             "vibid acquire";
    case wire::Reason::kLogOverwritten:
      return "the records asked for have been overwritten; the oldest the board holds is record " +
             std::to_string(d) + " (vibid log pull --from " + std::to_string(d) + ")";
    case wire::Reason::kUploadSequence:
      return "the calibration upload arrived out of order (chunk " + std::to_string(d) +
             " was due); upload it again (vibid cal upload)";
    case wire::Reason::kRecordLength:
      return "the board takes calibration records of " + std::to_string(d) +
             " bytes only; use a host that matches the firmware";
    case wire::Reason::kRecordCrc:
      return "the calibration record was corrupted on the way (CRC-32 mismatch); upload it again";
    case wire::Reason::kRecordInvalid:
      return std::string("the board's checks refuse the calibration record (") +
             StatusName(static_cast<Status>(d)) +
             "); rebuild it with a host that matches the firmware";
    case wire::Reason::kFlashWrite:
      return "writing the board's flash failed (counted in its flash errors); commit again, and "
             "if it fails again the flash is worn";
    case wire::Reason::kNoBootloader:
      return "this board has no DFU bootloader; flash it with a debugger (SWD)";
    case wire::Reason::kUnknownScenario:
      return "the emulator has no such scenario; choose hammer, shaker, push, step, tone, operate "
             "or idle (--scenario)";
    case wire::Reason::kScenarioParameter:
      return "scenario parameter " + std::to_string(d + 1) +
             " is out of range for this scenario and rig; see the scenario table in "
             "docs/emulator.md (--scenario-param)";
    case wire::Reason::kPortRefused: return StatusText(status) + " (refused by the board's port)";
    case wire::Reason::kUnknownInfoPage:
      return "the board has no get-info page " + std::to_string(d) +
             "; use a host that matches the firmware";
    case wire::Reason::kUnknownCheck:
      return "the board has no self-test check " + std::to_string(d) +
             "; use a host that matches the firmware";
    case wire::Reason::kInternalClock:
      return std::string("the board runs on its internal oscillator (") + ClockStateName(d) +
             "), so its sample clock would be off by up to a few percent; vibid info shows the "
             "measured crystal: build the image for the board's crystal (VIBID_BOARD or "
             "VIBID_HSE_HZ, docs/board.md) or check the crystal";
    case wire::Reason::kNoModelTest:
      return "the board's calibration holds no residual test, so its log has no model column; "
             "build the test into the calibration (vibid cal upload --watch-day REC.csv) or log "
             "without it";
  }
  return StatusText(status) + " (reason " + std::to_string(static_cast<unsigned>(r.reason)) +
         ", which this host does not know; use a host that matches the firmware)";
}

std::string RefusalCause(Status status, std::span<const std::uint8_t> payload) {
  wire::Refusal r;
  // A 2.0 board gives no reason (and a malformed one is none): the status and what it means.
  if (wire::Decode(payload, r) != Status::kOk || r.reason == wire::Reason::kUnspecified) {
    const std::string plain = StatusText(status);
    return StatusName(status) + (plain == StatusName(status) ? "" : " (" + plain + ")");
  }
  return ReasonText(status, r) + " [" + StatusName(status) + ", " + wire::ReasonName(r.reason) +
         "]";
}

std::string RefusalMessage(std::uint8_t command, Status status,
                           std::span<const std::uint8_t> payload) {
  return "the device refused " + std::string(wire::CommandName(command)) + ": " +
         RefusalCause(status, payload);
}

}  // namespace vibid::device
