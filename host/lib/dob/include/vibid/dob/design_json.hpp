// The design file written by `vibid dob design` and read by `vibid dob run` (format in README,
// section dob). It carries the double-precision observer (for --float replays and inspection) and
// the fixed-point description byte for byte (what the board runs, for --fixed replays).
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "vibid/dob/design.hpp"
#include "vibid/shared/fixed/filter_description.hpp"

namespace vibid::dob {

/// The design as JSON. Requires design.stable (an unstable design is not written).
nlohmann::json DesignToJson(const DobDesign& design);

/// What a replay needs from a design file.
struct ObserverFile {
  double fs_hz = 0.0;
  std::vector<ObserverPath> paths;       ///< Sensor inputs first, the force last.
  fixed::FilterDescription description;  ///< Validated.
};

/// Parses a design file's JSON; InputError naming `source` and the field on any problem, including
/// a fixed-point description that fails ValidateDescription (with the status name).
ObserverFile ObserverFromJson(const nlohmann::json& json, const std::string& source);

const char* InputKindName(fixed::InputKind kind);

}  // namespace vibid::dob
