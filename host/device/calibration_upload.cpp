#include "vibid/device/calibration_upload.hpp"

#include <chrono>
#include <cstdio>
#include <cstring>
#include <optional>
#include <sstream>

#include "vibid/common/error.hpp"
#include "vibid/common/json_file.hpp"
#include "vibid/device/log_table.hpp"
#include "vibid/dob/design_json.hpp"
#include "vibid/model/model_json.hpp"

namespace vibid::device {
namespace {

nlohmann::json Matrix(const std::array<float, wire::kMaxDof * wire::kMaxDof>& m, std::size_t n) {
  nlohmann::json rows = nlohmann::json::array();
  for (std::size_t i = 0; i < n; ++i) {
    nlohmann::json row = nlohmann::json::array();
    for (std::size_t k = 0; k < n; ++k)
      row.push_back(static_cast<double>(m[i * wire::kMaxDof + k]));
    rows.push_back(row);
  }
  return rows;
}

std::string Hex32(std::uint32_t v) {
  char b[11];
  std::snprintf(b, sizeof b, "0x%08x", v);
  return b;
}

}  // namespace

std::vector<std::string> ResponseColumnsOnMasses(const wire::CalibrationRecord& record,
                                                 std::size_t masses) {
  std::vector<std::string> columns;
  for (std::size_t m = 0; m < masses; ++m) {
    std::string column;
    // Accelerometers first: a mass with both is measured as the default columns measure it.
    for (const wire::Unit unit : {wire::Unit::kMeterPerSecond2, wire::Unit::kMeter}) {
      for (std::size_t c = 0; c < wire::kChannelCount && column.empty(); ++c) {
        const wire::ChannelScaling& s = record.channels[c];
        if (s.unit == unit && s.dof == m)
          column = std::string(ChannelStem(static_cast<wire::Channel>(c))) + "_" + UnitSuffix(unit);
      }
    }
    Require(!column.empty(),
            "mass " + std::to_string(m + 1) + " of " + std::to_string(masses) +
                " has no calibrated accelerometer or encoder on the board; calibrate the board "
                "with a sensors file that puts one of acc1, acc2, x1, x2 on it (\"dof\": " +
                std::to_string(m + 1) + ", vibid cal upload --sensors)");
    columns.push_back(column);
  }
  return columns;
}

std::optional<std::size_t> HammerMass(const wire::CalibrationRecord& record) {
  const std::uint8_t mass = record.channels[static_cast<std::size_t>(wire::Channel::kForce1)].dof;
  if (mass == wire::kNoDof) return std::nullopt;
  return static_cast<std::size_t>(mass);
}

std::string HammerMassSource(std::size_t mass) {
  return "the board's calibration record (load cell 1 on mass " + std::to_string(mass + 1) + ")";
}

std::string DrivingPointColumn(const wire::CalibrationRecord& record,
                               const std::vector<std::string>& columns) {
  const std::uint8_t mass = record.channels[static_cast<std::size_t>(wire::Channel::kForce1)].dof;
  return mass < columns.size() ? columns[mass] : std::string();
}

std::optional<ObserverPlacement> ObserverPlacementOf(const wire::CalibrationRecord& record) {
  const std::uint8_t mass = record.channels[static_cast<std::size_t>(wire::Channel::kForce1)].dof;
  if (mass == wire::kNoDof) return std::nullopt;
  for (const wire::Unit unit : {wire::Unit::kMeter, wire::Unit::kMeterPerSecond2}) {
    for (const wire::ChannelScaling& s : record.channels) {
      if (s.unit == unit && s.dof == mass) {
        return ObserverPlacement{.dof = mass + 1,
                                 .sensor = unit == wire::Unit::kMeter ? "disp" : "acc",
                                 .sensor_fs = static_cast<double>(s.full_scale)};
      }
    }
  }
  return std::nullopt;
}

std::optional<ObserverPlacement> ObserverPlacementOf(const SensorSet& sensors) {
  const std::optional<SensorScaling>& load_cell =
      sensors[static_cast<std::size_t>(wire::Channel::kForce1)];
  if (!load_cell || load_cell->dof < 0) return std::nullopt;
  for (const wire::Unit unit : {wire::Unit::kMeter, wire::Unit::kMeterPerSecond2}) {
    for (const std::optional<SensorScaling>& s : sensors) {
      if (s && s->unit == unit && s->dof == load_cell->dof) {
        return ObserverPlacement{.dof = load_cell->dof + 1,
                                 .sensor = unit == wire::Unit::kMeter ? "disp" : "acc",
                                 .sensor_fs = s->full_scale};
      }
    }
  }
  return std::nullopt;
}

std::string PlaceObserver(const SensorSet& sensors, int& input_dof, bool input_given,
                          int& output_dof, bool output_given, std::string& sensor,
                          bool sensor_given) {
  const std::optional<ObserverPlacement> p = ObserverPlacementOf(sensors);
  if (!p) return {};
  if (!input_given) input_dof = p->dof;
  if (!output_given) output_dof = p->dof;
  if (!sensor_given) sensor = p->sensor;
  if (input_given && output_given) return {};
  return "observer on mass " + std::to_string(input_given ? output_dof : input_dof) + " (force1's)";
}

std::string RecordLabel(const UploadFiles& files) {
  std::string label = files.label;
  if (label.empty()) {
    label = files.model.substr(files.model.find_last_of('/') + 1);
    if (label.size() > 5 && label.ends_with(".json")) label.resize(label.size() - 5);
    if (label.size() >= wire::kCalLabelBytes) label.resize(wire::kCalLabelBytes - 1);
  }
  return label;
}

RecordInputs ReadRecordInputs(const UploadFiles& files, const std::string& host_version,
                              Verdict* verdict) {
  RecordInputs in;
  model::ModelFile model = model::LoadModelFile(files.model);
  RequireUsable(model.verdict, files.accept_flagged, "model file " + files.model, "cal upload",
                files.accept_option);
  if (verdict != nullptr) *verdict = model.verdict;
  in.model = std::move(model.model);
  in.observer = dob::ObserverFromJson(ReadJsonFile(files.design), files.design).description;
  in.label = RecordLabel(files);
  in.created_unix_s = std::chrono::duration_cast<std::chrono::seconds>(
                          std::chrono::system_clock::now().time_since_epoch())
                          .count();
  unsigned major = 0, minor = 0, patch = 0;
  static_cast<void>(std::sscanf(host_version.c_str(), "%u.%u.%u", &major, &minor, &patch));
  in.host_major = static_cast<std::uint8_t>(major);
  in.host_minor = static_cast<std::uint8_t>(minor);
  in.host_patch = static_cast<std::uint16_t>(patch);
  if (!files.sensors.empty())
    in.sensors = SensorsFromJson(ReadJsonFile(files.sensors), files.sensors);
  return in;
}

void KeepBoardSensors(RecordInputs& inputs, const wire::CalibrationRecord* active) {
  if (active == nullptr)
    throw InputError("the board is uncalibrated: give its sensors with --sensors SENSORS.json");
  for (std::size_t k = 0; k < wire::kChannelCount; ++k) {
    if (active->channels[k].unit != wire::Unit::kCounts)
      inputs.sensors[k] = FromChannelScaling(active->channels[k]);
  }
}

std::optional<double> CalibratedFullScale(const wire::CalibrationRecord* active,
                                          wire::Channel channel) {
  if (active == nullptr) return std::nullopt;
  const wire::ChannelScaling& s = active->channels[static_cast<std::size_t>(channel)];
  if (s.unit == wire::Unit::kCounts) return std::nullopt;
  return FromChannelScaling(s).full_scale;
}

std::string TakeSensorFullScales(const SensorSet& sensors, int input_dof, int output_dof,
                                 const std::string& sensor, double& force_fs_n, bool force_given,
                                 double& sensor_fs, bool sensor_given) {
  const auto text = [](double v) {
    std::ostringstream o;
    o << v;
    return o.str();
  };
  const auto take = [&](wire::Unit unit, int dof, double& value, bool given, const char* option,
                        const char* what) -> std::string {
    for (std::size_t c = 0; c < wire::kChannelCount; ++c) {
      const std::optional<SensorScaling>& s = sensors[c];
      if (!s || s->unit != unit || s->dof != dof - 1) continue;
      const std::string name = ChannelStem(static_cast<wire::Channel>(c));
      const std::string fs = text(s->full_scale) + " " + UnitName(unit);
      // Compared as the board stores them (binary32), as `cal upload` compares them.
      if (given && static_cast<float>(value) != static_cast<float>(s->full_scale)) {
        throw InputError(std::string(option) + " " + text(value) + ": the sensors give " + name +
                         " (mass " + std::to_string(dof) + ") a full scale of " + fs +
                         ", and a channel has one range; leave " + option +
                         " out to take the sensors', or correct the sensors file");
      }
      value = s->full_scale;
      return std::string(what) + " full scale " + fs + " from " + name;
    }
    return {};
  };
  Require(sensor == "disp" || sensor == "vel" || sensor == "acc",
          "--sensor '" + sensor + "' is not one of disp, vel, acc");
  const wire::Unit sensor_unit = sensor == "disp"  ? wire::Unit::kMeter
                                 : sensor == "vel" ? wire::Unit::kMeterPerSecond
                                                   : wire::Unit::kMeterPerSecond2;
  std::string said =
      take(wire::Unit::kNewton, input_dof, force_fs_n, force_given, "--force-fs-n", "force");
  const std::string s =
      take(sensor_unit, output_dof, sensor_fs, sensor_given, "--sensor-fs", "sensor");
  if (!s.empty()) said += (said.empty() ? "" : ", ") + s;
  return said;
}

nlohmann::json RecordJson(const wire::CalibrationRecord& r) {
  const std::size_t n = r.dof_count;
  nlohmann::json channels = nlohmann::json::object();
  for (std::size_t c = 0; c < wire::kChannelCount; ++c) {
    const wire::ChannelScaling& s = r.channels[c];
    if (s.unit == wire::Unit::kCounts) continue;
    const SensorScaling p = FromChannelScaling(s);
    nlohmann::json ch = {{"unit", UnitName(s.unit)},
                         {"counts_per_unit", p.counts_per_unit},
                         {"offset_counts", s.offset_counts},
                         {"full_scale", static_cast<double>(s.full_scale)},
                         {"gain", s.gain},
                         {"gain_shift", s.gain_shift}};
    if (s.dof != wire::kNoDof) ch["dof"] = s.dof + 1;
    channels[ChannelStem(static_cast<wire::Channel>(c))] = ch;
  }
  nlohmann::json j = {
      {"label", std::string(r.label.data(), strnlen(r.label.data(), r.label.size()))},
      {"created_unix_s", r.created_unix_s},
      {"host_version", std::to_string(r.host_major) + "." + std::to_string(r.host_minor) + "." +
                           std::to_string(r.host_patch)},
      {"M", Matrix(r.mass_kg, n)},
      {"C", Matrix(r.damping_ns_per_m, n)},
      {"K", Matrix(r.stiffness_n_per_m, n)},
      {"channels", channels}};
  if ((r.flags & wire::kCalFlagHasDob) != 0) {
    fixed::FilterDescription d;
    static_cast<void>(fixed::DecodeDescription(r.dob, d));
    nlohmann::json inputs = nlohmann::json::array();
    for (std::size_t i = 0; i < d.input_count; ++i) {
      inputs.push_back(
          {{"channel", ChannelStem(static_cast<wire::Channel>(r.dob_input_channel[i]))},
           {"sections", d.paths[i].section_count}});
    }
    j["observer"] = {{"sample_rate_hz", d.sample_rate_hz},
                     {"output_dof", d.output_dof + 1},
                     {"output_full_scale_n",
                      static_cast<double>(fixed::FullScaleValue(d.output_full_scale_bits))},
                     {"inputs", inputs},
                     // The coefficients' CRC: a changed observer shows as a change even when its
                     // rate, mass and sensors stay.
                     {"checksum", Hex32(d.checksum)}};
  } else {
    j["observer"] = nullptr;
  }
  if ((r.flags & wire::kCalFlagHasWatch) != 0) {
    // The kernel's parameters as the board runs them (residual_cusum.hpp), so that a host-side
    // replay of the board's test on a logged d_hat is the board's own arithmetic.
    const fixed::ResidualCusumParams& w = r.watch;
    j["model_test"] = {
        {"window_samples", w.window_samples},
        {"residual_gain", w.residual_gain},
        {"reference_gain", w.reference_gain},
        {"reference_channel",
         r.watch_reference_channel == wire::kNoChannel
             ? nlohmann::json(nullptr)
             : nlohmann::json(ChannelStem(static_cast<wire::Channel>(r.watch_reference_channel)))},
        {"sum_shift", w.sum_shift},
        {"z_shift", w.z_shift},
        {"center", w.center},
        {"z_gain", w.z_gain},
        {"k_q16", w.k},
        {"h_q16", w.h},
        {"holdoff_windows", w.holdoff_windows},
        {"in_control_arl_windows", static_cast<double>(r.watch_in_control_arl_windows)}};
  } else {
    j["model_test"] = nullptr;
  }
  return j;
}

}  // namespace vibid::device
