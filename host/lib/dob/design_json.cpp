#include "vibid/dob/design_json.hpp"

#include <cstdint>
#include <cstdio>
#include <limits>
#include <optional>

#include "vibid/common/enum_names.hpp"
#include "vibid/common/error.hpp"
#include "vibid/common/json_keys.hpp"
#include "vibid/common/text_input.hpp"

namespace vibid::dob {
namespace {

std::string Hex(std::span<const std::uint8_t> bytes) {
  static const char* digits = "0123456789abcdef";
  std::string s;
  s.reserve(bytes.size() * 2);
  for (const std::uint8_t b : bytes) {
    s.push_back(digits[b >> 4]);
    s.push_back(digits[b & 0xF]);
  }
  return s;
}

int HexDigit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

nlohmann::json PolyJson(const Eigen::VectorXd& v) {
  return std::vector<double>(v.data(), v.data() + v.size());
}

const char* DiscretizationName(Discretization d) {
  return d == Discretization::kTustin ? "tustin" : "zoh";
}
const char* FormName(ObserverForm f) { return f == ObserverForm::kSiso ? "siso" : "mimo"; }

// The observer's input paths as the design file spells them.
constexpr EnumNames<fixed::InputKind, 4> kInputKindNames{
    {{fixed::InputKind::kForce, "force"},
     {fixed::InputKind::kDisplacement, "disp"},
     {fixed::InputKind::kVelocity, "vel"},
     {fixed::InputKind::kAcceleration, "acc"}}};

// Every key DesignToJson writes, level by level: the reader takes the discrete and fixed parts,
// the rest documents the design, and a misspelt key anywhere is refused.
void RequireDesignKeys(const nlohmann::json& j, const std::string& what) {
  RequireKnownKeys(j,
                   {"format", "version", "options", "q", "butterworth", "plant_relative_degree",
                    "discrete", "fixed", "stable", "valid_band_hz", "predicted_snr_db"},
                   what);
  const auto each = [](const nlohmann::json& parent, const char* key, const auto& check) {
    if (!parent.is_object() || !parent.contains(key) || !parent.at(key).is_array()) return;
    for (const nlohmann::json& item : parent.at(key)) check(item);
  };
  if (j.contains("options"))
    RequireKnownKeys(
        j.at("options"),
        {"N", "r", "tau_s", "fs_hz", "prototype", "sensor", "form", "discretize", "input_dof",
         "output_dof", "leak_hz", "force_full_scale_n", "sensor_full_scale", "output_full_scale_n"},
        what + " options");
  if (j.contains("q")) RequireKnownKeys(j.at("q"), {"num", "den"}, what + " q");
  if (j.contains("discrete")) {
    const nlohmann::json& discrete = j.at("discrete");
    RequireKnownKeys(discrete, {"fs_hz", "inputs", "max_pole_radius"}, what + " discrete");
    each(discrete, "inputs", [&](const nlohmann::json& in) {
      RequireKnownKeys(in, {"kind", "dof", "full_scale", "sos"}, what + " discrete.inputs");
    });
  }
  if (j.contains("fixed")) {
    const nlohmann::json& fixed_part = j.at("fixed");
    RequireKnownKeys(fixed_part,
                     {"bytes", "checksum", "output_full_scale_n", "predicted_noise_rms_n", "paths",
                      "description_hex"},
                     what + " fixed");
    each(fixed_part, "paths", [&](const nlohmann::json& path) {
      RequireKnownKeys(path, {"output_gain", "output_shift", "l1_gain", "sections"},
                       what + " fixed.paths");
      each(path, "sections", [&](const nlohmann::json& section) {
        RequireKnownKeys(section, {"b", "a", "shift", "feedback"}, what + " fixed.paths.sections");
      });
    });
  }
}

}  // namespace

const char* InputKindName(fixed::InputKind kind) { return NameOf(kInputKindNames, kind, "unused"); }

nlohmann::json DesignToJson(const DobDesign& design) {
  Require(design.stable, "an unstable design is not written: " + design.message);
  const DobOptions& o = design.options;
  nlohmann::json j;
  j["format"] = "vibid-dob-design";
  j["version"] = 1;
  j["options"] = {
      {"N", o.order},
      {"r", o.relative_degree},
      {"tau_s", o.tau_s},
      {"fs_hz", o.fs_hz},
      {"prototype", o.prototype == QPrototype::kButterworth ? "butterworth" : "binomial"},
      {"sensor", SensorName(o.sensor)},
      {"form", FormName(o.form)},
      {"discretize", DiscretizationName(o.discretization)},
      {"input_dof", o.input_dof + 1},
      {"output_dof", o.output_dof + 1},
      {"leak_hz", o.leak_hz},
      {"force_full_scale_n", o.force_full_scale_n},
      {"sensor_full_scale", o.sensor_full_scale},
      {"output_full_scale_n", o.output_full_scale_n}};
  j["q"] = {{"num", PolyJson(design.q.num)}, {"den", PolyJson(design.q.den)}};
  j["butterworth"] = PolyJson(design.q.prototype);
  j["plant_relative_degree"] = design.plant_relative_degree;
  nlohmann::json inputs = nlohmann::json::array();
  for (const ObserverPath& p : design.paths) {
    nlohmann::json sos = nlohmann::json::array();
    for (const SosSection& s : p.sos) sos.push_back({s.b0, s.b1, s.b2, 1.0, s.a1, s.a2});
    inputs.push_back({{"kind", InputKindName(p.kind)},
                      {"dof", p.dof + 1},
                      {"full_scale", p.full_scale},
                      {"sos", sos}});
  }
  j["discrete"] = {
      {"fs_hz", o.fs_hz}, {"inputs", inputs}, {"max_pole_radius", design.max_pole_radius}};

  const fixed::FilterDescription& d = design.fixed.description;
  std::array<std::uint8_t, fixed::kDescriptionBytes> bytes{};
  fixed::EncodeDescription(d, bytes);
  nlohmann::json paths = nlohmann::json::array();
  for (std::size_t i = 0; i < d.input_count; ++i) {
    const fixed::Path& p = d.paths[i];
    nlohmann::json sections = nlohmann::json::array();
    for (std::size_t k = 0; k < p.section_count; ++k) {
      const fixed::Section& s = p.sections[k];
      sections.push_back({{"b", {s.b0, s.b1, s.b2}},
                          {"a", {s.a1, s.a2}},
                          {"shift", s.shift},
                          {"feedback", static_cast<int>(s.feedback)}});
    }
    paths.push_back({{"output_gain", p.output_gain},
                     {"output_shift", p.output_shift},
                     {"l1_gain", design.fixed.path_l1_gain[i]},
                     {"sections", sections}});
  }
  char checksum[11];
  std::snprintf(checksum, sizeof(checksum), "0x%08x", d.checksum);
  j["fixed"] = {
      {"bytes", fixed::kDescriptionBytes},
      {"checksum", checksum},
      {"output_full_scale_n", static_cast<double>(fixed::FullScaleValue(d.output_full_scale_bits))},
      {"predicted_noise_rms_n", design.fixed.predicted_noise_rms_n},
      {"paths", paths},
      {"description_hex", Hex(bytes)}};
  j["stable"] = design.stable;
  j["valid_band_hz"] = {design.valid_band_lo_hz, design.valid_band_hi_hz};
  j["predicted_snr_db"] = design.fixed.predicted_snr_db;
  return j;
}

ObserverFile ObserverFromJson(const nlohmann::json& j, const std::string& source) {
  const auto fail = [&](const std::string& what) { throw InputError(source + ": " + what); };
  // Compared as JSON values: a field of another type is a wrong value, not a type error.
  if (!j.is_object() || j.value("format", nlohmann::json()) != "vibid-dob-design")
    fail("not a vibid DOB design file");
  if (j.value("version", nlohmann::json()) != 1) fail("unsupported design file version");
  RequireDesignKeys(j, "design file " + source);
  ObserverFile f;
  try {
    f.fs_hz = j.at("discrete").at("fs_hz").get<double>();
    for (const auto& in : j.at("discrete").at("inputs")) {
      ObserverPath p;
      const std::string kind = in.at("kind").get<std::string>();
      const std::optional<fixed::InputKind> known = FindByName(kInputKindNames, kind);
      if (!known) fail("discrete.inputs: unknown kind '" + Printable(kind) + "'");
      p.kind = *known;
      // Checked before the conversion: get<int> of 1e300 or of -2^31 minus one is undefined.
      const nlohmann::json& dof = in.at("dof");
      if (!dof.is_number_integer() || dof.get<std::int64_t>() < 1 ||
          dof.get<std::int64_t>() > std::numeric_limits<int>::max()) {
        fail("discrete.inputs: dof must be a mass number (1, 2, ...)");
      }
      p.dof = dof.get<int>() - 1;
      p.full_scale = in.at("full_scale").get<double>();
      for (const auto& row : in.at("sos")) {
        const auto v = row.get<std::vector<double>>();
        if (v.size() != 6 || v[3] != 1.0)
          fail("discrete.inputs.sos: rows must be [b0, b1, b2, 1, a1, a2]");
        p.sos.push_back(SosSection{.b0 = v[0], .b1 = v[1], .b2 = v[2], .a1 = v[4], .a2 = v[5]});
      }
      f.paths.push_back(std::move(p));
    }
    const std::string hex = j.at("fixed").at("description_hex").get<std::string>();
    if (hex.size() != 2 * fixed::kDescriptionBytes) {
      fail("fixed.description_hex must hold " + std::to_string(fixed::kDescriptionBytes) +
           " bytes");
    }
    std::array<std::uint8_t, fixed::kDescriptionBytes> bytes{};
    for (std::size_t i = 0; i < bytes.size(); ++i) {
      const int hi = HexDigit(hex[2 * i]);
      const int lo = HexDigit(hex[2 * i + 1]);
      if (hi < 0 || lo < 0) fail("fixed.description_hex is not hexadecimal");
      bytes[i] = static_cast<std::uint8_t>(hi * 16 + lo);
    }
    static_cast<void>(fixed::DecodeDescription(bytes, f.description));
  } catch (const nlohmann::json::exception& e) {
    fail(std::string("malformed design: ") + e.what());
  }
  const Status st = fixed::ValidateDescription(f.description);
  if (st != Status::kOk)
    fail(std::string("the fixed-point description is refused: ") + StatusName(st));
  if (f.paths.size() != f.description.input_count)
    fail("discrete and fixed parts disagree on the input count");
  if (!(f.fs_hz > 0.0) || f.fs_hz != f.description.sample_rate_hz)
    fail("discrete and fixed parts disagree on fs_hz");
  return f;
}

}  // namespace vibid::dob
