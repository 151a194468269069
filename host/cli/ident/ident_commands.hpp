// Registration of the identification commands and pieces shared between them.
#pragma once

#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "vibid/ident/modes.hpp"
#include "vibid/ident/updates.hpp"

namespace vibid::cli {

struct ModeArgs {
  std::string method = "lscf";
  std::string orders;  ///< "MIN:MAX[:STEP]" for lscf/lsce; empty: the defaults.
  std::string driving_point;
  ident::ModeIdentificationOptions options;
};

void AddModeOptions(CLI::App* cmd, ModeArgs& args);
std::size_t ResolveDrivingPoint(const ident::Frf& frf, const std::string& spec);
ident::ModeIdentification RunModes(const ident::Frf& receptance, const ModeArgs& args);

nlohmann::json MassUpdateJson(const ident::MassUpdateResult& result);
/// Sets `KEY_ci95` to [lo, hi] and `KEY_ci95_basis` to how it was estimated, or `KEY_ci95` to
/// null and `KEY_ci95_missing` to why there is none.
void PutInterval(nlohmann::json& j, const std::string& key, const ident::Interval95& ci);
nlohmann::json StiffnessJson(const ident::StiffnessAverage& average);

void RegisterFrfEstimate(CLI::App& app);
void RegisterModes(CLI::App& app);
void RegisterUpdate(CLI::App& app);
void RegisterDecay(CLI::App& app);
void RegisterIdentify(CLI::App& app);

}  // namespace vibid::cli
