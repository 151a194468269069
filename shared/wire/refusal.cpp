#include "vibid/shared/wire/refusal.hpp"

#include "vibid/shared/wire/byte_order.hpp"

namespace vibid::wire {

void Encode(const Refusal& v, std::span<std::uint8_t> out) {
  StoreU16(out, 0, static_cast<std::uint16_t>(v.reason));
  StoreU16(out, 2, 0);
  StoreU32(out, 4, v.detail);
}

Status Decode(std::span<const std::uint8_t> in, Refusal& v) {
  v = Refusal{};
  if (in.empty()) return Status::kOk;
  if (in.size() < Refusal::kBytes) return Status::kInvalidArgument;
  v.reason = static_cast<Reason>(LoadU16(in, 0));
  v.detail = LoadU32(in, 4);
  return Status::kOk;
}

const char* ReasonName(Reason reason) {
  switch (reason) {
    case Reason::kUnspecified: return "unspecified";
    case Reason::kMalformedRequest: return "malformed-request";
    case Reason::kPayloadLength: return "payload-length";
    case Reason::kUnknownCommand: return "unknown-command";
    case Reason::kBusySampling: return "busy-sampling";
    case Reason::kSamplePeriod: return "sample-period";
    case Reason::kChannelSelection: return "channel-selection";
    case Reason::kDecimation: return "decimation";
    case Reason::kTrigger: return "trigger";
    case Reason::kPretriggerTooLong: return "pretrigger-too-long";
    case Reason::kNoObserver: return "no-observer";
    case Reason::kObserverRate: return "observer-rate";
    case Reason::kNotConfigured: return "not-configured";
    case Reason::kNothingStaged: return "nothing-staged";
    case Reason::kNotCalibrated: return "not-calibrated";
    case Reason::kNoLog: return "no-log";
    case Reason::kLogOverwritten: return "log-overwritten";
    case Reason::kUploadSequence: return "upload-sequence";
    case Reason::kRecordLength: return "record-length";
    case Reason::kRecordCrc: return "record-crc";
    case Reason::kRecordInvalid: return "record-invalid";
    case Reason::kFlashWrite: return "flash-write";
    case Reason::kNoBootloader: return "no-bootloader";
    case Reason::kUnknownScenario: return "unknown-scenario";
    case Reason::kScenarioParameter: return "scenario-parameter";
    case Reason::kPortRefused: return "port-refused";
    case Reason::kUnknownInfoPage: return "unknown-info-page";
    case Reason::kUnknownCheck: return "unknown-check";
    case Reason::kInternalClock: return "internal-clock";
    case Reason::kNoModelTest: return "no-model-test";
  }
  return "unknown";
}

}  // namespace vibid::wire
