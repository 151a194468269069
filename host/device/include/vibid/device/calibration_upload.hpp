// What `cal upload` stages and `cal show` prints, for every front end (the CLI, the bench): the
// record's inputs read from the model, observer design and sensors files, the board's own sensor
// scaling kept when no sensors file is given, and the record as JSON.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "vibid/common/verdict.hpp"
#include "vibid/device/calibration_builder.hpp"

namespace vibid::device {

struct UploadFiles {
  std::string model;    ///< Model file (M, C, K).
  std::string design;   ///< Observer design from `vibid dob design`.
  std::string sensors;  ///< Sensors file; empty: the scaling the board already holds.
  std::string label;    ///< Rig name; empty: the model file's name without folder and .json.
  /// Take a model whose verdict is flagged (refused otherwise, naming `accept_option`).
  bool accept_flagged = false;
  /// How the front end spells the accept: "--accept-flagged", "accept_flagged=True".
  std::string accept_option = "--accept-flagged";
};

/// The rig name the record gets (cut to the record's label field).
std::string RecordLabel(const UploadFiles& files);

/// Reads the files (InputError naming the file on any problem); created now, built by
/// `host_version` ("MAJOR.MINOR.PATCH"). A model file whose verdict is flagged is refused
/// (FlaggedError naming its reasons and `accept_option`) unless `accept_flagged`; `verdict`, when
/// given, receives the model file's verdict (none stated for a file without one).
RecordInputs ReadRecordInputs(const UploadFiles& files, const std::string& host_version,
                              Verdict* verdict = nullptr);

/// Without a sensors file the record keeps the board's scaling: every calibrated channel of the
/// active record (`active` null: the board is uncalibrated, an InputError asking for --sensors).
void KeepBoardSensors(RecordInputs& inputs, const wire::CalibrationRecord* active);

/// The SI full scale the board's active record gives `channel` (a load cell's, in N), or none
/// when the board is uncalibrated (`active` null) or leaves the channel in counts: what an
/// observer designed for this board takes as its force full scale unless told otherwise.
std::optional<double> CalibratedFullScale(const wire::CalibrationRecord* active,
                                          wire::Channel channel);

/// An observer's full scales from where they are true, the sensors the board will scale with (a
/// sensors file): the load cell on mass `input_dof` (from 1) gives `force_fs_n`, the `sensor`
/// kind's (disp, vel, acc) on `output_dof` gives `sensor_fs`: each the first sensor of its kind
/// on its mass, the channel `cal upload` routes the input to (a channel has one range, and `cal
/// upload` refuses an observer designed for another). A value the caller gave (`force_given`,
/// `sensor_given`) is kept when it is the sensors' and refused (InputError naming both and the
/// way out) when it is not; a sensor the file does not have leaves the value as it is. Returns
/// what was taken ("force full scale 500 N from force1"), "" when nothing was.
std::string TakeSensorFullScales(const SensorSet& sensors, int input_dof, int output_dof,
                                 const std::string& sensor, double& force_fs_n, bool force_given,
                                 double& sensor_fs, bool sensor_given);

/// The recording column that measures each of the first `masses` masses, as the board's record
/// places its sensors (each channel's mass) and acquire names its calibrated columns: the
/// accelerometer on the mass (acc1_m_s2), else its encoder (x1_m). InputError naming the first
/// mass no calibrated response channel sits on, and the way out.
std::vector<std::string> ResponseColumnsOnMasses(const wire::CalibrationRecord& record,
                                                 std::size_t masses);

/// The mass (0-based) load cell 1, the hammer's, sits on as the record places it; none when on
/// no mass.
std::optional<std::size_t> HammerMass(const wire::CalibrationRecord& record);

/// Where that is, for a message: "the board's calibration record (load cell 1 on mass 3)".
std::string HammerMassSource(std::size_t mass);

/// The driving point of a hammer test on this board: of `columns` (ResponseColumnsOnMasses, in
/// mass order), the one on the mass load cell 1 (the hammer's) sits on; "" when the record puts
/// the load cell on no mass of them.
std::string DrivingPointColumn(const wire::CalibrationRecord& record,
                               const std::vector<std::string>& columns);

/// Where an observer for this board acts and what feeds it: the mass load cell 1 sits on (the
/// hammer's, the shaker's and the push's), fed by that mass's encoder (displacement sensing holds
/// down to DC), else its accelerometer, at that channel's full scale.
struct ObserverPlacement {
  int dof = 0;         ///< From 1.
  std::string sensor;  ///< disp or acc, as `vibid dob design --sensor` takes it.
  double sensor_fs = 0.0;
};
/// None when the record puts load cell 1 on no mass or no calibrated response channel on it.
std::optional<ObserverPlacement> ObserverPlacementOf(const wire::CalibrationRecord& record);
/// The same from a sensors file, before it is uploaded: where `cal upload` with these sensors
/// will accept the observer (on a chain of any length, not only mass 2).
std::optional<ObserverPlacement> ObserverPlacementOf(const SensorSet& sensors);

/// `dob design --sensors`' placement, for every front end: the observer's masses and sensor kind
/// from the sensors (ObserverPlacementOf), each unless the caller gave it (`*_given`: kept, for
/// `cal upload` to judge). Returns "observer on mass N (force1's)" when a mass was taken, ""
/// otherwise (nothing to take, or both given).
std::string PlaceObserver(const SensorSet& sensors, int& input_dof, bool input_given,
                          int& output_dof, bool output_given, std::string& sensor,
                          bool sensor_given);

/// The record as `cal show --json` prints it, without the slot, sequence and CRC the board adds:
/// label, created_unix_s, host_version, M, C, K (dof x dof), channels (calibrated ones: unit,
/// counts_per_unit, offset_counts, full_scale, gain, gain_shift, dof), observer (or null).
nlohmann::json RecordJson(const wire::CalibrationRecord& record);

}  // namespace vibid::device
