#include "emu_port.hpp"

#include <algorithm>
#include <cmath>

#include "vibid/shared/board_profile.hpp"

namespace vibid::emu {

fw::SystemControl::SelfTestMeasurement EmuSystemControl::MeasureSelfTest(
    wire::SelfTestCheck check, std::uint32_t sample_period_us) {
  using wire::SelfTestCheck;
  const auto index = static_cast<unsigned>(check);
  switch (check) {
    case SelfTestCheck::kHsePpm: return {.available = true, .mantissa = 0, .exp10 = -3};
    case SelfTestCheck::kVdda: return {.available = true, .mantissa = kVddaMv, .exp10 = -3};
    case SelfTestCheck::kImageCrc:
    case SelfTestCheck::kHsePpmLse: return {};  // no image; no LSE crystal in the rig
    default: break;
  }
  // Converter and encoder checks: sample the rig as the board would, kSelfTestSamples frames at
  // the configured period (the next acquisition restarts it from rest).
  rig_.Start(static_cast<double>(sample_period_us) * 1e-6);
  std::array<std::int32_t, wire::kChannelCount> raw{};
  if (check == SelfTestCheck::kEncoder1 || check == SelfTestCheck::kEncoder2) {
    rig_.Step(raw);
    const std::size_t channel = check == SelfTestCheck::kEncoder1 ? 4 : 5;
    // The simulated timer always counts; its value is the position count.
    return {.available = true, .mantissa = raw[channel], .exp10 = 0, .ok = true};
  }
  const bool noise = index <= static_cast<unsigned>(SelfTestCheck::kNoiseAccel2);
  const std::size_t channel = index - static_cast<unsigned>(noise ? SelfTestCheck::kNoiseForce1
                                                                  : SelfTestCheck::kOffsetForce1);
  double sum = 0.0;
  double sum_sq = 0.0;
  for (std::uint32_t k = 0; k < wire::kSelfTestSamples; ++k) {
    rig_.Step(raw);
    const auto code = static_cast<double>(raw[channel]);
    sum += code;
    sum_sq += code * code;
  }
  const double n = static_cast<double>(wire::kSelfTestSamples);
  const double mean = sum / n;
  const double variance = std::max(0.0, sum_sq / n - mean * mean);
  const double mid_code = static_cast<double>(1u << (kBoardProfile.adc_bits - 1));
  // Milli-LSB: the value as the board would report it.
  const double value = noise ? std::sqrt(variance) : mean - mid_code;
  return {.available = true, .mantissa = std::llround(value * 1000.0), .exp10 = -3};
}

Status RigFrameSource::Start(std::uint32_t sample_period_us, fw::FrameSink& sink) {
  if (sink_ != nullptr) return Status::kFailedPrecondition;
  if (sample_period_us == 0 ||
      1e6 / static_cast<double>(sample_period_us) > rig_.MaxSampleRateHz()) {
    return Status::kInvalidArgument;
  }
  period_us_ = sample_period_us;
  rig_.Start(static_cast<double>(sample_period_us) * 1e-6);
  frame_ = {};
  sink_ = &sink;
  return Status::kOk;
}

void RigFrameSource::Tick() {
  rig_.Step(frame_.raw);
  sink_->OnFrame(frame_);
  ++frame_.tick;
}

std::uint32_t FlashCalibrationSlots::Address(Slot slot, std::size_t offset) {
  return kSlotAddress[static_cast<int>(slot)] + static_cast<std::uint32_t>(offset);
}

Status FlashCalibrationSlots::Erase(Slot slot) {
  return flash_.EraseSector(kSlotSector[static_cast<int>(slot)]) ? Status::kOk : Status::kInternal;
}

Status FlashCalibrationSlots::Program(Slot slot, std::size_t offset,
                                      std::span<const std::uint8_t> data) {
  if (offset > SlotBytes() || data.size() > SlotBytes() - offset) return Status::kOutOfRange;
  return flash_.Program(Address(slot, offset), data) ? Status::kOk : Status::kInternal;
}

Status FlashCalibrationSlots::Read(Slot slot, std::size_t offset,
                                   std::span<std::uint8_t> out) const {
  if (offset > SlotBytes() || out.size() > SlotBytes() - offset) return Status::kOutOfRange;
  return flash_.Read(Address(slot, offset), out) ? Status::kOk : Status::kInternal;
}

Status ScenarioCommands::HandlePortCommand(std::uint8_t command,
                                           std::span<const std::uint8_t> request,
                                           std::span<std::uint8_t, wire::kMaxPayload> response,
                                           std::size_t& response_length) {
  response_length = 0;
  // A refusal's reason goes back in the response bytes (the core sends it as the refusal).
  const auto refuse = [&](Status status, wire::Reason reason) {
    wire::Encode(wire::Refusal{.reason = reason}, response);
    response_length = wire::Refusal::kBytes;
    return status;
  };
  if (command != static_cast<std::uint8_t>(wire::Command::kSelectScenario))
    return refuse(Status::kUnimplemented, wire::Reason::kUnknownCommand);
  if (frames_.Running()) return refuse(Status::kFailedPrecondition, wire::Reason::kBusySampling);
  wire::ScenarioRequest r;
  if (wire::Decode(request, r) != Status::kOk)
    return refuse(Status::kInvalidArgument, wire::Reason::kPayloadLength);
  wire::Refusal why;
  const Status s = rig_.SelectScenario(r, why);
  if (s != Status::kOk) {
    wire::Encode(why, response);
    response_length = wire::Refusal::kBytes;
  }
  return s;
}

}  // namespace vibid::emu
