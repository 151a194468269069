// Builds the calibration record the board keeps (shared/wire/calibration_record.hpp) from what the
// host knows: the (updated) model, the sensors' scaling, and the quantized observer.
//
// Sensors file (JSON, format in README section device):
//   {"format": "vibid-sensors", "version": 1,
//    "channels": {"force1": {"unit": "N", "counts_per_unit": 40.96, "offset_counts": 2048,
//                            "full_scale": 50, "dof": 2}, ...}}
// counts_per_unit: raw counts per SI unit (N, m/s^2, m, m/s); dof: 1-based mass the sensor is on
// (omitted: none); full_scale: the SI value that calibrated Q31 full scale stands for.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "vibid/model/model.hpp"
#include "vibid/shared/fixed/filter_description.hpp"
#include "vibid/shared/wire/calibration_record.hpp"

namespace vibid::device {

/// One channel's physical scaling: SI value = (raw - offset_counts) / counts_per_unit.
struct SensorScaling {
  wire::Unit unit = wire::Unit::kCounts;
  double counts_per_unit = 1.0;
  std::int32_t offset_counts = 0;
  double full_scale = 1.0;
  int dof = -1;  ///< 0-based; -1 for none.
  /// The sensitivity's expanded relative uncertainty as its calibration certificate states it
  /// (0.02: 2 %), and the certificate's coverage factor k (2 for about 95 %): the relative
  /// standard uncertainty is their quotient. 0: not stated (the board never uses either).
  double sensitivity_uncertainty = 0.0;
  double coverage_factor = 2.0;

  /// The relative standard uncertainty of the sensitivity (0 when not stated).
  double RelativeStandardUncertainty() const { return sensitivity_uncertainty / coverage_factor; }
};

using SensorSet = std::array<std::optional<SensorScaling>, wire::kChannelCount>;

/// A unit as a sensors file spells it ("N", "m/s2", "m", "m/s"); "counts" for raw counts.
const char* UnitName(wire::Unit unit);

/// Parses a sensors file; InputError naming `source` and the field on any problem.
SensorSet SensorsFromJson(const nlohmann::json& json, const std::string& source);

/// The physical scaling an existing record's channel stands for (the inverse of ToChannelScaling).
SensorScaling FromChannelScaling(const wire::ChannelScaling& s);

/// Integer gain and shift for a scaling: calibrated = round((raw - offset) gain / 2^shift) is
/// (raw - offset) / counts_per_unit / full_scale in Q31, with the largest shift whose gain fits
/// int32 (the finest representable gain). InputError if even shift 0 overflows.
wire::ChannelScaling ToChannelScaling(const SensorScaling& s, const std::string& channel_name);

/// The sensors an existing record holds (its channels not in raw counts): what an upload without a
/// sensors file keeps.
SensorSet SensorsOfRecord(const wire::CalibrationRecord& record);

/// The rig's name from a model file's path: its name without folder and .json, cut to fit.
std::string LabelFromModelPath(const std::string& path);

struct RecordInputs {
  model::Model model;
  std::string label;  ///< The rig's name (<= 23 printable ASCII characters).
  SensorSet sensors;  ///< Channels without a scaling stay in raw counts.
  std::optional<fixed::FilterDescription> observer;
  std::int64_t created_unix_s = 0;
  std::uint8_t host_major = 0, host_minor = 0;
  std::uint16_t host_patch = 0;
};

/// The record. Each observer input is routed to the first channel of its kind on its mass; that
/// channel's full scale (the sensors') must be the one the observer was designed for, so the
/// board's Q31 values mean the same to both: a channel has one range, never overwritten.
/// InputError when the model has more than wire::kMaxDof (four) masses, an observer input has no
/// matching sensor, an input's full scale differs from its channel's (naming both and the ways
/// out), or the finished record does not pass the board's own decoder (its status named).
wire::CalibrationRecord BuildCalibrationRecord(const RecordInputs& inputs);

}  // namespace vibid::device
