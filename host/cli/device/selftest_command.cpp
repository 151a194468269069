// vibid selftest: the board checks itself, one numbered check per request.
#include <iomanip>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/command.hpp"
#include "device_commands.hpp"
#include "session.hpp"
#include "vibid/device/error.hpp"
#include "vibid/device/health_report.hpp"
#include "vibid/device/info_json.hpp"

namespace vibid::cli {
namespace {

constexpr const char* kSelfTestHelp =
    "Ask the board to check itself (crystal, supply, converter noise and offsets, encoders, "
    "image, calibration slots, brown-out level) and print each check; exit 4 if one fails";

struct SelfTestArgs {
  const GlobalOptions* globals = nullptr;
  bool json = false;
};

bool IsNamed(wire::SelfTestUnit unit) {
  return unit == wire::SelfTestUnit::kCrc32 || unit == wire::SelfTestUnit::kSlot ||
         unit == wire::SelfTestUnit::kBrownOut || unit == wire::SelfTestUnit::kResetCause;
}

nlohmann::json CheckJson(const wire::SelfTestResponse& r) {
  const bool available = r.verdict != wire::SelfTestVerdict::kUnavailable;
  nlohmann::json value = nullptr;
  if (available) {
    value = IsNamed(r.unit) ? nlohmann::json(device::SelfTestValueText(r))
                            : nlohmann::json(device::SelfTestValue(r));
  }
  return {{"number", r.check},
          {"name", wire::SelfTestCheckName(r.check)},
          {"value", value},
          {"unit", device::SelfTestUnitName(r.unit)},
          {"reference", r.reference == wire::SelfTestReference::kNone
                            ? nlohmann::json(nullptr)
                            : nlohmann::json(device::SelfTestReferenceName(r.reference))},
          {"pass", available ? nlohmann::json(r.verdict == wire::SelfTestVerdict::kPass)
                             : nlohmann::json(nullptr)},
          {"verdict", r.verdict == wire::SelfTestVerdict::kFail
                          ? "fail"
                          : device::SelfTestVerdictName(r.verdict)}};
}

void Run(const SelfTestArgs& a) {
  std::vector<wire::SelfTestResponse> checks;
  std::optional<wire::FaultInfoResponse> fault;
  WithDevice(*a.globals, [&](device::Connection& c) {
    if (c.info().protocol_minor < 1) {
      throw device::DeviceError(
          "the board's firmware speaks protocol 2.0, which has no self-test; update it "
          "(vibid flash)");
    }
    // The first answer says how many checks the board has.
    checks.push_back(c.SelfTest(0));
    for (std::uint8_t k = 1; k < checks.front().check_count; ++k) checks.push_back(c.SelfTest(k));
    // A reset-cause check that says "fault": where the board crashed, from its record.
    for (const auto& r : checks) {
      if (r.unit == wire::SelfTestUnit::kResetCause &&
          r.mantissa == static_cast<std::int64_t>(wire::ResetCause::kFault))
        fault = c.GetFaultInfo();
    }
  });
  std::string failed;
  std::size_t failures = 0;
  if (a.json) {
    nlohmann::json list = nlohmann::json::array();
    for (const auto& r : checks) list.push_back(CheckJson(r));
    nlohmann::json fault_json = nullptr;
    if (fault && fault->recorded != 0) fault_json = device::FaultJson(*fault);
    std::cout << nlohmann::json{{"checks", list}, {"fault", fault_json}}.dump(2) << "\n";
  } else {
    std::cout << " #  check          value         unit     verdict\n";
  }
  std::size_t passed = 0;
  std::size_t unavailable = 0;
  for (const auto& r : checks) {
    if (!a.json) {
      std::cout << std::setw(2) << static_cast<int>(r.check) << "  " << std::left << std::setw(15)
                << wire::SelfTestCheckName(r.check) << std::setw(14) << device::SelfTestValueText(r)
                << std::setw(9) << device::SelfTestUnitName(r.unit)
                << device::SelfTestVerdictName(r.verdict) << std::right;
      if (r.reference != wire::SelfTestReference::kNone)
        std::cout << "  (against " << device::SelfTestReferenceName(r.reference) << ")";
      std::cout << "\n";
    }
    if (r.verdict == wire::SelfTestVerdict::kPass) ++passed;
    if (r.verdict == wire::SelfTestVerdict::kUnavailable) ++unavailable;
    if (r.verdict == wire::SelfTestVerdict::kFail) {
      ++failures;
      failed += (failed.empty() ? "" : ", ") + std::to_string(r.check) + " " +
                wire::SelfTestCheckName(r.check);
    }
  }
  if (!a.json && fault && fault->recorded != 0)
    std::cout << "fault record: " << device::FaultText(*fault) << "\n";
  if (!a.json) {
    std::cout << checks.size() << " checks: " << passed << " pass, " << failures << " fail, "
              << unavailable << " not measured on this board\n";
  }
  if (failures != 0) {
    throw device::DeviceError("self-test: " + std::to_string(failures) + " of " +
                              std::to_string(checks.size()) + " checks failed (" + failed +
                              "); docs/board.md, \"Self-test\", says what each one means");
  }
}

}  // namespace

void RegisterSelfTestCommand(CLI::App& app, const GlobalOptions& globals) {
  const auto [cmd, args] = AddCommand<SelfTestArgs>(app, "selftest", kSelfTestHelp, Run);
  args->globals = &globals;
  TakesDeviceOption(cmd);
  cmd->add_flag("--json", args->json,
                "Print JSON: {\"checks\": [{\"number\", \"name\", "
                "\"value\", \"unit\", \"reference\", \"pass\", \"verdict\"}]}");
}

}  // namespace vibid::cli
