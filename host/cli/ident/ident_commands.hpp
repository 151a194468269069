// Registration of the identification commands and pieces shared between them.
#pragma once

#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "vibid/workflow/modes_request.hpp"
#include "vibid/workflow/result_json.hpp"

namespace vibid::cli {

using ModeArgs = workflow::ModeRequest;
using workflow::MassUpdateJson;
using workflow::PutInterval;
using workflow::StiffnessJson;

void AddModeOptions(CLI::App* cmd, ModeArgs& args);

void RegisterFrfEstimate(CLI::App& app);
void RegisterModes(CLI::App& app);
void RegisterUpdate(CLI::App& app);
void RegisterDecay(CLI::App& app);
void RegisterIdentify(CLI::App& app);

}  // namespace vibid::cli
