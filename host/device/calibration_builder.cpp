#include "vibid/device/calibration_builder.hpp"

#include <cmath>
#include <cstdint>
#include <sstream>

#include "vibid/common/enum_names.hpp"
#include "vibid/common/error.hpp"
#include "vibid/common/json_keys.hpp"
#include "vibid/common/text_input.hpp"
#include "vibid/device/log_table.hpp"

namespace vibid::device {
namespace {

constexpr double kQ31 = 2147483648.0;

// The physical units a sensors file may name; a channel without one stays in raw counts.
constexpr EnumNames<wire::Unit, 4> kUnitNames{{{wire::Unit::kNewton, "N"},
                                               {wire::Unit::kMeterPerSecond2, "m/s2"},
                                               {wire::Unit::kMeter, "m"},
                                               {wire::Unit::kMeterPerSecond, "m/s"}}};

wire::Unit UnitFromName(const std::string& name, const std::string& where) {
  if (name == "m/s^2") return wire::Unit::kMeterPerSecond2;
  if (const std::optional<wire::Unit> unit = FindByName(kUnitNames, name)) return *unit;
  throw InputError(where + ": unit '" + Printable(name) + "' is not one of N, m/s2, m, m/s");
}

wire::Unit UnitOfInput(fixed::InputKind kind) {
  switch (kind) {
    case fixed::InputKind::kForce: return wire::Unit::kNewton;
    case fixed::InputKind::kDisplacement: return wire::Unit::kMeter;
    case fixed::InputKind::kVelocity: return wire::Unit::kMeterPerSecond;
    case fixed::InputKind::kAcceleration: return wire::Unit::kMeterPerSecond2;
    case fixed::InputKind::kUnused: break;
  }
  return wire::Unit::kCounts;
}

// The `vibid dob design` option that sets an input's full scale.
const char* DesignOptionFor(fixed::InputKind kind) {
  return kind == fixed::InputKind::kForce ? "--force-fs-n" : "--sensor-fs";
}

std::string Number(double v) {
  std::ostringstream o;
  o << v;
  return o.str();
}

}  // namespace

const char* UnitName(wire::Unit unit) { return NameOf(kUnitNames, unit, "counts"); }

SensorSet SensorsFromJson(const nlohmann::json& j, const std::string& source) {
  const auto fail = [&](const std::string& what) { throw InputError(source + ": " + what); };
  // Compared as JSON values: a field of another type is a wrong value, not a type error.
  if (!j.is_object() || j.value("format", nlohmann::json()) != "vibid-sensors")
    fail("not a vibid sensors file");
  if (j.value("version", nlohmann::json()) != 1) fail("unsupported sensors file version");
  RequireKnownKeys(j, {"format", "version", "channels"}, "sensors file " + source);
  if (!j.contains("channels") || !j["channels"].is_object()) fail("missing object 'channels'");
  SensorSet set;
  for (const auto& [name, c] : j["channels"].items()) {
    wire::Channel ch{};
    if (!ChannelFromStem(name, ch))
      fail("channels: unknown channel '" + Printable(name) +
           "' (force1, force2, acc1, acc2, x1, x2)");
    const std::string where = source + ": channels." + name;
    RequireKnownKeys(c,
                     {"unit", "counts_per_unit", "offset_counts", "full_scale", "dof",
                      "sensitivity_uncertainty", "coverage_factor"},
                     "sensors file " + source + " channels." + name);
    SensorScaling s;
    try {
      s.unit = UnitFromName(c.at("unit").get<std::string>(), where);
      s.counts_per_unit = c.at("counts_per_unit").get<double>();
      const double offset = c.value("offset_counts", 0.0);
      if (offset != std::round(offset) || std::abs(offset) > 2147483647.0)
        fail(name + ".offset_counts must be a 32-bit integer");
      s.offset_counts = static_cast<std::int32_t>(offset);
      s.full_scale = c.at("full_scale").get<double>();
      if (c.contains("dof")) {
        // Checked before the conversion: get<int> of 1e300 or of -2^31 minus one is undefined.
        const nlohmann::json& dof = c.at("dof");
        if (!dof.is_number_integer() || dof.get<std::int64_t>() < 1 ||
            dof.get<std::int64_t>() > static_cast<std::int64_t>(wire::kMaxDof)) {
          fail("channels." + name + ".dof must be 1 to " + std::to_string(wire::kMaxDof));
        }
        s.dof = dof.get<int>() - 1;
      }
      // A certificate's statement: U (relative, expanded) with its coverage factor k.
      if (c.contains("sensitivity_uncertainty")) {
        const nlohmann::json& u = c.at("sensitivity_uncertainty");
        if (!u.is_number() || !std::isfinite(u.get<double>()) || u.get<double>() < 0.0 ||
            u.get<double>() >= 1.0)
          fail("channels." + name +
               ".sensitivity_uncertainty must be a relative uncertainty in [0, 1) (0.02 for 2 %)");
        s.sensitivity_uncertainty = u.get<double>();
      }
      if (c.contains("coverage_factor")) {
        const nlohmann::json& k = c.at("coverage_factor");
        if (!k.is_number() || !std::isfinite(k.get<double>()) || k.get<double>() < 1.0 ||
            k.get<double>() > 10.0)
          fail("channels." + name +
               ".coverage_factor must be the certificate's k, 1 to 10 (2 for about 95 %)");
        if (!c.contains("sensitivity_uncertainty"))
          fail("channels." + name +
               ".coverage_factor is given without sensitivity_uncertainty; give both");
        s.coverage_factor = k.get<double>();
      }
    } catch (const nlohmann::json::exception& e) {
      fail("channels." + name + ": " + e.what());
    }
    if (!std::isfinite(s.counts_per_unit) || s.counts_per_unit == 0.0)
      fail("channels." + name + ".counts_per_unit must be finite and nonzero");
    if (!std::isfinite(s.full_scale) || s.full_scale <= 0.0)
      fail("channels." + name + ".full_scale must be finite and > 0");
    if (s.dof < -1 || s.dof >= static_cast<int>(wire::kMaxDof))
      fail("channels." + name + ".dof must be 1 to " + std::to_string(wire::kMaxDof));
    set[static_cast<std::size_t>(ch)] = s;
  }
  return set;
}

SensorScaling FromChannelScaling(const wire::ChannelScaling& c) {
  SensorScaling s;
  s.unit = c.unit;
  s.offset_counts = c.offset_counts;
  s.full_scale = static_cast<double>(c.full_scale);
  s.dof = c.dof == wire::kNoDof ? -1 : c.dof;
  // SI per count = gain / 2^shift * full_scale / 2^31.
  s.counts_per_unit =
      std::ldexp(1.0, c.gain_shift) * kQ31 / (static_cast<double>(c.gain) * s.full_scale);
  return s;
}

wire::ChannelScaling ToChannelScaling(const SensorScaling& s, const std::string& channel_name) {
  wire::ChannelScaling c;
  c.unit = s.unit;
  c.offset_counts = s.offset_counts;
  c.dof = s.dof < 0 ? wire::kNoDof : static_cast<std::uint8_t>(s.dof);
  c.full_scale = static_cast<float>(s.full_scale);
  // Gain per count in Q31 of the full scale the board stores (binary32).
  const double factor = kQ31 / (s.counts_per_unit * static_cast<double>(c.full_scale));
  int shift = wire::kMaxGainShift;
  while (shift > 0 && std::abs(std::round(std::ldexp(factor, shift))) > 2147483647.0) --shift;
  const double gain = std::round(std::ldexp(factor, shift));
  if (std::abs(gain) > 2147483647.0 || gain == 0.0) {
    throw InputError(channel_name +
                     ": counts_per_unit and full_scale give a gain the board cannot represent");
  }
  c.gain = static_cast<std::int32_t>(gain);
  c.gain_shift = static_cast<std::uint8_t>(shift);
  return c;
}

wire::CalibrationRecord BuildCalibrationRecord(const RecordInputs& in) {
  model::Validate(in.model);
  const int n = in.model.dofs();
  Require(n >= 1 && n <= static_cast<int>(wire::kMaxDof),
          "the board holds models of 1 to " + std::to_string(wire::kMaxDof) +
              " masses; this model has " + std::to_string(n));
  wire::CalibrationRecord r;
  r.dof_count = static_cast<std::uint8_t>(n);
  r.created_unix_s = in.created_unix_s;
  r.host_major = in.host_major;
  r.host_minor = in.host_minor;
  r.host_patch = in.host_patch;
  Require(in.label.size() < wire::kCalLabelBytes,
          "label '" + in.label + "' is longer than 23 characters");
  for (char ch : in.label)
    Require(ch >= 0x20 && ch < 0x7F, "label '" + in.label + "' must be printable ASCII");
  std::copy(in.label.begin(), in.label.end(), r.label.begin());
  for (int i = 0; i < n; ++i) {
    for (int k = 0; k < n; ++k) {
      const auto at = static_cast<std::size_t>(i * static_cast<int>(wire::kMaxDof) + k);
      r.mass_kg[at] = static_cast<float>(in.model.m_kg(i, k));
      r.damping_ns_per_m[at] = static_cast<float>(in.model.c_ns_per_m(i, k));
      r.stiffness_n_per_m[at] = static_cast<float>(in.model.k_n_per_m(i, k));
    }
  }
  SensorSet sensors = in.sensors;
  for (std::size_t c = 0; c < wire::kChannelCount; ++c) {
    if (sensors[c] && sensors[c]->dof >= n) {
      throw InputError(std::string(ChannelStem(static_cast<wire::Channel>(c))) + " sits on mass " +
                       std::to_string(sensors[c]->dof + 1) + " but the model has " +
                       std::to_string(n));
    }
  }
  if (in.observer) {
    const fixed::FilterDescription& d = *in.observer;
    r.flags = wire::kCalFlagHasDob;
    std::array<std::uint8_t, fixed::kDescriptionBytes> bytes{};
    fixed::EncodeDescription(d, bytes);
    std::copy(bytes.begin(), bytes.end(), r.dob.begin());
    for (std::size_t i = 0; i < d.input_count; ++i) {
      const wire::Unit unit = UnitOfInput(d.input_kind[i]);
      bool routed = false;
      for (std::size_t c = 0; c < wire::kChannelCount && !routed; ++c) {
        std::optional<SensorScaling>& s = sensors[c];
        if (!s || s->unit != unit || s->dof != d.input_dof[i]) continue;
        // One range per channel: the sensor's full scale is the channel's, and the observer's
        // Q31 input must mean the same value. Never overwrite one with the other (a 500 N cell
        // cut to a 100 N observer clips every hit above 100 N).
        const float observer_fs = fixed::FullScaleValue(d.input_full_scale_bits[i]);
        if (static_cast<float>(s->full_scale) != observer_fs) {
          const std::string name = ChannelStem(static_cast<wire::Channel>(c));
          const std::string u = UnitName(unit);
          throw InputError(
              name + ": the sensors give a full scale of " + Number(s->full_scale) + " " + u +
              ", the observer's input " + std::to_string(i + 1) + " was designed for " +
              Number(static_cast<double>(observer_fs)) + " " + u +
              "; a channel has one range: design the observer for the sensor's (vibid dob "
              "design " +
              DesignOptionFor(d.input_kind[i]) + " " + Number(s->full_scale) +
              "), or, if the sensor's range is " + Number(static_cast<double>(observer_fs)) + " " +
              u + ", set channels." + name + ".full_scale to it in the sensors file");
        }
        r.dob_input_channel[i] = static_cast<std::uint8_t>(c);
        routed = true;
      }
      if (!routed) {
        throw InputError("the observer's input " + std::to_string(i + 1) + " needs a sensor in " +
                         UnitSuffix(unit) + " on mass " + std::to_string(d.input_dof[i] + 1) +
                         " and the sensors have none");
      }
    }
  }
  for (std::size_t c = 0; c < wire::kChannelCount; ++c) {
    if (sensors[c])
      r.channels[c] = ToChannelScaling(*sensors[c], ChannelStem(static_cast<wire::Channel>(c)));
  }
  std::array<std::uint8_t, wire::kCalRecordBytes> bytes{};
  wire::EncodeCalibrationRecord(r, bytes);
  wire::CalibrationRecord check;
  const Status st = wire::DecodeCalibrationRecord(bytes, check);
  Require(st == Status::kOk,
          std::string("the calibration record would be refused by the board: ") + StatusName(st));
  return r;
}

SensorSet SensorsOfRecord(const wire::CalibrationRecord& record) {
  SensorSet sensors;
  for (std::size_t k = 0; k < wire::kChannelCount; ++k) {
    if (record.channels[k].unit != wire::Unit::kCounts)
      sensors[k] = FromChannelScaling(record.channels[k]);
  }
  return sensors;
}

std::string LabelFromModelPath(const std::string& path) {
  std::string label = path.substr(path.find_last_of('/') + 1);
  if (label.size() > 5 && label.ends_with(".json")) label.resize(label.size() - 5);
  if (label.size() >= wire::kCalLabelBytes) label.resize(wire::kCalLabelBytes - 1);
  return label;
}

}  // namespace vibid::device
