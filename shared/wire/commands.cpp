#include "vibid/shared/wire/commands.hpp"

#include <bit>

#include "vibid/shared/wire/byte_order.hpp"

namespace vibid::wire {
namespace {

bool KnownAcqState(std::uint8_t v) { return v <= static_cast<std::uint8_t>(AcqState::kDone); }
bool KnownCalState(std::uint8_t v) { return v <= static_cast<std::uint8_t>(CalState::kCalibrated); }

}  // namespace

void Encode(const InfoResponse& v, std::span<std::uint8_t> out) {
  StoreU8(out, 0, v.protocol_major);
  StoreU8(out, 1, v.protocol_minor);
  StoreU8(out, 2, v.fw_major);
  StoreU8(out, 3, v.fw_minor);
  StoreU16(out, 4, v.fw_patch);
  StoreU16(out, 6, static_cast<std::uint16_t>(v.board_id));
  StoreU32(out, 8, v.build_id);
  StoreU32(out, 12, v.capabilities);
  StoreU32(out, 16, v.sample_period_us);
  StoreU32(out, 20, v.min_sample_period_us);
  StoreU32(out, 24, v.log_capacity_bytes);
  StoreU16(out, 28, v.link_reports_per_s);
  StoreU8(out, 30, v.adc_bits);
  StoreU8(out, 31, static_cast<std::uint8_t>(v.reset_cause));
  for (std::size_t i = 0; i < kChannelCount; ++i) {
    StoreU8(out, 32 + i, static_cast<std::uint8_t>(v.channel_kind[i]));
  }
  StoreU8(out, 38, static_cast<std::uint8_t>(v.cal_state));
  StoreU8(out, 39, v.cal_slot);
  StoreU32(out, 40, v.cal_crc);
  StoreU32(out, 44, v.overrun_count);
  StoreU32(out, 48, v.dropped_records);
}

Status Decode(std::span<const std::uint8_t> in, InfoResponse& v) {
  if (in.size() != InfoResponse::kBytes) return Status::kInvalidArgument;
  v.protocol_major = LoadU8(in, 0);
  v.protocol_minor = LoadU8(in, 1);
  v.fw_major = LoadU8(in, 2);
  v.fw_minor = LoadU8(in, 3);
  v.fw_patch = LoadU16(in, 4);
  v.board_id = static_cast<BoardId>(LoadU16(in, 6));
  v.build_id = LoadU32(in, 8);
  v.capabilities = LoadU32(in, 12);
  v.sample_period_us = LoadU32(in, 16);
  v.min_sample_period_us = LoadU32(in, 20);
  v.log_capacity_bytes = LoadU32(in, 24);
  v.link_reports_per_s = LoadU16(in, 28);
  v.adc_bits = LoadU8(in, 30);
  v.reset_cause = static_cast<ResetCause>(LoadU8(in, 31));
  for (std::size_t i = 0; i < kChannelCount; ++i) {
    v.channel_kind[i] = static_cast<ChannelKind>(LoadU8(in, 32 + i));
  }
  const std::uint8_t cal_state = LoadU8(in, 38);
  v.cal_state = static_cast<CalState>(cal_state);
  v.cal_slot = LoadU8(in, 39);
  v.cal_crc = LoadU32(in, 40);
  v.overrun_count = LoadU32(in, 44);
  v.dropped_records = LoadU32(in, 48);
  if (!KnownCalState(cal_state)) return Status::kInvalidArgument;
  return Status::kOk;
}

void Encode(const InfoPageRequest& v, std::span<std::uint8_t> out) { StoreU8(out, 0, v.page); }

Status Decode(std::span<const std::uint8_t> in, InfoPageRequest& v) {
  if (in.size() != InfoPageRequest::kBytes) return Status::kInvalidArgument;
  v.page = LoadU8(in, 0);
  return Status::kOk;
}

void Encode(const SamplingInfoResponse& v, std::span<std::uint8_t> out) {
  for (std::size_t i = 0; i < kChannelCount; ++i) StoreU32(out, 4 * i, v.sample_instant_ns[i]);
}

Status Decode(std::span<const std::uint8_t> in, SamplingInfoResponse& v) {
  if (in.size() != SamplingInfoResponse::kBytes) return Status::kInvalidArgument;
  for (std::size_t i = 0; i < kChannelCount; ++i) v.sample_instant_ns[i] = LoadU32(in, 4 * i);
  return Status::kOk;
}

void Encode(const HealthInfoResponse& v, std::span<std::uint8_t> out) {
  StoreU8(out, 0, static_cast<std::uint8_t>(v.brown_out));
  StoreU8(out, 1, static_cast<std::uint8_t>(v.reset_cause));
  StoreU8(out, 2, static_cast<std::uint8_t>(v.clock));
  StoreU8(out, 3, 0);
  StoreU32(out, 4, v.hse_measured_hz);
  StoreU32(out, 8, v.sampler_recoveries);
}

Status Decode(std::span<const std::uint8_t> in, HealthInfoResponse& v) {
  if (in.size() != HealthInfoResponse::kBytes) return Status::kInvalidArgument;
  const std::uint8_t brown_out = LoadU8(in, 0);
  const std::uint8_t reset_cause = LoadU8(in, 1);
  const std::uint8_t clock = LoadU8(in, 2);
  if (brown_out > static_cast<std::uint8_t>(BrownOut::kLevel3) ||
      reset_cause > static_cast<std::uint8_t>(ResetCause::kFault) ||
      clock > static_cast<std::uint8_t>(ClockState::kPllDidNotLock) || LoadU8(in, 3) != 0) {
    return Status::kInvalidArgument;
  }
  v.brown_out = static_cast<BrownOut>(brown_out);
  v.reset_cause = static_cast<ResetCause>(reset_cause);
  v.clock = static_cast<ClockState>(clock);
  v.hse_measured_hz = LoadU32(in, 4);
  v.sampler_recoveries = LoadU32(in, 8);
  return Status::kOk;
}

void Encode(const FaultInfoResponse& v, std::span<std::uint8_t> out) {
  StoreU8(out, 0, v.recorded);
  StoreU8(out, 1, v.exception);
  StoreU16(out, 2, 0);
  StoreU32(out, 4, v.cfsr);
  StoreU32(out, 8, v.hfsr);
  StoreU32(out, 12, v.mmfar);
  StoreU32(out, 16, v.bfar);
  StoreU32(out, 20, v.pc);
  StoreU32(out, 24, v.lr);
}

Status Decode(std::span<const std::uint8_t> in, FaultInfoResponse& v) {
  if (in.size() != FaultInfoResponse::kBytes) return Status::kInvalidArgument;
  if (LoadU8(in, 0) > 1 || LoadU16(in, 2) != 0) return Status::kInvalidArgument;
  v.recorded = LoadU8(in, 0);
  v.exception = LoadU8(in, 1);
  v.cfsr = LoadU32(in, 4);
  v.hfsr = LoadU32(in, 8);
  v.mmfar = LoadU32(in, 12);
  v.bfar = LoadU32(in, 16);
  v.pc = LoadU32(in, 20);
  v.lr = LoadU32(in, 24);
  return Status::kOk;
}

void Encode(const SelfTestRequest& v, std::span<std::uint8_t> out) { StoreU8(out, 0, v.check); }

Status Decode(std::span<const std::uint8_t> in, SelfTestRequest& v) {
  if (in.size() != SelfTestRequest::kBytes) return Status::kInvalidArgument;
  v.check = LoadU8(in, 0);
  return Status::kOk;
}

void Encode(const SelfTestResponse& v, std::span<std::uint8_t> out) {
  StoreU8(out, 0, v.check);
  StoreU8(out, 1, v.check_count);
  StoreU8(out, 2, static_cast<std::uint8_t>(v.verdict));
  StoreU8(out, 3, static_cast<std::uint8_t>(v.unit));
  StoreU8(out, 4, static_cast<std::uint8_t>(v.exp10));
  StoreU8(out, 5, static_cast<std::uint8_t>(v.reference));
  StoreU16(out, 6, 0);
  StoreI64(out, 8, v.mantissa);
}

Status Decode(std::span<const std::uint8_t> in, SelfTestResponse& v) {
  if (in.size() != SelfTestResponse::kBytes) return Status::kInvalidArgument;
  const std::uint8_t verdict = LoadU8(in, 2);
  const std::uint8_t unit = LoadU8(in, 3);
  if (verdict > static_cast<std::uint8_t>(SelfTestVerdict::kUnavailable) ||
      unit > static_cast<std::uint8_t>(SelfTestUnit::kResetCause) ||
      LoadU8(in, 5) > static_cast<std::uint8_t>(SelfTestReference::kCalibration) ||
      LoadU16(in, 6) != 0) {
    return Status::kInvalidArgument;
  }
  v.check = LoadU8(in, 0);
  v.check_count = LoadU8(in, 1);
  v.verdict = static_cast<SelfTestVerdict>(verdict);
  v.unit = static_cast<SelfTestUnit>(unit);
  v.exp10 = static_cast<std::int8_t>(LoadU8(in, 4));
  v.reference = static_cast<SelfTestReference>(LoadU8(in, 5));
  v.mantissa = LoadI64(in, 8);
  return Status::kOk;
}

const char* SelfTestCheckName(std::uint8_t check) {
  switch (static_cast<SelfTestCheck>(check)) {
    case SelfTestCheck::kHsePpm: return "hse-ppm";
    case SelfTestCheck::kVdda: return "vdda";
    case SelfTestCheck::kNoiseForce1: return "noise-force1";
    case SelfTestCheck::kNoiseForce2: return "noise-force2";
    case SelfTestCheck::kNoiseAccel1: return "noise-acc1";
    case SelfTestCheck::kNoiseAccel2: return "noise-acc2";
    case SelfTestCheck::kOffsetForce1: return "offset-force1";
    case SelfTestCheck::kOffsetForce2: return "offset-force2";
    case SelfTestCheck::kOffsetAccel1: return "offset-acc1";
    case SelfTestCheck::kOffsetAccel2: return "offset-acc2";
    case SelfTestCheck::kEncoder1: return "encoder1";
    case SelfTestCheck::kEncoder2: return "encoder2";
    case SelfTestCheck::kImageCrc: return "image-crc";
    case SelfTestCheck::kCalSlotA: return "cal-slot-a";
    case SelfTestCheck::kCalSlotB: return "cal-slot-b";
    case SelfTestCheck::kBrownOut: return "brown-out";
    case SelfTestCheck::kResetCause: return "reset-cause";
    case SelfTestCheck::kHsePpmLse: return "hse-ppm-lse";
  }
  return "unknown";
}

void Encode(const StatusResponse& v, std::span<std::uint8_t> out) {
  StoreU8(out, 0, static_cast<std::uint8_t>(v.acq_state));
  StoreU8(out, 1, v.dob_running);
  StoreU8(out, 2, static_cast<std::uint8_t>(v.cal_state));
  StoreU8(out, 3, v.cal_staged);
  StoreU64(out, 4, v.uptime_us);
  StoreU32(out, 12, v.ticks);
  StoreU32(out, 16, v.records_written);
  StoreU32(out, 20, v.oldest_record);
  StoreU32(out, 24, v.overrun_count);
  StoreU32(out, 28, v.dropped_records);
  StoreU32(out, 32, v.rejected_requests);
  StoreU32(out, 36, v.saturation_count);
  StoreU32(out, 40, v.trigger_record);
  StoreU32(out, 44, v.cal_sequence);
  StoreU32(out, 48, v.flash_errors);
}

Status Decode(std::span<const std::uint8_t> in, StatusResponse& v) {
  if (in.size() != StatusResponse::kBytes) return Status::kInvalidArgument;
  const std::uint8_t acq = LoadU8(in, 0);
  const std::uint8_t cal = LoadU8(in, 2);
  v.acq_state = static_cast<AcqState>(acq);
  v.dob_running = LoadU8(in, 1);
  v.cal_state = static_cast<CalState>(cal);
  v.cal_staged = LoadU8(in, 3);
  v.uptime_us = LoadU64(in, 4);
  v.ticks = LoadU32(in, 12);
  v.records_written = LoadU32(in, 16);
  v.oldest_record = LoadU32(in, 20);
  v.overrun_count = LoadU32(in, 24);
  v.dropped_records = LoadU32(in, 28);
  v.rejected_requests = LoadU32(in, 32);
  v.saturation_count = LoadU32(in, 36);
  v.trigger_record = LoadU32(in, 40);
  v.cal_sequence = LoadU32(in, 44);
  v.flash_errors = LoadU32(in, 48);
  if (!KnownAcqState(acq) || !KnownCalState(cal) || v.dob_running > 1 || v.cal_staged > 1) {
    return Status::kInvalidArgument;
  }
  return Status::kOk;
}

void Encode(const AcqConfigureRequest& v, std::span<std::uint8_t> out) {
  StoreU32(out, 0, v.sample_period_us);
  StoreU8(out, 4, v.channel_mask);
  StoreU8(out, 5, v.flags);
  StoreU16(out, 6, v.decimation);
  StoreU8(out, 8, static_cast<std::uint8_t>(v.trigger_mode));
  StoreU8(out, 9, v.trigger_channel);
  StoreU16(out, 10, 0);
  StoreI32(out, 12, v.trigger_threshold);
  StoreU32(out, 16, v.pretrigger_records);
  StoreU32(out, 20, v.record_limit);
}

Status Decode(std::span<const std::uint8_t> in, AcqConfigureRequest& v) {
  if (in.size() != AcqConfigureRequest::kBytes) return Status::kInvalidArgument;
  v.sample_period_us = LoadU32(in, 0);
  v.channel_mask = LoadU8(in, 4);
  v.flags = LoadU8(in, 5);
  v.decimation = LoadU16(in, 6);
  const std::uint8_t mode = LoadU8(in, 8);
  v.trigger_mode = static_cast<TriggerMode>(mode);
  v.trigger_channel = LoadU8(in, 9);
  v.trigger_threshold = LoadI32(in, 12);
  v.pretrigger_records = LoadU32(in, 16);
  v.record_limit = LoadU32(in, 20);
  if (mode > static_cast<std::uint8_t>(TriggerMode::kFalling) || LoadU16(in, 10) != 0) {
    return Status::kInvalidArgument;
  }
  return Status::kOk;
}

void Encode(const AcqConfigureResponse& v, std::span<std::uint8_t> out) {
  StoreU16(out, 0, v.record_bytes);
  StoreU16(out, 2, 0);
  StoreU32(out, 4, v.capacity_records);
}

Status Decode(std::span<const std::uint8_t> in, AcqConfigureResponse& v) {
  if (in.size() != AcqConfigureResponse::kBytes || LoadU16(in, 2) != 0) {
    return Status::kInvalidArgument;
  }
  v.record_bytes = LoadU16(in, 0);
  v.capacity_records = LoadU32(in, 4);
  return Status::kOk;
}

void Encode(const AcqStopResponse& v, std::span<std::uint8_t> out) {
  StoreU32(out, 0, v.records_written);
}

Status Decode(std::span<const std::uint8_t> in, AcqStopResponse& v) {
  if (in.size() != AcqStopResponse::kBytes) return Status::kInvalidArgument;
  v.records_written = LoadU32(in, 0);
  return Status::kOk;
}

void Encode(const ClipResponse& v, std::span<std::uint8_t> out) {
  StoreU32(out, 0, v.ticks);
  for (std::size_t i = 0; i < kChannelCount; ++i) StoreU32(out, 4 + 4 * i, v.clipped[i]);
}

Status Decode(std::span<const std::uint8_t> in, ClipResponse& v) {
  if (in.size() != ClipResponse::kBytes) return Status::kInvalidArgument;
  v.ticks = LoadU32(in, 0);
  for (std::size_t i = 0; i < kChannelCount; ++i) v.clipped[i] = LoadU32(in, 4 + 4 * i);
  return Status::kOk;
}

void Encode(const LatestResponse& v, std::span<std::uint8_t> out) {
  StoreU32(out, 0, v.tick);
  for (std::size_t i = 0; i < kChannelCount; ++i) StoreI32(out, 4 + 4 * i, v.calibrated[i]);
  StoreI32(out, 28, v.d_hat);
  StoreU8(out, 32, static_cast<std::uint8_t>(v.acq_state));
  StoreU8(out, 33, v.dob_running);
}

Status Decode(std::span<const std::uint8_t> in, LatestResponse& v) {
  if (in.size() != LatestResponse::kBytes) return Status::kInvalidArgument;
  v.tick = LoadU32(in, 0);
  for (std::size_t i = 0; i < kChannelCount; ++i) v.calibrated[i] = LoadI32(in, 4 + 4 * i);
  v.d_hat = LoadI32(in, 28);
  const std::uint8_t acq = LoadU8(in, 32);
  v.acq_state = static_cast<AcqState>(acq);
  v.dob_running = LoadU8(in, 33);
  if (!KnownAcqState(acq) || v.dob_running > 1) return Status::kInvalidArgument;
  return Status::kOk;
}

void Encode(const LogReadRequest& v, std::span<std::uint8_t> out) {
  StoreU32(out, 0, v.first_record);
  StoreU32(out, 4, v.max_records);
}

Status Decode(std::span<const std::uint8_t> in, LogReadRequest& v) {
  if (in.size() != LogReadRequest::kBytes) return Status::kInvalidArgument;
  v.first_record = LoadU32(in, 0);
  v.max_records = LoadU32(in, 4);
  return Status::kOk;
}

void Encode(const StreamTrailer& v, std::span<std::uint8_t> out) {
  StoreU32(out, 0, v.total_bytes);
  StoreU32(out, 4, v.crc32);
}

Status Decode(std::span<const std::uint8_t> in, StreamTrailer& v) {
  if (in.size() < StreamTrailer::kBytes) return Status::kInvalidArgument;
  v.total_bytes = LoadU32(in, 0);
  v.crc32 = LoadU32(in, 4);
  return Status::kOk;
}

void Encode(const LogTrailer& v, std::span<std::uint8_t> out) {
  Encode(v.stream, out);
  StoreU32(out, 8, v.first_record);
  StoreU32(out, 12, v.record_count);
  StoreU16(out, 16, v.record_bytes);
  StoreU8(out, 18, v.channel_mask);
  StoreU8(out, 19, v.acq_flags);
  StoreU32(out, 20, v.sample_period_us);
  StoreU16(out, 24, v.decimation);
  StoreU8(out, 26, static_cast<std::uint8_t>(v.acq_state));
  StoreU8(out, 27, 0);
  StoreU32(out, 28, v.trigger_record);
  StoreU32(out, 32, v.dropped_records);
  StoreU32(out, 36, v.overrun_count);
  StoreU32(out, 40, v.records_written);
}

Status Decode(std::span<const std::uint8_t> in, LogTrailer& v) {
  if (in.size() != LogTrailer::kBytes) return Status::kInvalidArgument;
  (void)Decode(in, v.stream);
  v.first_record = LoadU32(in, 8);
  v.record_count = LoadU32(in, 12);
  v.record_bytes = LoadU16(in, 16);
  v.channel_mask = LoadU8(in, 18);
  v.acq_flags = LoadU8(in, 19);
  v.sample_period_us = LoadU32(in, 20);
  v.decimation = LoadU16(in, 24);
  const std::uint8_t acq = LoadU8(in, 26);
  v.acq_state = static_cast<AcqState>(acq);
  v.trigger_record = LoadU32(in, 28);
  v.dropped_records = LoadU32(in, 32);
  v.overrun_count = LoadU32(in, 36);
  v.records_written = LoadU32(in, 40);
  if (!KnownAcqState(acq) || LoadU8(in, 27) != 0) return Status::kInvalidArgument;
  return Status::kOk;
}

void Encode(const CalGetTrailer& v, std::span<std::uint8_t> out) {
  Encode(v.stream, out);
  StoreU8(out, 8, v.slot);
  StoreU8(out, 9, 0);
  StoreU16(out, 10, 0);
  StoreU32(out, 12, v.sequence);
}

Status Decode(std::span<const std::uint8_t> in, CalGetTrailer& v) {
  if (in.size() != CalGetTrailer::kBytes || LoadU8(in, 9) != 0 || LoadU16(in, 10) != 0) {
    return Status::kInvalidArgument;
  }
  (void)Decode(in, v.stream);
  v.slot = LoadU8(in, 8);
  v.sequence = LoadU32(in, 12);
  return Status::kOk;
}

void Encode(const CalPutBeginRequest& v, std::span<std::uint8_t> out) {
  StoreU32(out, 0, v.record_bytes);
  StoreU32(out, 4, v.crc32);
}

Status Decode(std::span<const std::uint8_t> in, CalPutBeginRequest& v) {
  if (in.size() != CalPutBeginRequest::kBytes) return Status::kInvalidArgument;
  v.record_bytes = LoadU32(in, 0);
  v.crc32 = LoadU32(in, 4);
  return Status::kOk;
}

void Encode(const CalCommitResponse& v, std::span<std::uint8_t> out) {
  StoreU8(out, 0, v.slot);
  StoreU8(out, 1, 0);
  StoreU16(out, 2, 0);
  StoreU32(out, 4, v.sequence);
}

Status Decode(std::span<const std::uint8_t> in, CalCommitResponse& v) {
  if (in.size() != CalCommitResponse::kBytes || LoadU8(in, 1) != 0 || LoadU16(in, 2) != 0) {
    return Status::kInvalidArgument;
  }
  v.slot = LoadU8(in, 0);
  v.sequence = LoadU32(in, 4);
  return Status::kOk;
}

void Encode(const DobControlRequest& v, std::span<std::uint8_t> out) { StoreU8(out, 0, v.run); }

Status Decode(std::span<const std::uint8_t> in, DobControlRequest& v) {
  if (in.size() != DobControlRequest::kBytes) return Status::kInvalidArgument;
  v.run = LoadU8(in, 0);
  return v.run <= 1 ? Status::kOk : Status::kInvalidArgument;
}

void Encode(const ScenarioRequest& v, std::span<std::uint8_t> out) {
  for (std::size_t i = 0; i < ScenarioRequest::kNameBytes; ++i) {
    StoreU8(out, i, static_cast<std::uint8_t>(v.name[i]));
  }
  for (std::size_t i = 0; i < v.params.size(); ++i) {
    StoreU32(out, 16 + 4 * i, std::bit_cast<std::uint32_t>(v.params[i]));
  }
}

Status Decode(std::span<const std::uint8_t> in, ScenarioRequest& v) {
  if (in.size() != ScenarioRequest::kBytes) return Status::kInvalidArgument;
  bool ended = false;
  for (std::size_t i = 0; i < ScenarioRequest::kNameBytes; ++i) {
    const std::uint8_t c = LoadU8(in, i);
    // NUL-padded printable ASCII: after the first NUL every byte is NUL.
    if (c == 0) {
      ended = true;
    } else if (ended || c < 0x20 || c > 0x7E) {
      return Status::kInvalidArgument;
    }
    v.name[i] = static_cast<char>(c);
  }
  for (std::size_t i = 0; i < v.params.size(); ++i) {
    v.params[i] = std::bit_cast<float>(LoadU32(in, 16 + 4 * i));
  }
  return v.name[0] != 0 ? Status::kOk : Status::kInvalidArgument;
}

std::size_t EncodedSize(const InjectFramesRequest& v) {
  return 4 + static_cast<std::size_t>(v.frame_count) * 4 * kChannelCount;
}

void Encode(const InjectFramesRequest& v, std::span<std::uint8_t> out) {
  StoreU8(out, 0, v.frame_count);
  StoreU8(out, 1, 0);
  StoreU16(out, 2, 0);
  for (std::size_t f = 0; f < v.frame_count && f < InjectFramesRequest::kMaxFrames; ++f) {
    for (std::size_t c = 0; c < kChannelCount; ++c) {
      StoreI32(out, 4 + 4 * (f * kChannelCount + c), v.raw[f][c]);
    }
  }
}

Status Decode(std::span<const std::uint8_t> in, InjectFramesRequest& v) {
  if (in.size() < 4) return Status::kInvalidArgument;
  v.frame_count = LoadU8(in, 0);
  if (v.frame_count == 0 || v.frame_count > InjectFramesRequest::kMaxFrames ||
      in.size() != EncodedSize(v) || LoadU8(in, 1) != 0 || LoadU16(in, 2) != 0) {
    return Status::kInvalidArgument;
  }
  for (std::size_t f = 0; f < v.frame_count; ++f) {
    for (std::size_t c = 0; c < kChannelCount; ++c) {
      v.raw[f][c] = LoadI32(in, 4 + 4 * (f * kChannelCount + c));
    }
  }
  return Status::kOk;
}

Status BuildReport(Command command, std::uint16_t token, std::uint16_t sequence, std::uint8_t flags,
                   Status status, std::span<const std::uint8_t> payload, Report& out) {
  Header header;
  header.command = static_cast<std::uint8_t>(command);
  header.status = status;
  header.flags = flags;
  header.token = token;
  header.sequence = sequence;
  return EncodeReport(header, payload, out);
}

const char* CommandName(std::uint8_t id) {
  switch (static_cast<Command>(id)) {
    case Command::kPing: return "ping";
    case Command::kGetInfo: return "get-info";
    case Command::kGetStatus: return "get-status";
    case Command::kReset: return "reset";
    case Command::kEnterDfu: return "enter-dfu";
    case Command::kSelfTest: return "self-test";
    case Command::kCalPutBegin: return "cal-put-begin";
    case Command::kCalPutData: return "cal-put-data";
    case Command::kCalCommit: return "cal-commit";
    case Command::kCalGet: return "cal-get";
    case Command::kAcqConfigure: return "acq-configure";
    case Command::kAcqStart: return "acq-start";
    case Command::kAcqStop: return "acq-stop";
    case Command::kReadLatest: return "read-latest";
    case Command::kLogRead: return "log-read";
    case Command::kGetClips: return "get-clips";
    case Command::kDobControl: return "dob-control";
    case Command::kSelectScenario: return "select-scenario";
    case Command::kInjectFrames: return "inject-frames";
  }
  return "unknown";
}

}  // namespace vibid::wire
