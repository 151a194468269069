#include "scenario.hpp"

#include <cmath>
#include <cstring>
#include <string_view>

namespace vibid::emu {
namespace {

bool Valid(float p) { return std::isfinite(p) && p >= 0.0f; }

double OrDefault(float p, double fallback) { return p == 0.0f ? fallback : static_cast<double>(p); }

constexpr float kMaxMassParam = static_cast<float>(kMaxMasses);

// A 1-based mass parameter and a configuration parameter, checked against the rig; a mass left
// at 0 is the mass alone, else `chain_default` (1-based).
bool MassAndConfiguration(float mass_param, float config_param, int dofs, int chain_default,
                          Scenario& s) {
  if (config_param != std::floor(config_param) || config_param > kMaxMassParam) return false;
  s.configuration = static_cast<Configuration>(static_cast<int>(config_param));
  const int alone = AloneMass(s.configuration) + 1;  // 0 for the chain
  if (alone > dofs) return false;
  if (mass_param != std::floor(mass_param) || mass_param > kMaxMassParam) return false;
  int mass = static_cast<int>(mass_param);
  if (mass == 0) mass = alone != 0 ? alone : chain_default;
  if (mass > dofs || (alone != 0 && mass != alone)) return false;
  s.mass = mass - 1;
  return true;
}

}  // namespace

Status ParseScenario(const wire::ScenarioRequest& request, int dofs, Scenario& out,
                     wire::Refusal* why, int hammer_mass) {
  const std::size_t length = strnlen(request.name.data(), request.name.size());
  const std::string_view name(request.name.data(), length);
  const auto refuse = [why](wire::Reason reason, std::uint32_t detail) {
    if (why != nullptr) *why = wire::Refusal{.reason = reason, .detail = detail};
    return Status::kInvalidArgument;
  };
  const auto bad_parameter = [&](std::uint32_t index) {
    return refuse(wire::Reason::kScenarioParameter, index);
  };
  if (name != "idle" && name != "hammer" && name != "shaker" && name != "push" && name != "step" &&
      name != "tone" && name != "operate")
    return refuse(wire::Reason::kUnknownScenario, 0);
  for (std::uint32_t i = 0; i < request.params.size(); ++i) {
    if (!Valid(request.params[i])) return bad_parameter(i);
  }
  const auto& p = request.params;
  // The first parameter a mass-and-configuration check blames: the configuration if it alone
  // is out of range, else the mass.
  const auto mass_or_configuration = [&] {
    return bad_parameter(
        p[3] != std::floor(p[3]) || p[3] > kMaxMassParam || static_cast<int>(p[3]) > dofs ? 3 : 0);
  };
  Scenario s;
  if (name == "idle") {
    s.kind = ScenarioKind::kIdle;
  } else if (name == "hammer") {
    s.kind = ScenarioKind::kHammer;
    const int chain_default = hammer_mass >= 0 && hammer_mass < dofs ? hammer_mass + 1 : dofs;
    if (!MassAndConfiguration(p[0], p[3], dofs, chain_default, s)) return mass_or_configuration();
    s.force_n = OrDefault(p[1], 100.0);
    s.spacing_s = static_cast<double>(p[2]);  // 0: from the rig when selected
    if (s.spacing_s != 0.0 && s.spacing_s < 0.05) return bad_parameter(2);
  } else if (name == "shaker") {
    s.kind = ScenarioKind::kShaker;
    s.mass = dofs - 1;
    s.frequency_hz = OrDefault(p[0], 16.0);
    s.force_n = OrDefault(p[1], 10.0);
    s.push_n = static_cast<double>(p[2]);
    if (p[3] != 0.0f) return bad_parameter(3);
  } else if (name == "push") {
    s.kind = ScenarioKind::kPush;
    s.force_n = OrDefault(p[0], 10.0);
    for (std::uint32_t i = 1; i < p.size(); ++i) {
      if (p[i] != 0.0f) return bad_parameter(i);
    }
  } else if (name == "step") {
    s.kind = ScenarioKind::kStep;
    if (!MassAndConfiguration(p[0], p[3], dofs, dofs, s)) return mass_or_configuration();
    s.force_n = OrDefault(p[1], 20.0);
    s.hold_s = OrDefault(p[2], 1.0);
  } else if (name == "operate") {
    s.kind = ScenarioKind::kOperate;
    s.force_n = OrDefault(p[0], 2.0);
    // 0: from the rig when selected (DefaultOperateBandHz); a band below 1 Hz would leave the
    // modes of any rig undriven.
    s.frequency_hz = static_cast<double>(p[1]);
    if (s.frequency_hz != 0.0 && s.frequency_hz < 1.0) return bad_parameter(1);
    const int chain_default = hammer_mass >= 0 && hammer_mass < dofs ? hammer_mass + 1 : dofs;
    if (!MassAndConfiguration(p[2], 0.0f, dofs, chain_default, s)) return bad_parameter(2);
    s.push_n = static_cast<double>(p[3]);
  } else {
    s.kind = ScenarioKind::kTone;
    s.frequency_hz = OrDefault(p[0], 1000.0);
    s.amplitude = OrDefault(p[1], 0.5);
    if (s.amplitude > 1.0) return bad_parameter(1);
    for (std::uint32_t i = 2; i < p.size(); ++i) {
      if (p[i] != 0.0f) return bad_parameter(i);
    }
  }
  out = s;
  return Status::kOk;
}

}  // namespace vibid::emu
