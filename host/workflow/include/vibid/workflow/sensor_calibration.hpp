// The sensors' calibration in the intervals of masses, springs and dampers (methods §16). A
// hammer test measures H = response / force, so every mass and spring of the chain scales with
// the load cell's sensitivity over the response sensor's: a load cell 1.6 % off moves every m and
// k by 1.6 %, and no internal check can see it (the chain stays consistent). The sensors file
// states each sensitivity's uncertainty as its certificate does (U relative, coverage factor k);
// the position of mass i then carries the relative variances of the load cell and of the sensor
// on mass i, added (a product of sensitivities), in m_i, k_i and c_i alike.
#pragma once

#include <string>
#include <vector>

#include "vibid/device/calibration_builder.hpp"
#include "vibid/ident/identify.hpp"

namespace vibid::workflow {

/// One position's calibration part: the relative standard uncertainty and the sensors it is of.
struct PositionCalibration {
  double relative_u = 0.0;
  std::string sensors;  ///< "force1 and acc1"
};

/// The calibration part of each position: `force_column` and `response_columns` (one per mass,
/// in mass order) as a recording names them (force1_n, acc1_m_s2, x1_m; the board's channel is
/// the name's stem). A sensor the file states no uncertainty for adds nothing, and a line in
/// `warnings` says so.
std::vector<PositionCalibration> CalibrationOfPositions(
    const device::SensorSet& sensors, const std::string& force_column,
    const std::vector<std::string>& response_columns, std::vector<std::string>& warnings);

/// Adds each position's calibration part to its m, k and c intervals (ident::AddCalibration),
/// in the table's positions and in the fit beside them.
void AddSensorCalibration(ident::ValidationTable& table,
                          const std::vector<PositionCalibration>& positions);

}  // namespace vibid::workflow
