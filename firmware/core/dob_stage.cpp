#include "vibid/fw/dob_stage.hpp"

namespace vibid::fw {

Status DobStage::Load(const wire::CalibrationRecord& record) {
  filter_ = fixed::DobFilter{};
  if ((record.flags & wire::kCalFlagHasDob) == 0) return Status::kOk;
  fixed::FilterDescription description;
  (void)fixed::DecodeDescription(record.dob, description);
  const Status s = filter_.Init(description);
  if (s != Status::kOk) return s;
  channels_ = record.dob_input_channel;
  return Status::kOk;
}

std::int32_t DobStage::Step(const std::array<std::int32_t, wire::kChannelCount>& calibrated) {
  if (!loaded()) return 0;
  fixed::InputFrame inputs{};
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    // Validated routing: a used input names a channel, an unused one kNoChannel (input ignored).
    if (channels_[i] < wire::kChannelCount) inputs[i] = calibrated[channels_[i]];
  }
  return filter_.Step(inputs);
}

}  // namespace vibid::fw
