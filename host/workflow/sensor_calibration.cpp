#include "vibid/workflow/sensor_calibration.hpp"

#include <cmath>

#include "vibid/common/csv.hpp"
#include "vibid/device/log_table.hpp"
#include "vibid/ident/intervals.hpp"

namespace vibid::workflow {
namespace {

// The board channel a column is of (force1_n -> force1), if it is one of the board's.
std::optional<wire::Channel> ChannelOfColumn(const std::string& column) {
  const std::string name = ParseColumnSpec(column).name;
  wire::Channel channel{};
  if (device::ChannelFromStem(name.substr(0, name.find('_')), channel)) return channel;
  return std::nullopt;
}

}  // namespace

std::vector<PositionCalibration> CalibrationOfPositions(
    const device::SensorSet& sensors, const std::string& force_column,
    const std::vector<std::string>& response_columns, std::vector<std::string>& warnings) {
  // The relative standard uncertainty of a column's sensor, and its name; 0 when not stated.
  const auto of = [&](const std::string& column, std::string& name) {
    const std::optional<wire::Channel> channel = ChannelOfColumn(column);
    name = channel ? device::ChannelStem(*channel) : ParseColumnSpec(column).name;
    const auto& s = channel ? sensors[static_cast<std::size_t>(*channel)] : std::nullopt;
    if (!s || s->sensitivity_uncertainty == 0.0) {
      warnings.push_back("the sensors file states no sensitivity uncertainty for " + name +
                         " (column " + ParseColumnSpec(column).name +
                         "): its calibration is not in the intervals (give its certificate's "
                         "sensitivity_uncertainty and coverage_factor)");
      return 0.0;
    }
    return s->RelativeStandardUncertainty();
  };
  std::string force_name;
  const double u_force = of(force_column, force_name);
  std::vector<PositionCalibration> out;
  for (const std::string& column : response_columns) {
    std::string response_name;
    const double u_response = of(column, response_name);
    // Relative variances add for a product (or quotient) of sensitivities.
    out.push_back({std::hypot(u_force, u_response), force_name + " and " + response_name});
  }
  return out;
}

void AddSensorCalibration(ident::ValidationTable& table,
                          const std::vector<PositionCalibration>& positions) {
  const auto add = [&](std::vector<ident::PositionComparison>& rows) {
    for (std::size_t i = 0; i < rows.size() && i < positions.size(); ++i) {
      ident::PositionComparison& p = rows[i];
      const PositionCalibration& c = positions[i];
      ident::AddCalibration(p.m_ci95, p.m_updated, c.relative_u, c.sensors);
      ident::AddCalibration(p.k_ci95, p.k_updated, c.relative_u, c.sensors);
      ident::AddCalibration(p.c_ci95, p.c_updated, c.relative_u, c.sensors);
    }
  };
  add(table.positions);
  add(table.beside);
}

}  // namespace vibid::workflow
