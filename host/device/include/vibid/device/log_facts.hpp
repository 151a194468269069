// The facts a recording of the board states in its sidecar (ident/recording_facts.hpp): what the
// board, its calibration record and the acquisition say about each logged channel. A channel's
// rails are the values its column holds when the converter sits on its lowest or highest code
// (or the calibration saturates first), computed with the board's own integer scaling, so a
// reader can tell a clipped sample from a large one exactly.
#pragma once

#include <optional>
#include <string>
#include <utility>

#include "vibid/device/connection.hpp"
#include "vibid/ident/recording_facts.hpp"
#include "vibid/shared/wire/calibration_record.hpp"
#include "vibid/shared/wire/commands.hpp"

namespace vibid::device {

/// The lowest and highest value a channel's column can hold (its unit: SI when calibrated,
/// counts when not): the scaling of the converter's codes 0 and 2^adc_bits - 1 for an analog
/// input, of the 32-bit counter's ends for an encoder, each saturated as the board saturates.
std::pair<double, double> ChannelRails(wire::Channel channel, const wire::ChannelScaling& scaling,
                                       unsigned adc_bits);

/// What the board knows of an acquisition, beside its records.
struct BoardContext {
  std::optional<wire::InfoResponse> info;  ///< get-info; empty: board facts not stated.
  std::string serial;                      ///< The link's serial number, empty if unknown.
  std::optional<wire::SamplingInfoResponse> instants;
  std::optional<wire::ClipResponse> clips;
};

/// What `c` states of itself: get-info, the serial number, and (for a board of protocol 2.1) its
/// sampling instants and clip counts; a page the board refuses is left empty.
BoardContext ContextOf(Connection& c);

/// The facts of a recording with `format`'s layout and trailer (its records are not read; the
/// record count is `records`) taken with `calibration` active (`has_record` false: columns in
/// counts). `acquisition` holds what the caller asked for (seconds, trigger, scenario...);
/// rate, decimation, record and drop counts are filled from the trailer. Without it (a writer that
/// did not run the acquisition) the sidecar states no acquisition. An empty `start_timestamp`
/// states no start.
ident::RecordingFacts LogFacts(const LogPull& format, std::uint64_t records,
                               const wire::CalibrationRecord& calibration, bool has_record,
                               const BoardContext& board,
                               std::optional<ident::AcquisitionFacts> acquisition,
                               const std::string& start_timestamp);

/// The emulator's seed from its serial number (EMU + 16 hex digits); empty for any other.
std::optional<std::uint64_t> EmulatorSeedOfSerial(const std::string& serial);

}  // namespace vibid::device
