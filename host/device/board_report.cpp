#include "vibid/device/board_report.hpp"

#include <sstream>

#include "vibid/device/calibration_builder.hpp"
#include "vibid/device/log_table.hpp"

namespace vibid::device {

std::string DescribeClips(const wire::ClipResponse& clips, const wire::CalibrationRecord* record) {
  std::ostringstream counts;
  std::ostringstream scales;
  int clipped_channels = 0;
  for (std::size_t c = 0; c < wire::kChannelCount; ++c) {
    if (clips.clipped[c] == 0) continue;
    const char* name = ChannelStem(static_cast<wire::Channel>(c));
    counts << (clipped_channels == 0 ? "" : ", ") << name << " " << clips.clipped[c];
    if (record != nullptr && record->channels[c].unit != wire::Unit::kCounts) {
      scales << (scales.tellp() == 0 ? "" : ", ") << name << " " << record->channels[c].full_scale
             << " " << UnitName(record->channels[c].unit);
    }
    ++clipped_channels;
  }
  if (clipped_channels == 0) return "";
  std::ostringstream o;
  o << "clipped samples: " << counts.str() << " of " << clips.ticks
    << " (at an end of the converter's range or beyond the calibrated full scale";
  if (scales.tellp() != 0) o << ": " << scales.str();
  o << "); the values there are not the signal: use a sensor range that covers it";
  return o.str();
}

bool IsSampling(wire::AcqState state) {
  return state == wire::AcqState::kArmed || state == wire::AcqState::kAcquiring;
}

std::string DescribeAcquisitionState(const wire::StatusResponse& status) {
  std::string s;
  switch (status.acq_state) {
    case wire::AcqState::kArmed: s = "armed: waiting for the trigger"; break;
    case wire::AcqState::kAcquiring: s = "sampling"; break;
    case wire::AcqState::kDone:
    case wire::AcqState::kIdle:
      // ticks counts the frames of the last acquisition: none since power-up leaves it 0.
      if (status.ticks == 0 && status.records_written == 0) {
        s = "idle: no acquisition since power-up";
      } else {
        s = std::string("stopped: the last acquisition ") +
            (status.acq_state == wire::AcqState::kDone ? "ended" : "was stopped") + " (" +
            std::to_string(status.records_written) + " records)";
      }
      break;
  }
  if (status.dob_running != 0) s += ", observer on";
  return s;
}

LatestKind ClassifyLatest(const wire::LatestResponse& latest, const wire::StatusResponse& status) {
  const bool sampling = IsSampling(latest.acq_state);
  // ticks counts the frames of the current or last acquisition; with none (since boot, or an
  // acquisition still waiting for its first frame) read-latest's values are not a measurement.
  if (status.ticks == 0) return LatestKind::kNoFrame;
  return sampling ? LatestKind::kLive : LatestKind::kStopped;
}

}  // namespace vibid::device
