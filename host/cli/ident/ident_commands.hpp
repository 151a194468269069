// Registration of the identification commands and pieces shared between them.
#pragma once

#include <string>

#include <CLI/CLI.hpp>

#include "vibid/ident/modes.hpp"

namespace vibid::cli {

struct ModeArgs {
  std::string method = "fit";
  std::string driving_point;
  ident::ModeIdentificationOptions options;
};

void AddModeOptions(CLI::App* cmd, ModeArgs& args);
std::size_t ResolveDrivingPoint(const ident::Frf& frf, const std::string& spec);
ident::ModeIdentification RunModes(const ident::Frf& receptance, const ModeArgs& args);

void RegisterFrfEstimate(CLI::App& app);
void RegisterModes(CLI::App& app);
void RegisterUpdate(CLI::App& app);
void RegisterDecay(CLI::App& app);
void RegisterIdentify(CLI::App& app);

}  // namespace vibid::cli
