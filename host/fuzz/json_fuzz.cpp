// Fuzzes the readers of the toolkit's JSON files: model files (chain, cart and matrix forms; the
// rig files in examples/ are model files), DOB design files, sensors files, and the emulator's
// rig files. The first byte picks the reader; the rest is the file's text, parsed as ReadJsonFile
// parses it (ParseJsonText).
// What is accepted must survive a write: a model through ModelToJson and a rig through RigToJson
// read back equal bit for bit; a sensors set written back as a sensors file reads back equal; a
// design's fixed-point description encodes back to bytes that decode and validate the same.
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "fuzz_support.hpp"
#include "vibid/common/json_file.hpp"
#include "rig.hpp"
#include "vibid/device/calibration_builder.hpp"
#include "vibid/device/log_table.hpp"
#include "vibid/dob/design_json.hpp"
#include "vibid/model/model_json.hpp"
#include "vibid/shared/fixed/filter_description.hpp"

namespace {

using namespace vibid;
using fuzz::Accepts;
using fuzz::Require;

bool SameMatrix(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  if (a.rows() != b.rows() || a.cols() != b.cols()) return false;
  for (Eigen::Index i = 0; i < a.size(); ++i) {
    if (!fuzz::Same(a.data()[i], b.data()[i])) return false;
  }
  return true;
}

void Model(const nlohmann::json& j) {
  std::optional<model::Model> m;
  if (!Accepts([&] { m = model::ModelFromJson(j, "fuzz.json"); })) return;
  std::optional<model::Model> back;
  Require(Accepts([&] {
    back =
        model::ModelFromJson(nlohmann::json::parse(model::ModelToJson(*m).dump(2)), "again.json");
  }));
  Require(SameMatrix(m->m_kg, back->m_kg) && SameMatrix(m->c_ns_per_m, back->c_ns_per_m) &&
          SameMatrix(m->k_n_per_m, back->k_n_per_m));
}

void Design(const nlohmann::json& j) {
  std::optional<dob::ObserverFile> f;
  if (!Accepts([&] { f = dob::ObserverFromJson(j, "fuzz.json"); })) return;
  Require(f->paths.size() == f->description.input_count && f->fs_hz > 0.0);
  std::array<std::uint8_t, fixed::kDescriptionBytes> bytes{};
  fixed::EncodeDescription(f->description, bytes);
  fixed::FilterDescription again{};
  Require(fixed::DecodeDescription(bytes, again) == Status::kOk &&
          fixed::ValidateDescription(again) == Status::kOk);
  std::array<std::uint8_t, fixed::kDescriptionBytes> bytes_again{};
  fixed::EncodeDescription(again, bytes_again);
  Require(bytes == bytes_again);
}

void Sensors(const nlohmann::json& j) {
  std::optional<device::SensorSet> set;
  if (!Accepts([&] { set = device::SensorsFromJson(j, "fuzz.json"); })) return;
  nlohmann::json written = {
      {"format", "vibid-sensors"}, {"version", 1}, {"channels", nlohmann::json::object()}};
  for (std::size_t c = 0; c < set->size(); ++c) {
    const auto& s = (*set)[c];
    if (!s) continue;
    Require(std::isfinite(s->counts_per_unit) && s->counts_per_unit != 0.0 &&
            std::isfinite(s->full_scale) && s->full_scale > 0.0 && s->dof >= -1 &&
            s->dof < static_cast<int>(wire::kMaxDof) && s->unit != wire::Unit::kCounts);
    nlohmann::json channel = {{"unit", device::UnitName(s->unit)},
                              {"counts_per_unit", s->counts_per_unit},
                              {"offset_counts", s->offset_counts},
                              {"full_scale", s->full_scale}};
    if (s->dof >= 0) channel["dof"] = s->dof + 1;
    if (s->sensitivity_uncertainty > 0.0) {
      channel["sensitivity_uncertainty"] = s->sensitivity_uncertainty;
      channel["coverage_factor"] = s->coverage_factor;
    }
    written["channels"][device::ChannelStem(static_cast<wire::Channel>(c))] = channel;
    // What the board is sent: an integer gain and shift, or a refusal naming the channel.
    (void)Accepts([&] { (void)device::ToChannelScaling(*s, "x"); });
  }
  std::optional<device::SensorSet> back;
  Require(Accepts([&] {
    back = device::SensorsFromJson(nlohmann::json::parse(written.dump()), "again.json");
  }));
  for (std::size_t c = 0; c < set->size(); ++c) {
    const auto& a = (*set)[c];
    const auto& b = (*back)[c];
    Require(a.has_value() == b.has_value());
    if (!a) continue;
    Require(a->unit == b->unit && fuzz::Same(a->counts_per_unit, b->counts_per_unit) &&
            a->offset_counts == b->offset_counts && fuzz::Same(a->full_scale, b->full_scale) &&
            a->dof == b->dof);
  }
}

void Rig(const nlohmann::json& j) {
  std::optional<emu::RigSpec> r;
  if (!Accepts([&] { r = emu::RigFromJson(j, "fuzz.json"); })) return;
  std::optional<emu::RigSpec> back;
  Require(Accepts([&] {
    back = emu::RigFromJson(nlohmann::json::parse(emu::RigToJson(*r).dump(2)), "again.json");
  }));
  Require(r->masses_kg == back->masses_kg && r->springs_n_per_m == back->springs_n_per_m &&
          r->dampers_ns_per_m == back->dampers_ns_per_m && r->coulomb_n == back->coulomb_n &&
          r->effective_mass_loss == back->effective_mass_loss &&
          r->encoder_counts_per_m == back->encoder_counts_per_m &&
          r->max_sample_rate_hz == back->max_sample_rate_hz && r->changes == back->changes);
  for (std::size_t i = 0; i < 2; ++i) {
    Require(r->load_cells[i].range == back->load_cells[i].range &&
            r->load_cells[i].adc_bits == back->load_cells[i].adc_bits &&
            r->accelerometers[i].noise_rms == back->accelerometers[i].noise_rms);
  }
  // The emulator builds its simulator from the rig: the truth must be a valid model, at the
  // start and at every change's start and end.
  Require(Accepts([&] { (void)r->Truth(); }));
  for (const emu::RigChange& c : r->changes) {
    Require(Accepts([&] { (void)r->TruthAt(c.at_s); }));
    Require(Accepts([&] { (void)r->TruthAt(c.at_s + c.over_s); }));
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::uint8_t reader = data[0] % 4;
  nlohmann::json j;
  const std::string_view text(reinterpret_cast<const char*>(data + 1), size - 1);
  if (!Accepts([&] { j = ParseJsonText(text, "fuzz.json"); })) return 0;
  switch (reader) {
    case 0: Model(j); break;
    case 1: Design(j); break;
    case 2: Sensors(j); break;
    default: Rig(j); break;
  }
  return 0;
}
