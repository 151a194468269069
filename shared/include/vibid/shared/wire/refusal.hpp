// Why the device refused a request: the payload of a refusal (protocol 2.1).
//
// A refusal is a response report with a nonzero Status. From protocol 2.1 on its payload says why
// and what the device knows that the host needs to name the way out:
//
//   0  u16 reason    Reason (append only: a value is never renumbered or reused)
//   2  u16 reserved  0
//   4  u32 detail    a number the reason names (a rate, a limit, an index), else 0
//
// A 2.0 device sends no payload (Reason::kUnspecified); a 2.0 host never reads the payload of a
// refusal, so both directions keep working. A longer payload is read for its first kBytes, so a
// later minor may append fields.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "vibid/shared/status.hpp"

namespace vibid::wire {

enum class Reason : std::uint16_t {
  kUnspecified = 0,         ///< No reason given (a 2.0 device).
  kMalformedRequest = 1,    ///< The header: response flag, sequence or reserved byte.
  kPayloadLength = 2,       ///< The payload's length does not fit the command.
  kUnknownCommand = 3,      ///< The device does not know the command id.
  kBusySampling = 4,        ///< Not while an acquisition runs (acq-stop first).
  kSamplePeriod = 5,        ///< Period out of range; detail: the fastest period in µs (0: the
                            ///< port's own limit, below the protocol's).
  kChannelSelection = 6,    ///< Channel mask empty or unknown, or unknown acquisition flags.
  kDecimation = 7,          ///< Not 2^a 5^b up to the limit; detail: the largest factor.
  kTrigger = 8,             ///< Trigger mode, channel, threshold or pre-trigger inconsistent.
  kPretriggerTooLong = 9,   ///< The pre-trigger does not fit the log; detail: capacity, records.
  kNoObserver = 10,         ///< The calibration holds no observer (or none is loaded).
  kObserverRate = 11,       ///< The observer runs at another rate; detail: its rate in Hz.
  kNotConfigured = 12,      ///< acq-start before any acq-configure.
  kNothingStaged = 13,      ///< cal-commit with no complete record staged.
  kNotCalibrated = 14,      ///< cal-get on a board with no calibration.
  kNoLog = 15,              ///< log-read before any acquisition.
  kLogOverwritten = 16,     ///< The records asked for are overwritten; detail: the oldest held.
  kUploadSequence = 17,     ///< cal-put-data out of order or without begin; detail: chunk due.
  kRecordLength = 18,       ///< cal-put-begin of another length; detail: the length taken.
  kRecordCrc = 19,          ///< The uploaded record does not match its announced CRC-32.
  kRecordInvalid = 20,      ///< The record fails the board's checks; detail: the decode's Status.
  kFlashWrite = 21,         ///< Writing the flash failed (counted in get-status flash_errors).
  kNoBootloader = 22,       ///< This port has no DFU bootloader.
  kUnknownScenario = 23,    ///< Emulator: no scenario of that name.
  kScenarioParameter = 24,  ///< Emulator: a parameter is out of range; detail: its index (0..3).
  kPortRefused = 25,        ///< A port command was refused for a port-specific cause.
  kUnknownInfoPage = 26,    ///< get-info of a page the board does not have; detail: the page.
  kUnknownCheck = 27,       ///< self-test of a check the board does not have; detail: the check.
  kInternalClock = 28,      ///< acq-start on a board running from its internal oscillator (the
                            ///< crystal was refused or did not start); detail: the ClockState.
  kNoModelTest = 29,        ///< The log's residual-test column without a test in the calibration.
};

/// The highest Reason this build knows; a larger value decodes and names itself "unknown".
inline constexpr Reason kLastReason = Reason::kNoModelTest;

struct Refusal {
  static constexpr std::size_t kBytes = 8;
  Reason reason = Reason::kUnspecified;
  std::uint32_t detail = 0;
};

/// Writes exactly kBytes.
void Encode(const Refusal& v, std::span<std::uint8_t> out);
/// kOk for an empty payload (a 2.0 device: kUnspecified) or kBytes or more (the first kBytes);
/// kInvalidArgument for 1..kBytes-1 bytes. Any reason value decodes (newer devices add some).
Status Decode(std::span<const std::uint8_t> in, Refusal& v);

/// Short stable name ("observer-rate"), "unknown" for a value this build does not know.
const char* ReasonName(Reason reason);

}  // namespace vibid::wire
