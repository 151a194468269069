#include "scenario.hpp"

#include <cmath>
#include <cstring>
#include <string_view>

namespace vibid::emu {
namespace {

bool Valid(float p) { return std::isfinite(p) && p >= 0.0f; }

double OrDefault(float p, double fallback) { return p == 0.0f ? fallback : static_cast<double>(p); }

// A 1-based mass parameter and a configuration parameter, checked against the rig.
bool MassAndConfiguration(float mass_param, float config_param, int dofs, Scenario& s) {
  if (config_param != std::floor(config_param) || config_param > 2.0f) return false;
  s.configuration = static_cast<Configuration>(static_cast<int>(config_param));
  const int alone = s.configuration == Configuration::kMass1Alone   ? 1
                    : s.configuration == Configuration::kMass2Alone ? 2
                                                                    : 0;
  if (alone > dofs) return false;
  if (mass_param != std::floor(mass_param) || mass_param > 2.0f) return false;
  int mass = static_cast<int>(mass_param);
  if (mass == 0) mass = alone != 0 ? alone : dofs;
  if (mass > dofs || (alone != 0 && mass != alone)) return false;
  s.mass = mass - 1;
  return true;
}

}  // namespace

Status ParseScenario(const wire::ScenarioRequest& request, int dofs, Scenario& out) {
  const std::size_t length = strnlen(request.name.data(), request.name.size());
  const std::string_view name(request.name.data(), length);
  for (float p : request.params) {
    if (!Valid(p)) return Status::kInvalidArgument;
  }
  const auto& p = request.params;
  Scenario s;
  if (name == "idle") {
    s.kind = ScenarioKind::kIdle;
  } else if (name == "hammer") {
    s.kind = ScenarioKind::kHammer;
    if (!MassAndConfiguration(p[0], p[3], dofs, s)) return Status::kInvalidArgument;
    s.force_n = OrDefault(p[1], 100.0);
    s.spacing_s = static_cast<double>(p[2]);  // 0: from the rig when selected
    if (s.spacing_s != 0.0 && s.spacing_s < 0.05) return Status::kInvalidArgument;
  } else if (name == "shaker") {
    s.kind = ScenarioKind::kShaker;
    s.mass = dofs - 1;
    s.frequency_hz = OrDefault(p[0], 16.0);
    s.force_n = OrDefault(p[1], 10.0);
    s.push_n = static_cast<double>(p[2]);
    if (p[3] != 0.0f) return Status::kInvalidArgument;
  } else if (name == "push") {
    s.kind = ScenarioKind::kPush;
    s.force_n = OrDefault(p[0], 10.0);
    if (p[1] != 0.0f || p[2] != 0.0f || p[3] != 0.0f) return Status::kInvalidArgument;
  } else if (name == "step") {
    s.kind = ScenarioKind::kStep;
    if (!MassAndConfiguration(p[0], p[3], dofs, s)) return Status::kInvalidArgument;
    s.force_n = OrDefault(p[1], 20.0);
    s.hold_s = OrDefault(p[2], 1.0);
  } else {
    return Status::kInvalidArgument;
  }
  out = s;
  return Status::kOk;
}

}  // namespace vibid::emu
